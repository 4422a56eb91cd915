//! Sweep results and their tables: JSON (complete, exact, the input of `moreau merge` and of
//! resumed runs), CSV (complete, exact), Markdown and LaTeX (booktabs and siunitx `S` columns;
//! significant digits, one notation per column: [`ColumnNumbers`]).
//! Every writer sorts the points by index, so the files do not depend on the thread count.
use super::eval::{Cell, Column, ColumnKind};
use super::shard::Shard;
use super::spec::TableSettings;
use super::SweepError;
use serde_json::{json, Map, Value};
use std::path::Path;

/// Format tag of the JSON result files.
pub const FORMAT: &str = "moreau-sweep/1";

/// One evaluated point.
#[derive(Debug, Clone, PartialEq)]
pub struct PointRecord {
    /// Index in the full grid (the last axis varies fastest).
    pub index: usize,
    /// Axis values.
    pub params: Vec<f64>,
    /// One cell per column (all [`Cell::Empty`] when the point failed).
    pub cells: Vec<Cell>,
    /// `ok`, or `error: ...` when the evaluation failed.
    pub status: String,
}

impl PointRecord {
    pub fn ok(&self) -> bool {
        self.status == "ok"
    }
}

/// One axis as stored in a result file.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisInfo {
    pub name: String,
    pub label: String,
    pub values: Vec<f64>,
}

/// A sweep's results (complete, one shard, or partial).
#[derive(Debug, Clone, PartialEq)]
pub struct SweepResult {
    pub name: String,
    pub spec_hash: String,
    pub model: String,
    pub evaluator: String,
    pub axes: Vec<AxisInfo>,
    pub columns: Vec<Column>,
    pub total_points: usize,
    pub shard: Option<Shard>,
    pub table: TableSettings,
    /// Sorted by index.
    pub points: Vec<PointRecord>,
}

fn num_json(x: f64) -> Value {
    if x.is_finite() {
        json!(x)
    } else if x.is_nan() {
        json!("NaN")
    } else if x > 0.0 {
        json!("inf")
    } else {
        json!("-inf")
    }
}

fn json_num(v: &Value) -> Option<f64> {
    match v {
        Value::Number(n) => n.as_f64(),
        Value::String(s) if s == "NaN" => Some(f64::NAN),
        Value::String(s) if s == "inf" => Some(f64::INFINITY),
        Value::String(s) if s == "-inf" => Some(f64::NEG_INFINITY),
        _ => None,
    }
}

fn cell_json(c: &Cell) -> Value {
    match c {
        Cell::Num(x) => num_json(*x),
        Cell::Flag(b) => json!(b),
        Cell::Text(s) => json!(s),
        Cell::Empty => Value::Null,
    }
}

fn json_cell(v: &Value, kind: ColumnKind) -> Option<Cell> {
    Some(match (v, kind) {
        (Value::Null, _) => Cell::Empty,
        (_, ColumnKind::Number) => Cell::Num(json_num(v)?),
        (Value::Bool(b), ColumnKind::Flag) => Cell::Flag(*b),
        (Value::String(s), ColumnKind::Text) => Cell::Text(s.clone()),
        _ => return None,
    })
}

impl PointRecord {
    /// JSON object of the point (also one line of the checkpoint file).
    pub fn to_json(&self) -> Value {
        json!({
            "index": self.index,
            "params": self.params.iter().map(|&x| num_json(x)).collect::<Vec<_>>(),
            "values": self.cells.iter().map(cell_json).collect::<Vec<_>>(),
            "status": self.status,
        })
    }
    /// Reads a point written by [`PointRecord::to_json`]; `None` if malformed.
    pub fn from_json(v: &Value, columns: &[Column], n_axes: usize) -> Option<Self> {
        let index = v.get("index")?.as_u64()? as usize;
        let params: Vec<f64> = v.get("params")?.as_array()?.iter().map(json_num).collect::<Option<_>>()?;
        let vals = v.get("values")?.as_array()?;
        if params.len() != n_axes || vals.len() != columns.len() {
            return None;
        }
        let cells = vals.iter().zip(columns).map(|(v, c)| json_cell(v, c.kind)).collect::<Option<_>>()?;
        let status = v.get("status")?.as_str()?.to_string();
        Some(Self { index, params, cells, status })
    }
}

