//! The sweep specification file (TOML):
//!
//! ```toml
//! name = "theta and measured rate vs amplitude"
//! model = "../worked-example.toml"     # base model, relative to this file
//!
//! [[axis]]                             # one or more; the grid is their Cartesian product
//! parameter = "input.amplitude"        # see `sweep::axis` for the names
//! range = { from = 0.5, to = 5.0, count = 10 }   # or { from, to, step }, spacing = "log"
//! # values = [0.5, 1.0, 2.0]           # or an explicit list
//! # label = "$a$"                      # LaTeX column header (optional)
//!
//! [evaluate]                           # settings handed to the evaluator (hashed)
//!
//! [table]                              # Markdown / LaTeX only; CSV and JSON hold everything
//! columns = ["theta", "measured_rate", "ratio"]
//! digits = 4
//! caption = "..."
//! ```
use super::axis::{Axis, Parameter, Values};
use super::SweepError;
use model::System;
use std::path::{Path, PathBuf};
use toml::{Table, Value};

/// Most points a single spec may describe.
pub const MAX_POINTS: usize = 10_000_000;

/// Markdown / LaTeX table settings (`[table]`).
#[derive(Debug, Clone, PartialEq)]
pub struct TableSettings {
    /// Columns shown (default: all). The axes always come first.
    pub columns: Option<Vec<String>>,
    /// Significant digits. Default `4`.
    pub digits: usize,
    /// LaTeX caption. Default: the sweep name.
    pub caption: Option<String>,
}

impl Default for TableSettings {
    fn default() -> Self {
        Self { columns: None, digits: 4, caption: None }
    }
}

/// A parsed and validated sweep specification.
#[derive(Debug, Clone)]
pub struct SweepSpec {
    pub path: PathBuf,
    pub name: String,
    /// The `model` key as written (relative to the spec file).
    pub model: String,
    pub model_path: PathBuf,
    /// The base model file's text (part of the spec hash).
    pub model_text: String,
    pub base: System,
    pub axes: Vec<Axis>,
    /// The `[evaluate]` table, handed to the evaluator.
    pub evaluate: Table,
    pub table: TableSettings,
}

fn wrong(path: &Path, key: &str, expected: &'static str) -> SweepError {
    SweepError::WrongType { path: path.to_path_buf(), key: key.to_string(), expected }
}

fn num(v: &Value) -> Option<f64> {
    match v {
        Value::Float(x) => Some(*x),
        Value::Integer(i) => Some(*i as f64),
        _ => None,
    }
}

fn check_keys(path: &Path, t: &Table, pre: &str, allowed: &'static str) -> Result<(), SweepError> {
    for k in t.keys() {
        if !allowed.split(", ").any(|a| a == k) {
            return Err(SweepError::UnknownKey { path: path.to_path_buf(), key: format!("{pre}{k}"), allowed });
        }
    }
    Ok(())
}

impl SweepSpec {
    /// Reads a spec file; the base model path is relative to the spec file.
    pub fn load(path: &Path) -> Result<Self, SweepError> {
        let text = model::files::read_regular(path, model::files::MAX_MODEL_BYTES)
            .map_err(|source| SweepError::File { source })?;
        Self::parse(&text, path)
    }

