//! Typed access to a parsed TOML tree with errors that carry the full key path.
use crate::ModelError;
use nalgebra::DMatrix;
use toml::{Table, Value};

pub(crate) fn describe(v: &Value) -> String {
    match v {
        Value::String(s) => format!("string {s:?}"),
        Value::Integer(i) => format!("integer {i}"),
        Value::Float(f) => format!("float {f}"),
        Value::Boolean(b) => format!("boolean {b}"),
        Value::Datetime(d) => format!("datetime {d}"),
        Value::Array(a) => format!("array of length {}", a.len()),
        Value::Table(_) => "table".to_string(),
    }
}

pub(crate) fn key(prefix: &str, k: &str) -> String {
    if prefix.is_empty() {
        k.to_string()
    } else {
        format!("{prefix}.{k}")
    }
}

/// Largest magnitude of a number in a model file or a CSV input.
pub const MAX_MAGNITUDE: f64 = 1e100;

pub(crate) fn number(v: &Value, key: &str) -> Result<f64, ModelError> {
    let x = match v {
        Value::Float(f) => *f,
        Value::Integer(i) => *i as f64,
        other => return Err(ModelError::WrongType { key: key.into(), expected: "a number", found: describe(other) }),
    };
    if !x.is_finite() {
        return Err(ModelError::NotFinite { key: key.into(), value: x });
    }
    if x.abs() > MAX_MAGNITUDE {
        return Err(ModelError::Invalid {
            key: key.into(),
            value: x,
            reason: format!("magnitude above {MAX_MAGNITUDE:e}: products of such numbers overflow"),
        });
    }
    Ok(x)
}

pub(crate) fn get<'a>(t: &'a Table, prefix: &str, k: &str) -> Result<&'a Value, ModelError> {
    t.get(k).ok_or_else(|| ModelError::Missing { key: key(prefix, k) })
}

pub(crate) fn f64_at(t: &Table, prefix: &str, k: &str) -> Result<f64, ModelError> {
    number(get(t, prefix, k)?, &key(prefix, k))
}

pub(crate) fn opt_f64(t: &Table, prefix: &str, k: &str) -> Result<Option<f64>, ModelError> {
    t.get(k).map(|v| number(v, &key(prefix, k))).transpose()
}

/// A number at `k` that must be non-negative.
pub(crate) fn nonneg(t: &Table, prefix: &str, k: &str) -> Result<f64, ModelError> {
    let v = f64_at(t, prefix, k)?;
    if v < 0.0 {
        return Err(ModelError::OutOfRange { key: key(prefix, k), value: v, reason: "must be non-negative" });
    }
    Ok(v)
}

/// A number at `k` that must be positive.
pub(crate) fn positive(t: &Table, prefix: &str, k: &str) -> Result<f64, ModelError> {
    let v = f64_at(t, prefix, k)?;
    if v <= 0.0 {
        return Err(ModelError::OutOfRange { key: key(prefix, k), value: v, reason: "must be positive" });
    }
    Ok(v)
}

/// [`nonneg`] where `k` may be absent.
pub(crate) fn opt_nonneg(t: &Table, prefix: &str, k: &str) -> Result<Option<f64>, ModelError> {
    t.get(k).map(|_| nonneg(t, prefix, k)).transpose()
}

/// [`positive`] where `k` may be absent.
pub(crate) fn opt_positive(t: &Table, prefix: &str, k: &str) -> Result<Option<f64>, ModelError> {
    t.get(k).map(|_| positive(t, prefix, k)).transpose()
}

pub(crate) fn str_at<'a>(t: &'a Table, prefix: &str, k: &str) -> Result<&'a str, ModelError> {
    match get(t, prefix, k)? {
        Value::String(s) => Ok(s),
        other => Err(ModelError::WrongType { key: key(prefix, k), expected: "a string", found: describe(other) }),
    }
}

