//! Checks of recordings and logs before the `discovery` readers see them: regular files of
//! bounded size only, no duplicate column names (a header `t,w,y,y` would silently drop a
//! column), numeric time stamps resolvable in double precision, no number near overflow
//! (`|x| > 1e100`), and for the play-width logs (whose reader accepts them) every row as long
//! as the header and ISO time stamps in order. The recording reader itself names ragged rows
//! and non-increasing times.
use anyhow::bail;
use model::MAX_MAGNITUDE;
use std::path::Path;

/// How the time column is checked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TimeColumn<'a> {
    /// A numeric column (`t` of a recording): steps resolvable in double precision.
    Numeric(&'a str),
    /// A text column of ISO 8601 stamps (`timestamp` of the Robonine logs): not decreasing.
    Iso8601(&'a str),
}

/// Reads `path` (a regular file of at most `model::files::MAX_CSV_BYTES`) and checks it as
/// described in the module documentation; returns the text. `what` names the file in read
/// errors (`cannot read recording PATH: ...`).
pub fn read_checked(path: &Path, what: &str, time: TimeColumn) -> anyhow::Result<String> {
    use model::ModelError;
    let text = model::files::read_regular(path, model::files::MAX_CSV_BYTES).map_err(|e| match e {
        ModelError::Io { path, source } => anyhow::anyhow!("cannot read {what} {path}: {source}"),
        ModelError::NotRegularFile { path, kind } => {
            anyhow::anyhow!("cannot read {what} {path}: {kind}, not a regular file (input files must be regular files)")
        }
        ModelError::FileTooLarge { path, bytes, limit } => {
            anyhow::anyhow!("cannot read {what} {path}: {bytes} bytes, more than the limit of {limit} bytes")
        }
        other => other.into(),
    })?;
    check_text(&text, &path.display().to_string(), time)?;
    Ok(text)
}

/// The checks of [`read_checked`] on CSV text; `source` names it in errors.
pub fn check_text(text: &str, source: &str, time: TimeColumn) -> anyhow::Result<()> {
    let mut rdr =
        csv::ReaderBuilder::new().has_headers(true).flexible(true).trim(csv::Trim::All).from_reader(text.as_bytes());
    let header: Vec<String> = match rdr.headers() {
        Ok(h) => h.iter().map(String::from).collect(),
        Err(e) => bail!("{source}: unreadable header: {e}"),
    };
    for (j, name) in header.iter().enumerate() {
        if let Some(i) = header[..j].iter().position(|h| h == name) {
            bail!("{source}: duplicate column `{name}` (columns {} and {}) in the header", i + 1, j + 1);
        }
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
            Err(e) => bail!("{source}: row {row}: {e}"),
        };
        // a recording's reader names ragged rows itself; the play-width log reader does not
        if !numeric && rec.len() != header.len() {
            bail!("{source}: row {row} has {} fields, the header has {}", rec.len(), header.len());
        }
        for (j, cell) in rec.iter().enumerate() {
            if let Ok(x) = cell.parse::<f64>() {
                if x.is_finite() && x.abs() > MAX_MAGNITUDE {
                    bail!(
                        "{source}: row {row}, column `{}`: value {x:e} has a magnitude above {MAX_MAGNITUDE:e}",
                        header[j]
                    );
                }
            }
        }
        let Some(it) = it else { continue };
        let cell = &rec[it];
        if numeric {
            let Ok(t) = cell.parse::<f64>() else { continue }; // the reader names bad cells
            if let Some(p) = prev_num {
                // order is checked (and named) by the recording's reader
                if t > p && t - p <= 1e-12 * t.abs().max(p.abs()) {
                    bail!(
                        "{source}: row {row}: time step {} at `{tname}` = {t:e} is below the resolution of double precision",
                        t - p
                    );
                }
            }
            prev_num = Some(t);
        } else if !cell.is_empty() {
            if let Some(p) = &prev_text {
                if cell < p.as_str() {
                    bail!("{source}: row {row}: `{tname}` {cell} is earlier than {p} of the row before (the log must be in time order)");
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
        assert!(e.contains("duplicate column `y`"), "{e}");
        let e = check_text("t,w,y\n1e90,1,2\n1.0000000000000001e90,2,3\n", "r", t).unwrap_err().to_string();
        assert!(e.contains("row 3") && e.contains("resolution"), "{e}");
        let e = check_text("t,w,y\n0,1,2\n1,2,1e300\n", "r", t).unwrap_err().to_string();
        assert!(e.contains("1e300"), "{e}");
        let iso = TimeColumn::Iso8601("timestamp");
        let e = check_text("timestamp,a,b\n2025,1,2\n2026,2\n", "r", iso).unwrap_err().to_string();
        assert!(e.contains("row 3 has 2 fields"), "{e}");
        let e = check_text("timestamp,a\n2025-01-02T00:00:00Z,1\n2025-01-01T00:00:00Z,2\n", "l", iso)
            .unwrap_err()
            .to_string();
        assert!(e.contains("earlier"), "{e}");
    }
}
