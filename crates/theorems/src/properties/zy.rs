//! Eq. (zy): `|z'| <= |y'|` for the backlash law `z' = P_{N_Theta(q)}(y')` (eq. (zdot)),
//! which follows from (PP) since `P_N(0) = 0`.
//!
//! Cases: every shape; `q` a boundary point (support point, where the inward cone is
//! nontrivial) or an interior point (cone `{0}`), `y'` an arbitrary vector. The projection is
//! `ConvexSet::project_normal_cone` with boundary tolerance `1e-9` times the set's size.
//! Besides `|z'| <= |y'|`, the case checks that `z'` is an inward normal, i.e. `q` minimises
//! `z'^T s` over `S`: `sigma_S(-z') + z'^T q <= tol`; a failure is reported as `lhs = NaN`.
//! Negative control: `|z'| <= |y'| / 2` (wrong constant): fails when `y'` points along the
//! inward normal.
//! Tolerance: [`fp_tol`] of `|y'|` (the projection onto a cone is a few flops per entry).
use super::sets_prelude::*;

pub fn info() -> PropertyInfo {
    PropertyInfo {
        name: "zy",
        label: "(zy)",
        title: "|z'| <= |y'| for z' = P_{N(q)}(y')",
        default_cases: 20_000,
        negative_control: "|z'| <= |y'|/2",
    }
}

#[derive(Debug, Clone)]
pub struct ZyCase {
    pub set: SetParams,
    pub q: PointParams,
    pub ydot: ([f64; MAX_P], f64),
}

pub fn strategy() -> BoxedStrategy<ZyCase> {
    (set_params(&SetStrategyConfig::default()), point_params(), vector_params())
        .prop_map(|(set, q, ydot)| ZyCase { set, q, ydot })
        .boxed()
}

pub fn eval(case: &ZyCase, variant: Variant) -> Eval {
    let set = case.set.build();
    let p = set.dim();
    let size = case.set.scale() * case.set.max_cond; // >= the set's size, no sphere search
    let (q, _) = case.q.build(&set);
    let ydot: Vec<f64> = case.ydot.0[..p].iter().map(|x| x * 10f64.powf(case.ydot.1)).collect();
    let mut zdot = vec![0.0; p];
    set.project_normal_cone(&q, &ydot, 1e-9 * size, &mut zdot);
    let k = match variant {
        Variant::Claim => 1.0,
        Variant::NegativeControl => 0.5,
    };
    let mut lhs = norm(&zdot);
    let rhs = k * norm(&ydot);
    // z' must be an inward normal at q: max_s (-z')^T s = (-z')^T q
    let neg: Vec<f64> = zdot.iter().map(|x| -x).collect();
    let gap = set.support(&neg) + dot(&zdot, &q);
    if gap > 1e-6 * norm(&zdot) * (size + norm(&q)) + 1e-300 {
        lhs = f64::NAN;
    }
    Eval::new(lhs, rhs, fp_tol(norm(&ydot), p))
}

pub fn export(case: &ZyCase, e: &Eval) -> Counterexample {
    let set = case.set.build();
    let p = set.dim();
    let (q, _) = case.q.build(&set);
    let ydot: Vec<f64> = case.ydot.0[..p].iter().map(|x| x * 10f64.powf(case.ydot.1)).collect();
    geometric_counterexample(&set, &[("q", &q), ("ydot", &ydot)], e, "zy")
}

pub fn property() -> Prop<ZyCase> {
    Prop { info: info(), strategy, eval, export, max_shrink_iters: 2000 }
}
