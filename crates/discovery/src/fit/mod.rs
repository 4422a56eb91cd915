//! Simulation-error fitting of hypotheses: [`problem`] defines the residual (free-run
//! simulation minus measurement on the estimation segment), [`levenberg_marquardt`] the
//! bounded multi-start solver and the Gauss-Newton parameter covariance.
pub mod levenberg_marquardt;
pub mod problem;

pub use levenberg_marquardt::{fit, FitResult, FitSettings, FitStatus};
pub use problem::Problem;
