//! A recording of the real machine: CSV with header `t,w,y` or `t,w1..wm,y1..yp`, optional
//! `z` (or `z1..zp`). Any other column that is numeric throughout is kept as an *extra*
//! signal ([`Recording::extra`]): not a model input, but the diagnosis checks whether the
//! residual follows it (an input missing from the model). Checked on reading (missing columns, non-finite values, non-increasing
//! time, constant inputs) and put on a uniform time grid: irregular time stamps are resampled
//! by linear interpolation at the median sampling interval.
//!
//! A file or text from outside goes through [`Recording::load`] or
//! [`Recording::parse_checked`], which first run the file checks of [`checks`] (regular file
//! of bounded size, no duplicate columns, time steps resolvable in double precision, no
//! number near overflow), so every front end (the CLI, Python) refuses the same inputs with
//! the same messages.
use crate::DiscoveryError;
use std::path::Path;
use thiserror::Error;

pub mod checks;

pub use checks::{check_text, read_checked, CsvCheckError, TimeColumn};

/// Why a recording was refused: by the file checks ([`checks`]) or by the reader.
#[derive(Debug, Error)]
pub enum RecordingError {
    #[error(transparent)]
    Check(#[from] CsvCheckError),
    #[error(transparent)]
    Read(#[from] DiscoveryError),
}

/// `Some(len - 1)` when the time stamps are regular but for a last interval shorter than the
/// others (at least 3 intervals before it); `None` otherwise.
fn short_last_step(t: &[f64]) -> Option<usize> {
    if t.len() < 5 {
        return None;
    }
    let n = t.len() - 1;
    let (dt, regular) = grid_step(&t[..n]);
    let last = t[n] - t[n - 1];
    (regular && last > 0.0 && last < 0.99 * dt).then_some(n)
}

/// The median step of time stamps `t` (at least two) and whether they are a regular grid
/// (every step within 1 % of the median).
fn grid_step(t: &[f64]) -> (f64, bool) {
    let mut d: Vec<f64> = t.windows(2).map(|p| p[1] - p[0]).collect();
    d.sort_by(f64::total_cmp);
    let dt = d[d.len() / 2];
    (dt, d[d.len() - 1] - d[0] <= 0.01 * dt)
}

/// The number with the fewest significant decimal digits within `tol` of `dt` (`dt` itself when
/// none is closer than `tol` with fewer than 17 digits).
fn shortest_step(dt: f64, tol: f64) -> f64 {
    for digits in 0..17 {
        if let Ok(v) = format!("{dt:.digits$e}").parse::<f64>() {
            if (v - dt).abs() <= tol {
                return v;
            }
        }
    }
    dt
}

/// A recording on a uniform grid `t_k = t0 + k dt`.
#[derive(Debug, Clone)]
pub struct Recording {
    /// Where it came from (for messages).
    pub source: String,
    pub t0: f64,
    pub dt: f64,
    /// `w[k]` in R^m.
    pub w: Vec<Vec<f64>>,
    /// `y[k]` in R^p.
    pub y: Vec<Vec<f64>>,
    /// Measured backlash output, if recorded.
    pub z: Option<Vec<Vec<f64>>>,
    /// Whether the original time stamps were irregular (relative spread of the sampling
    /// interval above 1 %) and so were resampled.
    pub resampled: bool,
    /// Number of rows in the file.
    pub rows_in_file: usize,
    /// Other numeric columns of the file (name, samples on the uniform grid), in file order.
    pub extra: Vec<(String, Vec<f64>)>,
}

/// Minimum number of samples of a recording.
pub const MIN_SAMPLES: usize = 50;

/// Largest sampling interval allowed, in units of the median interval: a longer gap is
/// rejected rather than bridged by interpolation (which would invent data and could blow the
/// resampled grid up to an unbounded length).
pub const MAX_GAP_RATIO: f64 = 20.0;

fn col_names(prefix: &str, header: &[String]) -> Vec<usize> {
    if let Some(i) = header.iter().position(|h| h == prefix) {
        return vec![i];
    }
    // `prefix1, prefix2, ...` up to the first missing number (one pass over the header)
    let numbered: std::collections::HashMap<usize, usize> = header
        .iter()
        .enumerate()
        .filter_map(|(i, h)| {
            let k = h.strip_prefix(prefix)?;
            (k.bytes().all(|b| b.is_ascii_digit()) && !k.starts_with('0')).then(|| k.parse().ok().map(|k| (k, i)))?
        })
        .collect();
    (1..).map_while(|k| numbered.get(&k).copied()).collect()
}

/// Where a recording's columns are in its header: the time, the inputs `w*`, the outputs
/// `y*`, the backlash outputs `z*` (optional) and every other column (kept as an extra column
/// while each of its values parses as a finite number).
struct Columns {
    t: usize,
    w: Vec<usize>,
    y: Vec<usize>,
    z: Vec<usize>,
    extra: Vec<usize>,
}

impl Columns {
    /// The columns of `header`; an error naming the first of `t`, `w`, `y` it lacks.
    fn of(header: &[String], path: &str) -> Result<Self, DiscoveryError> {
        let missing = |c: &str| DiscoveryError::MissingColumn {
            path: path.to_string(),
            column: c.into(),
            header: header.to_vec(),
        };
        let t = header.iter().position(|h| h == "t").ok_or_else(|| missing("t"))?;
        let w = col_names("w", header);
        if w.is_empty() {
            return Err(missing("w"));
        }
        let y = col_names("y", header);
        if y.is_empty() {
            return Err(missing("y"));
        }
        let z = col_names("z", header);
        let extra =
            (0..header.len()).filter(|i| *i != t && !w.contains(i) && !y.contains(i) && !z.contains(i)).collect();
        Ok(Columns { t, w, y, z, extra })
    }
}

/// At least [`MIN_SAMPLES`] time stamps, and no step longer than [`MAX_GAP_RATIO`] times
/// their median step (an error naming the row after the gap).
fn check_time_grid(path: &str, t: &[f64]) -> Result<(), DiscoveryError> {
    if t.len() < MIN_SAMPLES {
        return Err(DiscoveryError::TooFewSamples { path: path.to_string(), rows: t.len(), min: MIN_SAMPLES });
    }
    let mut d: Vec<f64> = t.windows(2).map(|p| p[1] - p[0]).collect();
    d.sort_by(f64::total_cmp);
    let median = d[d.len() / 2];
    if let Some(k) = t.windows(2).position(|p| p[1] - p[0] > MAX_GAP_RATIO * median) {
        let gap = t[k + 1] - t[k];
        return Err(DiscoveryError::TimeGap {
            path: path.to_string(),
            row: k + 3, // row of t[k + 1]: 1-based, header is row 1
            gap,
            median,
            ratio: gap / median,
            max_ratio: MAX_GAP_RATIO,
        });
    }
    Ok(())
}

/// Every input column (`iw`, at rows of `w`) varies: a constant input excites nothing.
fn check_inputs_vary(path: &str, header: &[String], iw: &[usize], w: &[Vec<f64>]) -> Result<(), DiscoveryError> {
    for (j, &i) in iw.iter().enumerate() {
        let v0 = w[0][j];
        let scale = w.iter().map(|r| r[j].abs()).fold(0.0, f64::max).max(1e-300);
        if w.iter().all(|r| (r[j] - v0).abs() <= 1e-12 * scale) {
            return Err(DiscoveryError::ConstantInput { path: path.to_string(), column: header[i].clone(), value: v0 });
        }
    }
    Ok(())
}

impl Recording {
    pub fn m(&self) -> usize {
        self.w[0].len()
    }
    pub fn p(&self) -> usize {
        self.y[0].len()
    }
    pub fn len(&self) -> usize {
        self.y.len()
    }
    pub fn is_empty(&self) -> bool {
        self.y.is_empty()
    }
    pub fn duration(&self) -> f64 {
        self.dt * (self.len().saturating_sub(1)) as f64
    }
    pub fn time(&self, k: usize) -> f64 {
        self.t0 + self.dt * k as f64
    }

    /// Its first `n` samples (every column), named as such in messages; the whole recording
    /// where it is no longer.
    pub fn leading(&self, n: usize) -> Self {
        let n = n.min(self.len());
        Self {
            source: format!("{} (first {n} samples)", self.source),
            t0: self.t0,
            dt: self.dt,
            w: self.w[..n].to_vec(),
            y: self.y[..n].to_vec(),
            z: self.z.as_ref().map(|z| z[..n].to_vec()),
            resampled: self.resampled,
            rows_in_file: n,
            extra: self.extra.iter().map(|(name, v)| (name.clone(), v[..n].to_vec())).collect(),
        }
    }

    /// Reads a CSV file after the file checks of [`checks::read_checked`] (as `recording` in
    /// messages).
    pub fn load(path: &Path) -> Result<Self, RecordingError> {
        let text = read_checked(path, "recording", TimeColumn::Numeric("t"))?;
        Ok(Self::parse_str(&text, &path.display().to_string())?)
    }

    /// Parses CSV text after the checks of [`checks::check_text`]; `source` names it in
    /// errors.
    pub fn parse_checked(text: &str, source: &str) -> Result<Self, RecordingError> {
        check_text(text, source, TimeColumn::Numeric("t"))?;
        Ok(Self::parse_str(text, source)?)
    }

    /// Parses CSV text without the file checks (text made by the program itself); `source`
    /// names it in errors.
    pub fn parse_str(text: &str, source: &str) -> Result<Self, DiscoveryError> {
        let path = source.to_string();
        let mut rdr = csv::ReaderBuilder::new()
            .has_headers(true)
            .trim(csv::Trim::All)
            .flexible(true)
            .from_reader(text.as_bytes());
        let header: Vec<String> = rdr
            .headers()
            .map_err(|e| DiscoveryError::Io { path: path.clone(), reason: e.to_string() })?
            .iter()
            .map(|s| s.to_string())
            .collect();
        let Columns { t: it, w: iw, y: iy, z: iz, extra: mut ix } = Columns::of(&header, &path)?;
        let mut xcols: Vec<Vec<f64>> = vec![Vec::new(); header.len()];
        let mut t = Vec::new();
        let mut w = Vec::new();
        let mut y = Vec::new();
        let mut z = Vec::new();
        for (r, rec) in rdr.records().enumerate() {
            let row = r + 2; // 1-based, header is row 1
            let rec = rec.map_err(|e| DiscoveryError::Io { path: path.clone(), reason: e.to_string() })?;
            if rec.len() != header.len() {
                return Err(DiscoveryError::RowLength {
                    path: path.clone(),
                    row,
                    got: rec.len(),
                    expected: header.len(),
                });
            }
            let get = |i: usize| -> Result<f64, DiscoveryError> {
                let s = &rec[i];
                match s.parse::<f64>() {
                    Ok(v) if v.is_finite() => Ok(v),
                    _ => Err(DiscoveryError::NotFinite {
                        path: path.clone(),
                        row,
                        column: header[i].clone(),
                        value: s.to_string(),
                    }),
                }
            };
            let tk = get(it)?;
            if let Some(&prev) = t.last() {
                if tk <= prev {
                    return Err(DiscoveryError::NonIncreasingTime { path: path.clone(), row, t: tk, prev });
                }
            }
            t.push(tk);
            w.push(iw.iter().map(|&i| get(i)).collect::<Result<Vec<_>, _>>()?);
            y.push(iy.iter().map(|&i| get(i)).collect::<Result<Vec<_>, _>>()?);
            if !iz.is_empty() {
                z.push(iz.iter().map(|&i| get(i)).collect::<Result<Vec<_>, _>>()?);
            }
            ix.retain(|&i| match rec[i].parse::<f64>() {
                Ok(v) if v.is_finite() => {
                    xcols[i].push(v);
                    true
                }
                _ => false,
            });
        }
        check_time_grid(&path, &t)?;
        check_inputs_vary(&path, &header, &iw, &w)?;
        let z = if iz.is_empty() { None } else { Some(z) };
        let extra: Vec<(String, Vec<f64>)> =
            ix.iter().map(|&i| (header[i].clone(), std::mem::take(&mut xcols[i]))).collect();
        Ok(Self::from_samples_with_extra(source, &t, w, y, z, extra))
    }

    /// Builds a recording from (possibly irregular) samples; times must increase strictly. On a
    /// regular grid the step is the median difference of the time stamps, written with the
    /// fewest decimal digits within their rounding ([`shortest_step`]): time stamps `k * 0.016`
    /// printed in shortest form give the step 0.016, not 0.016000000000000014.
    pub fn from_samples(source: &str, t: &[f64], w: Vec<Vec<f64>>, y: Vec<Vec<f64>>, z: Option<Vec<Vec<f64>>>) -> Self {
        Self::from_samples_with_extra(source, t, w, y, z, vec![])
    }

    /// As [`Recording::from_samples`] with extra columns (name, one value per time stamp).
    pub fn from_samples_with_extra(
        source: &str,
        t: &[f64],
        w: Vec<Vec<f64>>,
        y: Vec<Vec<f64>>,
        z: Option<Vec<Vec<f64>>>,
        extra: Vec<(String, Vec<f64>)>,
    ) -> Self {
        // `moreau simulate --max-rows` keeps every k-th step and the last one: a final interval
        // shorter than the others is the end of the simulation off the output grid, not an
        // irregular clock; that row is left out rather than resampling every row
        if let Some(n) = short_last_step(t) {
            let keep = |v: Vec<Vec<f64>>| v.into_iter().take(n).collect::<Vec<_>>();
            let (w, y, z) = (keep(w), keep(y), z.map(keep));
            let extra = extra.into_iter().map(|(name, v)| (name, v.into_iter().take(n).collect())).collect();
            let mut r = Self::from_samples_with_extra(source, &t[..n], w, y, z, extra);
            r.rows_in_file = t.len();
            return r;
        }
        let (dt, regular) = grid_step(t);
        let rows_in_file = t.len();
        if regular {
            // a difference of two rounded time stamps is the step only up to their rounding
            let t_max = t.iter().fold(0.0_f64, |a, &x| a.max(x.abs()));
            let dt = shortest_step(dt, 4.0 * f64::EPSILON * t_max);
            return Self { source: source.into(), t0: t[0], dt, w, y, z, resampled: false, rows_in_file, extra };
        }
        let n = ((t[t.len() - 1] - t[0]) / dt).floor() as usize + 1;
        let interp = |s: &Vec<Vec<f64>>| -> Vec<Vec<f64>> {
            let mut out = Vec::with_capacity(n);
            let mut j = 0;
            for k in 0..n {
                let tk = t[0] + dt * k as f64;
                while j + 2 < t.len() && t[j + 1] < tk {
                    j += 1;
                }
                let a = ((tk - t[j]) / (t[j + 1] - t[j])).clamp(0.0, 1.0);
                out.push(s[j].iter().zip(&s[j + 1]).map(|(u, v)| u + a * (v - u)).collect());
            }
            out
        };
        let (w, y, z) = (interp(&w), interp(&y), z.as_ref().map(interp));
        let extra = extra
            .into_iter()
            .map(|(name, v)| {
                let rows: Vec<Vec<f64>> = v.into_iter().map(|x| vec![x]).collect();
                (name, interp(&rows).into_iter().map(|r| r[0]).collect())
            })
            .collect();
        Self { source: source.into(), t0: t[0], dt, w, y, z, resampled: true, rows_in_file, extra }
    }

    /// Writes the recording as CSV text (`t,w..,y..`).
    pub fn to_csv_string(&self) -> String {
        let mut s = String::from("t");
        let (m, p) = (self.m(), self.p());
        for j in 1..=m {
            s += &if m == 1 { ",w".to_string() } else { format!(",w{j}") };
        }
        for j in 1..=p {
            s += &if p == 1 { ",y".to_string() } else { format!(",y{j}") };
        }
        s.push('\n');
        for k in 0..self.len() {
            s += &format!("{}", self.time(k));
            for v in self.w[k].iter().chain(&self.y[k]) {
                s += &format!(",{v}");
            }
            s.push('\n');
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbered_columns_are_found_in_one_pass() {
        let h = |cols: &[&str]| cols.iter().map(|c| c.to_string()).collect::<Vec<_>>();
        assert_eq!(col_names("y", &h(&["t", "y2", "w", "y1", "y3"])), [3, 1, 4]);
        assert_eq!(col_names("y", &h(&["t", "y1", "y3"])), [1], "numbering stops at the first gap");
        assert_eq!(col_names("y", &h(&["t", "y", "y1"])), [1], "a bare name wins");
        assert!(col_names("y", &h(&["t", "y01", "yy1"])).is_empty(), "no leading zeros, no other prefixes");
        // a header of 100000 numbered columns (quadratic before)
        let wide: Vec<String> = (1..=100_000).map(|k| format!("w{k}")).collect();
        assert_eq!(col_names("w", &wide).len(), 100_000);
    }

    fn csv(rows: usize, f: impl Fn(usize) -> String) -> String {
        let mut s = "t,w,y\n".to_string();
        for k in 0..rows {
            s += &f(k);
            s.push('\n');
        }
        s
    }

    #[test]
    fn reads_regular_and_resamples_irregular() {
        let r = Recording::parse_str(&csv(100, |k| format!("{},{},{}", k as f64 * 0.01, (k as f64).sin(), k)), "a")
            .unwrap();
        assert!(!r.resampled);
        assert_eq!(r.len(), 100);
        assert!((r.dt - 0.01).abs() < 1e-12);
        let irr = csv(100, |k| {
            let t = k as f64 * 0.01 + if k % 2 == 1 { 0.003 } else { 0.0 };
            format!("{t},{},{}", (k as f64).sin(), 2.0 * t)
        });
        let r = Recording::parse_str(&irr, "b").unwrap();
        assert!(r.resampled);
        // y = 2 t is linear: interpolation must reproduce it exactly.
        for k in 0..r.len() {
            assert!((r.y[k][0] - 2.0 * r.time(k)).abs() < 1e-9);
        }
    }

    #[test]
    fn bad_inputs_are_named() {
        let e = Recording::parse_str("t,w\n0,1\n", "x").unwrap_err().to_string();
        assert!(e.contains("lacks column `y`"), "{e}");
        let e = Recording::parse_str(
            &csv(60, |k| if k == 7 { "0.07,NaN,1".into() } else { format!("{},{},1", k as f64 * 0.01, k) }),
            "x",
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("row 9") && e.contains("NaN"), "{e}");
        let e = Recording::parse_str(&csv(60, |k| format!("{},{},1", if k == 5 { 0.0 } else { k as f64 }, k)), "x")
            .unwrap_err()
            .to_string();
        assert!(e.contains("increase strictly"), "{e}");
        let e = Recording::parse_str(&csv(60, |k| format!("{},3,{}", k, k)), "x").unwrap_err().to_string();
        assert!(e.contains("constant"), "{e}");
        let e = Recording::parse_str(&csv(10, |k| format!("{},{},{}", k, k, k)), "x").unwrap_err().to_string();
        assert!(e.contains("only 10 samples"), "{e}");
        // A gap of 1e9 s after 0.01 s sampling (once resampled to 1e11 rows): rejected.
        let e =
            Recording::parse_str(&csv(60, |k| format!("{},{},1", if k < 59 { k as f64 * 0.01 } else { 1e9 }, k)), "x")
                .unwrap_err()
                .to_string();
        assert!(e.contains("sampling gap") && e.contains("row 61"), "{e}");
        // Negative control: jitter of a few times the median interval is resampled, not rejected.
        let ok = Recording::parse_str(
            &csv(60, |k| format!("{},{},1", k as f64 * 0.01 + if k >= 30 { 0.04 } else { 0.0 }, k)),
            "x",
        );
        assert!(ok.is_ok_and(|r| r.resampled));
    }

    #[test]
    fn the_step_of_shortest_printed_time_stamps_is_the_stated_step() {
        // `moreau simulate` writes t_k = k h in shortest form (`{:e}`): the median difference is
        // 0.016000000000000014, a different f64 from the step 0.016
        let t: Vec<f64> = (0..6000).map(|k| format!("{:e}", k as f64 * 0.016).parse().unwrap()).collect();
        let mut d: Vec<f64> = t.windows(2).map(|p| p[1] - p[0]).collect();
        d.sort_by(f64::total_cmp);
        assert_ne!(d[d.len() / 2], 0.016, "the raw median must show the rounding this test is about");
        let w: Vec<Vec<f64>> = t.iter().map(|x| vec![x.sin()]).collect();
        let r = Recording::from_samples("sim", &t, w.clone(), w.clone(), None);
        assert!(!r.resampled);
        assert_eq!(r.dt, 0.016);
        // a step that is not a short decimal is kept as it is (negative control)
        let h = 9.998703544206852e-4;
        let t: Vec<f64> = (0..6000).map(|k| format!("{:e}", k as f64 * h).parse().unwrap()).collect();
        let r = Recording::from_samples("sim", &t, w.clone(), w, None);
        assert!((r.dt - h).abs() <= 1e-15 && r.dt.to_string().len() > 12, "{}", r.dt);
    }

    #[test]
    fn a_short_last_step_is_left_out_not_resampled() {
        // `moreau simulate --periods 1 --max-rows 1000` of the worked example: 6284 steps of h,
        // every 7th kept and the last one (6284 = 7 * 897 + 5): a final interval of 5 h
        let h = 9.998703544206852e-4;
        let mut k: Vec<usize> = (0..=6284).step_by(7).collect();
        k.push(6284);
        let t: Vec<f64> = k.iter().map(|&k| format!("{:e}", k as f64 * h).parse().unwrap()).collect();
        let w: Vec<Vec<f64>> = t.iter().map(|x| vec![x.sin()]).collect();
        let r = Recording::from_samples("sim", &t, w.clone(), w.clone(), None);
        assert!(!r.resampled, "simulate's own time stamps are not irregular");
        assert_eq!((r.len(), r.rows_in_file), (t.len() - 1, t.len()));
        assert!((r.dt - 7.0 * h).abs() < 1e-12, "{}", r.dt);
        assert_eq!(r.w[r.len() - 1], w[t.len() - 2]);
        // negative control: a short interval inside the record is still irregular
        let mut t2 = t.clone();
        t2[10] = t2[9] + 0.5 * (t2[11] - t2[9]) * 0.5;
        let r = Recording::from_samples("sim", &t2, w.clone(), w, None);
        assert!(r.resampled);
    }
}
