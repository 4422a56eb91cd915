//! The external input `w(t)` of eq. (xy).
use crate::ModelError;
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;
use std::path::Path;

/// How `w` behaves between its samples `w(t_k)`, `w(t_{k+1})`: the one hold type of the
/// whole workspace (a CSV input's interpolation here; the step maps, the catching-up scheme and
/// the extended model of `dynamics`, which re-exports it as `dynamics::linear::hold::InputHold`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum InputHold {
    /// `w(t_k + s) = w(t_k) + (s/h)(w(t_{k+1}) - w(t_k))`: linear interpolation between
    /// samples (first-order hold). Default.
    #[default]
    #[serde(rename = "Linear")]
    Foh,
    /// `w(t_k + s) = w(t_k)`: each sample held until the next (zero-order hold, a digital
    /// controller's command).
    #[serde(rename = "Held")]
    Zoh,
}

impl InputHold {
    /// The hold named `"foh"` or `"zoh"` (the key `key` of a model file, or Python's `hold`).
    pub fn parse(word: &str, key: &str) -> Result<Self, ModelError> {
        match word {
            "foh" => Ok(InputHold::Foh),
            "zoh" => Ok(InputHold::Zoh),
            other => Err(ModelError::Dimension {
                key: key.into(),
                expected: "\"foh\" (linear interpolation) or \"zoh\" (each sample held until the next)".into(),
                got: format!("{other:?}"),
            }),
        }
    }
    /// `"foh"` or `"zoh"` (reports).
    pub fn name(&self) -> &'static str {
        match self {
            InputHold::Foh => "foh",
            InputHold::Zoh => "zoh",
        }
    }
}

/// Input signal `w : R -> R^m`.
#[derive(Debug, Clone, PartialEq)]
pub enum Input {
    /// `w = 0` in R^m.
    Zero { m: usize },
    /// `w_i(t) = a_i sin(omega t + phase)`; period `2 pi / omega`.
    Sine { amplitudes: Vec<f64>, omega: f64, phase: f64 },
    /// `w_i(t) = a_i sign(sin(omega t + phase))` (value `+a_i` at the jumps); period `2 pi / omega`.
    Square { amplitudes: Vec<f64>, omega: f64, phase: f64 },
    /// A sum of harmonics of `omega`: `w_i(t) = a_i sum_j c_j sin(k_j (omega t + phase) + phi_j)`
    /// (harmonic `j`: multiple `k_j`, weight `c_j`, phase `phi_j`); period `2 pi / omega`.
    Multisine { amplitudes: Vec<f64>, omega: f64, phase: f64, harmonics: Vec<Harmonic> },
    /// Samples `(t_k, w_k)` from a CSV file, linearly interpolated (`hold = Foh`) or each held
    /// until the next (`Zoh`), held constant outside the sampled range. Periodic only if a
    /// `period` is stated.
    Samples { path: String, t: Vec<f64>, w: Vec<Vec<f64>>, period: Option<f64>, hold: InputHold },
}

/// One term of a [`Input::Multisine`]: `weight sin(k (omega t + phase) + phase_k)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Harmonic {
    /// The multiple of the fundamental `omega` (at least 1).
    pub k: u32,
    /// Weight `c` (relative amplitude; the input's `amplitudes` scale the sum).
    pub weight: f64,
    /// Phase `phi` of this harmonic (radians), added to `k` times the input's own phase.
    pub phase: f64,
}

/// Most harmonics a multisine may have (each costs a complex solve in the closed form of
/// `eta_T` and a sine per sample).
pub const MAX_HARMONICS: usize = 256;

/// Checks the harmonics of a multisine: at least one, `k` from 1 to 10^6 and distinct, finite
/// weights (not all 0) and phases.
pub fn check_harmonics(harmonics: &[Harmonic]) -> Result<(), ModelError> {
    let bad = |key: &str, value: f64, reason: &'static str| {
        Err(ModelError::OutOfRange { key: format!("input.{key}"), value, reason })
    };
    if harmonics.is_empty() || harmonics.len() > MAX_HARMONICS {
        return bad("harmonics", harmonics.len() as f64, "a multisine needs 1 to 256 harmonics");
    }
    for (j, h) in harmonics.iter().enumerate() {
        if h.k == 0 || h.k > 1_000_000 {
            return bad("harmonics", h.k as f64, "each harmonic is a whole multiple of omega from 1 to 10^6");
        }
        if harmonics[..j].iter().any(|g| g.k == h.k) {
            return bad("harmonics", h.k as f64, "each harmonic may appear once");
        }
        if !h.weight.is_finite() {
            return bad("weights", h.weight, "weights must be finite");
        }
        if !h.phase.is_finite() {
            return bad("phases", h.phase, "phases must be finite");
        }
    }
    if harmonics.iter().all(|h| h.weight == 0.0) {
        return bad("weights", 0.0, "at least one weight must be non-zero");
    }
    Ok(())
}

