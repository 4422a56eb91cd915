//! The solver status of a conic solve, mirrored from Clarabel's `SolverStatus` so that
//! Clarabel's types stay out of the API. Its own module so that [`crate::error`] (whose
//! variants carry a status) and [`crate::sdp`] (which produces it) both depend on it and not
//! on each other.
use clarabel::solver::SolverStatus;

/// Solver status, mirrored from Clarabel so that its types do not leak into the API.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum SdpStatus {
    /// Converged to the requested tolerances.
    Solved,
    /// Converged to the reduced tolerances.
    AlmostSolved,
    /// Primal infeasibility certificate (possibly reduced accuracy).
    PrimalInfeasible,
    /// Dual infeasibility certificate, i.e. unbounded (possibly reduced accuracy).
    DualInfeasible,
    /// Iteration limit reached.
    MaxIterations,
    /// Time limit reached.
    MaxTime,
    /// Numerical error in the factorisation.
    NumericalError,
    /// Lack of progress.
    InsufficientProgress,
    /// Not solved / terminated by callback.
    Unsolved,
}

impl From<SolverStatus> for SdpStatus {
    fn from(s: SolverStatus) -> Self {
        match s {
            SolverStatus::Solved => SdpStatus::Solved,
            SolverStatus::AlmostSolved => SdpStatus::AlmostSolved,
            SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => SdpStatus::PrimalInfeasible,
            SolverStatus::DualInfeasible | SolverStatus::AlmostDualInfeasible => SdpStatus::DualInfeasible,
            SolverStatus::MaxIterations => SdpStatus::MaxIterations,
            SolverStatus::MaxTime => SdpStatus::MaxTime,
            SolverStatus::NumericalError => SdpStatus::NumericalError,
            SolverStatus::InsufficientProgress => SdpStatus::InsufficientProgress,
            SolverStatus::Unsolved | SolverStatus::CallbackTerminated => SdpStatus::Unsolved,
        }
    }
}
