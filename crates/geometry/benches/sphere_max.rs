//! Certified sphere maxima of sublinear functions for `p >= 4` (issue 15 item 6): the
//! simplicial-cone branch and bound of `sublinear_sphere_max` against the Lipschitz branch and
//! bound `sphere_max` (its former fallback), in the same run, at the production settings
//! (`tol_abs 1e-9`, `tol_rel 1e-6`, `max_evals 20_000` scaled by
//! `SphereMaxSettings::scaled_for_dimension`: 60,000 for `p = 5`). The looseness
//! `upper/true - 1` of each is printed once before the timings.
use criterion::{criterion_group, criterion_main, Criterion};
use geometry::{sphere_max, sublinear_sphere_max, SphereMaxSettings};
use std::hint::black_box;

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// `(name, p, g, Lipschitz constant of g on the sphere, true maximum)`: support functions of
/// balls of radius 0.7, centred at 0 (every direction maximal: the hardest case) and at `c`.
#[allow(clippy::type_complexity)]
fn cases() -> Vec<(String, usize, Box<dyn Fn(&[f64]) -> f64>, f64, f64)> {
    let mut out: Vec<(String, usize, Box<dyn Fn(&[f64]) -> f64>, f64, f64)> = Vec::new();
    for p in [4usize, 5] {
        out.push((format!("centred_ball_p{p}"), p, Box::new(|v: &[f64]| 0.7 * norm(v)), 0.7, 0.7));
        let c: Vec<f64> = (0..p).map(|i| 0.1 * (i as f64 + 1.0) * if i % 2 == 0 { 1.0 } else { -1.0 }).collect();
        let (cn, c2) = (norm(&c), c.clone());
        let g = move |v: &[f64]| 0.7 * norm(v) + c2.iter().zip(v).map(|(a, b)| a * b).sum::<f64>();
        out.push((format!("offcentre_ball_p{p}"), p, Box::new(g), 0.7 + cn, 0.7 + cn));
    }
    out
}

fn bench(c: &mut Criterion) {
    let base = SphereMaxSettings { tol_abs: 1e-9, tol_rel: 1e-6, max_evals: 20_000 };
    let cases = cases();
    for (name, p, g, lip, truth) in &cases {
        let s = base.scaled_for_dimension(*p);
        // evaluations decide the time when g is expensive (the tube support functions)
        let (mut na, mut nb) = (0usize, 0usize);
        let a = sublinear_sphere_max(
            *p,
            |v| {
                na += 1;
                g(v)
            },
            *lip,
            &s,
        );
        let b = sphere_max(
            *p,
            |v| {
                nb += 1;
                g(v)
            },
            *lip,
            &s,
        );
        eprintln!(
            "{name}: cones upper/true - 1 = {:.3e} ({na} evaluations); lipschitz {:.3e} ({nb} evaluations)",
            a.upper / truth - 1.0,
            b.upper / truth - 1.0
        );
    }
    let mut grp = c.benchmark_group("sphere_max");
    grp.sample_size(10);
    for (name, p, g, lip, _) in &cases {
        let s = base.scaled_for_dimension(*p);
        grp.bench_function(format!("cones/{name}"), |bch| {
            bch.iter(|| black_box(sublinear_sphere_max(*p, g, *lip, black_box(&s))))
        });
        grp.bench_function(format!("lipschitz/{name}"), |bch| {
            bch.iter(|| black_box(sphere_max(*p, g, *lip, black_box(&s))))
        });
    }
    grp.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