fn bad(path: &Path, reason: &str) -> SweepError {
    SweepError::BadResultFile { path: path.to_path_buf(), reason: reason.to_string() }
}

impl SweepResult {
    /// Header fields without the points (for the checkpoint file's first line).
    pub fn header_json(&self) -> Value {
        json!({
            "format": FORMAT,
            "name": self.name,
            "spec_hash": self.spec_hash,
            "model": self.model,
            "evaluator": self.evaluator,
            "axes": self.axes.iter().map(|a| json!({"parameter": a.name, "label": a.label, "values": a.values.iter().map(|&x| num_json(x)).collect::<Vec<_>>()})).collect::<Vec<_>>(),
            "columns": self.columns.iter().map(|c| json!({"name": c.name, "latex": c.latex, "kind": c.kind.as_str()})).collect::<Vec<_>>(),
            "total_points": self.total_points,
            "shard": self.shard.map(|s| json!({"k": s.k, "n": s.n})),
            "table": {"columns": self.table.columns, "digits": self.table.digits, "caption": self.table.caption},
        })
    }

    pub fn to_json_string(&self) -> String {
        let mut h = self.header_json();
        h.as_object_mut()
            .expect("object")
            .insert("points".into(), Value::Array(self.points.iter().map(|p| p.to_json()).collect()));
        let mut s = serde_json::to_string_pretty(&h).expect("serialisable");
        s.push('\n');
        s
    }

    /// Parses the header fields of a result or checkpoint (points left empty).
    pub fn header_from_json(v: &Value, path: &Path) -> Result<Self, SweepError> {
        let o: &Map<String, Value> = v.as_object().ok_or_else(|| bad(path, "not a JSON object"))?;
        if o.get("format").and_then(Value::as_str) != Some(FORMAT) {
            return Err(bad(path, &format!("missing or unknown `format` (expected {FORMAT})")));
        }
        let s = |k: &str| {
            o.get(k).and_then(Value::as_str).map(String::from).ok_or_else(|| bad(path, &format!("missing `{k}`")))
        };
        let axes = o
            .get("axes")
            .and_then(Value::as_array)
            .ok_or_else(|| bad(path, "missing `axes`"))?
            .iter()
            .map(|a| {
                Some(AxisInfo {
                    name: a.get("parameter")?.as_str()?.into(),
                    label: a.get("label")?.as_str()?.into(),
                    values: a.get("values")?.as_array()?.iter().map(json_num).collect::<Option<_>>()?,
                })
            })
            .collect::<Option<Vec<_>>>()
            .ok_or_else(|| bad(path, "malformed `axes`"))?;
        let columns = o
            .get("columns")
            .and_then(Value::as_array)
            .ok_or_else(|| bad(path, "missing `columns`"))?
            .iter()
            .map(|c| {
                Some(Column {
                    name: c.get("name")?.as_str()?.into(),
                    latex: c.get("latex")?.as_str()?.into(),
                    kind: ColumnKind::parse(c.get("kind")?.as_str()?)?,
                })
            })
            .collect::<Option<Vec<_>>>()
            .ok_or_else(|| bad(path, "malformed `columns`"))?;
        let total_points =
            o.get("total_points").and_then(Value::as_u64).ok_or_else(|| bad(path, "missing `total_points`"))? as usize;
        let shard = match o.get("shard") {
            None | Some(Value::Null) => None,
            Some(v) => {
                let k = v.get("k").and_then(Value::as_u64).ok_or_else(|| bad(path, "malformed `shard`"))? as usize;
                let n = v.get("n").and_then(Value::as_u64).ok_or_else(|| bad(path, "malformed `shard`"))? as usize;
                Some(Shard::new(k, n).map_err(|_| bad(path, "malformed `shard`"))?)
            }
        };
        let t = o.get("table");
        let table = TableSettings {
            columns: t
                .and_then(|t| t.get("columns"))
                .and_then(Value::as_array)
                .map(|a| a.iter().filter_map(|x| x.as_str().map(String::from)).collect()),
            digits: t
                .and_then(|t| t.get("digits"))
                .and_then(Value::as_u64)
                .map(|d| d as usize)
                .filter(|d| (1..=17).contains(d))
                .unwrap_or(4),
            caption: t.and_then(|t| t.get("caption")).and_then(Value::as_str).map(String::from),
        };
        Ok(Self {
            name: s("name")?,
            spec_hash: s("spec_hash")?,
            model: s("model")?,
            evaluator: s("evaluator")?,
            axes,
            columns,
            total_points,
            shard,
            table,
            points: vec![],
        })
    }

