//! Eq. (QZdot) with (zz): along two trajectories with the same input,
//! `Q^T Z' <= -gamma |Q|^2`, `gamma = (|z1'| + |z2'|)/(2R)`, `Q = q1 - q2`, `Z = z1 - z2`.
//!
//! Discrete form checked on every step of the catching-up scheme: `Dz_i = z_i(k+1) - z_i(k)`
//! is an inward normal of `Theta` at `q_i(k+1)` (projection property), so Lemma A2 gives
//! `(Dz_1 - Dz_2)^T Q(k+1) <= -(|Dz_1| + |Dz_2|) |Q(k+1)|^2 / (2R)` exactly up to rounding;
//! dividing by `h` this is (QZdot). Per case the step with the smallest normalised slack is
//! reported. Cases: random systems (mu in `[-2, -0.2]`), strongly convex `Theta`, two initial
//! states, 2 periods.
//! Negative control: `1/R` instead of `1/(2R)`; two 1-D trajectories resting on opposite ends
//! of `[-delta, delta]` attain equality in the claim.
//! Tolerance: [`fp_tol`] of `(|Dz_1| + |Dz_2| + |z|) (|q_1| + |q_2| + |Q|)`, `|z|` the sum of the
//! norms of the four `z` values (each `Dz` is a difference of two of them).
use super::sets_prelude::*;
use super::simulation::simulate;
use crate::strategies::systems::{system_params, SystemParams, SystemStrategyConfig};

pub fn info() -> PropertyInfo {
    PropertyInfo {
        name: "qzdot",
        label: "(QZdot)",
        title: "Q^T Z' <= -(|z1'|+|z2'|)|Q|^2/(2R) along pairs of trajectories",
        default_cases: 2000,
        negative_control: "1/R instead of 1/(2R)",
    }
}

#[derive(Debug, Clone)]
pub struct QzCase {
    pub sys: SystemParams,
    /// Second initial state: `x0 + 2 dx`, `q0` from another point.
    pub dx: [f64; 4],
    pub q2: PointParams,
}

pub fn strategy() -> BoxedStrategy<QzCase> {
    (system_params(&SystemStrategyConfig::default()), proptest::array::uniform4(-1.0..=1.0f64), point_params())
        .prop_map(|(sys, dx, q2)| QzCase { sys, dx, q2 })
        .boxed()
}

pub fn second_state(case: &QzCase, sys: &model::System) -> (Vec<f64>, Vec<f64>) {
    let n = sys.n();
    let x2: Vec<f64> = (0..n).map(|i| sys.x0[i] + 2.0 * case.dx[i]).collect();
    let (q2, _) = PointParams { interior: true, ..case.q2.clone() }.build(&sys.theta);
    let y2 = &sys.C * nalgebra::DVector::from_column_slice(&x2);
    let z2: Vec<f64> = (0..sys.p()).map(|i| y2[i] + q2[i]).collect();
    (x2, z2)
}

pub fn eval(case: &QzCase, variant: Variant) -> Eval {
    let sys = case.sys.build();
    let R = sys.theta.strong_convexity().upper();
    let T = sys.period().unwrap_or(1.0);
    let dt = (T / 2000.0).min(5e-3);
    let steps = (2.0 * T / dt).ceil() as usize;
    let (n, p) = (sys.n(), sys.p());
    let mut x1: Vec<f64> = sys.x0.iter().copied().collect();
    let mut z1: Vec<f64> = sys.z0.iter().copied().collect();
    let (mut x2, mut z2) = second_state(case, &sys);
    // record z and q of both trajectories
    let mut tr1: Vec<(Vec<f64>, Vec<f64>)> = Vec::with_capacity(steps + 1);
    let mut tr2: Vec<(Vec<f64>, Vec<f64>)> = Vec::with_capacity(steps + 1);
    let q_of = |x: &[f64], z: &[f64]| -> Vec<f64> {
        (0..p).map(|i| z[i] - (0..n).map(|j| sys.C[(i, j)] * x[j]).sum::<f64>()).collect()
    };
    tr1.push((z1.clone(), q_of(&x1, &z1)));
    tr2.push((z2.clone(), q_of(&x2, &z2)));
    if !simulate(&sys, dt, 0.0, &mut x1, &mut z1, steps, |_, x, z| tr1.push((z.to_vec(), q_of(x, z))))
        || !simulate(&sys, dt, 0.0, &mut x2, &mut z2, steps, |_, x, z| tr2.push((z.to_vec(), q_of(x, z))))
    {
        return Eval::skipped();
    }
    let k = match variant {
        Variant::Claim => 0.5,
        Variant::NegativeControl => 1.0,
    };
    let mut worst: Option<(f64, Eval)> = None;
    for s in 0..steps {
        let d1: Vec<f64> = (0..p).map(|i| tr1[s + 1].0[i] - tr1[s].0[i]).collect();
        let d2: Vec<f64> = (0..p).map(|i| tr2[s + 1].0[i] - tr2[s].0[i]).collect();
        let (q1, q2) = (&tr1[s + 1].1, &tr2[s + 1].1);
        let Q: Vec<f64> = (0..p).map(|i| q1[i] - q2[i]).collect();
        let dZ: Vec<f64> = (0..p).map(|i| d1[i] - d2[i]).collect();
        let nu = norm(&d1) + norm(&d2);
        if nu == 0.0 {
            continue;
        }
        let lhs = dot(&Q, &dZ);
        let rhs = -k * nu * dot(&Q, &Q) / R;
        // Dz is a difference of z values: absolute error ~ eps (|z1| + |z2|)
        let zmag = norm(&tr1[s + 1].0) + norm(&tr2[s + 1].0) + norm(&tr1[s].0) + norm(&tr2[s].0);
        let e = Eval::new(lhs, rhs, fp_tol((nu + zmag) * (norm(q1) + norm(q2) + norm(&Q)), p));
        let key = if e.violated() { -2.0 } else { e.slack() };
        if worst.as_ref().is_none_or(|(w, _)| key < *w) {
            worst = Some((key, e));
        }
    }
    match worst {
        Some((_, e)) => e,
        None => Eval::skipped(), // the backlash never moved: nothing to check
    }
}

pub fn export(case: &QzCase, e: &Eval) -> Counterexample {
    let sys = case.sys.build();
    let (x2, z2) = second_state(case, &sys);
    system_counterexample(&sys, e, "qzdot", &format!("second trajectory: x0 = {x2:?}, z0 = {z2:?}"))
}

pub fn property() -> Prop<QzCase> {
    Prop { info: info(), strategy, eval, export, max_shrink_iters: 200 }
}