/// `sum_j c_j sin(k_j theta + phi_j)`, the waveform of a multisine at `theta = omega t + phase`.
pub fn multisine_wave(harmonics: &[Harmonic], theta: f64) -> f64 {
    harmonics.iter().map(|h| h.weight * (h.k as f64 * theta + h.phase).sin()).sum()
}

impl Input {
    /// Dimension `m` of `w`.
    pub fn m(&self) -> usize {
        match self {
            Input::Zero { m } => *m,
            Input::Sine { amplitudes, .. } | Input::Square { amplitudes, .. } | Input::Multisine { amplitudes, .. } => {
                amplitudes.len()
            }
            Input::Samples { w, .. } => w[0].len(),
        }
    }

    /// The period `T` if the input is periodic.
    pub fn period(&self) -> Option<f64> {
        match self {
            Input::Zero { .. } => None,
            Input::Sine { omega, .. } | Input::Square { omega, .. } | Input::Multisine { omega, .. } => {
                Some(TAU / omega)
            }
            Input::Samples { period, .. } => *period,
        }
    }

    /// The amplitudes, `omega` and `phase` of a sine, square wave or multisine (`None` for
    /// other inputs): what sweeps and guidance vary.
    pub fn wave(&self) -> Option<(&[f64], f64, f64)> {
        match self {
            Input::Sine { amplitudes, omega, phase }
            | Input::Square { amplitudes, omega, phase }
            | Input::Multisine { amplitudes, omega, phase, .. } => Some((amplitudes, *omega, *phase)),
            Input::Zero { .. } | Input::Samples { .. } => None,
        }
    }

    /// [`Input::wave`], to be changed in place.
    pub fn wave_mut(&mut self) -> Option<(&mut Vec<f64>, &mut f64, &mut f64)> {
        match self {
            Input::Sine { amplitudes, omega, phase }
            | Input::Square { amplitudes, omega, phase }
            | Input::Multisine { amplitudes, omega, phase, .. } => Some((amplitudes, omega, phase)),
            Input::Zero { .. } | Input::Samples { .. } => None,
        }
    }

