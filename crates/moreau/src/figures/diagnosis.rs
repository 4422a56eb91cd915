//! The figures of a diagnosis report (`moreau diagnose`, output 1): measured against nominal
//! and fitted, the residuals with their located windows shaded, and zooms into the top
//! windows, each a stack of panels sharing the time axis.
use super::canvas::{self, Element, Figure, SizePreset};
use discovery::Report;
use plotters::style::RGBColor;

/// At most about `max` points of a series for figures of long records: per bucket its first,
/// smallest and largest sample in time order, so spikes survive the thinning.
fn thin(t: &[f64], v: &[f64], max: usize) -> Vec<(f64, f64)> {
    let n = t.len().min(v.len());
    let step = (3 * n / max.max(3)).max(1);
    if step <= 3 {
        return t.iter().zip(v).map(|(&a, &b)| (a, b)).collect();
    }
    let mut out = Vec::with_capacity(max + 3);
    for lo in (0..n).step_by(step) {
        let hi = (lo + step).min(n);
        let (mut kmin, mut kmax) = (lo, lo);
        for k in lo..hi {
            if !v[k].is_finite() {
                continue;
            }
            if v[k] < v[kmin] || !v[kmin].is_finite() {
                kmin = k;
            }
            if v[k] > v[kmax] || !v[kmax].is_finite() {
                kmax = k;
            }
        }
        let mut ks = vec![lo, kmin, kmax];
        ks.sort_unstable();
        ks.dedup();
        out.extend(ks.into_iter().map(|k| (t[k], v[k])));
    }
    out
}

/// The report's time series for output 1, as figures draw them.
struct Curves {
    t: Vec<f64>,
    y: Vec<f64>,
    nominal: Vec<f64>,
    fitted: Vec<f64>,
    v: Vec<f64>,
    v_nominal: Vec<f64>,
    v_fitted: Vec<f64>,
}

impl Curves {
    fn of(r: &Report) -> Self {
        let s = &r.series;
        let p = s.p.max(1);
        let col = |v: &[f64]| -> Vec<f64> { v.iter().step_by(p).copied().collect() };
        let (y, nominal, fitted) = (col(&s.y), col(&s.yhat_nominal), col(&s.yhat_fitted));
        // the derived velocity; its first and last 3 samples (where the filter is cut) left out
        let vel = |a: &[f64]| {
            let mut v = discovery::metrics::velocity(a, r.dt);
            let n = v.len();
            for k in (0..3.min(n)).chain(n.saturating_sub(3)..n) {
                v[k] = f64::NAN;
            }
            v
        };
        Self { t: s.t.clone(), v: vel(&y), v_nominal: vel(&nominal), v_fitted: vel(&fitted), y, nominal, fitted }
    }
}

fn diff(a: &[f64], b: &[f64]) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x - y).collect()
}

/// Largest finite `|x|` over several series restricted to `[k0, k1)`.
fn max_abs(series: &[&[f64]], k0: usize, k1: usize) -> f64 {
    series
        .iter()
        .flat_map(|s| s[k0..k1.min(s.len())].iter())
        .filter(|x| x.is_finite())
        .fold(0.0f64, |m, x| m.max(x.abs()))
}

/// A panel: the `(label, data, colour, dashed)` curves on `[k0, k1)` in `unit` (with an SI
/// prefix or power of ten chosen for the data, [`discovery::metrics::axis_scale`]), the
/// intervals `shade` translucent (first one labelled `shade_label`) and a dashed vertical
/// line at `mark` (labelled).
#[allow(clippy::too_many_arguments)]
fn panel(
    name: &str,
    unit: &str,
    t: &[f64],
    k: (usize, usize),
    curves: &[(&str, &[f64], RGBColor, bool)],
    shade: &[(f64, f64)],
    shade_label: &str,
    mark: Option<(f64, &str)>,
    max_points: usize,
) -> Figure {
    let (k0, k1) = k;
    let data: Vec<&[f64]> = curves.iter().map(|c| c.1).collect();
    let (div, u) = discovery::metrics::axis_scale(max_abs(&data, k0, k1), unit);
    let label = if u.is_empty() { name.to_string() } else { format!("{name} ({u})") };
    let mut f = Figure::new("", "t (s)", &label);
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let scaled: Vec<Vec<f64>> = data.iter().map(|d| d[k0..k1].iter().map(|x| x / div).collect()).collect();
    for v in scaled.iter().flatten().filter(|x| x.is_finite()) {
        lo = lo.min(*v);
        hi = hi.max(*v);
    }
    if lo > hi {
        (lo, hi) = (-1.0, 1.0);
    }
    let (ta, tb) = (t[k0], t[k1 - 1]);
    for (i, &(a, b)) in shade.iter().enumerate() {
        let (a, b) = (a.max(ta), b.min(tb));
        if a <= b {
            f.elements.push(Element::Polygon {
                label: if i == 0 { shade_label.into() } else { String::new() },
                pts: vec![(a, lo), (b, lo), (b, hi), (a, hi)],
                color: canvas::PURPLE,
            });
        }
    }
    if let Some((tm, l)) = mark.filter(|m| m.0 >= ta && m.0 <= tb) {
        f.elements.push(Element::Line {
            label: l.into(),
            pts: vec![(tm, lo), (tm, hi)],
            color: canvas::GREY,
            dashed: true,
        });
    }
    for ((label, _, color, dashed), v) in curves.iter().zip(&scaled) {
        f.elements.push(Element::Line {
            label: (*label).into(),
            pts: thin(&t[k0..k1], v, max_points),
            color: *color,
            dashed: *dashed,
        });
    }
    f
}

