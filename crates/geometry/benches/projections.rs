//! Projections per second for the shapes used as backlash sets (issue: geometry benchmark).
//! Results are recorded in BENCHMARKS.md.
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use geometry::{Ball, ConvexSet, Ellipsoid, Interval, Shape};
use nalgebra::DMatrix;
use std::hint::black_box;

const N: usize = 1024;

fn points(p: usize) -> Vec<f64> {
    // deterministic pseudo-random points, half inside, half outside typical sets
    let mut s = 0x9E3779B97F4A7C15u64;
    (0..N * p)
        .map(|_| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 * 0.6 - 0.3
        })
        .collect()
}

fn bench_set<S: ConvexSet>(c: &mut Criterion, name: &str, set: &S) {
    let p = set.dim();
    let xs = points(p);
    let mut out = vec![0.0; p];
    let mut g = c.benchmark_group("projection");
    g.throughput(Throughput::Elements(N as u64));
    g.bench_function(name, |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for x in xs.chunks_exact(p) {
                set.project(black_box(x), &mut out);
                acc += out[0];
            }
            black_box(acc)
        })
    });
    g.finish();
}

fn projections(c: &mut Criterion) {
    let interval = Interval::symmetric(0.1).unwrap();
    bench_set(c, "interval", &interval);
    bench_set(c, "shape_enum_interval", &Shape::Interval(interval));
    bench_set(c, "ball_p2", &Ball::centred(2, 0.1).unwrap());
    let m2 = DMatrix::from_row_slice(2, 2, &[0.01, 0.002, 0.002, 0.004]);
    bench_set(c, "ellipsoid_p2", &Ellipsoid::new(vec![0.0, 0.0], &m2).unwrap());
    let m3 = DMatrix::from_row_slice(3, 3, &[0.01, 0.002, 0.0, 0.002, 0.004, 0.001, 0.0, 0.001, 0.0025]);
    bench_set(c, "ellipsoid_p3", &Ellipsoid::new(vec![0.0, 0.0, 0.0], &m3).unwrap());
}

criterion_group!(benches, projections);
criterion_main!(benches);