    pub fn kind(&self) -> &'static str {
        match self {
            Input::Zero { .. } => "zero",
            Input::Sine { .. } => "sine",
            Input::Square { .. } => "square",
            Input::Multisine { .. } => "multisine",
            Input::Samples { .. } => "csv",
        }
    }

    /// Writes `w(t)` into `out` (length `m`).
    pub fn eval(&self, t: f64, out: &mut [f64]) {
        match self {
            Input::Zero { .. } => out.iter_mut().for_each(|o| *o = 0.0),
            Input::Sine { amplitudes, omega, phase } => {
                let s = (omega * t + phase).sin();
                out.iter_mut().zip(amplitudes).for_each(|(o, a)| *o = a * s);
            }
            Input::Square { amplitudes, omega, phase } => {
                let s = if (omega * t + phase).rem_euclid(TAU) < std::f64::consts::PI { 1.0 } else { -1.0 };
                out.iter_mut().zip(amplitudes).for_each(|(o, a)| *o = a * s);
            }
            Input::Multisine { amplitudes, omega, phase, harmonics } => {
                let s = multisine_wave(harmonics, omega * t + phase);
                out.iter_mut().zip(amplitudes).for_each(|(o, a)| *o = a * s);
            }
            Input::Samples { t: ts, w, period, hold, .. } => {
                let mut tt = t;
                if let Some(per) = period {
                    tt = ts[0] + (t - ts[0]).rem_euclid(*per);
                }
                let k = ts.partition_point(|&s| s <= tt);
                if k == 0 {
                    out.copy_from_slice(&w[0]);
                } else if k >= ts.len() || *hold == InputHold::Zoh {
                    // after the last sample, or a zero-order hold: the last sample at or before t
                    out.copy_from_slice(&w[k - 1]);
                } else {
                    let (t0, t1) = (ts[k - 1], ts[k]);
                    let a = (tt - t0) / (t1 - t0);
                    for (i, o) in out.iter_mut().enumerate() {
                        *o = (1.0 - a) * w[k - 1][i] + a * w[k][i];
                    }
                }
            }
        }
    }

    /// The samples of a `csv` input as CSV text (`t,w1..wm`, shortest round-trip decimals),
    /// readable by [`Input::from_csv`]; `None` for other kinds.
    pub fn samples_csv(&self) -> Option<String> {
        let Input::Samples { t, w, .. } = self else { return None };
        let mut wr = csv::Writer::from_writer(Vec::new());
        let mut header = vec!["t".to_string()];
        header.extend((1..=self.m()).map(|j| format!("w{j}")));
        wr.write_record(&header).ok()?;
        for (tk, wk) in t.iter().zip(w) {
            let mut row = vec![tk.to_string()];
            row.extend(wk.iter().map(|v| v.to_string()));
            wr.write_record(&row).ok()?;
        }
        String::from_utf8(wr.into_inner().ok()?).ok()
    }

    /// `w(t)` as a new vector.
    pub fn at(&self, t: f64) -> Vec<f64> {
        let mut out = vec![0.0; self.m()];
        self.eval(t, &mut out);
        out
    }

    /// Reads samples from a CSV file with header exactly `t,w` (or `t,w1`) or `t,w1,...,wm`.
    /// Rejects other headers, missing or non-numeric cells, NaN/inf, and time stamps that do
    /// not increase strictly. A stated `period` is checked by the caller ([`check_period`]).
    pub fn from_csv(path: &Path, period: Option<f64>, hold: InputHold) -> Result<Self, ModelError> {
        let ps = path.display().to_string();
        let text = crate::files::read_regular(path, crate::files::MAX_CSV_BYTES)?;
        let mut rdr = csv::ReaderBuilder::new().trim(csv::Trim::All).from_reader(text.as_bytes());
        let headers = rdr.headers().map_err(|e| ModelError::Csv { path: ps.clone(), reason: e.to_string() })?.clone();
        let names: Vec<String> = headers.iter().map(|h| h.to_string()).collect();
        if names.len() < 2 || names[0] != "t" || !names[1..].iter().all(|h| h.starts_with('w')) {
            return Err(ModelError::Csv {
                path: ps,
                reason: format!("header must be `t,w` or `t,w1,...,wm`, found `{}`", names.join(",")),
            });
        }
        if let Some((j, dup)) = names.iter().enumerate().find(|(j, n)| names[..*j].contains(n)) {
            return Err(ModelError::Csv {
                path: ps,
                reason: format!("duplicate column `{dup}` (column {}) in header `{}`", j + 1, names.join(",")),
            });
        }
        // the columns are taken by position: a header that names them otherwise (`t,wfoo`,
        // `t,w2,w1`) would be read as something it does not say
        let m = names.len() - 1;
        let numbered: Vec<String> = (1..=m).map(|j| format!("w{j}")).collect();
        if names[1..] != numbered[..] && !(m == 1 && names[1] == "w") {
            let expected = if m == 1 { "`t,w` or `t,w1`".to_string() } else { format!("`t,{}`", numbered.join(",")) };
            return Err(ModelError::Csv {
                path: ps,
                reason: format!(
                    "header `{}` does not name its {m} input column(s) as expected: {expected}",
                    names.join(",")
                ),
            });
        }
        let mut t = Vec::new();
        let mut w = Vec::new();
        for (i, rec) in rdr.records().enumerate() {
            let row = i + 2; // 1-based, after the header
            let rec = rec.map_err(|e| ModelError::Csv { path: ps.clone(), reason: format!("row {row}: {e}") })?;
            if rec.len() != names.len() {
                return Err(ModelError::Csv {
                    path: ps,
                    reason: format!("row {row} has {} fields, header has {}", rec.len(), names.len()),
                });
            }
            let mut vals = Vec::with_capacity(names.len());
            for (j, cell) in rec.iter().enumerate() {
                match cell.parse::<f64>() {
                    Ok(x) if x.is_finite() && x.abs() <= crate::MAX_MAGNITUDE => vals.push(x),
                    Ok(x) if x.is_finite() => {
                        return Err(ModelError::Csv {
                            path: ps,
                            reason: format!(
                                "row {row}, column `{}`: value {x:e} has a magnitude above {:e}",
                                names[j],
                                crate::MAX_MAGNITUDE
                            ),
                        })
                    }
                    _ => {
                        return Err(ModelError::CsvValue {
                            path: ps,
                            row,
                            column: names[j].clone(),
                            value: cell.to_string(),
                        })
                    }
                }
            }
            if let Some(&prev) = t.last() {
                if vals[0] <= prev {
                    return Err(ModelError::UnsortedTimes { path: ps, row, t: vals[0], prev });
                }
                // steps lost in rounding: t so large that neighbouring stamps barely differ
                if vals[0] - prev <= 1e-12 * vals[0].abs().max(prev.abs()) {
                    return Err(ModelError::Csv {
                        path: ps,
                        reason: format!(
                            "row {row}: time step {} at t = {} is below the resolution of double precision",
                            vals[0] - prev,
                            vals[0]
                        ),
                    });
                }
            }
            t.push(vals[0]);
            w.push(vals[1..].to_vec());
        }
        if t.len() < 2 {
            return Err(ModelError::Csv { path: ps, reason: format!("needs at least 2 samples, found {}", t.len()) });
        }
        Ok(Input::Samples { path: path.display().to_string(), t, w, period, hold })
    }
}

