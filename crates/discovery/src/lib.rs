//! Model-vs-recording diagnosis ("discovery"): given a nominal model of the paper's class
//! (linear plant closed by a backlash, eqs. (xy)-(yz)) and a recording `t, w, y` of the real
//! machine, find where simulation and recording disagree, name the physical effect the model
//! lacks, add it, refit, and show the improvement on a validation segment fitting never saw.
//!
//! Pipeline ([`diagnose::diagnose`], a list of named stages: see [`diagnose`](mod@diagnose)'s module map):
//! 1. [`recording`]: read and check the CSV, resample irregular time stamps to a uniform grid.
//! 2. [`dynamics::extended`]: free-run simulation of the model extended by [`model::effects`]
//!    (exact linear step, catching-up projection for the play, implicit stick-slip friction).
//! 3. [`metrics`]: fit % and RMSE on the validation segment (the last 30 % of the record).
//! 4. [`residual`]: whiteness and input cross-correlation tests of the nominal residual.
//! 5. [`localise`]: residual energy per regime (reversals, contact, input extremes, high
//!    acceleration) and the time windows where it concentrates.
//! 6. [`hypothesis`] + [`fit`]: each effect of the physics library ([`physics`], one file per
//!    family) fitted by simulation-error
//!    Levenberg-Marquardt with bounds and starts over decades (stuck fits flagged, never
//!    evidence against their effect); [`select`]: BIC with a margin (plus the remaining
//!    discretisation error's worth) and blocked cross-validation over contiguous folds
//!    ("not testable" where an effect lives in one fold), greedy forward selection.
//! 7. [`diagnose`](mod@diagnose): the verdict, the fitted model (`fitted.toml`) and the report
//!    ([`diagnose::report`], rendered as `report.md`), from [`diagnose::settings`].
//!
//! Before fitting: the input hold between samples (zero-/first-order, `auto` from the data)
//! and the sub-steps per sample by convergence against the noise level ([`discretisation`]);
//! the model file's initial state is used when it states one.
//!
//! [`bench_gen`] generates recordings with a concealed effect for the benchmark; no diagnosis
//! module imports it (the benchmark runner [`bench`] joins the two).
#![allow(non_snake_case)]

pub mod bench;
pub mod bench_gen;
pub mod diagnose;
pub mod discretisation;
pub mod error;
pub mod fit;
pub mod hypothesis;
pub mod localise;
pub mod metrics;
pub mod physics;
pub mod play_width;
pub mod recording;
pub mod residual;
pub mod select;

pub use diagnose::{diagnose, diagnose_recordings, DiagnoseSettings, HoldChoice, InitialState, Report};
pub use error::DiscoveryError;
pub use recording::Recording;
