//! Lemma A2, eq. (lem1:2): for a strongly convex `S` with constant `R` (eq. (R)), points
//! `x, y in S` and inward normals `u in N_S(x)`, `v in N_S(y)`,
//! `(u - v)^T (x - y) <= -(|u| + |v|) |x - y|^2 / (2R)`.
//!
//! Cases: every shape ([`SetKind::ALL`]; polytopes have `R = inf` and the claim reduces to
//! monotonicity of the normal cone), boundary points `x = s_S(d)` with `u = -t d`, 20% interior
//! points with `u = 0`. `R` is `strong_convexity().upper()` (the safe value).
//! Negative control: the constant `1/(2R)` replaced by `1/R` (twice too strong): balls attain
//! equality in the claim, so the control fails on them.
//! Tolerance: [`fp_tol`] of `(|u| + |v|) (|x| + |y| + |x - y|)`.
use super::sets_prelude::*;

pub fn info() -> PropertyInfo {
    PropertyInfo {
        name: "lemma_a2",
        label: "(lem1:2)",
        title: "Lemma A2: (u-v)^T(x-y) <= -(|u|+|v|)|x-y|^2/(2R)",
        default_cases: 20_000,
        negative_control: "constant 1/R instead of 1/(2R)",
    }
}

pub fn strategy() -> BoxedStrategy<PairCase> {
    pair_case(&SetStrategyConfig::default())
}

/// Strategy restricted to ellipsoids (throughput benchmark).
pub fn strategy_ellipsoids() -> BoxedStrategy<PairCase> {
    pair_case(&SetStrategyConfig::only(SetKind::Ellipsoid))
}

/// Evaluates the claim on built data.
pub fn eval_pair(pr: &Pair, variant: Variant) -> Eval {
    let R = pr.set.strong_convexity().upper();
    let p = pr.x.len();
    let dxy: Vec<f64> = (0..p).map(|i| pr.x[i] - pr.y[i]).collect();
    let duv: Vec<f64> = (0..p).map(|i| pr.u[i] - pr.v[i]).collect();
    let lhs = dot(&duv, &dxy);
    let nu = norm(&pr.u) + norm(&pr.v);
    let d2 = dot(&dxy, &dxy);
    let k = match variant {
        Variant::Claim => 0.5,
        Variant::NegativeControl => 1.0,
    };
    let rhs = if R.is_finite() { -k * nu * d2 / R } else { 0.0 };
    let scale = nu * (norm(&pr.x) + norm(&pr.y) + d2.sqrt());
    Eval::new(lhs, rhs, fp_tol(scale, p))
}

pub fn eval(case: &PairCase, variant: Variant) -> Eval {
    eval_pair(&case.build(), variant)
}

pub fn export(case: &PairCase, e: &Eval) -> Counterexample {
    let pr = case.build();
    geometric_counterexample(&pr.set, &[("x", &pr.x), ("u", &pr.u), ("y", &pr.y), ("v", &pr.v)], e, "lemma_a2")
}

pub fn property() -> Prop<PairCase> {
    Prop { info: info(), strategy, eval, export, max_shrink_iters: 2000 }
}
