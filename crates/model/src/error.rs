//! Errors of model files: each names the offending key and value.
use thiserror::Error;

#[derive(Debug, Error)]
pub enum ModelError {
    #[error("cannot read {path}: {source}")]
    Io { path: String, source: std::io::Error },
    #[error("{path}: TOML syntax error: {message}")]
    Syntax { path: String, message: String },
    #[error("missing key `{key}`")]
    Missing { key: String },
    #[error("key `{key}`: expected {expected}, found {found}")]
    WrongType { key: String, expected: &'static str, found: String },
    #[error("key `{key}`: value {value} is not finite")]
    NotFinite { key: String, value: f64 },
    #[error("key `{key}`: {reason} (value {value})")]
    OutOfRange { key: String, value: f64, reason: &'static str },
    #[error("key `{key}`: expected {expected}, got {got}")]
    Dimension { key: String, expected: String, got: String },
    #[error("key `{key}`: rows have different lengths (row 0 has {first}, row {row} has {len})")]
    Ragged { key: String, first: usize, row: usize, len: usize },
    #[error("key `theta.shape`: unknown shape {value:?} (known: interval, ball, ellipsoid, ball_intersection, polytope, box, point)")]
    UnknownShape { value: String },
    #[error("key `input.kind`: unknown input {value:?} (known: sine, square, csv, zero)")]
    UnknownInput { value: String },
    #[error("key `{key}`: {source}")]
    Geometry { key: String, source: geometry::GeometryError },
    #[error("Theta does not contain 0 (distance {distance:e} from 0 to Theta = {theta})")]
    ThetaMissesOrigin { distance: f64, theta: String },
    #[error("initial condition violates z0 - C x0 in Theta: q0 = {q0:?} is at distance {distance:e} from Theta")]
    InitialOutsideTheta { q0: Vec<f64>, distance: f64 },
    #[error("input CSV {path}: {reason}")]
    Csv { path: String, reason: String },
    #[error("input CSV {path}: time stamps must increase strictly: row {row} has t = {t} after t = {prev}")]
    UnsortedTimes { path: String, row: usize, t: f64, prev: f64 },
    #[error("input CSV {path}: row {row}, column `{column}`: value {value:?} is not a finite number")]
    CsvValue { path: String, row: usize, column: String, value: String },
    #[error("key `{key}`: unknown key (known here: {known})")]
    UnknownKey { key: String, known: &'static str },
    #[error("cannot read {path}: {kind}, not a regular file (input files must be regular files)")]
    NotRegularFile { path: String, kind: &'static str },
    #[error("cannot read {path}: {bytes} bytes, more than the limit of {limit} bytes")]
    FileTooLarge { path: String, bytes: u64, limit: u64 },
    #[error("keys `{a}` and `{b}` exclude each other: give only one")]
    ExclusiveKeys { a: String, b: String },
    #[error("key `{key}`: {reason} (value {})", fmt_num(*value))]
    Invalid { key: String, value: f64, reason: String },
    #[error("key `theta`: the intersection of the balls has an empty interior ({reason}); projections onto it do not converge")]
    EmptyInterior { reason: String },
}

/// A number for an error message: plain decimals for ordinary magnitudes, scientific
/// notation for very large or small ones.
pub fn fmt_num(x: f64) -> String {
    if x == 0.0 || (1e-4..1e15).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}