/// `x` to 7 significant digits, for messages (`6.279999999999999` -> `6.28`).
fn short(x: f64) -> String {
    crate::error::fmt_num(format!("{x:.6e}").parse().unwrap_or(x))
}

/// Checks the stated `period` of sampled data `t` (from `source`, for messages): positive and
/// finite, not shorter than the data (the rest would be cut silently) and not longer than the
/// data plus their largest sample step (beyond the last sample the input holds its last value,
/// so the data would not cover the period: `period = 1e12` for 6.28 s of data).
pub fn check_period(period: f64, t: &[f64], source: &str) -> Result<(), ModelError> {
    if !(period > 0.0 && period.is_finite()) {
        return Err(ModelError::OutOfRange { key: "input.period".into(), value: period, reason: "must be positive" });
    }
    let (Some(&t0), Some(&t1)) = (t.first(), t.last()) else { return Ok(()) };
    let span = t1 - t0;
    if period < span * (1.0 - 1e-12) {
        return Err(ModelError::Invalid {
            key: "input.period".into(),
            value: period,
            reason: format!(
                "shorter than the data in `{source}` (samples span {span} from t = {t0} to t = {t1}): the rest would be cut silently"
            ),
        });
    }
    let step = t.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max);
    if period > (span + step) * (1.0 + 1e-12) {
        return Err(ModelError::Invalid {
            key: "input.period".into(),
            value: period,
            reason: format!(
                "longer than the data in `{source}` cover: the samples span {} from t = {} to t = {} (largest step {}), so a period above {} would hold the last sample for the rest of each period",
                short(span),
                short(t0),
                short(t1),
                short(step),
                short(span + step)
            ),
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sine_and_square_have_the_stated_period_and_values() {
        let s = Input::Sine { amplitudes: vec![2.0], omega: 2.0, phase: 0.0 };
        assert!((s.period().unwrap() - std::f64::consts::PI).abs() < 1e-15);
        assert!((s.at(std::f64::consts::PI / 4.0)[0] - 2.0).abs() < 1e-15);
        let q = Input::Square { amplitudes: vec![1.0, -3.0], omega: 1.0, phase: 0.0 };
        assert_eq!(q.at(1.0), vec![1.0, -3.0]);
        assert_eq!(q.at(4.0), vec![-1.0, 3.0]);
    }

    #[test]
    fn a_multisine_sums_its_harmonics_and_its_checks_name_the_bad_value() {
        let h = |k, weight, phase| Harmonic { k, weight, phase };
        let w = Input::Multisine {
            amplitudes: vec![2.0],
            omega: 1.0,
            phase: 0.5,
            harmonics: vec![h(1, 1.0, 0.0), h(3, 0.25, 1.0)],
        };
        assert_eq!(w.period(), Some(TAU));
        assert_eq!(w.kind(), "multisine");
        let t = 0.7;
        let expect = 2.0 * ((t + 0.5f64).sin() + 0.25 * (3.0 * (t + 0.5) + 1.0f64).sin());
        assert!((w.at(t)[0] - expect).abs() < 1e-15);
        assert!((w.at(t + TAU)[0] - expect).abs() < 1e-12);
        assert!(check_harmonics(&[h(1, 1.0, 0.0), h(2, 0.5, 0.0)]).is_ok());
        for (bad, word) in [
            (vec![], "1 to 256"),
            (vec![h(0, 1.0, 0.0)], "whole multiple"),
            (vec![h(2, 1.0, 0.0), h(2, 1.0, 0.0)], "once"),
            (vec![h(1, f64::NAN, 0.0)], "finite"),
            (vec![h(1, 0.0, 0.0)], "non-zero"),
        ] {
            let e = check_harmonics(&bad).unwrap_err().to_string();
            assert!(e.contains(word), "{e}");
        }
    }

    #[test]
    fn samples_interpolate_linearly_and_hold_outside() {
        let s = Input::Samples {
            path: String::new(),
            t: vec![0.0, 1.0, 3.0],
            w: vec![vec![0.0], vec![2.0], vec![0.0]],
            period: None,
            hold: InputHold::Foh,
        };
        assert_eq!(s.at(0.5), vec![1.0]);
        assert_eq!(s.at(2.0), vec![1.0]);
        assert_eq!(s.at(-1.0), vec![0.0]);
        assert_eq!(s.at(9.0), vec![0.0]);
        // zero-order hold: each sample until the next
        let Input::Samples { t, w, .. } = s else { unreachable!() };
        let z = Input::Samples { path: String::new(), t, w, period: None, hold: InputHold::Zoh };
        assert_eq!(
            (z.at(0.5), z.at(1.0), z.at(2.9), z.at(3.0), z.at(-1.0)),
            (vec![0.0], vec![2.0], vec![2.0], vec![0.0], vec![0.0])
        );
    }
}
