//! Catching-up throughput: n = 2, p = 1 interval (worked example) and n = 6, p = 2 ellipse.
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use dynamics::integrators::catching_up::{CatchingUpSettings, FastCatchingUp};
use geometry::{Ellipsoid, Interval};
use nalgebra::SVector;

const STEPS: usize = 1_000_000;

fn six_two() -> model::System {
    model::parse_str(include_str!("../examples/six_two.toml")).unwrap()
}

fn bench(c: &mut Criterion) {
    let sys = model::parse_str(include_str!("../../../examples/worked-example.toml")).unwrap();
    let mut g = c.benchmark_group("catching_up");
    g.throughput(Throughput::Elements(STEPS as u64));
    g.sample_size(10);
    let mut f =
        FastCatchingUp::<2, 1, Interval>::new(&sys, Interval::symmetric(0.1).unwrap(), &CatchingUpSettings::default())
            .unwrap();
    g.bench_function("n2_p1_interval", |b| {
        b.iter(|| {
            let mut x = SVector::<f64, 2>::zeros();
            let mut z = SVector::<f64, 1>::zeros();
            f.run(0.0, &mut x, &mut z, STEPS, |_, _, _, _| {});
            std::hint::black_box((x, z))
        })
    });
    let s6 = six_two();
    let geometry::Shape::Ellipsoid(e) = s6.theta.clone() else { panic!("ellipse expected") };
    let mut f6 = FastCatchingUp::<6, 2, Ellipsoid>::new(&s6, e, &CatchingUpSettings::default()).unwrap();
    g.bench_function("n6_p2_ellipse", |b| {
        b.iter(|| {
            let mut x = SVector::<f64, 6>::zeros();
            let mut z = SVector::<f64, 2>::zeros();
            f6.run(0.0, &mut x, &mut z, STEPS, |_, _, _, _| {});
            std::hint::black_box((x, z))
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
