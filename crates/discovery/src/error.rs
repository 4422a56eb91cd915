//! Errors of the diagnosis: each names the problem and the offending value.
use thiserror::Error;

#[derive(Debug, Error)]
pub enum DiscoveryError {
    #[error("cannot read recording {path}: {reason}")]
    Io { path: String, reason: String },
    #[error("recording {path}: header {header:?} lacks column `{column}` (expected `t,w,y` or `t,w1..wm,y1..yp`, optional `z`)")]
    MissingColumn { path: String, column: String, header: Vec<String> },
    #[error("recording {path}: row {row}, column `{column}`: value {value:?} is not a finite number")]
    NotFinite { path: String, row: usize, column: String, value: String },
    #[error("recording {path}: row {row} has {got} fields, the header has {expected}")]
    RowLength { path: String, row: usize, got: usize, expected: usize },
    #[error("recording {path}: time must increase strictly: row {row} has t = {t} after t = {prev}")]
    NonIncreasingTime { path: String, row: usize, t: f64, prev: f64 },
    #[error("recording {path}: the sampling gap of {gap} s before row {row} is {ratio:.0} times the median interval {median} s (at most {max_ratio} allowed): resampling would invent data across it; split the recording at the gap")]
    TimeGap { path: String, row: usize, gap: f64, median: f64, ratio: f64, max_ratio: f64 },
    #[error("recording {path}: input column `{column}` is constant (value {value}); nothing can be identified from a constant input")]
    ConstantInput { path: String, column: String, value: f64 },
    #[error("recording {path}: only {rows} samples; at least {min} are needed")]
    TooFewSamples { path: String, rows: usize, min: usize },
    #[error("recording lasts {duration} s, shorter than 3 x the model's slowest time constant ({tau_slow} s): the dynamics cannot be seen")]
    TooShort { duration: f64, tau_slow: f64 },
    #[error(
        "model and recording disagree: the model has {what} = {model} but the recording has {recording} ({columns})"
    )]
    DimensionMismatch { what: &'static str, model: usize, recording: usize, columns: String },
    #[error("the model is not stable (max Re eig(F) = {mu}); a free-run simulation fit is meaningless")]
    Unstable { mu: f64 },
    #[error("simulation: {0}")]
    Dynamics(#[from] dynamics::DynamicsError),
    #[error("no recording to fit on (give at least one --data)")]
    NoRecording,
    #[error("recordings {first} and {other} differ in their {what}: {first_has} against {other_has} (recordings of one machine have the same signal columns)")]
    RecordingsDiffer { first: String, other: String, what: &'static str, first_has: String, other_has: String },
    #[error("recording {path}: {reason}")]
    InRecording { path: String, reason: String },
    #[error("settings: {field} = {value}: {reason}")]
    BadSetting { field: &'static str, value: f64, reason: &'static str },
}
