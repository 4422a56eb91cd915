//! Simulation-error fitting of hypotheses: [`problem`] defines the residual (free-run
//! simulation minus measurement on the estimation segment), [`levenberg_marquardt`] the
//! bounded multi-start solver and the Gauss-Newton parameter covariance, [`nominal`] the
//! freed nominal parameters of a grey-box refit (`[fit] free` in the model file),
//! [`missing_input`] the check for a recorded signal the model leaves out, [`input_effects`]
//! input effects on one input of several, [`joint`] one model fitted to several recordings,
//! [`jackknife`] the model-error spread of fitted
//! parameters over contiguous folds.
pub mod input_effects;
pub mod jackknife;
pub mod joint;
pub mod levenberg_marquardt;
pub mod missing_input;
pub mod nominal;
pub mod problem;

pub use levenberg_marquardt::{
    fit, fit_estimate, fit_groups, EffectCovariance, FitResult, FitSettings, FitStatus, PartStarts, LONG_RECORD,
    MIN_START_SUBSTEPS, START_COARSENING,
};
pub use nominal::{FreeNominal, Refit};
pub use problem::Problem;