/// Okabe-Ito black for the recording.
const MEASURED: RGBColor = RGBColor(0, 0, 0);

/// The figures of a report (output 1), each measured against nominal (orange, dashed) and
/// fitted (blue), located windows shaded, units from the model file's `[signals] y`:
/// - `fit`: the record and the residual, validation start marked;
/// - `residual`: the position and the derived velocity residual, each with its windows;
/// - `zoom-1` .. `zoom-3`: the top located windows with context (record, residual, velocity
///   residual).
///
/// At their own sizes (1200 x 760 and 1100 x 900); [`figures_sized`] for a paper's column.
pub fn figures(r: &Report) -> Vec<(String, Figure)> {
    figures_sized(r, None)
}

/// Height in points of a stack of `panels` panels at the width of `preset` (`moreau diagnose
/// --size`): each panel two thirds of the preset's height (its own y axis, tick labels and
/// legend rows; the x axis once, under the bottom one), so the text stays 8-9 pt and the panels
/// readable: `column` 252 x 288 (2 panels) and 252 x 432 (3), `two-column` 515 x 344 and 515 x 516.
pub fn stack_size(preset: SizePreset, panels: usize) -> (u32, u32) {
    let (w, h) = preset.size();
    (w, 2 * h * panels as u32 / 3)
}

/// [`figures`] at the width of a paper's column (`None`: their own sizes), see [`stack_size`].
pub fn figures_sized(r: &Report, preset: Option<SizePreset>) -> Vec<(String, Figure)> {
    let c = Curves::of(r);
    let n = c.t.len();
    if n < 2 {
        return vec![];
    }
    let panels = Panels::of(r, &c);
    let pw: Vec<(f64, f64)> = r.windows.iter().map(|w| (w.t_start, w.t_end)).collect();
    let vw: Vec<(f64, f64)> = r.velocity_windows.iter().map(|w| (w.t_start, w.t_end)).collect();
    let sel = r.selected();
    let all = (0, n);
    let mut out = vec![
        (
            "fit".to_string(),
            stack(
                preset,
                format!("Measured vs nominal vs fitted (output 1): {sel}"),
                vec![panels.record(all, &pw, 4000), panels.residual(all, &pw, 4000)],
                (1200, 760),
            ),
        ),
        (
            "residual".to_string(),
            stack(
                preset,
                "Residuals (output 1), each with its located windows shaded".to_string(),
                vec![panels.residual(all, &pw, 4000), panels.velocity_residual(all, &vw, 4000)],
                (1200, 760),
            ),
        ),
    ];
    for (i, (w, what)) in zoom_windows(r).into_iter().take(3).enumerate() {
        if let Some(f) = zoom(r, &c, &panels, preset, i, w, what) {
            out.push((format!("zoom-{}", i + 1), f));
        }
    }
    out
}

/// The panels of the diagnosis figures (record, residual, velocity residual) with the data
/// they share: output 1's curves and residuals, its units and the validation mark.
struct Panels<'c> {
    c: &'c Curves,
    unit: String,
    vunit: String,
    /// Residuals of the nominal and fitted models, of the output and of its derived velocity.
    en: Vec<f64>,
    ef: Vec<f64>,
    ven: Vec<f64>,
    vef: Vec<f64>,
    fitted_label: String,
    validation: Option<(f64, &'static str)>,
}

const NOMINAL_COLOUR: RGBColor = canvas::ORANGE;
const FITTED_COLOUR: RGBColor = canvas::BLUE;

