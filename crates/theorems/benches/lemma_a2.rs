//! Throughput of the campaign on Lemma A2 (eq. (lem1:2)) with ellipsoids: cases per second on
//! one core, generation (proptest strategy, ellipsoid construction with its eigen-decomposition,
//! support points) and evaluation included. Target: >= 1e5 cases/s.
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use proptest::strategy::{Strategy, ValueTree};
use proptest::test_runner::{Config, TestRunner};
use theorems::properties::{lemma_a2, Variant};

const BATCH: u64 = 1000;

fn bench(c: &mut Criterion) {
    let strat = lemma_a2::strategy_ellipsoids();
    let mut runner = TestRunner::new_with_rng(Config::default(), theorems::campaign::chunk_rng(1, "bench", 0));
    let mut g = c.benchmark_group("lemma_a2");
    g.throughput(Throughput::Elements(BATCH));
    g.bench_function("ellipsoid cases (generate + check), batch of 1000", |b| {
        b.iter(|| {
            let mut bad = 0u32;
            for _ in 0..BATCH {
                let case = strat.new_tree(&mut runner).unwrap().current();
                if lemma_a2::eval(&case, Variant::Claim).violated() {
                    bad += 1;
                }
            }
            assert_eq!(bad, 0);
            bad
        })
    });
    // check only (pre-generated cases): the cost of the inequality itself
    let cases: Vec<_> = (0..BATCH).map(|_| strat.new_tree(&mut runner).unwrap().current().build()).collect();
    g.bench_function("ellipsoid cases (check only), batch of 1000", |b| {
        b.iter(|| cases.iter().filter(|p| lemma_a2::eval_pair(p, Variant::Claim).violated()).count())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
