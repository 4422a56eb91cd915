//! Theorem 1, eq. (stat1) for `p = 1`: if `Phi(t) = I_p - t C Psi(tA) E` (eq. (Phi), `I_p`:
//! see the typo note) is nonsingular on `[0, T]`, the set of `T`-stationary initial conditions
//! is `R(T) = cap_t Phi(t)^{-1}(C x_*(t) + Theta)`, `x_*` the feedback-free solution (eq. (xz0)).
//!
//! Computation (deliberately independent of `bounds::stationary`, so the two cross-check):
//! on the grid `t_k = k h`, `h = T/N`, `phi_k = 1 - C (t_k Psi(t_k A)) E` from
//! `dynamics::linear::expm::t_psi`, `c_k = C x_*(t_k)` with `x_*` exact for sine inputs (one
//! augmented exponential of `[[A, B a, 0], [0, 0, omega], [0, -omega, 0]]`). For `p = 1` each
//! `Phi(t_k)^{-1}(c_k + Theta)` is an interval, so `R(T)` on the grid is an exact intersection of
//! intervals. The violation `v(z) = max_k max(phi_k z - c_k - hi, lo + c_k - phi_k z)` is `<= 0`
//! exactly on `R(T)`.
//!
//! Check: the catching-up scheme (same grid) is run from `x(0)` and
//! - the midpoint `z_r` of `R(T)` when `v(z_r) <= -delta`: `z` must stay at rest,
//!   `max_k |z_k - z_r| <= 1e-12 (|z_r| + |Theta|)`;
//! - a random admissible `z_o in C x(0) + Theta` when `v(z_o) >= delta`: `z` must move,
//!   path length `sum |z_{k+1} - z_k| > 1e-9 |Theta|`.
//!
//! `delta = 1e-6 |Theta| + e_x / min_k phi_k` with `e_x = max_k |C (x_*(t_k) - x^h_*(t_k))|` the
//! measured difference between the exact `x_*` and the scheme's own linear-hold `x_*`, so the
//! margin covers the discretisation. Cases where `Phi` changes sign on the grid (hypothesis
//! fails) or where neither point exists are skipped. The case's slack is the smaller of the two.
//! Negative control: claim rest from the outside point `z_o`.
use super::sets_prelude::*;
use super::simulation::linear_response_exact;
use crate::strategies::inputs::InputStrategyConfig;
use crate::strategies::systems::{system_params, SystemParams, SystemStrategyConfig};
use dynamics::integrators::catching_up::{CatchingUp, CatchingUpSettings};
use dynamics::linear::expm::t_psi;
use dynamics::linear::step_map::{InputHold, SystemStepMap};
use nalgebra::DVector;

/// Grid steps over `[0, T]`.
pub const STEPS: usize = 100;

pub fn info() -> PropertyInfo {
    PropertyInfo {
        name: "theorem1",
        label: "(stat1)",
        title: "Theorem 1 (p = 1): z(0) in R(T) stays at rest on [0, T]; z(0) outside R(T) moves",
        default_cases: 2000,
        negative_control: "claim rest from a point outside R(T)",
    }
}

#[derive(Debug, Clone)]
pub struct Theorem1Case {
    pub sys: SystemParams,
    /// Horizon `T`.
    pub horizon: f64,
    /// Position of the candidate outside point in `C x(0) + Theta` (0: lower end, 1: upper end).
    pub frac: f64,
}

pub fn config() -> SystemStrategyConfig {
    SystemStrategyConfig {
        max_n: 3,
        max_p: 1,
        input: InputStrategyConfig { amp_exp: (-1.5, 0.5), ..Default::default() },
        ..Default::default()
    }
}

pub fn strategy() -> BoxedStrategy<Theorem1Case> {
    (system_params(&config()), 0.05..=1.5f64, 0.0..=1.0f64)
        .prop_map(|(sys, horizon, frac)| Theorem1Case { sys, horizon, frac })
        .boxed()
}

/// `R(T)` on the grid and what the check needs.
#[derive(Debug, Clone)]
pub struct RestSet {
    pub h: f64,
    /// `phi_k`, `k = 0..=N`.
    pub phi: Vec<f64>,
    /// `c_k = C x_*(t_k)` (exact `x_*`).
    pub c: Vec<f64>,
    pub lo: f64,
    pub hi: f64,
    /// `R(T) = [lower, upper]` (empty when `lower > upper`).
    pub lower: f64,
    pub upper: f64,
    /// Margin `delta` (see the module doc).
    pub delta: f64,
}

impl RestSet {
    /// `v(z)`: `<= 0` iff `z in R(T)` (on the grid).
    pub fn violation(&self, z: f64) -> f64 {
        self.phi
            .iter()
            .zip(&self.c)
            .map(|(f, c)| (f * z - c - self.hi).max(self.lo + c - f * z))
            .fold(f64::NEG_INFINITY, f64::max)
    }
}

/// Exact `C x_*(t_k)` (eq. (xz0)) for a sine (or zero) input; `None` for other inputs.
fn c_xstar_exact(sys: &model::System, h: f64, steps: usize) -> Option<Vec<f64>> {
    Some(linear_response_exact(sys, &sys.A, h, steps)?.iter().map(|x| (&sys.C * x)[0]).collect())
}