pub(crate) fn table_at<'a>(t: &'a Table, prefix: &str, k: &str) -> Result<&'a Table, ModelError> {
    match get(t, prefix, k)? {
        Value::Table(s) => Ok(s),
        other => Err(ModelError::WrongType { key: key(prefix, k), expected: "a table", found: describe(other) }),
    }
}

pub(crate) fn vector(v: &Value, key: &str) -> Result<Vec<f64>, ModelError> {
    match v {
        Value::Array(a) => a.iter().enumerate().map(|(i, x)| number(x, &format!("{key}[{i}]"))).collect(),
        // a bare number is accepted as a vector of length one
        Value::Float(_) | Value::Integer(_) => Ok(vec![number(v, key)?]),
        other => {
            Err(ModelError::WrongType { key: key.into(), expected: "an array of numbers", found: describe(other) })
        }
    }
}

pub(crate) fn vec_at(t: &Table, prefix: &str, k: &str) -> Result<Vec<f64>, ModelError> {
    vector(get(t, prefix, k)?, &key(prefix, k))
}

/// A matrix written as an array of rows. A flat array is read as a column vector when
/// `column_if_flat` (so `B = [0, 1]` means the 2x1 matrix), otherwise as a single row.
pub(crate) fn matrix(v: &Value, key: &str, column_if_flat: bool) -> Result<DMatrix<f64>, ModelError> {
    let rows = match v {
        Value::Array(a) => a,
        other => {
            return Err(ModelError::WrongType { key: key.into(), expected: "an array of rows", found: describe(other) })
        }
    };
    if rows.is_empty() {
        return Err(ModelError::Dimension {
            key: key.into(),
            expected: "at least one row".into(),
            got: "an empty array".into(),
        });
    }
    if rows.iter().all(|r| !matches!(r, Value::Array(_))) {
        let flat = vector(v, key)?;
        let n = flat.len();
        return Ok(if column_if_flat { DMatrix::from_vec(n, 1, flat) } else { DMatrix::from_vec(1, n, flat) });
    }
    let mut data: Vec<Vec<f64>> = Vec::with_capacity(rows.len());
    for (i, r) in rows.iter().enumerate() {
        let row_key = format!("{key}[{i}]");
        match r {
            Value::Array(_) => data.push(vector(r, &row_key)?),
            other => {
                return Err(ModelError::WrongType {
                    key: row_key,
                    expected: "a row (array of numbers)",
                    found: describe(other),
                })
            }
        }
    }
    let ncols = data[0].len();
    if let Some((row, r)) = data.iter().enumerate().find(|(_, r)| r.len() != ncols) {
        return Err(ModelError::Ragged { key: key.into(), first: ncols, row, len: r.len() });
    }
    Ok(DMatrix::from_fn(data.len(), ncols, |i, j| data[i][j]))
}

pub(crate) fn matrix_at(t: &Table, prefix: &str, k: &str, column_if_flat: bool) -> Result<DMatrix<f64>, ModelError> {
    matrix(get(t, prefix, k)?, &key(prefix, k), column_if_flat)
}

pub(crate) fn rows_at(t: &Table, prefix: &str, k: &str) -> Result<Vec<Vec<f64>>, ModelError> {
    let m = matrix_at(t, prefix, k, false)?;
    Ok((0..m.nrows()).map(|i| m.row(i).iter().copied().collect()).collect())
}

pub(crate) fn check_keys(t: &Table, prefix: &str, known: &'static str) -> Result<(), ModelError> {
    let list: Vec<&str> = known.split(", ").collect();
    for k in t.keys() {
        if !list.contains(&k.as_str()) {
            return Err(ModelError::UnknownKey { key: key(prefix, k), known });
        }
    }
    Ok(())
}

pub(crate) fn matrix_value(m: &DMatrix<f64>) -> Value {
    Value::Array((0..m.nrows()).map(|i| Value::Array(m.row(i).iter().map(|&x| Value::Float(x)).collect())).collect())
}

pub(crate) fn vec_value(v: &[f64]) -> Value {
    Value::Array(v.iter().map(|&x| Value::Float(x)).collect())
}
