//! Speed of `moreau sweep` on the worked example (NOTES.md): one point (theta with the measured
//! side, as in examples/sweeps/amplitude.toml) and the 10-point example sweep end to end
//! (tables included) on 2 threads. The 200-point timing of BENCHMARKS.md (## sweep) is the CLI
//! run of examples/sweeps/amplitude-200.toml.
use criterion::{criterion_group, criterion_main, Criterion};
use moreau::sweep::theta_eval::ThetaEvaluator;
use moreau::sweep::{Evaluator, RunOptions, SweepSpec};
use std::path::Path;

fn bench(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let spec = SweepSpec::load(&root.join("examples/sweeps/amplitude.toml")).unwrap();
    let ev = ThetaEvaluator::from_table(&spec.evaluate, &spec.path).unwrap();
    let sys = spec.system_at(3).unwrap(); // amplitude 1
    let mut g = c.benchmark_group("sweep");
    g.sample_size(10);
    g.bench_function("point_worked_example_a1_theta_and_measured", |b| b.iter(|| ev.evaluate(&sys).unwrap()));
    let mut bound_only = ev.clone();
    bound_only.settings.measure = None;
    g.bench_function("point_worked_example_a1_theta_only", |b| b.iter(|| bound_only.evaluate(&sys).unwrap()));
    let tmp = tempfile::tempdir().unwrap();
    g.bench_function("sweep_10_points_2_threads", |b| {
        b.iter(|| {
            moreau::sweep::run(
                &spec,
                &ev,
                &RunOptions { out: tmp.path().to_path_buf(), threads: Some(2), fresh: true, ..Default::default() },
            )
            .unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
