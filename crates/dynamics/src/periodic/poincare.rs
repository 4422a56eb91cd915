//! Fixed point of the Poincare map `P : (x(0), z(0)) -> (x(T), z(T))` of the catching-up scheme
//! for a `T`-periodic input (`h = T / N` divides the period, so `P` is the same map each period).
//!
//! Method: plain fixed-point iteration `s_{j+1} = P(s_j)`. The paper's theory (and every
//! measurement so far) makes `P` a contraction whenever the rate exponent is negative, so the
//! iteration converges at the measured rate; each iteration costs one simulated period. The
//! result carries its residual `|P(s) - s|_inf` (one more application of `P` after the stop)
//! and a status instead of panicking when `max_periods` is reached.
use super::{period_of, steps_per_period};
use crate::error::DynamicsError;
use crate::integrators::catching_up::{CatchingUpSettings, Simulator};
use crate::linear::step_map::InputHold;
use model::System;
use serde::Serialize;

/// Settings of the periodic-regime search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoincareSettings {
    /// Requested step (the step used is `T / ceil(T / dt)`). Default `1e-3`.
    pub dt: f64,
    /// Input hold of the catching-up scheme. Default linear.
    pub hold: InputHold,
    /// Stop when `|P(s) - s|_inf <= tol_residual (1 + |s|_inf)`. Default `1e-11`.
    pub tol_residual: f64,
    /// Maximal number of simulated periods. Default `5000`.
    pub max_periods: usize,
}

impl Default for PoincareSettings {
    fn default() -> Self {
        Self { dt: 1e-3, hold: InputHold::Foh, tol_residual: 1e-11, max_periods: 5000 }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum FixedPointStatus {
    Converged,
    MaxPeriodsReached,
}

/// The periodic regime found.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PeriodicRegime {
    pub period: f64,
    /// Step used (`T / steps_per_period`).
    pub h: f64,
    pub steps_per_period: usize,
    /// Periodic state at `t = 0 (mod T)`.
    pub x0: Vec<f64>,
    pub z0: Vec<f64>,
    /// `|P(s) - s|_inf` at the returned `s`.
    pub residual: f64,
    /// Periods simulated.
    pub iterations: usize,
    /// Geometric mean contraction of successive steps over the last iterations (estimate of
    /// `e^{2 lambda T}`-like decay per period of the step size, not a certificate).
    pub contraction_per_period: f64,
    pub status: FixedPointStatus,
}

fn dist_inf(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(u, v)| (u - v).abs()).fold(0.0, f64::max)
}

/// Finds the periodic regime from `(sys.x0, sys.z0)`.
pub fn periodic_regime(sys: &System, settings: &PoincareSettings) -> Result<PeriodicRegime, DynamicsError> {
    let T = period_of(sys)?;
    let (N, h) = steps_per_period(T, settings.dt)?;
    if !(settings.tol_residual > 0.0) {
        return Err(DynamicsError::BadSetting {
            name: "tol_residual",
            value: settings.tol_residual,
            reason: "must be positive",
        });
    }
    let mut sim = Simulator::new(sys, &CatchingUpSettings { dt: h, hold: settings.hold })?;
    let (mut x, mut z) = (sys.x0.as_slice().to_vec(), sys.z0.as_slice().to_vec());
    let mut prev = [x.clone(), z.clone()].concat();
    let mut steps_hist: Vec<f64> = Vec::new();
    let mut status = FixedPointStatus::MaxPeriodsReached;
    let mut it = 0;
    while it < settings.max_periods {
        sim.run(0.0, &mut x, &mut z, N, |_, _, _, _| {});
        it += 1;
        let cur = [x.as_slice(), z.as_slice()].concat();
        if !cur.iter().all(|v| v.is_finite()) {
            return Err(DynamicsError::NonFinite { t: it as f64 * T });
        }
        let d = dist_inf(&cur, &prev);
        steps_hist.push(d);
        let scale = 1.0 + cur.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        prev = cur;
        if d <= settings.tol_residual * scale {
            status = FixedPointStatus::Converged;
            break;
        }
    }
    // honest residual: one more period from the returned state
    let (mut x1, mut z1) = (x.clone(), z.clone());
    sim.run(0.0, &mut x1, &mut z1, N, |_, _, _, _| {});
    let residual = dist_inf(&[x1, z1].concat(), &prev);
    let k = steps_hist.len();
    let contraction = if k >= 4 {
        let (a, b) = (steps_hist[k / 2].max(1e-300), steps_hist[k - 1].max(1e-300));
        (b / a).powf(1.0 / (k - 1 - k / 2).max(1) as f64)
    } else {
        f64::NAN
    };
    Ok(PeriodicRegime {
        period: T,
        h,
        steps_per_period: N,
        x0: x,
        z0: z,
        residual,
        iterations: it,
        contraction_per_period: contraction,
        status,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn worked_example_has_a_periodic_regime_with_small_residual() {
        let sys = model::parse_str(include_str!("../../../../examples/worked-example.toml")).unwrap();
        let r = periodic_regime(&sys, &PoincareSettings::default()).unwrap();
        assert_eq!(r.status, FixedPointStatus::Converged);
        assert!(r.residual < 1e-9, "residual {}", r.residual);
        // negative control: the initial state (rest) is not periodic
        let mut x = sys.x0.as_slice().to_vec();
        let mut z = sys.z0.as_slice().to_vec();
        let mut sim = Simulator::new(&sys, &CatchingUpSettings { dt: r.h, hold: InputHold::Foh }).unwrap();
        sim.run(0.0, &mut x, &mut z, r.steps_per_period, |_, _, _, _| {});
        assert!(dist_inf(&x, sys.x0.as_slice()) > 1e-3);
    }

    #[test]
    fn non_periodic_input_is_rejected() {
        let mut sys = model::parse_str(include_str!("../../../../examples/worked-example.toml")).unwrap();
        sys.input = model::Input::Zero { m: 1 };
        assert!(matches!(periodic_regime(&sys, &PoincareSettings::default()), Err(DynamicsError::NotPeriodic { .. })));
    }
}
