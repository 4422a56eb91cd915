//! Lemma 2, eq. (xX) with (Xsupp): `x(t) in xi(t) + Xi(t)`, i.e. for every direction `u`
//! `u^T (x(t) - xi(t)) <= sigma_{Xi(t)}(u) = int_0^t sigma_Theta(E^T e^{sF^T} u) ds`,
//! `xi` the linearised solution (eq. (xi)) with `xi(0) = x(0)`.
//!
//! Computation: `x` from the catching-up scheme (`h = 0.01`, horizon `[0.5, 3]`), `xi` exact
//! ([`super::simulation::linear_response_exact`] with `F`), `sigma_{Xi(t)}` from above by the
//! production kernel `bounds::tube::TubeKernel` (certified quadrature, finite horizon `t`) at
//! [`CHECKPOINTS`] grid times, in 8 directions (4 random unit vectors and their negatives).
//!
//! Discretisation allowance (derived, not tuned): in the scheme `x' = F x + B w + E q` with
//! `q(s) = z_k - C x(s)` on a step, and `z_k - C x_k in Theta`, so `q(s)` lies within
//! `eps = 1.5 max_k |y_{k+1} - y_k|` of `Theta`; hence the scheme satisfies
//! `u^T (x - xi) <= sigma_{Xi(t)}(u) + eps int_0^t |E^T e^{sF^T} u| ds` (the integral by the
//! same kernel over the unit ball, whose support function is the norm). The scheme also
//! interpolates the sine input linearly over a step, while `xi` is exact: the input error is at
//! most `eps_w = h^2 omega^2 |a| / 8` (linear interpolation of `a sin(omega s + phase)`), which
//! adds at most `eps_w |B|_F int_0^inf |e^{sF}|_2 ds` (the integral bounded by the certified
//! `bounds::tube::ExpNormBounds` of the case's shared `SemigroupData`; without this term a
//! system with `E = 0`, where `Xi = {0}`, was flagged at 20,000 cases for a scheme error of
//! 1.2e-6 on `B w`). On top:
//! `1e-12 (|x| + |xi|)` for rounding (the kernel's values are upper bounds already). Slack per direction and step, worst reported.
//! Negative control: `Xi` shrunk by the factor `0.5` (the allowance kept).
use super::sets_prelude::*;
use super::simulation::{linear_response_exact, simulate};
use crate::strategies::inputs::InputStrategyConfig;
use crate::strategies::systems::{system_params, SystemParams, SystemStrategyConfig};
use bounds::tube::{Horizon, SemigroupData, TubeKernel, TubeSettings};
use nalgebra::DVector;

/// Step of the scheme and of the quadrature.
pub const H: f64 = 0.01;
/// Shrink factor of the negative control.
pub const SHRINK: f64 = 0.5;
/// Times at which the tube is checked (evenly spread, the last at the horizon).
pub const CHECKPOINTS: usize = 6;

pub fn info() -> PropertyInfo {
    PropertyInfo {
        name: "lemma2",
        label: "(xX)",
        title: "Lemma 2: x(t) in xi(t) + Xi(t) along catching-up trajectories, 8 directions at 6 times",
        default_cases: 2000,
        negative_control: "Xi shrunk by 0.5",
    }
}

#[derive(Debug, Clone)]
pub struct Lemma2Case {
    pub sys: SystemParams,
    pub horizon: f64,
    /// Four directions (normalised; their negatives are checked too).
    pub dirs: [[f64; 4]; 4],
}

pub fn config() -> SystemStrategyConfig {
    SystemStrategyConfig {
        max_n: 3,
        input: InputStrategyConfig { amp_exp: (-1.5, 0.5), ..Default::default() },
        ..Default::default()
    }
}

pub fn strategy() -> BoxedStrategy<Lemma2Case> {
    (system_params(&config()), 0.5..=3.0f64, proptest::array::uniform4(proptest::array::uniform4(-1.0..=1.0f64)))
        .prop_map(|(sys, horizon, dirs)| Lemma2Case { sys, horizon, dirs })
        .boxed()
}