    /// Reads a result file written by [`SweepResult::to_json_string`].
    pub fn read(path: &Path) -> Result<Self, SweepError> {
        let text = model::files::read_regular(path, model::files::MAX_CSV_BYTES)
            .map_err(|source| SweepError::File { source })?;
        let v: Value = serde_json::from_str(&text).map_err(|e| bad(path, &format!("invalid JSON: {e}")))?;
        let mut r = Self::header_from_json(&v, path)?;
        let pts = v.get("points").and_then(Value::as_array).ok_or_else(|| bad(path, "missing `points`"))?;
        for p in pts {
            let rec =
                PointRecord::from_json(p, &r.columns, r.axes.len()).ok_or_else(|| bad(path, "malformed point"))?;
            if rec.index >= r.total_points {
                return Err(bad(path, &format!("point index {} >= total_points {}", rec.index, r.total_points)));
            }
            r.points.push(rec);
        }
        r.points.sort_by_key(|p| p.index);
        r.points.dedup_by_key(|p| p.index);
        Ok(r)
    }

    /// Columns shown in Markdown / LaTeX (the `[table] columns` choice, default all).
    fn shown(&self) -> Vec<usize> {
        match &self.table.columns {
            None => (0..self.columns.len()).collect(),
            Some(names) => names.iter().filter_map(|n| self.columns.iter().position(|c| &c.name == n)).collect(),
        }
    }

    /// Names in `[table] columns` that are not columns of this evaluator.
    pub fn unknown_table_columns(&self) -> Vec<String> {
        self.table.columns.iter().flatten().filter(|n| !self.columns.iter().any(|c| &c.name == *n)).cloned().collect()
    }

    /// CSV: `index`, the axes, every column, `status`; numbers in shortest round-trip form.
    pub fn to_csv(&self) -> String {
        let mut s = String::new();
        let mut head: Vec<String> = vec!["index".into()];
        head.extend(self.axes.iter().map(|a| csv_field(&a.name)));
        head.extend(self.columns.iter().map(|c| csv_field(&c.name)));
        head.push("status".into());
        s.push_str(&head.join(","));
        s.push('\n');
        for p in &self.points {
            let mut row: Vec<String> = vec![p.index.to_string()];
            row.extend(p.params.iter().map(|&x| exact(x)));
            row.extend(p.cells.iter().map(|c| match c {
                Cell::Num(x) => exact(*x),
                Cell::Flag(b) => b.to_string(),
                Cell::Text(t) => csv_field(t),
                Cell::Empty => String::new(),
            }));
            row.push(csv_field(&p.status));
            s.push_str(&row.join(","));
            s.push('\n');
        }
        s
    }

    fn any_failed(&self) -> bool {
        self.points.iter().any(|p| !p.ok())
    }

