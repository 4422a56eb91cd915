//! Eq. (PP): the metric projection (eq. (P)) is nonexpanding,
//! `|P_S(a) - P_S(b)| <= |a - b|` for all `a, b`.
//!
//! Cases: every shape; `a, b` arbitrary points at `10^[-1, 1]` times the set's size (inside,
//! outside, far away). `P_S` is `ConvexSet::project`.
//! Negative control: the over-relaxed map `a + 3 (P_S(a) - a)` (relaxation 3 instead of 1;
//! relaxations in `[0, 2]` are nonexpanding, 3 is not: two points outside a ball on one ray).
//! Tolerance: [`fp_tol`] of `|a| + |b| + |P(a)| + |P(b)|`.
use super::sets_prelude::*;

pub fn info() -> PropertyInfo {
    PropertyInfo {
        name: "pp",
        label: "(PP)",
        title: "projection is nonexpanding: |P(a)-P(b)| <= |a-b|",
        default_cases: 20_000,
        negative_control: "over-relaxed projection a + 3(P(a)-a)",
    }
}

/// Set and two arbitrary points (direction arrays and scale exponents).
#[derive(Debug, Clone)]
pub struct PpCase {
    pub set: SetParams,
    pub a: ([f64; MAX_P], f64),
    pub b: ([f64; MAX_P], f64),
}

pub fn strategy() -> BoxedStrategy<PpCase> {
    (set_params(&SetStrategyConfig::default()), vector_params(), vector_params())
        .prop_map(|(set, a, b)| PpCase { set, a, b })
        .boxed()
}

fn point(set: &geometry::Shape, v: &([f64; MAX_P], f64), size: f64) -> Vec<f64> {
    let p = set.dim();
    let s = size * 10f64.powf(v.1);
    v.0[..p].iter().map(|x| s * x).collect()
}

pub fn eval(case: &PpCase, variant: Variant) -> Eval {
    let set = case.set.build();
    let p = set.dim();
    let size = case.set.scale() * case.set.max_cond; // >= the set's size, no sphere search
    let a = point(&set, &case.a, size);
    let b = point(&set, &case.b, size);
    let mut pa = vec![0.0; p];
    let mut pb = vec![0.0; p];
    set.project(&a, &mut pa);
    set.project(&b, &mut pb);
    if variant == Variant::NegativeControl {
        for i in 0..p {
            pa[i] = a[i] + 3.0 * (pa[i] - a[i]);
            pb[i] = b[i] + 3.0 * (pb[i] - b[i]);
        }
    }
    let lhs = dist(&pa, &pb);
    let rhs = dist(&a, &b);
    let scale = norm(&a) + norm(&b) + norm(&pa) + norm(&pb);
    Eval::new(lhs, rhs, fp_tol(scale, p))
}

pub fn export(case: &PpCase, e: &Eval) -> Counterexample {
    let set = case.set.build();
    let size = case.set.scale() * case.set.max_cond; // >= the set's size, no sphere search
    let a = point(&set, &case.a, size);
    let b = point(&set, &case.b, size);
    geometric_counterexample(&set, &[("a", &a), ("b", &b)], e, "pp")
}

pub fn property() -> Prop<PpCase> {
    Prop { info: info(), strategy, eval, export, max_shrink_iters: 2000 }
}
