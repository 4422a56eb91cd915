//! Lemma 2, eq. (xX) with (Xsupp): `x(t) in xi(t) + Xi(t)`, i.e. for every direction `u`
//! `u^T (x(t) - xi(t)) <= sigma_{Xi(t)}(u) = int_0^t sigma_Theta(E^T e^{sF^T} u) ds`,
//! `xi` the linearised solution (eq. (xi)) with `xi(0) = x(0)`.
//!
//! Computation: `x` from the catching-up scheme (`h = 0.01`, horizon `[0.5, 3]`), `xi` exact
//! ([`super::simulation::linear_response_exact`] with `F`), `sigma_{Xi(t_k)}` by the trapezoid rule
//! on the same grid (nodes `(e^{s_i F} E)^T`, running sums, so every step is checked), in 8
//! directions (4 random unit vectors and their negatives) per case.
//!
//! Discretisation allowance (derived, not tuned): in the scheme `x' = F x + B w + E q` with
//! `q(s) = z_k - C x(s)` on a step, and `z_k - C x_k in Theta`, so `q(s)` lies within
//! `eps = 1.5 max_k |y_{k+1} - y_k|` of `Theta`; hence the scheme satisfies
//! `u^T (x - xi) <= sigma_{Xi(t)}(u) + eps int_0^t |E^T e^{sF^T} u| ds` (same quadrature).
//! On top: `1e-3` of the tube width `sigma(u) + sigma(-u)` for the trapezoid rule and
//! `1e-12 (|x| + |xi|)` for rounding. Slack per direction and step, worst reported.
//! Negative control: `Xi` shrunk by the factor `0.5` (the allowance kept).
use super::sets_prelude::*;
use super::simulation::{linear_response_exact, simulate, XiNodes};
use crate::strategies::inputs::InputStrategyConfig;
use crate::strategies::systems::{system_params, SystemParams, SystemStrategyConfig};
use nalgebra::DVector;

/// Step of the scheme and of the quadrature.
pub const H: f64 = 0.01;
/// Shrink factor of the negative control.
pub const SHRINK: f64 = 0.5;

pub fn info() -> PropertyInfo {
    PropertyInfo {
        name: "lemma2",
        label: "(xX)",
        title: "Lemma 2: x(t) in xi(t) + Xi(t) along catching-up trajectories, 8 directions per step",
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
    let nodes = XiNodes::new(&sys, H, steps as f64 * H + 0.5 * H);
    let k_shrink = if variant == Variant::Claim { 1.0 } else { SHRINK };
    let mut worst: Option<Eval> = None;
    for d in &case.dirs {
        let nu = norm(&d[..n]);
        if nu < 1e-3 {
            continue;
        }
        let u = DVector::from_iterator(n, d[..n].iter().map(|v| v / nu));
        let mu = -&u;
        // running trapezoid sums of sigma(E^T e^{sF^T} (+-u)) and |E^T e^{sF^T} u|
        let (mut sp, mut sm, mut g) = (0.0, 0.0, 0.0);
        let (mut fp0, mut fm0, mut g0) = (0.0, 0.0, 0.0);
        for k in 0..=steps {
            let (fp, fm, gk) = match nodes.nodes.get(k) {
                Some(M) => {
                    let v = M * &u;
                    (sys.theta.support(v.as_slice()), sys.theta.support((M * &mu).as_slice()), v.norm())
                }
                None => (0.0, 0.0, 0.0),
            };
            if k > 0 {
                sp += 0.5 * H * (fp0 + fp);
                sm += 0.5 * H * (fm0 + fm);
                g += 0.5 * H * (g0 + gk);
            }
            (fp0, fm0, g0) = (fp, fm, gk);
            let dx = &xs[k] - &xi[k];
            let allow = eps * g + 1e-3 * (sp + sm).abs() + 1e-12 * (xs[k].norm() + xi[k].norm());
            for (lhs, sig) in [(u.dot(&dx), sp), (-u.dot(&dx), sm)] {
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