    /// Markdown table with `digits` significant digits.
    pub fn to_markdown(&self, digits: usize) -> String {
        let shown = self.shown();
        let mut head: Vec<String> = self.axes.iter().map(|a| format!("`{}`", a.name)).collect();
        head.extend(shown.iter().map(|&k| format!("`{}`", self.columns[k].name)));
        let failed = self.any_failed();
        if failed {
            head.push("status".into());
        }
        let mut s = format!(
            "<!-- moreau sweep `{}`, spec hash {}, {} of {} points -->\n\n",
            self.name,
            self.spec_hash,
            self.points.len(),
            self.total_points
        );
        s.push_str(&format!("| {} |\n", head.join(" | ")));
        s.push_str(&format!("|{}\n", "---:|".repeat(head.len())));
        let (axes_fmt, cols_fmt) = self.number_formats(&shown, digits);
        for p in &self.points {
            let mut row: Vec<String> = p.params.iter().zip(&axes_fmt).map(|(&x, f)| f.text(x)).collect();
            row.extend(shown.iter().zip(&cols_fmt).map(|(&k, f)| match &p.cells[k] {
                Cell::Num(x) => f.text(*x),
                Cell::Flag(b) => (if *b { "yes" } else { "no" }).into(),
                Cell::Text(t) => t.replace('|', "\\|"),
                Cell::Empty => "-".into(),
            }));
            if failed {
                row.push(p.status.replace('|', "\\|"));
            }
            s.push_str(&format!("| {} |\n", row.join(" | ")));
        }
        s
    }

    /// Notation of the axes' and the `shown` columns' numbers (text and flag columns: `None`).
    fn number_formats(&self, shown: &[usize], digits: usize) -> (Vec<ColumnNumbers>, Vec<ColumnNumbers>) {
        let axes =
            (0..self.axes.len()).map(|a| ColumnNumbers::of(self.points.iter().map(|p| p.params[a]), digits)).collect();
        let cols = shown
            .iter()
            .map(|&k| {
                let nums =
                    self.points.iter().filter_map(|p| if let Cell::Num(x) = p.cells[k] { Some(x) } else { None });
                ColumnNumbers::of(nums, digits)
            })
            .collect();
        (axes, cols)
    }

    /// LaTeX `table` with a booktabs `tabular` whose numeric columns are siunitx `S` columns
    /// (`\usepackage{booktabs,siunitx}`), aligned on the decimal marker with a `table-format`
    /// from the column's numbers; `digits` significant digits, one notation per column.
    pub fn to_latex(&self, digits: usize) -> String {
        let shown = self.shown();
        let failed = self.any_failed();
        let (axes_fmt, cols_fmt) = self.number_formats(&shown, digits);
        let numeric: Vec<bool> = std::iter::repeat_n(true, self.axes.len())
            .chain(shown.iter().map(|&k| self.columns[k].kind == ColumnKind::Number))
            .collect();
        let spec: Vec<String> = axes_fmt
            .iter()
            .chain(&cols_fmt)
            .zip(&numeric)
            .map(|(f, &num)| if num { format!("S[table-format={}]", f.table_format()) } else { "l".into() })
            .chain(failed.then(|| "l".to_string()))
            .collect();
        // headers of S columns in braces (siunitx reads them as text)
        let mut head: Vec<String> = self.axes.iter().map(|a| format!("{{{}}}", a.label)).collect();
        head.extend(shown.iter().map(|&k| {
            let c = &self.columns[k];
            if c.kind == ColumnKind::Number {
                format!("{{{}}}", c.latex)
            } else {
                c.latex.clone()
            }
        }));
        if failed {
            head.push("status".into());
        }
        let caption = self.table.caption.clone().unwrap_or_else(|| latex_escape(&self.name));
        let label: String =
            self.name.chars().map(|c| if c.is_ascii_alphanumeric() { c.to_ascii_lowercase() } else { '-' }).collect();
        let mut s = String::new();
        s.push_str(&format!(
            "% moreau sweep `{}`: spec hash {}, {} of {} points; needs \\usepackage{{booktabs,siunitx}}\n",
            self.name,
            self.spec_hash,
            self.points.len(),
            self.total_points
        ));
        s.push_str("\\begin{table}[ht]\n\\centering\n");
        s.push_str(&format!("\\caption{{{caption}}}\n\\label{{tab:{label}}}\n"));
        s.push_str(&format!("\\begin{{tabular}}{{{}}}\n\\toprule\n", spec.join(" ")));
        s.push_str(&format!("{} \\\\\n\\midrule\n", head.join(" & ")));
        for p in &self.points {
            let mut row: Vec<String> = p.params.iter().zip(&axes_fmt).map(|(&x, f)| f.latex(x)).collect();
            row.extend(shown.iter().zip(&cols_fmt).map(|(&k, f)| match &p.cells[k] {
                Cell::Num(x) => f.latex(*x),
                Cell::Flag(b) => (if *b { "yes" } else { "no" }).into(),
                Cell::Text(t) => latex_escape(t),
                // in an S column text goes in braces
                Cell::Empty if self.columns[k].kind == ColumnKind::Number => "{--}".into(),
                Cell::Empty => "--".into(),
            }));
            if failed {
                row.push(latex_escape(if p.ok() { "ok" } else { "failed" }));
            }
            s.push_str(&format!("{} \\\\\n", row.join(" & ")));
        }
        s.push_str("\\bottomrule\n\\end{tabular}\n\\end{table}\n");
        s
    }
}

