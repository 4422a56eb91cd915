//! Errors of the `bounds` library: every variant names the offending value. Only the CLI turns
//! them into `anyhow` messages.
use thiserror::Error;

/// Why a quantity of the paper could not be computed at all.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum BoundsError {
    /// `F = A + E C` (eq. (F)) is not Hurwitz: no periodic regime theory applies.
    #[error("F = A + E C is not Hurwitz: mu = max Re eig(F) = {mu} >= 0 (eq. (stab)); theta does not exist")]
    NotHurwitz { mu: f64 },
    /// The input has no period: Theorem 2 and eq. (theta) need a T-periodic input.
    #[error("the input `{kind}` has no period: theta (eq. (theta)) needs a T-periodic input (sine, square, multisine, or csv with `period`)")]
    NoPeriod { kind: &'static str },
    /// A settings field is out of range.
    #[error("setting `{name}` = {value} is out of range: {reason}")]
    BadSetting { name: &'static str, value: f64, reason: &'static str },
    /// The tail bound of eq. (DXX) could not be established (no `tau` with `||e^{tau F}|| < 1`).
    #[error("no tail bound for eq. (DXX): ||e^(tau F)||_F >= 1 up to tau = {tau_max}")]
    NoTailBound { tau_max: f64 },
    /// The tube quadrature did not reach its tolerance within the allowed number of nodes.
    #[error("tube quadrature: error bound {error_bound:e} > tolerance {tol:e} with {nodes} nodes")]
    QuadratureBudget { error_bound: f64, tol: f64, nodes: usize },
    /// The LMI step (eqs. (ALI), (bet)) failed.
    #[error("Lyapunov matrix Pi (eqs. (ALI), (bet)): {0}")]
    Lmi(#[from] lmi::LmiError),
    /// The simulation / linearised periodic solution failed.
    #[error("dynamics: {0}")]
    Dynamics(#[from] dynamics::DynamicsError),
    /// The conic program of the stationary set (eq. (stat1)) could not be posed.
    #[error("stationary set (eq. (stat1)): {what}")]
    ConicData { what: &'static str },
    /// The conic solver for the stationary set (eq. (stat1)) stopped without a solution.
    #[error("stationary set (eq. (stat1)): the conic solver stopped with status {status:?}")]
    ConicSolver { status: lmi::SdpStatus },
}
