//! Errors of sweeps and merges: every variant names the offending value.
use std::path::PathBuf;
use thiserror::Error;

#[derive(Debug, Error)]
pub enum SweepError {
    #[error("cannot read {path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("{path}: not valid TOML: {message}")]
    Toml { path: PathBuf, message: String },
    #[error("{source}")]
    File { source: model::ModelError },
    #[error(transparent)]
    Locked(#[from] crate::output::LockError),
    #[error("cannot merge: {path}: {reason}")]
    MergeGrid { path: PathBuf, reason: String },
    #[error("[evaluate] {key}: {reason}")]
    Evaluate { key: &'static str, reason: String },
    #[error("{path}: missing key `{key}`")]
    MissingKey { path: PathBuf, key: String },
    #[error("{path}: unknown key `{}` (allowed: {allowed})", model::error::clip(key))]
    UnknownKey { path: PathBuf, key: String, allowed: &'static str },
    #[error("{path}: key `{key}` has the wrong type: expected {expected}")]
    WrongType { path: PathBuf, key: String, expected: &'static str },
    #[error("base model {path}: {source}")]
    Model { path: PathBuf, source: model::ModelError },
    #[error("the spec has no axes: add at least one [[axis]] with `parameter` and `values` or `range`")]
    NoAxes,
    #[error("axis `{name}`: unknown parameter (known: plant.A[i][j], plant.B[i][j], plant.C[i][j], plant.E[i][j] (0-based), input.amplitude, input.amplitude[k], input.omega, input.phase, theta.scale, theta.R, theta.half_width, parameters.NAME)")]
    UnknownParameter { name: String },
    #[error("axis `{name}`: the base model has no such parameter (its [parameters]: {})", if known.is_empty() { "none" } else { known.as_str() })]
    UnknownModelParameter { name: String, known: String },
    #[error("axis `{name}`: index ({i}, {j}) outside the {rows}x{cols} matrix (indices are 0-based)")]
    IndexOutOfRange { name: String, i: usize, j: usize, rows: usize, cols: usize },
    #[error("axis `{name}`: not applicable to the base model: {reason}")]
    NotApplicable { name: String, reason: &'static str },
    #[error("parameter `{name}` appears on two axes")]
    DuplicateAxis { name: String },
    #[error("axis `{name}`: the value list is empty")]
    EmptyValues { name: String },
    #[error("axis `{name}`: empty range from {from} to {to} ({detail})")]
    EmptyRange { name: String, from: f64, to: f64, detail: String },
    #[error("axis `{name}`: bad range: {reason}")]
    BadRange { name: String, reason: &'static str },
    #[error("axis `{name}`: value {value} is not finite")]
    NotFinite { name: String, value: f64 },
    #[error("axis `{name}`: value {value} gives an invalid model: {source}")]
    InvalidPoint { name: String, value: f64, source: model::ModelError },
    #[error("the grid has {points} points, more than the limit {limit}{}", points_hint(*limit))]
    TooManyPoints { points: u128, limit: usize },
    #[error("bad shard `{text}`: expected K/N with 0 <= K < N (K counts from 0, e.g. $SLURM_ARRAY_TASK_ID)")]
    BadShard { text: String },
    #[error("{source_key} {digits} is out of range: use 1 to 17")]
    BadDigits { digits: i64, source_key: &'static str },
    #[error("{path} holds results of a different sweep (spec hash {found}, this spec {expected}): choose another --out or pass --overwrite")]
    OtherSpec { path: PathBuf, found: String, expected: String },
    #[error("{path}: not a moreau sweep result: {reason}")]
    BadResultFile { path: PathBuf, reason: String },
    #[error("cannot merge: {a} has spec hash {hash_a} but {b} has {hash_b} (shards of different specs)")]
    MergeSpecMismatch { a: PathBuf, hash_a: String, b: PathBuf, hash_b: String },
    #[error("cannot merge: point {index} differs between {a} and {b}")]
    MergeConflict { index: usize, a: PathBuf, b: PathBuf },
    #[error("cannot merge: {missing} of {total} points missing (first missing index {first}); pass --partial to merge anyway")]
    MergeIncomplete { missing: usize, total: usize, first: usize },
    #[error("nothing to merge: no sweep result files given or found in {path}")]
    NothingToMerge { path: PathBuf },
    #[error("[table] columns: unknown column `{name}` (columns of this evaluator: {known})")]
    UnknownColumn { name: String, known: String },
    #[error("cannot create a thread pool with {threads} threads: {reason}")]
    ThreadPool { threads: usize, reason: String },
    #[error("cannot write {path}: {reason}")]
    Write { path: PathBuf, reason: String },
}

/// What lifts a grid-point limit: `--allow-large` the soft one, nothing the hard one (so the
/// message never advises `--allow-large` when it was given).
fn points_hint(limit: usize) -> String {
    if limit < super::spec::MAX_POINTS {
        format!("; pass --allow-large to raise it to {}", super::spec::MAX_POINTS)
    } else {
        " (the hard limit; --allow-large does not raise it)".to_string()
    }
}