/// The notation of one table column's numbers: `digits` significant digits ([`sig`]), fixed
/// when every finite value of the column is written fixed by [`sig`], otherwise every value
/// in scientific notation (`1.06e-5`, `-7.80e-3`), so a column never mixes the two.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ColumnNumbers {
    pub digits: usize,
    pub scientific: bool,
    /// For the siunitx `table-format`: a minus sign, integer digits, decimals, a negative
    /// exponent and exponent digits among the column's values.
    sign: bool,
    int: usize,
    dec: usize,
    exp_sign: bool,
    exp: usize,
}

impl ColumnNumbers {
    /// The notation of a column of `values` at `digits` significant digits.
    pub fn of(values: impl Iterator<Item = f64>, digits: usize) -> Self {
        let values: Vec<f64> = values.filter(|x| x.is_finite()).collect();
        let scientific = values.iter().any(|&x| sig(x, digits, false).contains('e'));
        let mut f = Self { digits, scientific, sign: false, int: 1, dec: 0, exp_sign: false, exp: 0 };
        for &x in &values {
            let t = f.text(x);
            let (mant, exp) = t.split_once('e').unwrap_or((&t, ""));
            f.sign |= mant.starts_with('-');
            let (i, d) = mant.trim_start_matches('-').split_once('.').unwrap_or((mant.trim_start_matches('-'), ""));
            f.int = f.int.max(i.len());
            f.dec = f.dec.max(d.len());
            f.exp_sign |= exp.starts_with('-');
            f.exp = f.exp.max(exp.trim_start_matches('-').len());
        }
        f
    }

    /// `x` in this notation, plain text (Markdown; numbers of an `S` column).
    pub fn text(&self, x: f64) -> String {
        let digits = self.digits.clamp(1, 17);
        if self.scientific && x.is_finite() {
            format!("{:.*e}", digits - 1, x)
        } else {
            sig(x, digits, false)
        }
    }

    /// `x` as a cell of an siunitx `S` column (non-finite values as braced text).
    pub fn latex(&self, x: f64) -> String {
        if x.is_finite() {
            self.text(x)
        } else {
            format!("{{{}}}", sig(x, self.digits, true))
        }
    }

