//! One beta SDP (eq. (bet)) for n = 4, p = 2 (target <= 5 ms) and the full lambda
//! optimisation of eq. (theta) (target <= 0.3 s). Results: BENCHMARKS.md, `## lmi`.
#![allow(non_snake_case)]

use criterion::{criterion_group, criterion_main, Criterion};
use lmi::fixtures::random_hurwitz_system;
use lmi::{certified_beta, hurwitz_mu, optimise_lambda, solve_beta_sdp, BetaSdpSettings, LambdaSearchSettings};
use std::hint::black_box;
use std::time::Duration;

/// theta of eq. (theta) with psi of eq. (phipsi), for fixed alpha, gamma_1, gamma_inf.
fn theta(alpha: f64, gamma_1: f64, gamma_inf: f64) -> impl Fn(f64, f64) -> f64 {
    move |lambda: f64, beta: f64| {
        let psi = |g: f64| (beta + 0.25 * (alpha - lambda + g).powi(2)).sqrt() - 0.5 * (alpha + lambda + g);
        psi(0.0) - gamma_1 / gamma_inf * (psi(0.0) - psi(gamma_inf))
    }
}

fn bench(c: &mut Criterion) {
    let (F, E, C) = random_hurwitz_system(42, 4, 2);
    let lambda = 0.5 * -hurwitz_mu(&F).unwrap();
    let s = BetaSdpSettings::default();
    c.bench_function("beta_sdp n=4 p=2 (solve)", |b| {
        b.iter(|| black_box(solve_beta_sdp(&F, &E, &C, black_box(lambda), &s).unwrap()))
    });
    c.bench_function("beta_sdp n=4 p=2 (solve + verify)", |b| {
        b.iter(|| black_box(certified_beta(&F, &E, &C, black_box(lambda), &s).unwrap()))
    });
    let ls = LambdaSearchSettings::default();
    let mut g = c.benchmark_group("lambda_search");
    g.sample_size(10).measurement_time(Duration::from_secs(5));
    g.bench_function("optimise_lambda n=4 p=2 (grid 12 + golden)", |b| {
        b.iter(|| black_box(optimise_lambda(&F, &E, &C, theta(0.0, 0.2, 1.0), &ls).unwrap()))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
