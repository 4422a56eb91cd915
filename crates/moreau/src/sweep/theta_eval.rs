//! The evaluator of `moreau sweep`: [`bounds::assemble`] at every point (theta of
//! eq. (theta) and its parts, the path bounds (path), (path1), (path2)), with the measured
//! exponent and path length of simulated trajectories, their ratio and which bounds are
//! verified.
//!
//! `[evaluate]` keys of a sweep spec (all optional): `measure` (bool, default `true`: simulate
//! pairs of trajectories), `dt` (default `1e-3`), `periods` (default `40`),
//! `transient_periods` (default `10`), `pairs` (default `2`), `seed` (default `11`).
use super::eval::{Cell, Column, Evaluator, PointError};
use super::SweepError;
use bounds::{assemble_memo, Memo, ThetaSettings};
use dynamics::rate::lyapunov_exponent::RateSettings;
use model::System;
use std::cell::RefCell;
use std::path::Path;
use toml::{Table, Value};

/// theta and the measured side at one point.
#[derive(Debug, Clone)]
pub struct ThetaEvaluator {
    pub settings: ThetaSettings,
}

impl Default for ThetaEvaluator {
    fn default() -> Self {
        let mut settings = ThetaSettings::bound_only();
        settings.measure = Some(RateSettings { periods: 40, transient_periods: 10, pairs: 2, ..Default::default() });
        Self { settings }
    }
}

impl ThetaEvaluator {
    /// Settings from a spec's `[evaluate]` table (`path` names the spec in errors).
    pub fn from_table(t: &Table, path: &Path) -> Result<Self, SweepError> {
        const ALLOWED: &str = "measure, dt, periods, transient_periods, pairs, seed";
        let mut ev = Self::default();
        let mut rate = ev.settings.measure.clone().unwrap_or_default();
        let wrong = |key: &str, expected| SweepError::WrongType {
            path: path.to_path_buf(),
            key: format!("evaluate.{key}"),
            expected,
        };
        let mut measure = true;
        for (k, v) in t {
            match (k.as_str(), v) {
                ("measure", Value::Boolean(b)) => measure = *b,
                ("dt", Value::Float(x)) if *x > 0.0 && x.is_finite() => rate.dt = *x,
                ("periods", Value::Integer(i)) if *i > 0 => rate.periods = *i as usize,
                ("transient_periods", Value::Integer(i)) if *i >= 0 => rate.transient_periods = *i as usize,
                ("pairs", Value::Integer(i)) if *i > 0 => rate.pairs = *i as usize,
                ("seed", Value::Integer(i)) if *i >= 0 => rate.seed = *i as u64,
                ("measure", _) => return Err(wrong(k, "true or false")),
                ("dt", _) => return Err(wrong(k, "a positive number")),
                ("periods" | "transient_periods" | "pairs" | "seed", _) => {
                    return Err(wrong(k, "a non-negative integer (periods, pairs: positive)"))
                }
                _ => {
                    return Err(SweepError::UnknownKey {
                        path: path.to_path_buf(),
                        key: format!("evaluate.{k}"),
                        allowed: ALLOWED,
                    })
                }
            }
        }
        if measure && rate.periods < rate.transient_periods + 3 {
            return Err(wrong("periods", "at least transient_periods + 3"));
        }
        ev.settings.measure = measure.then_some(rate);
        Ok(ev)
    }
}

/// The report quantities that are sweep columns (keys of `bounds::report::defs`), in order;
/// their names and LaTeX headers come from the declarations. The derived columns
/// ([`DERIVED`]) follow `theta` and `path2_bound`.
pub const QUANTITY_COLUMNS: [&str; 18] = [
    "mu",
    "r",
    "alpha",
    "lambda",
    "beta",
    "osc",
    "d",
    "eta_dot_inf",
    "d_ftheta",
    "gamma_1",
    "gamma_inf",
    "kappa",
    "psi_0",
    "psi_inf",
    "theta",
    "theta_star",
    "theta_profile",
    "theta_engaged",
];

/// Columns that are not report quantities: verified flags, the best verified bound, the
/// measured side and ratios. `ratio` (`theta / measured`) and `best_ratio` (`theta_best /
/// measured`) are left empty unless the bound certifies (verified and `< 0`): a ratio of a
/// bound that certifies nothing means nothing.
pub const DERIVED: [(&str, &str); 8] = [
    ("theta_verified", "verified"),
    ("theta_best", "$\\theta_{\\mathrm{best}}$"),
    ("certified", "certified"),
    ("measured_rate", "measured"),
    ("measured_rate_ci_low", "CI low"),
    ("measured_rate_ci_high", "CI high"),
    ("ratio", "$\\theta/\\mathrm{measured}$"),
    ("best_ratio", "$\\theta_{\\mathrm{best}}/\\mathrm{measured}$"),
];

