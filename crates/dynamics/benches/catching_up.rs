//! Catching-up throughput: n = 2, p = 1 interval (worked example) and n = 6, p = 2 ellipse, one
//! trajectory; and the SIMD ensemble (`dynamics::integrators::ensemble`) of 1,000 trajectories
//! of the worked example and of the n = 6, p = 2 ellipse (throughput in trajectory-steps).
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use dynamics::integrators::catching_up::{CatchingUpSettings, FastCatchingUp};
use dynamics::integrators::ensemble::{EnsembleCatchingUp, EnsembleState};
use geometry::{Ellipsoid, Interval};
use nalgebra::SVector;

const STEPS: usize = 1_000_000;
/// Ensemble benches: trajectories and steps.
const ENS: usize = 1000;
const ENS_STEPS: usize = 10_000;

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

    let mut g = c.benchmark_group("ensemble");
    g.sample_size(10);
    let st = CatchingUpSettings::default();
    g.throughput(Throughput::Elements((ENS * ENS_STEPS) as u64));
    let mut e = EnsembleCatchingUp::<2, 1>::new(&sys, &st).unwrap();
    g.bench_function("n2_p1_interval_1000", |b| {
        b.iter(|| {
            let mut s = EnsembleState::from_fn(2, 1, ENS, |j, x, z| {
                x[0] = 0.01 * j as f64 / ENS as f64;
                z[0] = x[0];
            });
            e.run(0.0, &mut s, ENS_STEPS);
            std::hint::black_box(s)
        })
    });
    // the ellipse is projected lane by lane (scalar secular equation): fewer steps
    let steps6 = ENS_STEPS / 10;
    g.throughput(Throughput::Elements((ENS * steps6) as u64));
    let mut e6 = EnsembleCatchingUp::<6, 2>::new(&s6, &st).unwrap();
    g.bench_function("n6_p2_ellipse_1000", |b| {
        b.iter(|| {
            let mut s = EnsembleState::zeros(6, 2, ENS);
            e6.run(0.0, &mut s, steps6);
            std::hint::black_box(s)
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
