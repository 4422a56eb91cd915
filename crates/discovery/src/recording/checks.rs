//! Checks of recordings and logs before a reader parses them: regular files of bounded size
//! only, no duplicate column names (a header `t,w,y,y` would silently drop a column), numeric
//! time stamps resolvable in double precision, no number near overflow (`|x| > 1e100`), and
//! for the play-width logs (whose reader accepts them) every row as long as the header and
//! ISO time stamps in order. The recording reader itself ([`super::Recording::parse_str`])
//! names ragged rows and non-increasing times.
use model::{ModelError, MAX_MAGNITUDE};
use std::path::Path;
use thiserror::Error;

/// How the time column is checked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TimeColumn<'a> {
    /// A numeric column (`t` of a recording): steps resolvable in double precision.
    Numeric(&'a str),
    /// A text column of ISO 8601 stamps (`timestamp` of the Robonine logs): not decreasing.
    Iso8601(&'a str),
}

/// Why a recording or log file was refused before its reader saw it. `file` names the file
/// (its path, or the name given to CSV text); `what` names its role in read errors.
#[derive(Debug, Error)]
pub enum CsvCheckError {
    #[error("cannot read {what} {path}: {reason}")]
    Unreadable { what: String, path: String, reason: String },
    #[error("cannot read {what} {path}: {kind}, not a regular file (input files must be regular files)")]
    NotRegularFile { what: String, path: String, kind: &'static str },
    #[error("cannot read {what} {path}: {bytes} bytes, more than the limit of {limit} bytes")]
    TooLarge { what: String, path: String, bytes: u64, limit: u64 },
    #[error(transparent)]
    Model(ModelError),
    #[error("{file}: unreadable header: {reason}")]
    Header { file: String, reason: String },
    #[error("{file}: duplicate column `{name}` (columns {first} and {second}) in the header")]
    DuplicateColumn { file: String, name: String, first: usize, second: usize },
    #[error("{file}: row {row}: {reason}")]
    Row { file: String, row: usize, reason: String },
    #[error("{file}: row {row} has {got} fields, the header has {expected}")]
    RowLength { file: String, row: usize, got: usize, expected: usize },
    #[error("{file}: row {row}, column `{column}`: value {value:e} has a magnitude above {max:e}", max = MAX_MAGNITUDE)]
    Overflow { file: String, row: usize, column: String, value: f64 },
    #[error("{file}: row {row}: time step {step} at `{column}` = {t:e} is below the resolution of double precision")]
    TimeResolution { file: String, row: usize, step: f64, column: String, t: f64 },
    #[error("{file}: row {row}: `{column}` {stamp} is earlier than {prev} of the row before (the log must be in time order)")]
    TimeOrder { file: String, row: usize, column: String, stamp: String, prev: String },
}

/// Reads `path` (a regular file of at most `model::files::MAX_CSV_BYTES`) and checks it as
/// described in the module documentation; returns the text. `what` names the file in read
/// errors (`cannot read recording PATH: ...`).
pub fn read_checked(path: &Path, what: &str, time: TimeColumn) -> Result<String, CsvCheckError> {
    let what = what.to_string();
    let text = model::files::read_regular(path, model::files::MAX_CSV_BYTES).map_err(|e| match e {
        ModelError::Io { path, source } => CsvCheckError::Unreadable { what, path, reason: source.to_string() },
        ModelError::NotRegularFile { path, kind } => CsvCheckError::NotRegularFile { what, path, kind },
        ModelError::FileTooLarge { path, bytes, limit } => CsvCheckError::TooLarge { what, path, bytes, limit },
        other => CsvCheckError::Model(other),
    })?;
    check_text(&text, &path.display().to_string(), time)?;
    Ok(text)
}

/// The checks of [`read_checked`] on CSV text; `source` names it in errors.
pub fn check_text(text: &str, source: &str, time: TimeColumn) -> Result<(), CsvCheckError> {
    let file = || source.to_string();
    let mut rdr =
        csv::ReaderBuilder::new().has_headers(true).flexible(true).trim(csv::Trim::All).from_reader(text.as_bytes());
    let header: Vec<String> = match rdr.headers() {
        Ok(h) => h.iter().map(String::from).collect(),
        Err(e) => return Err(CsvCheckError::Header { file: file(), reason: e.to_string() }),
    };
    let mut seen = std::collections::HashMap::with_capacity(header.len());
    for (j, name) in header.iter().enumerate() {
        if let Some(&i) = seen.get(name.as_str()) {
            return Err(CsvCheckError::DuplicateColumn {
                file: file(),
                name: name.clone(),
                first: i + 1,
                second: j + 1,
            });
        }
        seen.insert(name.as_str(), j);
    }
    let (tname, numeric) = match time {
        TimeColumn::Numeric(n) => (n, true),
        TimeColumn::Iso8601(n) => (n, false),
    };
    let it = header.iter().position(|h| h == tname);
    let mut prev_num: Option<f64> = None;
    let mut prev_text: Option<String> = None;
    for (r, rec) in rdr.records().enumerate() {
        let row = r + 2; // 1-based, the header is row 1
        let rec = match rec {
            Ok(rec) => rec,
            Err(e) => return Err(CsvCheckError::Row { file: file(), row, reason: e.to_string() }),
        };
        // a recording's reader names ragged rows itself; the play-width log reader does not
        if !numeric && rec.len() != header.len() {
            return Err(CsvCheckError::RowLength { file: file(), row, got: rec.len(), expected: header.len() });
        }
        for (j, cell) in rec.iter().enumerate() {
            if let Ok(x) = cell.parse::<f64>() {
                if x.is_finite() && x.abs() > MAX_MAGNITUDE {
                    // a row may be longer than the header (the reader names ragged rows)
                    let column = header.get(j).cloned().unwrap_or_else(|| format!("#{}", j + 1));
                    return Err(CsvCheckError::Overflow { file: file(), row, column, value: x });
                }
            }
        }
        // a row shorter than the time column is named by the reader
        let Some(cell) = it.and_then(|it| rec.get(it)) else { continue };
        if numeric {
            let Ok(t) = cell.parse::<f64>() else { continue }; // the reader names bad cells
            if let Some(p) = prev_num {
                // order is checked (and named) by the recording's reader
                if t > p && t - p <= 1e-12 * t.abs().max(p.abs()) {
                    return Err(CsvCheckError::TimeResolution {
                        file: file(),
                        row,
                        step: t - p,
                        column: tname.to_string(),
                        t,
                    });
                }
            }
            prev_num = Some(t);
        } else if !cell.is_empty() {
            if let Some(p) = &prev_text {
                if cell < p.as_str() {
                    return Err(CsvCheckError::TimeOrder {
                        file: file(),
                        row,
                        column: tname.to_string(),
                        stamp: cell.to_string(),
                        prev: p.clone(),
                    });
                }
            }
            prev_text = Some(cell.to_string());
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn duplicate_columns_reversed_time_and_overflow_are_named() {
        let t = TimeColumn::Numeric("t");
        assert!(check_text("t,w,y\n0,1,2\n1,2,3\n", "r", t).is_ok());
        let e = check_text("t,w,y,y\n0,1,2,3\n", "r", t).unwrap_err().to_string();
        assert_eq!(e, "r: duplicate column `y` (columns 3 and 4) in the header");
        let e = check_text("t,w,y\n1e90,1,2\n1.0000000000000001e90,2,3\n", "r", t).unwrap_err().to_string();
        assert!(e.contains("row 3") && e.contains("resolution"), "{e}");
        let e = check_text("t,w,y\n0,1,2\n1,2,1e300\n", "r", t).unwrap_err().to_string();
        assert_eq!(e, "r: row 3, column `y`: value 1e300 has a magnitude above 1e100");
        let iso = TimeColumn::Iso8601("timestamp");
        let e = check_text("timestamp,a,b\n2025,1,2\n2026,2\n", "r", iso).unwrap_err().to_string();
        assert!(e.contains("row 3 has 2 fields"), "{e}");
        let e = check_text("timestamp,a\n2025-01-02T00:00:00Z,1\n2025-01-01T00:00:00Z,2\n", "l", iso)
            .unwrap_err()
            .to_string();
        assert!(e.contains("earlier"), "{e}");
    }

    /// Found by the coverage-guided fuzzer (fuzz/regressions/recording_csv/): ragged rows of a
    /// recording (the reader names them) panicked here: a row shorter than the time column
    /// (`rec[it]`), an over-large cell beyond the header (`header[j]`).
    #[test]
    fn ragged_rows_do_not_panic() {
        let t = TimeColumn::Numeric("t");
        assert!(check_text("w,t\n0\n", "r", t).is_ok(), "the reader names the short row");
        let e = check_text("t,w,y\n0,1,2,1e200\n", "r", t).unwrap_err().to_string();
        assert_eq!(e, "r: row 2, column `#4`: value 1e200 has a magnitude above 1e100");
        let e = crate::Recording::parse_checked("w,t\n0\n", "r").unwrap_err().to_string();
        assert!(!e.contains('\n'), "{e}");
    }

    #[test]
    fn unreadable_files_are_named_with_their_role() {
        let d = tempfile::tempdir().unwrap();
        let e = read_checked(d.path(), "recording", TimeColumn::Numeric("t")).unwrap_err().to_string();
        assert!(e.starts_with("cannot read recording ") && e.contains("not a regular file"), "{e}");
        let e = read_checked(&d.path().join("missing.csv"), "log", TimeColumn::Numeric("t")).unwrap_err().to_string();
        assert!(e.starts_with("cannot read log "), "{e}");
    }
}
