//! Eq. (QZdot) with (zz): along two trajectories with the same input,
//! `Q^T Z' <= -gamma |Q|^2`, `gamma = (|z1'| + |z2'|)/(2R)`, `Q = q1 - q2`, `Z = z1 - z2`.
//!
//! Discrete form checked on every step of the catching-up scheme: `Dz_i = z_i(k+1) - z_i(k)`
//! is an inward normal of `Theta` at `q_i(k+1)` (projection property), so Lemma A2 gives
//! `(Dz_1 - Dz_2)^T Q(k+1) <= -(|Dz_1| + |Dz_2|) |Q(k+1)|^2 / (2R)` exactly up to rounding;
//! dividing by `h` this is (QZdot). Per case the step with the smallest normalised slack is
//! reported. Cases: random systems (mu in `[-2, -0.2]`), strongly convex `Theta`, two initial
//! states, 2 periods, simulated together on the ensemble integrator (`dynamics::integrators::
//! ensemble`, the single path's arithmetic lane by lane) and checked step by step on the fly.
//! Negative control: `1/R` instead of `1/(2R)`; two 1-D trajectories resting on opposite ends
//! of `[-delta, delta]` attain equality in the claim.
//! Tolerance: [`fp_tol`] of `(|Dz_1| + |Dz_2| + |z|) (|q_1| + |q_2| + |Q|)`, `|z|` the sum of the
//! norms of the four `z` values (each `Dz` is a difference of two of them).
use super::sets_prelude::*;
use crate::strategies::systems::{system_params, SystemParams, SystemStrategyConfig};
use dynamics::integrators::catching_up::CatchingUpSettings;
use dynamics::integrators::ensemble::{Ensemble, EnsembleState};

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
    let (x2, z2) = second_state(case, &sys);
    // both trajectories on the ensemble integrator (lane 0: the system's initial state, lane 1:
    // the second one), the check made on the fly at every step
    let Ok(mut ens) = Ensemble::new(&sys, &CatchingUpSettings { dt, ..Default::default() }) else {
        return Eval::skipped();
    };
    let mut state = EnsembleState::zeros(n, p, 2);
    state.set(0, sys.x0.as_slice(), sys.z0.as_slice());
    state.set(1, &x2, &z2);
    let q_of = |s: &EnsembleState, l: usize, i: usize| -> f64 {
        s.z_component(i)[l] - (0..n).map(|j| sys.C[(i, j)] * s.x_component(j)[l]).sum::<f64>()
    };
    let k = match variant {
        Variant::Claim => 0.5,
        Variant::NegativeControl => 1.0,
    };
    // z of both trajectories before the step
    let mut zp: [Vec<f64>; 2] = [sys.z0.as_slice().to_vec(), z2.clone()];
    let (mut zn, mut q, mut d) =
        ([vec![0.0; p], vec![0.0; p]], [vec![0.0; p], vec![0.0; p]], [vec![0.0; p], vec![0.0; p]]);
    let (mut Q, mut dZ) = (vec![0.0; p], vec![0.0; p]);
    let mut worst: Option<(f64, Eval)> = None;
    ens.run_observed(0.0, &mut state, steps, |_, _, s| {
        for l in 0..2 {
            for i in 0..p {
                zn[l][i] = s.z_component(i)[l];
                q[l][i] = q_of(s, l, i);
                d[l][i] = zn[l][i] - zp[l][i];
            }
        }
        for i in 0..p {
            Q[i] = q[0][i] - q[1][i];
            dZ[i] = d[0][i] - d[1][i];
        }
        let nu = norm(&d[0]) + norm(&d[1]);
        if nu != 0.0 {
            let lhs = dot(&Q, &dZ);
            let rhs = -k * nu * dot(&Q, &Q) / R;
            // Dz is a difference of z values: absolute error ~ eps (|z1| + |z2|)
            let zmag = norm(&zn[0]) + norm(&zn[1]) + norm(&zp[0]) + norm(&zp[1]);
            let e = Eval::new(lhs, rhs, fp_tol((nu + zmag) * (norm(&q[0]) + norm(&q[1]) + norm(&Q)), p));
            let key = if e.violated() { -2.0 } else { e.slack() };
            if worst.as_ref().is_none_or(|(w, _)| key < *w) {
                worst = Some((key, e));
            }
        }
        for l in 0..2 {
            zp[l].copy_from_slice(&zn[l]);
        }
    });
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
