//! `bounds::assemble` on the examples with p <= 2 (the `moreau theta` workload minus
//! file parsing and printing): bound only, and with the measured side and the stationary set.
use bounds::{assemble, ThetaSettings};
use criterion::{criterion_group, criterion_main, Criterion};

fn load(name: &str) -> model::System {
    model::load(std::path::Path::new(&format!("{}/../../examples/{name}", env!("CARGO_MANIFEST_DIR")))).unwrap()
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("theta");
    g.sample_size(10);
    for file in ["worked-example.toml", "worked-example-a5.toml", "ellipse-p2.toml", "lens-p2.toml", "polytope-p2.toml"]
    {
        let sys = load(file);
        let full = ThetaSettings::default();
        let bound = ThetaSettings::bound_only();
        g.bench_function(format!("{file} full"), |b| b.iter(|| assemble(&sys, &full).unwrap()));
        g.bench_function(format!("{file} bound only"), |b| b.iter(|| assemble(&sys, &bound).unwrap()));
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
