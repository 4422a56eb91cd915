//! Speed of `diagnose` on a 50,000-sample recording against all hypotheses (rayon over
//! hypotheses, folds, starts and Jacobian columns; run with RAYON_NUM_THREADS=2 for the 2-core
//! target of issue 27 item 5, <= 8 s). The per-case, record-length, hypotheses and threads
//! tables are `examples/speed.rs` (BENCHMARKS.md, "Speed (issue 27 item 5)").
use criterion::{criterion_group, criterion_main, Criterion};
use discovery::bench_gen::long_record::{self, LongNoise};
use discovery::{diagnose, DiagnoseSettings, Recording};

fn long_recording() -> (model::System, Recording) {
    long_record::long_recording(50_000, LongNoise::Sawtooth)
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