    /// Parses spec text; `path` locates the base model and names the file in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Self, SweepError> {
        let root: Table = toml::from_str(text)
            .map_err(|e| SweepError::Toml { path: path.to_path_buf(), message: toml_message(&e) })?;
        check_keys(path, &root, "", "name, model, axis, evaluate, table")?;
        let model_rel = match root.get("model") {
            Some(Value::String(s)) => s.clone(),
            Some(_) => return Err(wrong(path, "model", "a string (path of the base model file)")),
            None => return Err(SweepError::MissingKey { path: path.to_path_buf(), key: "model".into() }),
        };
        let dir = path.parent().unwrap_or(Path::new("."));
        let model_path = dir.join(&model_rel);
        let model_text = model::files::read_regular(&model_path, model::files::MAX_MODEL_BYTES)
            .map_err(|source| SweepError::Model { path: model_path.clone(), source })?;
        let base = model::load(&model_path).map_err(|source| SweepError::Model { path: model_path.clone(), source })?;
        let name = match root.get("name") {
            Some(Value::String(s)) => s.clone(),
            Some(_) => return Err(wrong(path, "name", "a string")),
            None => path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "sweep".into()),
        };
        let axes = parse_axes(path, &root, &base)?;
        let evaluate = match root.get("evaluate") {
            Some(Value::Table(t)) => t.clone(),
            Some(_) => return Err(wrong(path, "evaluate", "a table")),
            None => Table::new(),
        };
        let table = parse_table_settings(path, root.get("table"))?;
        let spec = Self {
            path: path.to_path_buf(),
            name,
            model: model_rel,
            model_path,
            model_text,
            base,
            axes,
            evaluate,
            table,
        };
        // every axis value must give a valid model on its own (e.g. no z0 outside Theta)
        for a in &spec.axes {
            for &v in &a.values {
                super::axis::apply_all(&spec.base, &[(&a.parameter, v)])?;
            }
        }
        Ok(spec)
    }

    /// Number of grid points (product of the axis lengths).
    pub fn total_points(&self) -> usize {
        self.axes.iter().map(|a| a.values.len()).product()
    }

    /// Parameter values of point `index` (the last axis varies fastest).
    pub fn point(&self, index: usize) -> Vec<f64> {
        let mut r = index;
        let mut out = vec![0.0; self.axes.len()];
        for (k, a) in self.axes.iter().enumerate().rev() {
            out[k] = a.values[r % a.values.len()];
            r /= a.values.len();
        }
        out
    }

    /// The model at point `index`.
    pub fn system_at(&self, index: usize) -> Result<System, SweepError> {
        let vals = self.point(index);
        let settings: Vec<(&Parameter, f64)> = self.axes.iter().map(|a| &a.parameter).zip(vals).collect();
        super::axis::apply_all(&self.base, &settings)
    }

    /// Identity of the sweep's data: FNV-1a (64 bit) over the base model text, the axes (names
    /// and exact values), the `[evaluate]` table and the evaluator's fingerprint. Table
    /// formatting (`[table]`, `--digits`) is not part of it.
    pub fn hash(&self, evaluator_fingerprint: &str) -> String {
        let mut h = Fnv::new();
        h.write(b"moreau-sweep/1\0");
        h.write(self.model_text.as_bytes());
        h.write(b"\0");
        for a in &self.axes {
            h.write(a.parameter.name().as_bytes());
            h.write(b"\0");
            for v in &a.values {
                h.write(&v.to_bits().to_le_bytes());
            }
        }
        h.write(b"\0");
        h.write(toml::to_string(&self.evaluate).unwrap_or_default().as_bytes());
        h.write(b"\0");
        h.write(evaluator_fingerprint.as_bytes());
        format!("{:016x}", h.0)
    }
}

/// One line from a TOML error: the reason (its last line) and the place (its first line).
fn toml_message(e: &toml::de::Error) -> String {
    let full = e.to_string();
    let lines: Vec<&str> = full.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
    let first = lines.first().copied().unwrap_or("");
    let last = lines.last().copied().unwrap_or("");
    let place = first.strip_prefix("TOML parse error at ").unwrap_or(first);
    if lines.len() <= 1 || last == first {
        place.to_string()
    } else {
        format!("{last} ({place})")
    }
}

/// 64-bit FNV-1a (an identity check, not a cryptographic hash).
struct Fnv(u64);
impl Fnv {
    fn new() -> Self {
        Fnv(0xcbf29ce484222325)
    }
    fn write(&mut self, b: &[u8]) {
        for &x in b {
            self.0 ^= x as u64;
            self.0 = self.0.wrapping_mul(0x100000001b3);
        }
    }
}

/// The `[[axis]]` tables, each expanded; the number of grid points is checked before each axis
/// is expanded, so that no list longer than the limit is ever built.
fn parse_axes(path: &Path, root: &Table, base: &model::System) -> Result<Vec<Axis>, SweepError> {
    let axes_v = match root.get("axis") {
        Some(Value::Array(a)) => a,
        Some(_) => return Err(wrong(path, "axis", "an array of tables ([[axis]])")),
        None => return Err(SweepError::NoAxes),
    };
    if axes_v.is_empty() {
        return Err(SweepError::NoAxes);
    }
    let mut axes: Vec<Axis> = Vec::new();
    let mut total: u128 = 1;
    for (k, a) in axes_v.iter().enumerate() {
        let key = |s: &str| format!("axis[{k}].{s}");
        let Value::Table(t) = a else { return Err(wrong(path, &format!("axis[{k}]"), "a table")) };
        check_keys(path, t, &format!("axis[{k}]."), "parameter, values, range, label")?;
        let pname = match t.get("parameter") {
            Some(Value::String(s)) => s.clone(),
            Some(_) => return Err(wrong(path, &key("parameter"), "a string")),
            None => return Err(SweepError::MissingKey { path: path.to_path_buf(), key: key("parameter") }),
        };
        let parameter = Parameter::parse(&pname)?;
        parameter.check_applicable(base)?;
        if axes.iter().any(|x| x.parameter == parameter) {
            return Err(SweepError::DuplicateAxis { name: parameter.name() });
        }
        let values = parse_values(path, &key, t, &parameter)?;
        total = total.saturating_mul(values.len_before_expanding());
        // the soft limit too (unless --allow-large): every axis value is validated below,
        // which costs ~2 us a value (fuzzing found a 1.3 M-value axis taking 2.9 s to refuse)
        let limit = if crate::budget::allow_large() { MAX_POINTS } else { crate::budget::MAX_SWEEP_POINTS };
        if total > limit as u128 {
            return Err(SweepError::TooManyPoints { points: total, limit });
        }
        let values = values.expand(&parameter.name())?;
        let label = match t.get("label") {
            Some(Value::String(s)) => s.clone(),
            Some(_) => return Err(wrong(path, &key("label"), "a string")),
            None => parameter.latex(),
        };
        axes.push(Axis { parameter, values, label });
    }
    let total = axes.iter().fold(1u128, |acc, a| acc.saturating_mul(a.values.len() as u128));
    if total > MAX_POINTS as u128 {
        return Err(SweepError::TooManyPoints { points: total, limit: MAX_POINTS });
    }
    Ok(axes)
}

