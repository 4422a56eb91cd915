//! Speed of `diagnose` on a 50,000-sample recording against all hypotheses (rayon over
//! hypotheses, folds, starts and Jacobian columns; run with RAYON_NUM_THREADS=2 for the 2-core
//! target of issue 27 item 5, <= 8 s). The per-case, record-length, hypotheses and threads
//! tables are `examples/speed.rs` (BENCHMARKS.md, "Speed (issue 27 item 5)").
use criterion::{criterion_group, criterion_main, Criterion};
use discovery::{diagnose, DiagnoseSettings, Recording};
use dynamics::extended::ExtendedModel;

fn long_recording() -> (model::System, Recording) {
    let case = discovery::bench_gen::generate("coulomb_friction", 3, 0);
    let sys = case.nominal.clone();
    let dt = case.recording.dt;
    let n = 50_000;
    let w: Vec<f64> = (0..n)
        .map(|k| {
            let t = k as f64 * dt;
            0.6 * (0.31 * t).sin() + 0.3 * (0.97 * t + 1.0).sin() + 0.2 * (2.3 * t + 2.0).sin()
        })
        .collect();
    let truth = case.truth.clone().into_iter().collect::<Vec<_>>();
    let y = ExtendedModel::new(&sys, &truth, dt, 8).unwrap().simulate(&w, dt, sys.x0.as_slice()).y;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
    // Deterministic pseudo-noise at about 1 % of the output range.
    let yr = y.iter().copied().fold(f64::NEG_INFINITY, f64::max) - y.iter().copied().fold(f64::INFINITY, f64::min);
    let ys: Vec<Vec<f64>> =
        y.iter().enumerate().map(|(k, v)| vec![v + 0.01 * yr * (((k * 7919) % 1000) as f64 / 1000.0 - 0.5)]).collect();
    let rec = Recording::from_samples("long", &t, w.iter().map(|v| vec![*v]).collect(), ys, None);
    (sys, rec)
}

fn bench(c: &mut Criterion) {
    let (sys, rec) = long_recording();
    let mut g = c.benchmark_group("diagnose");
    g.sample_size(10);
    g.bench_function("50k_samples_all_hypotheses", |b| {
        b.iter(|| diagnose(&sys, &rec, &DiagnoseSettings::default()).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
