//! Errors of the dynamics crate: every variant names the offending value.
use thiserror::Error;

#[derive(Debug, Error, Clone, PartialEq)]
pub enum DynamicsError {
    #[error("time step dt = {dt} must be positive and finite")]
    BadStep { dt: f64 },
    #[error("number of periods must be at least 1, got {periods}")]
    ZeroPeriods { periods: usize },
    #[error("the input `{kind}` is not periodic: the periodic regime needs a T-periodic w")]
    NotPeriodic { kind: &'static str },
    #[error("setting `{name}` = {value} is out of range: {reason}")]
    BadSetting { name: &'static str, value: f64, reason: &'static str },
    #[error("dimension mismatch for {what}: expected {expected}, got {got}")]
    Dimension { what: &'static str, expected: usize, got: usize },
    #[error("I - e^(T F) is singular (min singular value {sigma_min:e}): F has an eigenvalue on 2 pi i Z / T")]
    ResonantPeriod { sigma_min: f64 },
    #[error("the event-driven integrator supports Theta = interval (p = 1), ball or ellipsoid; got {shape}")]
    UnsupportedShape { shape: String },
    #[error("the event-driven integrator needs an input of kind zero or sine (the exosystem); got {kind}")]
    UnsupportedInput { kind: &'static str },
    #[error("event location failed at t = {t}: {what}")]
    EventLocation { t: f64, what: &'static str },
    #[error("too many events ({count}) before t = {t}: chattering or Zeno behaviour")]
    TooManyEvents { count: usize, t: f64 },
    #[error("effect {kind}: {reason} (value {value})")]
    BadEffect { kind: &'static str, reason: &'static str, value: f64 },
    #[error("controller.period = {period} is not a positive integer multiple of the sample spacing dt = {dt}: the controller ticks on the samples")]
    ControllerPeriod { period: f64, dt: f64 },
    #[error("the state became non-finite at t = {t}")]
    NonFinite { t: f64 },
}

/// Checks a time step.
pub fn check_dt(dt: f64) -> Result<(), DynamicsError> {
    if dt > 0.0 && dt.is_finite() {
        Ok(())
    } else {
        Err(DynamicsError::BadStep { dt })
    }
}
