//! Eq. (rR): for a strongly convex `S` with constant `R` and `x, y in S`, the distance
//! `r = rho(c, boundary S)` from the midpoint `c = (x + y)/2` to the boundary satisfies
//! `r >= R - sqrt(R^2 - |x - y|^2/4) >= |x - y|^2 / (8R)`.
//!
//! The middle term is evaluated stably as `(|x-y|^2/4) / (R + sqrt(R^2 - |x-y|^2/4))`. The
//! check is `lhs = R - sqrt(...) <= rhs = r`; the second (algebraic) inequality is checked
//! too and a failure of it is reported as `lhs = NaN` (a violation).
//! Cases: strongly convex shapes, boundary or interior points.
//! Negative control: `1.5 (R - sqrt(...)) <= r`; a ball with both points on its sphere attains
//! equality in the claim.
//! Tolerance: [`fp_tol`] of `|x| + |y| + |x - y|` for the rounding in `x`, `y` and `r`, plus
//! the conditioning of the left side: moving `x`, `y` by that much moves `s = |x-y|^2/4` by
//! up to `ds = |x - y| fp_tol`, and `R - sqrt(R^2 - s)` by up to
//! `min(ds / sqrt(R^2 - s), sqrt(ds))`, which is large for nearly antipodal points on a sphere
//! of radius `R` (a CI run met such a pair: excess 4.8e-14 over a tolerance of 3.2e-14, with
//! `sqrt(R^2 - s) = 1.3e-4`; the regression seed is kept).
use super::sets_prelude::*;

pub fn info() -> PropertyInfo {
    PropertyInfo {
        name: "rr",
        label: "(rR)",
        title: "r >= R - sqrt(R^2 - |x-y|^2/4) >= |x-y|^2/(8R)",
        default_cases: 10_000,
        negative_control: "1.5 (R - sqrt(R^2 - |x-y|^2/4)) <= r",
    }
}

pub fn strategy() -> BoxedStrategy<PairCase> {
    pair_case(&SetStrategyConfig::strongly_convex())
}

pub fn eval_pair(pr: &Pair, variant: Variant) -> Eval {
    let p = pr.x.len();
    let R = pr.set.strong_convexity().upper();
    let c: Vec<f64> = (0..p).map(|i| 0.5 * (pr.x[i] + pr.y[i])).collect();
    let r = pr.set.dist_to_boundary(&c);
    let d2 = pr.x.iter().zip(&pr.y).map(|(a, b)| (a - b) * (a - b)).sum::<f64>();
    let s = 0.25 * d2;
    let b1 = s / (R + (R * R - s).max(0.0).sqrt());
    let b2 = d2 / (8.0 * R);
    let k = match variant {
        Variant::Claim => 1.0,
        Variant::NegativeControl => 1.5,
    };
    let mut lhs = k * b1;
    if b2 > b1 * (1.0 + 1e-12) + f64::MIN_POSITIVE {
        lhs = f64::NAN;
    }
    let scale = norm(&pr.x) + norm(&pr.y) + d2.sqrt();
    let rounding = fp_tol(scale, p);
    let ds = d2.sqrt() * rounding;
    let root = (R * R - s).max(0.0).sqrt();
    let conditioning = if root > 0.0 { (ds / root).min(ds.sqrt()) } else { ds.sqrt() };
    Eval::new(lhs, r, rounding + conditioning)
}

pub fn eval(case: &PairCase, variant: Variant) -> Eval {
    eval_pair(&case.build(), variant)
}

pub fn export(case: &PairCase, e: &Eval) -> Counterexample {
    let pr = case.build();
    geometric_counterexample(&pr.set, &[("x", &pr.x), ("y", &pr.y)], e, "rr")
}

pub fn property() -> Prop<PairCase> {
    Prop { info: info(), strategy, eval, export, max_shrink_iters: 2000 }
}
