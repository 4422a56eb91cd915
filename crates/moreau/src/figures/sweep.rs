//! theta (eq. (theta)) and the measured exponent against a swept parameter, from a sweep
//! result file (`moreau sweep`). With several axes, one curve per combination of the others.
//! When the sweep has the `certified` column, the points where the best verified bound
//! certifies convergence are drawn in the curve's colour and the others grey.
//! Every column shares one y axis: the bounds (`theta`, `theta_best`, ...) and the measured
//! exponent are rates of the same kind, and their ratio is what a reader compares. Axes and
//! legend carry the spec's labels (`label = "$\\delta$ (m)"`, the columns' TeX names), drawn
//! with Greek letters in SVG/PNG/PDF and kept as TeX in pgf.
use super::canvas::{num_text, palette, Element, Figure, GREY};
use super::FigureError;
use crate::sweep::{Cell, Column, ColumnKind, SweepResult};
use plotters::style::RGBColor;
use std::collections::BTreeMap;

/// Whether a column is a rate exponent (a theta bound or the measured exponent).
fn is_exponent(column: &str) -> bool {
    column.starts_with("theta") && !column.ends_with("verified") || column.starts_with("measured_rate")
}

/// The name of a column in a figure: its TeX label (`$\\theta_{\\mathrm{best}}$`), the
/// measured rate as "measured exponent".
fn column_label(c: &Column) -> String {
    match c.name.as_str() {
        "measured_rate" => "measured exponent".into(),
        _ if c.latex.trim().is_empty() => c.name.clone(),
        _ => c.latex.clone(),
    }
}

/// Curves of the numeric `columns` against axis `x` (default: the first axis), all on one y
/// axis (see the module doc).
pub fn sweep_figure(r: &SweepResult, x: Option<&str>, columns: &[&str]) -> Result<Figure, FigureError> {
    let mut colour = 0;
    let mut top = panel(r, x, columns, &mut colour)?;
    // the sweep's own name; the columns are on the axes
    top.title = r.name.clone();
    if top.ranges().is_none() {
        return Err(FigureError::NoData { figure: top.title });
    }
    Ok(top)
}

/// One panel: the `columns` against axis `x`, colours from `colour` on; one curve per column
/// and combination of the other axes' values.
fn panel(r: &SweepResult, x: Option<&str>, columns: &[&str], colour_from: &mut usize) -> Result<Figure, FigureError> {
    let xi = axis_index(r, x)?;
    let col_idx = column_indices(r, columns)?;
    let names: Vec<String> = col_idx.iter().map(|&k| column_label(&r.columns[k])).collect();
    let y_label =
        if columns.iter().all(|c| is_exponent(c)) { "convergence exponent".to_string() } else { names.join(", ") };
    let mut f = Figure::new(&r.name, &axis_label(&r.axes[xi]), &y_label);
    let groups = groups(r, xi);
    let mut curves =
        Curves { xi, cert_idx: r.columns.iter().position(|k| k.name == "certified"), grey_labelled: false };
    for (key_bits, pts) in &groups {
        let suffix = if groups.len() > 1 { others_suffix(r, xi, key_bits) } else { String::new() };
        for (&c, name) in col_idx.iter().zip(&names) {
            curves.push(&mut f, pts, c, format!("{name}{suffix}"), palette(*colour_from));
            *colour_from += 1;
        }
    }
    Ok(f)
}

/// The position of axis `x` among the sweep's axes (the first where `None`).
fn axis_index(r: &SweepResult, x: Option<&str>) -> Result<usize, FigureError> {
    let Some(n) = x else { return Ok(0) };
    r.axes.iter().position(|a| a.name == n).ok_or_else(|| FigureError::UnknownAxis {
        name: n.into(),
        known: r.axes.iter().map(|a| a.name.as_str()).collect::<Vec<_>>().join(", "),
    })
}

/// The positions of the numeric `columns` among the sweep's columns.
fn column_indices(r: &SweepResult, columns: &[&str]) -> Result<Vec<usize>, FigureError> {
    let numeric = || r.columns.iter().filter(|k| k.kind == ColumnKind::Number);
    columns
        .iter()
        .map(|c| {
            r.columns.iter().position(|k| k.name == *c && k.kind == ColumnKind::Number).ok_or_else(|| {
                FigureError::UnknownColumn {
                    name: c.to_string(),
                    known: numeric().map(|k| k.name.as_str()).collect::<Vec<_>>().join(", "),
                }
            })
        })
        .collect()
}

/// An axis in a figure: its label, else its name.
fn axis_label(a: &crate::sweep::table::AxisInfo) -> String {
    if a.label.trim().is_empty() {
        a.name.clone()
    } else {
        a.label.clone()
    }
}

/// The sweep's finished points grouped by the other axes' values (as bits, in order).
fn groups(r: &SweepResult, xi: usize) -> BTreeMap<Vec<u64>, Vec<&crate::sweep::PointRecord>> {
    let mut groups: BTreeMap<Vec<u64>, Vec<&crate::sweep::PointRecord>> = BTreeMap::new();
    for p in r.points.iter().filter(|p| p.ok()) {
        let key: Vec<u64> = p.params.iter().enumerate().filter(|(k, _)| *k != xi).map(|(_, v)| v.to_bits()).collect();
        groups.entry(key).or_default().push(p);
    }
    groups
}

/// A curve's legend suffix for one combination of the other axes: `, label = value, ...`.
fn others_suffix(r: &SweepResult, xi: usize, key_bits: &[u64]) -> String {
    let others: Vec<String> = r
        .axes
        .iter()
        .enumerate()
        .filter(|(k, _)| *k != xi)
        .zip(key_bits)
        .map(|((_, a), b)| format!("{} = {}", axis_label(a), num_text(f64::from_bits(*b))))
        .collect();
    format!(", {}", others.join(", "))
}

/// The curves of a panel: the swept axis, the `certified` column where the sweep has it, and
/// whether the grey "not certified" markers have their legend entry yet.
struct Curves {
    xi: usize,
    cert_idx: Option<usize>,
    grey_labelled: bool,
}

impl Curves {
    /// Column `c` of the points `pts` as a line and its markers: with the `certified` column,
    /// certified points filled in the curve's colour, the others grey.
    fn push(&mut self, f: &mut Figure, pts: &[&crate::sweep::PointRecord], c: usize, label: String, color: RGBColor) {
        let xi = self.xi;
        let mut xy: Vec<(f64, f64)> = pts
            .iter()
            .filter_map(|p| if let Cell::Num(v) = p.cells[c] { Some((p.params[xi], v)) } else { None })
            .collect();
        xy.sort_by(|a, b| a.0.total_cmp(&b.0));
        f.elements.push(Element::Line { label, pts: xy.clone(), color, dashed: false });
        let Some(ci) = self.cert_idx else {
            f.elements.push(Element::Markers { label: String::new(), pts: xy, text: vec![], color });
            return;
        };
        let certified = |x: f64| pts.iter().any(|p| p.params[xi] == x && matches!(p.cells[ci], Cell::Flag(true)));
        let (yes, no): (Vec<_>, Vec<_>) = xy.iter().partition(|(x, _)| certified(*x));
        f.elements.push(Element::Markers { label: String::new(), pts: yes, text: vec![], color });
        if !no.is_empty() {
            let label = if self.grey_labelled { String::new() } else { "not certified".to_string() };
            self.grey_labelled = true;
            f.elements.push(Element::Markers { label, pts: no, text: vec![], color: GREY });
        }
    }
}
