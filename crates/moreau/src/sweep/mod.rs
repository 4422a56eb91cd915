//! Parameter sweeps for papers' tables: a TOML spec ([`spec`]) names a base model and axes
//! ([`axis`]); every grid point is evaluated ([`eval`], theta in [`theta_eval`]) in parallel
//! and written as CSV, JSON, Markdown and LaTeX ([`table`]); runs resume ([`run`]) and split
//! over machines (`--shard K/N`, [`shard`]) to be joined by [`merge`].
pub mod axis;
pub mod error;
pub mod eval;
pub mod merge;
pub mod run;
pub mod shard;
pub mod spec;
pub mod table;
pub mod theta_eval;

pub use error::SweepError;
pub use eval::{Cell, Column, ColumnKind, Evaluator, FnEvaluator, PointError};
pub use run::{run, RunOptions, RunSummary};
pub use shard::Shard;
pub use spec::SweepSpec;
pub use table::{PointRecord, SweepResult};