/// `C x^h_*(t_k)`: the scheme's own feedback-free state (linear hold of `w`).
fn c_xstar_scheme(sys: &model::System, h: f64, steps: usize) -> Option<Vec<f64>> {
    let map = SystemStepMap::for_system(sys, h, InputHold::Foh).ok()?;
    let m = sys.m();
    let mut x = sys.x0.clone();
    let (mut w0, mut w1) = (DVector::zeros(m), DVector::zeros(m));
    let mut out = vec![(&sys.C * &x)[0]];
    sys.input.eval(0.0, w0.as_mut_slice());
    for k in 0..steps {
        sys.input.eval((k + 1) as f64 * h, w1.as_mut_slice());
        x = &map.phi * &x + &map.g1B * &w0 + &map.g2B * (&w1 - &w0);
        out.push((&sys.C * &x)[0]);
        std::mem::swap(&mut w0, &mut w1);
    }
    Some(out)
}

/// `R(T)` on the grid of `STEPS` steps; `None` when `p != 1`, the input is not a sine, or
/// `Phi` is singular / changes sign on the grid (hypothesis of Theorem 1 not met).
pub fn rest_set(sys: &model::System, horizon: f64) -> Option<RestSet> {
    if sys.p() != 1 {
        return None;
    }
    let h = horizon / STEPS as f64;
    let lo = -sys.theta.support(&[-1.0]);
    let hi = sys.theta.support(&[1.0]);
    let phi: Vec<f64> = (0..=STEPS).map(|k| 1.0 - (&sys.C * t_psi(&sys.A, k as f64 * h) * &sys.E)[(0, 0)]).collect();
    let min_phi = phi.iter().copied().fold(f64::INFINITY, f64::min);
    if !(min_phi > 1e-6) {
        return None;
    }
    let c = c_xstar_exact(sys, h, STEPS)?;
    let ch = c_xstar_scheme(sys, h, STEPS)?;
    let e_x = c.iter().zip(&ch).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    let (mut lower, mut upper) = (f64::NEG_INFINITY, f64::INFINITY);
    for (f, ck) in phi.iter().zip(&c) {
        lower = lower.max((ck + lo) / f);
        upper = upper.min((ck + hi) / f);
    }
    let delta = 1e-6 * (hi - lo) + 2.0 * e_x / min_phi;
    Some(RestSet { h, phi, c, lo, hi, lower, upper, delta })
}

/// Runs the scheme from `(x0, z)` over the grid: `(max |z_k - z|, path length)`.
fn run_from(sys: &model::System, rs: &RestSet, z: f64) -> Option<(f64, f64)> {
    let mut cu = CatchingUp::new(sys, &CatchingUpSettings { dt: rs.h, hold: InputHold::Foh }).ok()?;
    let mut x: Vec<f64> = sys.x0.iter().copied().collect();
    let mut zz = [z];
    let (mut dev, mut path, mut prev) = (0.0f64, 0.0, z);
    cu.run(0.0, &mut x, &mut zz, STEPS, |_, _, _, zk| {
        dev = dev.max((zk[0] - z).abs());
        path += (zk[0] - prev).abs();
        prev = zk[0];
    });
    Some((dev, path))
}

/// The rest point and the outside point of a case (either may be absent).
pub fn points(case: &Theorem1Case, sys: &model::System, rs: &RestSet) -> (Option<f64>, Option<f64>) {
    let rest = (rs.lower <= rs.upper).then_some(0.5 * (rs.lower + rs.upper)).filter(|z| rs.violation(*z) <= -rs.delta);
    let c0 = (&sys.C * &sys.x0)[0];
    let zo = c0 + rs.lo + case.frac * (rs.hi - rs.lo);
    let outside = Some(zo).filter(|z| rs.violation(*z) >= rs.delta);
    (rest, outside)
}

pub fn eval(case: &Theorem1Case, variant: Variant) -> Eval {
    let sys = case.sys.build();
    let Some(rs) = rest_set(&sys, case.horizon) else { return Eval::skipped() };
    let (rest, outside) = points(case, &sys, &rs);
    let width = rs.hi - rs.lo;
    let rest_eval = |z: f64| run_from(&sys, &rs, z).map(|(dev, _)| Eval::new(dev, 0.0, 1e-12 * (z.abs() + width)));
    match variant {
        Variant::Claim => {
            let a = rest.and_then(rest_eval);
            // claim path > thresh: violated iff thresh > path
            let b = outside.and_then(|z| run_from(&sys, &rs, z)).map(|(_, path)| Eval::new(1e-9 * width, path, 0.0));
            match (a, b) {
                (Some(a), Some(b)) => {
                    if a.violated() || (!b.violated() && a.slack() <= b.slack()) {
                        a
                    } else {
                        b
                    }
                }
                (Some(e), None) | (None, Some(e)) => e,
                (None, None) => Eval::skipped(),
            }
        }
        Variant::NegativeControl => outside.and_then(rest_eval).unwrap_or_else(Eval::skipped),
    }
}

fn export(case: &Theorem1Case, e: &Eval) -> Counterexample {
    let sys = case.sys.build();
    let extra = match rest_set(&sys, case.horizon) {
        Some(rs) => {
            let (r, o) = points(case, &sys, &rs);
            format!(
                "T = {}, R(T) = [{:e}, {:e}], rest point {:?}, outside point {:?}, delta {:e}",
                case.horizon, rs.lower, rs.upper, r, o, rs.delta
            )
        }
        None => format!("T = {}", case.horizon),
    };
    system_counterexample(&sys, e, "theorem1", &extra)
}

pub fn property() -> Prop<Theorem1Case> {
    Prop { info: info(), strategy, eval, export, max_shrink_iters: 60 }
}