/// An axis's `values = [...]` or `range = { ... }` (not expanded).
fn parse_values(
    path: &Path,
    key: &dyn Fn(&str) -> String,
    t: &Table,
    parameter: &Parameter,
) -> Result<Values, SweepError> {
    match (t.get("values"), t.get("range")) {
        (Some(_), Some(_)) => Err(wrong(path, &key("values"), "either `values` or `range`, not both")),
        (Some(Value::Array(v)), None) => Ok(Values::List(
            v.iter()
                .map(|x| num(x).ok_or_else(|| wrong(path, &key("values"), "an array of numbers")))
                .collect::<Result<_, _>>()?,
        )),
        (Some(_), None) => Err(wrong(path, &key("values"), "an array of numbers")),
        (None, Some(Value::Table(r))) => parse_range(path, key, r, parameter),
        (None, Some(_)) => Err(wrong(path, &key("range"), "a table { from, to, count | step }")),
        (None, None) => Err(SweepError::MissingKey { path: path.to_path_buf(), key: key("values (or range)") }),
    }
}

/// An axis's `range = { from, to, count | step, spacing }`.
fn parse_range(
    path: &Path,
    key: &dyn Fn(&str) -> String,
    r: &Table,
    parameter: &Parameter,
) -> Result<Values, SweepError> {
    check_keys(path, r, &key("range."), "from, to, count, step, spacing")?;
    let g = |s: &str| -> Result<Option<f64>, SweepError> {
        match r.get(s) {
            None => Ok(None),
            Some(v) => num(v).map(Some).ok_or_else(|| wrong(path, &key(&format!("range.{s}")), "a number")),
        }
    };
    let need = |s: &str| -> Result<f64, SweepError> {
        g(s)?.ok_or_else(|| SweepError::MissingKey { path: path.to_path_buf(), key: key(&format!("range.{s}")) })
    };
    let (from, to) = (need("from")?, need("to")?);
    let log = match r.get("spacing") {
        None => false,
        Some(Value::String(s)) if s == "linear" => false,
        Some(Value::String(s)) if s == "log" => true,
        Some(_) => return Err(wrong(path, &key("range.spacing"), "\"linear\" or \"log\"")),
    };
    match (r.get("count"), g("step")?) {
        (Some(Value::Integer(c)), None) => {
            if *c < 0 {
                return Err(SweepError::EmptyRange {
                    name: parameter.name(),
                    from,
                    to,
                    detail: format!("count = {c}"),
                });
            }
            Ok(Values::Count { from, to, count: *c as usize, log })
        }
        (Some(_), None) => Err(wrong(path, &key("range.count"), "a non-negative integer")),
        (None, Some(step)) if !log => Ok(Values::Step { from, to, step }),
        (None, Some(_)) => Err(wrong(path, &key("range.step"), "no step with spacing = \"log\" (use count)")),
        (Some(_), Some(_)) => Err(wrong(path, &key("range"), "either `count` or `step`, not both")),
        (None, None) => {
            Err(SweepError::MissingKey { path: path.to_path_buf(), key: key("range.count (or range.step)") })
        }
    }
}

/// The `[table]` settings (columns, digits, caption).
fn parse_table_settings(path: &Path, v: Option<&Value>) -> Result<TableSettings, SweepError> {
    let mut table = TableSettings::default();
    let t = match v {
        None => return Ok(table),
        Some(Value::Table(t)) => t,
        Some(_) => return Err(wrong(path, "table", "a table")),
    };
    check_keys(path, t, "table.", "columns, digits, caption")?;
    if let Some(c) = t.get("columns") {
        let Value::Array(c) = c else {
            return Err(wrong(path, "table.columns", "an array of column names"));
        };
        table.columns = Some(
            c.iter()
                .map(|v| {
                    v.as_str().map(String::from).ok_or_else(|| wrong(path, "table.columns", "an array of column names"))
                })
                .collect::<Result<_, _>>()?,
        );
    }
    if let Some(d) = t.get("digits") {
        let d = d.as_integer().ok_or_else(|| wrong(path, "table.digits", "an integer"))?;
        if !(1..=17).contains(&d) {
            return Err(SweepError::BadDigits { digits: d, source_key: "[table] digits =" });
        }
        table.digits = d as usize;
    }
    if let Some(c) = t.get("caption") {
        table.caption = Some(c.as_str().ok_or_else(|| wrong(path, "table.caption", "a string"))?.to_string());
    }
    Ok(table)
}