    /// The siunitx `table-format` of the column: `-1.3`, `2.2e-1`.
    pub fn table_format(&self) -> String {
        let mut s = String::new();
        if self.sign {
            s.push('-');
        }
        s.push_str(&self.int.to_string());
        if self.dec > 0 {
            s.push_str(&format!(".{}", self.dec));
        }
        if self.scientific && self.exp > 0 {
            s.push('e');
            if self.exp_sign {
                s.push('-');
            }
            s.push_str(&self.exp.to_string());
        }
        s
    }
}

/// Shortest string that parses back to the same `f64`.
pub fn exact(x: f64) -> String {
    if x.is_nan() {
        "NaN".into()
    } else if x.is_infinite() {
        (if x > 0.0 { "inf" } else { "-inf" }).into()
    } else {
        format!("{x:?}")
    }
}

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

fn latex_escape(s: &str) -> String {
    let mut o = String::new();
    for c in s.chars() {
        match c {
            '&' | '%' | '$' | '#' | '_' | '{' | '}' => {
                o.push('\\');
                o.push(c)
            }
            '~' => o.push_str("\\textasciitilde{}"),
            '^' => o.push_str("\\textasciicircum{}"),
            '\\' => o.push_str("\\textbackslash{}"),
            _ => o.push(c),
        }
    }
    o
}

/// `x` with `digits` significant digits: fixed notation for exponents in `[-4, digits)`,
/// otherwise scientific (`1.234e-5`, or `1.234\times 10^{-5}` in LaTeX math).
pub fn sig(x: f64, digits: usize, latex: bool) -> String {
    let digits = digits.clamp(1, 17);
    if x.is_nan() {
        return (if latex { "--" } else { "NaN" }).into();
    }
    if x.is_infinite() {
        return match (latex, x > 0.0) {
            (true, true) => "$\\infty$".into(),
            (true, false) => "$-\\infty$".into(),
            (false, true) => "inf".into(),
            (false, false) => "-inf".into(),
        };
    }
    let e = format!("{:.*e}", digits - 1, x);
    let (mant, exp) = e.split_once('e').expect("exponent");
    let exp: i32 = exp.parse().expect("integer exponent");
    let body = if (-4..digits as i32).contains(&exp) {
        format!("{:.*}", (digits as i32 - 1 - exp).max(0) as usize, x)
    } else if latex {
        format!("{mant}\\times 10^{{{exp}}}")
    } else {
        format!("{mant}e{exp}")
    };
    if latex {
        format!("${body}$")
    } else {
        body
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn significant_digits() {
        assert_eq!(sig(0.0213456, 3, false), "0.0213");
        assert_eq!(sig(-0.0213456, 3, true), "$-0.0213$");
        assert_eq!(sig(1234.5, 3, false), "1.23e3");
        assert_eq!(sig(123.45, 3, false), "123");
        assert_eq!(sig(9.9996, 4, false), "10.00");
        assert_eq!(sig(1.5e-7, 2, true), "$1.5\\times 10^{-7}$");
        assert_eq!(sig(0.0, 3, false), "0.00");
        assert_eq!(exact(0.1), "0.1");
        // one notation per column: scientific for all when one value needs it
        let f = ColumnNumbers::of([1.06e-5, -0.0078, -0.0468].into_iter(), 3);
        assert!(f.scientific);
        assert_eq!(
            (f.text(1.06e-5), f.text(-0.0078), f.text(-0.0468)),
            ("1.06e-5".into(), "-7.80e-3".into(), "-4.68e-2".into())
        );
        assert_eq!(f.table_format(), "-1.2e-1");
        let g = ColumnNumbers::of([0.196, 65.4, 12.1].into_iter(), 3);
        assert!(!g.scientific);
        assert_eq!((g.text(0.196), g.text(65.4)), ("0.196".into(), "65.4".into()));
        assert_eq!(g.table_format(), "2.3");
        assert_eq!(g.latex(f64::NAN), "{--}");
        assert_eq!(exact(1e-300).parse::<f64>().unwrap(), 1e-300);
    }
}
