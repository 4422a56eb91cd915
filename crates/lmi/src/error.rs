//! Error values of the `lmi` crate.
//!
//! Every variant carries the offending values so that a caller (the driver) can
//! report *why* a certificate for eqs. (ALI), (bet) could not be produced. There is
//! deliberately no catch-all `String` variant.

use crate::status::SdpStatus;

/// Errors returned by the public functions of this crate.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LmiError {
    /// `F = A + E C` (eq. (F)) is not Hurwitz: `mu = max Re eig(F) >= 0` (eq. (stab)).
    #[error("F is not Hurwitz: mu = max Re eig(F) = {mu} >= 0")]
    NotHurwitz {
        /// Spectral abscissa of `F`.
        mu: f64,
    },
    /// `lambda` is outside the open interval `(0, |mu|)` required by eq. (lammu).
    #[error("lambda = {lambda} is outside (0, |mu|) with mu = {mu} (eq. (lammu))")]
    LambdaOutOfRange {
        /// Requested decay rate.
        lambda: f64,
        /// Spectral abscissa of `F`.
        mu: f64,
    },
    /// A matrix has the wrong shape.
    #[error("dimension mismatch for {what}: expected {expected:?}, found {found:?}")]
    DimensionMismatch {
        /// Which matrix (`"F"`, `"E"`, `"C"`, `"Pi"`).
        what: &'static str,
        /// Expected `(rows, cols)`.
        expected: (usize, usize),
        /// Actual `(rows, cols)`.
        found: (usize, usize),
    },
    /// A matrix is empty (`n = 0` or `p = 0`).
    #[error("{what} is empty: shape {shape:?}")]
    Empty {
        /// Which matrix.
        what: &'static str,
        /// Its shape.
        shape: (usize, usize),
    },
    /// A NaN or infinite entry in an input.
    #[error("non-finite entry {value} in {what} at ({row}, {col})")]
    NonFinite {
        /// Which matrix or scalar.
        what: &'static str,
        /// Row index.
        row: usize,
        /// Column index.
        col: usize,
        /// The entry.
        value: f64,
    },
    /// A settings field has an invalid value.
    #[error("invalid setting {name} = {value}")]
    InvalidSetting {
        /// Field name.
        name: &'static str,
        /// Field value (integers converted to `f64`).
        value: f64,
    },
    /// The eigenvalue iteration for `mu` (eq. (stab)) did not converge.
    #[error("Schur iteration for the eigenvalues of an {n} x {n} matrix did not converge")]
    EigenNotConverged {
        /// Matrix order.
        n: usize,
    },
    /// The SDP was reported (primal) infeasible by the solver.
    #[error("SDP infeasible at lambda = {lambda} (solver status {status:?})")]
    Infeasible {
        /// Decay rate at which the problem was posed.
        lambda: f64,
        /// Solver status.
        status: SdpStatus,
    },
    /// The SDP was reported unbounded (dual infeasible) by the solver.
    #[error("SDP unbounded at lambda = {lambda} (solver status {status:?})")]
    Unbounded {
        /// Decay rate at which the problem was posed.
        lambda: f64,
        /// Solver status.
        status: SdpStatus,
    },
    /// The solver stopped on its iteration limit.
    #[error("SDP solver hit its iteration limit {max_iter} at lambda = {lambda}")]
    IterationLimit {
        /// Decay rate at which the problem was posed.
        lambda: f64,
        /// The limit (`SdpSettings::max_iter`).
        max_iter: u32,
    },
    /// The solver stopped for another reason (numerical error, lack of progress, time limit).
    #[error("SDP solver failed at lambda = {lambda} with status {status:?}")]
    SolverFailed {
        /// Decay rate at which the problem was posed.
        lambda: f64,
        /// Solver status.
        status: SdpStatus,
    },
    /// Clarabel rejected the problem data at set-up (should not happen for validated input).
    #[error("SDP set-up rejected by the solver ({rows} rows, {cols} columns)")]
    SetupRejected {
        /// Number of constraint rows.
        rows: usize,
        /// Number of variables.
        cols: usize,
    },
    /// The returned `Pi` could not be rigorously verified even after backing off `lambda`
    /// and inflating `b_hat` (see [`crate::verify`]).
    #[error("certificate not verified at lambda = {lambda} (b_hat = {b_hat})")]
    NotVerified {
        /// Requested decay rate.
        lambda: f64,
        /// Last `b_hat` tried.
        b_hat: f64,
    },
    /// No `lambda` of the search grid produced a certificate (eq. (theta) cannot be evaluated).
    #[error("no lambda in (0, {abs_mu}) gave a verified certificate ({failures} failures)")]
    NoCertificate {
        /// `|mu|`.
        abs_mu: f64,
        /// Number of failed evaluations.
        failures: usize,
    },
    /// The user's `theta(lambda, beta)` closure returned NaN.
    #[error("theta({lambda}, {beta}) returned NaN")]
    ThetaNaN {
        /// Decay rate.
        lambda: f64,
        /// Verified beta bound.
        beta: f64,
    },
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, LmiError>;
