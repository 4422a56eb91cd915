//! The system of the paper, eq. (xy)-(yz): `x' = A x + B w + E z`, `y = C x`, `z in y + Theta`,
//! with its input `w(t)`, initial state `(x0, z0)` and simulation defaults, and the TOML
//! model-file format that describes it.
//!
//! - [`system`]: the validated [`System`] and its linearisation `F = A + E C` (eq. (F)).
//! - [`input`]: the input signal `w(t)` ([`Input`]: sine, square wave, multisine, samples from a CSV).
//! - [`fit`]: `[fit]`, the nominal parameters a grey-box refit may free ([`FitSpec`]) and the
//!   refits recorded in a fitted model.
//! - [`parameters`]: `[parameters]`, named physical constants and the numbers of the file
//!   written as expressions of them ([`Parameters`]).
//! - [`signals`]: `[signals]`, units of the recorded signals and tracking references
//!   ([`Signals`]).
//! - [`model_file`]: reading and writing model files with errors that name key and value (the
//!   parser: it builds the domain types above, which do not depend on it).
//! - [`files`]: regular files only, with a size limit (no FIFO or device blocks a load).
//! - [`controller`]: `[controller]`, a digital controller in the loop at its own sample period
//!   ([`Controller`]: cascade, PID or a discrete state-space law, computation delay).
//! - [`effects`]: optional physics extensions (friction, delay, ...) used by `discovery`;
//!   all equal to the nominal model at zero.
#![allow(non_snake_case)]

pub mod controller;
pub mod effects;
pub mod error;
pub mod files;
pub mod fit;
pub mod input;
pub mod model_file;
pub mod parameters;
pub mod signals;
pub mod system;
mod toml_access;

pub use controller::{ControlLaw, Controller};
pub use effects::Effects;
pub use error::ModelError;
pub use fit::{FitRecord, FitSpec, FreeParam, PlantMatrix};
pub use input::Input;
pub use model_file::{load, parse_str, to_toml_string};
pub use parameters::Parameters;
pub use signals::Signals;
pub use system::{check_step, SimDefaults, System, SystemBuilder, MIN_STEPS_PER_PERIOD};
pub use toml_access::MAX_MAGNITUDE;