pub fn eval(case: &Lemma2Case, variant: Variant) -> Eval {
    let sys = case.sys.build();
    let n = sys.n();
    let steps = (case.horizon / H).ceil() as usize;
    let Some(xi) = linear_response_exact(&sys, &sys.F(), H, steps) else { return Eval::skipped() };
    let mut xs = vec![sys.x0.clone()];
    let mut x: Vec<f64> = sys.x0.iter().copied().collect();
    let mut z: Vec<f64> = sys.z0.iter().copied().collect();
    if !simulate(&sys, H, 0.0, &mut x, &mut z, steps, |_, xk, _| xs.push(DVector::from_column_slice(xk))) {
        return Eval::skipped();
    }
    let ys: Vec<DVector<f64>> = xs.iter().map(|x| &sys.C * x).collect();
    let eps = 1.5 * ys.windows(2).map(|w| (&w[1] - &w[0]).norm()).fold(0.0, f64::max);
    let k_shrink = if variant == Variant::Claim { 1.0 } else { SHRINK };
    // sigma_{Xi(t)} by the production kernel of `bounds` (L = I_n, finite horizon t), and
    // int_0^t |E^T e^{sF^T} u| ds by the same kernel over the unit ball (its support function
    // is the norm), at CHECKPOINTS times spread over the horizon.
    let F = sys.F();
    let I = nalgebra::DMatrix::<f64>::identity(n, n);
    let p = sys.p();
    let unit_ball = geometry::Shape::Ball(geometry::Ball::new(vec![0.0; p], 1.0).expect("unit ball"));
    // Computed once for the 2 x CHECKPOINTS kernels (`TubeKernel::with_shared`: the same
    // kernels as `TubeKernel::new`): D(Theta, {0}), D(unit ball, {0}), the semigroup bounds of F.
    // interpolation error of the input (module docs); w is a sine here (`linear_response_exact`)
    let eps_w = match &sys.input {
        model::Input::Sine { amplitudes, omega, .. } => {
            H * H * omega * omega * amplitudes.iter().map(|a| a * a).sum::<f64>().sqrt() / 8.0
        }
        _ => 0.0,
    };
    let d_theta = sys.theta.deviation_from_origin().upper;
    let d_ball = unit_ball.deviation_from_origin().upper;
    let sg = SemigroupData::new(&F);
    let input_allowance = match (eps_w > 0.0, sg.bounds()) {
        (false, _) => 0.0,
        (true, Ok(b)) => eps_w * sys.B.norm() * b.integral,
        (true, Err(_)) => return Eval::skipped(),
    };
    let mut worst: Option<Eval> = None;
    for c in 1..=CHECKPOINTS {
        let k = (c * steps).div_ceil(CHECKPOINTS);
        let t = k as f64 * H;
        let tube = TubeSettings { tol_abs: 1e-6 * d_theta.max(1e-300), ..TubeSettings::default() };
        let (Ok(xi_t), Ok(norm_t)) = (
            TubeKernel::with_shared(&I, &F, &sys.E, &sys.theta, d_theta, &sg, Horizon::Finite(t), &tube),
            TubeKernel::with_shared(
                &I,
                &F,
                &sys.E,
                &unit_ball,
                d_ball,
                &sg,
                Horizon::Finite(t),
                &TubeSettings { tol_abs: 1e-6, ..tube },
            ),
        ) else {
            return Eval::skipped();
        };
        let dx = &xs[k] - &xi[k];
        for d in &case.dirs {
            let nu = norm(&d[..n]);
            if nu < 1e-3 {
                continue;
            }
            let u = DVector::from_iterator(n, d[..n].iter().map(|v| v / nu));
            let mu = -&u;
            let g = norm_t.support_upper(u.as_slice());
            let allow = eps * g + input_allowance + 1e-12 * (xs[k].norm() + xi[k].norm());
            for (lhs, dir) in [(u.dot(&dx), &u), (-u.dot(&dx), &mu)] {
                let sig = xi_t.support_upper(dir.as_slice());
                let e = Eval::new(lhs, k_shrink * sig, allow);
                if worst.is_none_or(|w| {
                    e.violated() && !w.violated() || (e.violated() == w.violated() && e.slack() < w.slack())
                }) {
                    worst = Some(e);
                }
            }
        }
    }
    worst.unwrap_or_else(Eval::skipped)
}

fn export(case: &Lemma2Case, e: &Eval) -> Counterexample {
    system_counterexample(
        &case.sys.build(),
        e,
        "lemma2",
        &format!("horizon {}, h = {H}; lhs = u^T (x - xi), rhs = sigma_Xi(t)(u)", case.horizon),
    )
}

pub fn property() -> Prop<Lemma2Case> {
    Prop { info: info(), strategy, eval, export, max_shrink_iters: 60 }
}
