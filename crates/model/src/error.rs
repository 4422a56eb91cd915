//! Errors of model files: each names the offending key and value.
use thiserror::Error;

#[derive(Debug, Error)]
pub enum ModelError {
    #[error("cannot read {path}: {source}")]
    Io { path: String, source: std::io::Error },
    #[error("{path}: TOML syntax error: {}", clip_to(message, 10 * MAX_ECHO))]
    Syntax { path: String, message: String },
    #[error("missing key `{}`", clip(key))]
    Missing { key: String },
    #[error("key `{}`: expected {expected}, found {}", clip(key), clip(found))]
    WrongType { key: String, expected: &'static str, found: String },
    #[error("key `{}`: value {value} is not finite", clip(key))]
    NotFinite { key: String, value: f64 },
    #[error("key `{}`: {reason} (value {value})", clip(key))]
    OutOfRange { key: String, value: f64, reason: &'static str },
    #[error("key `{}`: expected {expected}, got {}", clip(key), clip(got))]
    Dimension { key: String, expected: String, got: String },
    #[error("key `{}`: rows have different lengths (row 0 has {first}, row {row} has {len})", clip(key))]
    Ragged { key: String, first: usize, row: usize, len: usize },
    #[error("key `theta.shape`: unknown shape {:?} (known: interval, ball, ellipsoid, ball_intersection, polytope, box, point)", clip(value))]
    UnknownShape { value: String },
    #[error("key `input.kind`: unknown input {:?} (known: sine, square, multisine, csv, zero)", clip(value))]
    UnknownInput { value: String },
    #[error("key `{}`: {source}", clip(key))]
    Geometry { key: String, source: geometry::GeometryError },
    #[error("Theta does not contain 0 (distance {distance:e} from 0 to Theta = {theta})")]
    ThetaMissesOrigin { distance: f64, theta: String },
    #[error("initial condition violates z0 - C x0 in Theta: q0 = {q0:?} is at distance {distance:e} from Theta")]
    InitialOutsideTheta { q0: Vec<f64>, distance: f64 },
    #[error("input CSV {path}: {reason}")]
    Csv { path: String, reason: String },
    #[error("input CSV {path}: time stamps must increase strictly: row {row} has t = {t} after t = {prev}")]
    UnsortedTimes { path: String, row: usize, t: f64, prev: f64 },
    #[error("input CSV {path}: row {row}, column `{}`: value {:?} is not a finite number", clip(column), clip(value))]
    CsvValue { path: String, row: usize, column: String, value: String },
    #[error("key `{}`: unknown key (known here: {known})", clip(key))]
    UnknownKey { key: String, known: &'static str },
    #[error("cannot read {path}: {kind}, not a regular file (input files must be regular files)")]
    NotRegularFile { path: String, kind: &'static str },
    #[error("cannot read {path}: {bytes} bytes, more than the limit of {limit} bytes")]
    FileTooLarge { path: String, bytes: u64, limit: u64 },
    #[error("key `{key}`: {bytes} bytes long, more than the limit of {limit} bytes")]
    TooLong { key: String, bytes: usize, limit: usize },
    #[error("keys `{}` and `{}` exclude each other: give only one", clip(a), clip(b))]
    ExclusiveKeys { a: String, b: String },
    #[error("key `{}`: {reason} (value {})", clip(key), fmt_num(*value))]
    Invalid { key: String, value: f64, reason: String },
    #[error("key `theta`: the intersection of the balls has an empty interior ({reason}); projections onto it do not converge")]
    EmptyInterior { reason: String },
    #[error("key `{}`: expression {:?}: {}", clip(key), clip(text), clip(reason))]
    Expression { key: String, text: String, reason: String },
    #[error("unknown parameter `{}` (parameters of this model: {})", clip(name), if known.is_empty() { "none" } else { known.as_str() })]
    UnknownParameter { name: String, known: String },
}

impl ModelError {
    /// `Ok` where a vector at `key` has the `expected` length `dim` (`dim` names it: `n`, `p`,
    /// `nc`), else the [`ModelError::Dimension`] naming both lengths.
    pub fn check_length(key: impl Into<String>, len: usize, dim: &str, expected: usize) -> Result<(), ModelError> {
        if len == expected {
            return Ok(());
        }
        Err(ModelError::Dimension {
            key: key.into(),
            expected: format!("length {dim} = {expected}"),
            got: format!("length {len}"),
        })
    }
}

/// Longest text (a key, a path, a value) an error message echoes in full.
pub const MAX_ECHO: usize = 200;

/// Text for an error message: as it is up to [`MAX_ECHO`] bytes, otherwise its start and its
/// length (a 10 MB key is named, not echoed).
pub fn clip(text: &str) -> std::borrow::Cow<'_, str> {
    clip_to(text, MAX_ECHO)
}

/// [`clip`] with another limit (a parser's message with its source snippet gets more room).
pub fn clip_to(text: &str, max: usize) -> std::borrow::Cow<'_, str> {
    if text.len() <= max {
        return text.into();
    }
    let mut end = max / 2;
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    format!("{}... ({} bytes in all)", &text[..end], text.len()).into()
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_huge_key_is_named_not_echoed() {
        let key = "k".repeat(10 << 20);
        let msg = ModelError::UnknownKey { key: key.clone(), known: "name" }.to_string();
        assert!(msg.len() < 400, "{} bytes", msg.len());
        assert!(msg.contains(&format!("({} bytes in all)", key.len())), "{msg}");
        // negative control: an ordinary key is echoed whole
        let msg = ModelError::UnknownKey { key: "plant.Q".into(), known: "A, B" }.to_string();
        assert_eq!(msg, "key `plant.Q`: unknown key (known here: A, B)");
        // a multi-byte character at the cut is not split
        let wide = "\u{e9}".repeat(MAX_ECHO);
        assert!(clip(&wide).ends_with("bytes in all)"));
    }
}