impl<'c> Panels<'c> {
    fn of(r: &Report, c: &'c Curves) -> Self {
        let unit = r.units.first().cloned().unwrap_or_default();
        let vunit = if unit.is_empty() { String::new() } else { discovery::metrics::per_second(&unit) };
        Panels {
            c,
            en: diff(&c.y, &c.nominal),
            ef: diff(&c.y, &c.fitted),
            ven: diff(&c.v, &c.v_nominal),
            vef: diff(&c.v, &c.v_fitted),
            unit,
            vunit,
            fitted_label: format!("fitted ({})", r.selected()),
            validation: Some((r.validation_segment[0], "validation from here")),
        }
    }

    /// Measured, nominal and fitted output over samples `k`, windows `shade` shaded.
    fn record(&self, k: (usize, usize), shade: &[(f64, f64)], max: usize) -> Figure {
        let c = self.c;
        let curves = [
            ("measured", &c.y[..], MEASURED, false),
            ("nominal", &c.nominal[..], NOMINAL_COLOUR, true),
            (&self.fitted_label[..], &c.fitted[..], FITTED_COLOUR, false),
        ];
        self.panel("y", &self.unit, k, &curves, shade, max)
    }

    /// The nominal and fitted models' output residuals.
    fn residual(&self, k: (usize, usize), shade: &[(f64, f64)], max: usize) -> Figure {
        let curves = [("nominal", &self.en[..], NOMINAL_COLOUR, true), ("fitted", &self.ef[..], FITTED_COLOUR, false)];
        self.panel("residual y − ŷ", &self.unit, k, &curves, shade, max)
    }

    /// The nominal and fitted models' residuals of the derived velocity.
    fn velocity_residual(&self, k: (usize, usize), shade: &[(f64, f64)], max: usize) -> Figure {
        let curves =
            [("nominal", &self.ven[..], NOMINAL_COLOUR, true), ("fitted", &self.vef[..], FITTED_COLOUR, false)];
        self.panel("velocity residual", &self.vunit, k, &curves, shade, max)
    }

    fn panel(
        &self,
        name: &str,
        unit: &str,
        k: (usize, usize),
        curves: &[(&str, &[f64], RGBColor, bool)],
        shade: &[(f64, f64)],
        max: usize,
    ) -> Figure {
        panel(name, unit, &self.c.t, k, curves, shade, "located window", self.validation, max)
    }
}

/// Panels stacked under the first, which carries `title`; all at `size`, or at the preset's
/// stack size.
fn stack(preset: Option<SizePreset>, title: String, mut panels: Vec<Figure>, size: (u32, u32)) -> Figure {
    let size = preset.map_or(size, |p| stack_size(p, panels.len()));
    let mut top = panels.remove(0);
    top.title = title;
    top.size = size;
    for p in &mut panels {
        p.size = size;
    }
    top.below = panels;
    top
}

/// The located windows to zoom into: position windows first, then velocity windows that
/// overlap none.
fn zoom_windows(r: &Report) -> Vec<(&discovery::localise::Window, &'static str)> {
    let mut zooms: Vec<(&discovery::localise::Window, &str)> = r.windows.iter().map(|w| (w, "position")).collect();
    for w in &r.velocity_windows {
        if !zooms.iter().any(|(z, _)| w.t_start <= z.t_end && z.t_start <= w.t_end) {
            zooms.push((w, "velocity"));
        }
    }
    zooms
}

/// The `i`-th zoom: window `w` (of the `what` residual) padded by three quarters of its width
/// (at least 25 samples) on each side; `None` where fewer than 2 samples fall in it.
fn zoom(
    r: &Report,
    c: &Curves,
    panels: &Panels,
    preset: Option<SizePreset>,
    i: usize,
    w: &discovery::localise::Window,
    what: &str,
) -> Option<Figure> {
    let n = c.t.len();
    let k_of = |t: f64| c.t.partition_point(|x| *x < t).min(n - 1);
    let width = (w.t_end - w.t_start).max(r.dt);
    let pad = (0.75 * width).max(25.0 * r.dt);
    let (k0, k1) = (k_of(w.t_start - pad), (k_of(w.t_end + pad) + 1).min(n));
    if k1 < k0 + 2 {
        return None;
    }
    let shade = [(w.t_start, w.t_end)];
    let title = format!(
        "Window {}: t = {:.3} - {:.3} s, {:.0} % of the {what} residual energy in {:.1} % of the time{}",
        i + 1,
        w.t_start,
        w.t_end,
        100.0 * w.share_energy,
        100.0 * w.share_time,
        if w.dominant_regime == "none" { String::new() } else { format!(" ({})", w.dominant_regime) }
    );
    let k = (k0, k1);
    Some(stack(
        preset,
        title,
        vec![
            panels.record(k, &shade, 3000),
            panels.residual(k, &shade, 3000),
            panels.velocity_residual(k, &shade, 3000),
        ],
        (1100, 900),
    ))
}