/// Path-length columns (report quantities, then the measured path and the ratio).
pub const PATH_COLUMNS: [&str; 4] = ["path_bound", "path1_bound", "path1_local_bound", "path2_bound"];

fn def(key: &str) -> &'static bounds::report::QuantityDef {
    bounds::report::defs::by_key(key).expect("sweep columns name declared quantities")
}

thread_local! {
    /// One [`Memo`] per worker thread of the sweep (it forgets a plant when it meets another).
    static MEMO: RefCell<Memo> = RefCell::new(Memo::new());
}

/// Column names of [`ThetaEvaluator`], in order.
pub fn column_names() -> Vec<&'static str> {
    let mut v: Vec<&str> = QUANTITY_COLUMNS.to_vec();
    v.extend(DERIVED.iter().map(|d| d.0));
    v.extend(PATH_COLUMNS);
    v.extend(["path_measured", "path_ratio"]);
    v
}

impl Evaluator for ThetaEvaluator {
    fn fingerprint(&self) -> String {
        let m = match &self.settings.measure {
            None => "measure=false".to_string(),
            Some(r) => format!(
                "measure=true dt={:?} periods={} transient={} pairs={} seed={}",
                r.dt, r.periods, r.transient_periods, r.pairs, r.seed
            ),
        };
        format!("moreau {} theta::assemble ({m})", env!("CARGO_PKG_VERSION"))
    }

    fn columns(&self) -> Vec<Column> {
        let n = Column::number;
        let mut c: Vec<Column> = QUANTITY_COLUMNS.iter().map(|k| n(k, def(k).tex)).collect();
        c.push(Column::flag(DERIVED[0].0, DERIVED[0].1));
        c.push(n(DERIVED[1].0, DERIVED[1].1));
        c.push(Column::flag(DERIVED[2].0, DERIVED[2].1));
        c.extend(DERIVED[3..].iter().map(|(k, t)| n(k, t)));
        c.extend(PATH_COLUMNS.iter().map(|k| n(k, def(k).tex)));
        c.push(n("path_measured", bounds::report::defs::PATH_MEASURED.tex));
        c.push(n("path_ratio", "bound/path"));
        c
    }

    fn evaluate(&self, sys: &System) -> Result<Vec<Cell>, PointError> {
        // each worker keeps the memo of its last plant (bounds::Memo): points that vary only the
        // input or Theta (amplitude, omega, theta.scale axes) solve each lambda once
        let r = MEMO.with(|m| assemble_memo(sys, &self.settings, &mut m.borrow_mut()))?;
        let num = Cell::Num;
        let (rate, lo, hi, path) = match &r.measured {
            Some(m) => (num(m.rate), num(m.ci_low), num(m.ci_high), num(m.path_length_per_period)),
            None => (Cell::Empty, Cell::Empty, Cell::Empty, Cell::Empty),
        };
        let certified = r.theta_best_verified && r.theta_best < 0.0;
        let ratio = match &r.measured {
            Some(m) if r.theta_verified && r.theta < 0.0 => num(r.theta / m.rate),
            _ => Cell::Empty,
        };
        let best_ratio = match &r.measured {
            Some(m) if certified => num(r.theta_best / m.rate),
            _ => Cell::Empty,
        };
        let best_path = r.path_bound.max(r.path1_bound).max(r.path1_local_bound).max(r.path2.value);
        let path_ratio = match &r.measured {
            Some(m) if m.path_length_per_period > 0.0 => num(best_path / m.path_length_per_period),
            Some(_) => num(f64::NAN),
            None => Cell::Empty,
        };
        let q = r.quantities();
        let val = |k: &str| q.iter().find(|x| x.key == k).map(|x| num(x.value)).unwrap_or(Cell::Empty);
        let mut cells: Vec<Cell> = QUANTITY_COLUMNS.iter().map(|k| val(k)).collect();
        cells.extend([
            Cell::Flag(r.theta_verified),
            num(r.theta_best),
            Cell::Flag(certified),
            rate,
            lo,
            hi,
            ratio,
            best_ratio,
        ]);
        cells.extend(PATH_COLUMNS.iter().map(|k| val(k)));
        cells.extend([path, path_ratio]);
        Ok(cells)
    }
}
