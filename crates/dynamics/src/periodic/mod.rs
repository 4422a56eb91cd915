//! The periodic regime for a `T`-periodic input.
//! - [`poincare`]: fixed point of the Poincare map of the catching-up scheme, its residual.
//! - [`linearised`]: `xi_T`, `eta_T = C xi_T` of the linearised system, eqs. (xT), (xiT), (etaT).
//!
//! (The check that the periodic state lies in the set (loc) uses the certified tube of
//! `bounds::tube::localisation`.)
pub mod linearised;
pub mod poincare;

use crate::error::{check_dt, DynamicsError};

/// Steps per period and the step that divides the period exactly: `N = ceil(T / dt)`,
/// `h = T / N <= dt`.
pub fn steps_per_period(T: f64, dt: f64) -> Result<(usize, f64), DynamicsError> {
    check_dt(dt)?;
    if !(T > 0.0 && T.is_finite()) {
        return Err(DynamicsError::BadSetting { name: "period", value: T, reason: "must be positive and finite" });
    }
    let r = T / dt;
    if r > 1e12 {
        return Err(DynamicsError::BadSetting { name: "dt", value: dt, reason: "more than 1e12 steps per period" });
    }
    let n = ((r * (1.0 - 1e-12)).ceil() as usize).max(1);
    Ok((n, T / n as f64))
}

/// The period of the system's input, or [`DynamicsError::NotPeriodic`].
pub fn period_of(sys: &model::System) -> Result<f64, DynamicsError> {
    sys.period().ok_or(DynamicsError::NotPeriodic { kind: sys.input.kind() })
}
