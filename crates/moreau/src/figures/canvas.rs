//! A small figure description (lines, dashed lines, bands, filled polygons, markers) and its
//! rendering with plotters to SVG and PNG. Fonts: [`super::fonts`].
use super::FigureError;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// Colours used by the figures: the Okabe-Ito palette, distinguishable with every common form
/// of colour-vision deficiency (names kept for what they are closest to).
pub const BLUE: RGBColor = RGBColor(0, 114, 178);
pub const ORANGE: RGBColor = RGBColor(230, 159, 0);
pub const GREEN: RGBColor = RGBColor(0, 158, 115);
pub const RED: RGBColor = RGBColor(213, 94, 0);
pub const PURPLE: RGBColor = RGBColor(204, 121, 167);
pub const GREY: RGBColor = RGBColor(110, 110, 110);
/// Colour number `i` of the palette.
pub fn palette(i: usize) -> RGBColor {
    [BLUE, ORANGE, GREEN, RED, PURPLE, GREY][i % 6]
}

/// One thing drawn in a figure.
#[derive(Debug, Clone)]
pub enum Element {
    /// A polyline (`dashed` for reference lines).
    Line { label: String, pts: Vec<(f64, f64)>, color: RGBColor, dashed: bool },
    /// The region between `lo(x)` and `hi(x)`, translucent.
    Band { label: String, x: Vec<f64>, lo: Vec<f64>, hi: Vec<f64>, color: RGBColor },
    /// A filled translucent polygon (closed automatically); `label` empty: no legend entry.
    Polygon { label: String, pts: Vec<(f64, f64)>, color: RGBColor },
    /// Markers with optional text next to each.
    Markers { label: String, pts: Vec<(f64, f64)>, text: Vec<String>, color: RGBColor },
}

impl Element {
    /// The legend label (empty: no legend entry) and the colour.
    pub fn label_and_color(&self) -> (&str, RGBColor) {
        match self {
            Element::Line { label, color, .. }
            | Element::Band { label, color, .. }
            | Element::Polygon { label, color, .. }
            | Element::Markers { label, color, .. } => (label, *color),
        }
    }

    fn points(&self) -> Vec<(f64, f64)> {
        match self {
            Element::Line { pts, .. } | Element::Polygon { pts, .. } | Element::Markers { pts, .. } => pts.clone(),
            Element::Band { x, lo, hi, .. } => {
                x.iter().zip(lo).map(|(&a, &b)| (a, b)).chain(x.iter().zip(hi).map(|(&a, &b)| (a, b))).collect()
            }
        }
    }
}

/// A figure: title, axis labels, elements; `equal_aspect` keeps one unit the same length on
/// both axes (plane curves).
#[derive(Debug, Clone)]
pub struct Figure {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub elements: Vec<Element>,
    pub equal_aspect: bool,
    /// Pixel size. Default `900 x 600`.
    pub size: (u32, u32),
    /// Further panels stacked below this one, sharing its x axis (quantities of different
    /// scales, e.g. a bound near -0.02 and a measured rate near -0.3): each panel keeps its own
    /// y axis, label and legend; only the top panel's title is drawn.
    pub below: Vec<Figure>,
}

impl Figure {
    pub fn new(title: &str, x_label: &str, y_label: &str) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            elements: vec![],
            equal_aspect: false,
            size: (900, 600),
            below: vec![],
        }
    }

    /// Width in pixels of the legend column right of the plot (0 when nothing is labelled):
    /// the legend stands beside the data, never on it.
    pub fn legend_width(&self) -> u32 {
        let chars = self.elements.iter().map(|e| e.label_and_color().0.chars().count()).max().unwrap_or(0);
        if chars == 0 {
            0
        } else {
            (48 + 8 * chars as u32).min(self.size.0 / 3)
        }
    }

    /// This panel and the ones stacked below it, top first.
    pub fn panels(&self) -> Vec<&Figure> {
        std::iter::once(self).chain(self.below.iter()).collect()
    }

    /// The x range shared by all panels (padded, as [`Figure::ranges`]).
    pub fn shared_x_range(&self) -> Option<(f64, f64)> {
        let rs: Vec<(f64, f64)> = self.panels().iter().filter_map(|p| p.ranges().map(|r| r.0)).collect();
        let lo = rs.iter().map(|r| r.0).fold(f64::INFINITY, f64::min);
        let hi = rs.iter().map(|r| r.1).fold(f64::NEG_INFINITY, f64::max);
        (lo <= hi).then_some((lo, hi))
    }

    /// Data ranges with 5 % padding; `None` when nothing is finite.
    pub fn ranges(&self) -> Option<((f64, f64), (f64, f64))> {
        let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
        for e in &self.elements {
            for (x, y) in e.points() {
                if x.is_finite() && y.is_finite() {
                    x0 = x0.min(x);
                    x1 = x1.max(x);
                    y0 = y0.min(y);
                    y1 = y1.max(y);
                }
            }
        }
        if !(x0 <= x1 && y0 <= y1) {
            return None;
        }
        let pad = |a: f64, b: f64| {
            let w = (b - a).max(1e-12 * (1.0 + a.abs().max(b.abs())));
            (a - 0.05 * w, b + 0.05 * w)
        };
        let (mut xr, mut yr) = (pad(x0, x1), pad(y0, y1));
        if self.equal_aspect {
            let (w, h) = (xr.1 - xr.0, yr.1 - yr.0);
            let (pw, ph) = (self.size.0 as f64 - 110.0 - self.legend_width() as f64, self.size.1 as f64 - 110.0);
            let scale = (w / pw).max(h / ph);
            let (cx, cy) = (0.5 * (xr.0 + xr.1), 0.5 * (yr.0 + yr.1));
            xr = (cx - 0.5 * scale * pw, cx + 0.5 * scale * pw);
            yr = (cy - 0.5 * scale * ph, cy + 0.5 * scale * ph);
        }
        Some((xr, yr))
    }
}

/// `text` in runs of (text, is_subscript): `_X` with `X` a single letter or digit (not followed
/// by another) is a subscript, as in `η_T`; `theta_best` keeps its underscore (the rule of
/// [`super::pgf::tex_text`]).
fn rich_runs(text: &str) -> Vec<(String, bool)> {
    let chars: Vec<char> = text.chars().collect();
    let mut runs: Vec<(String, bool)> = vec![];
    let mut i = 0;
    while i < chars.len() {
        let single = chars.get(i + 1).is_some_and(|c| c.is_alphanumeric())
            && !chars.get(i + 2).is_some_and(|c| c.is_alphanumeric());
        if chars[i] == '_' && single {
            runs.push((chars[i + 1].to_string(), true));
            i += 2;
            continue;
        }
        match runs.last_mut() {
            Some((s, false)) => s.push(chars[i]),
            _ => runs.push((chars[i].to_string(), false)),
        }
        i += 1;
    }
    runs
}

/// Width in pixels of the plain string `s` at font size `sz`.
fn text_width<DB: DrawingBackend>(area: &DrawingArea<DB, plotters::coord::Shift>, s: &str, sz: u32) -> i32 {
    area.estimate_text_size(s, &TextStyle::from(("sans-serif", sz).into_font())).map(|(w, _)| w as i32).unwrap_or(0)
}

/// Font size of a run of [`rich_runs`] and its offset across the line (subscripts smaller,
/// set off by 45 % of `size`).
fn run_metrics(size: u32, sub: bool) -> (u32, i32) {
    if sub {
        (size * 7 / 10, (size * 45 / 100) as i32)
    } else {
        (size, 0)
    }
}

/// Width in pixels of `text` drawn by [`draw_rich`] at `size`.
fn rich_width<DB: DrawingBackend>(area: &DrawingArea<DB, plotters::coord::Shift>, text: &str, size: u32) -> i32 {
    rich_runs(text).iter().map(|(s, sub)| text_width(area, s, run_metrics(size, *sub).0)).sum()
}

/// Draws `text` with its top-left at `at` (`vertical`: rotated a quarter turn counter-clockwise,
/// reading upwards as a y-axis label, `at` the bottom-left of the line), subscripts (see
/// [`rich_runs`]) smaller and set off to the reader's "below". Leading blanks of a run are
/// dropped by the backends: their width is skipped instead.
fn draw_rich_runs<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    text: &str,
    at: (i32, i32),
    size: u32,
    vertical: bool,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let mut along = 0;
    for (s, sub) in rich_runs(text) {
        let (sz, off) = run_metrics(size, sub);
        let (w, lead) = (text_width(area, &s, sz), text_width(area, &s, sz) - text_width(area, s.trim_start(), sz));
        let (font, pos) = if vertical {
            let font = ("sans-serif", sz).into_font().transform(FontTransform::Rotate270).color(&BLACK);
            (font, (at.0 + off, at.1 - along - lead))
        } else {
            (("sans-serif", sz).into_font().color(&BLACK), (at.0 + along + lead, at.1 + off))
        };
        area.draw(&Text::new(s.trim_start().to_string(), pos, font))?;
        along += w;
    }
    Ok(())
}

/// Draws `text` with its top-left at `at`, subscripts (see [`rich_runs`]) smaller and lower.
fn draw_rich<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    text: &str,
    at: (i32, i32),
    size: u32,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    draw_rich_runs(area, text, at, size, false)
}

/// Draws `text` rotated a quarter turn counter-clockwise (a y-axis label), centred on `centre`.
fn draw_rich_vertical<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    text: &str,
    centre: (i32, i32),
    size: u32,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let half = rich_width(area, text, size) / 2;
    draw_rich_runs(area, text, (centre.0 - size as i32 / 2, centre.1 + half), size, true)
}

/// Whether `text` has a subscript that is not a digit (those have no Unicode subscript glyph
/// in general, so the axis label is drawn by [`draw_rich`] / [`draw_rich_vertical`]).
fn has_letter_subscript(text: &str) -> bool {
    rich_runs(text).iter().any(|(s, sub)| *sub && !s.chars().all(|c| c.is_ascii_digit()))
}

/// Axis labels drawn by plotters (possibly rotated): `_D` with `D` a digit as the Unicode
/// subscript digit (in the embedded DejaVu font). Labels with letter subscripts are drawn by
/// [`draw_rich`] instead (see [`has_letter_subscript`]).
fn unicode_subscripts(text: &str) -> String {
    rich_runs(text)
        .into_iter()
        .map(|(s, is_sub)| match (is_sub, s.chars().next().and_then(|c| c.to_digit(10))) {
            (true, Some(d)) => char::from_u32(0x2080 + d).map_or(format!("_{s}"), String::from),
            (true, None) => format!("_{s}"),
            (false, _) => s,
        })
        .collect()
}

fn finite(p: &[(f64, f64)]) -> Vec<(f64, f64)> {
    p.iter().copied().filter(|(x, y)| x.is_finite() && y.is_finite()).collect()
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, plotters::coord::Shift>, f: &Figure) -> Result<(), FigureError>
where
    DB::ErrorType: 'static,
{
    let err = |e: &dyn std::fmt::Debug| FigureError::Draw { figure: f.title.clone(), reason: format!("{e:?}") };
    root.fill(&WHITE).map_err(|e| err(&e))?;
    // the title drawn by us (subscripts as subscripts), the panels below it
    let body = if f.title.is_empty() {
        root.clone()
    } else {
        let (top, body) = root.split_vertically(40);
        let (w, _) = top.dim_in_pixel();
        let tw = rich_width(&top, &f.title, 22);
        draw_rich(&top, &f.title, ((w as i32 - tw) / 2, 10), 22).map_err(|e| err(&e))?;
        body
    };
    if f.below.is_empty() {
        draw_panel(&body, f, None)?;
    } else {
        let xr = f.shared_x_range().ok_or_else(|| FigureError::NoData { figure: f.title.clone() })?;
        let panels = f.panels();
        for (area, p) in body.split_evenly((panels.len(), 1)).iter().zip(panels) {
            // an empty panel (no finite data) is left blank rather than failing the figure
            if p.ranges().is_some() {
                draw_panel(area, p, Some(xr))?;
            }
        }
    }
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

/// One panel of `f` in `root`: its own y range, the x range `x_range` when given (stacked
/// panels).
fn draw_panel<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    f: &Figure,
    x_range: Option<(f64, f64)>,
) -> Result<(), FigureError>
where
    DB::ErrorType: 'static,
{
    let err = |e: &dyn std::fmt::Debug| FigureError::Draw { figure: f.title.clone(), reason: format!("{e:?}") };
    let ((x0, x1), (y0, y1)) = f.ranges().ok_or_else(|| FigureError::NoData { figure: f.title.clone() })?;
    let (x0, x1) = x_range.unwrap_or((x0, x1));
    let mut builder = ChartBuilder::on(root);
    let mut chart = builder
        .margin(14)
        .margin_right(14 + f.legend_width())
        .x_label_area_size(48)
        .y_label_area_size(72)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|e| err(&e))?;
    // tick labels with as many decimals as the range needs (and no "-0.0")
    let decimals = |a: f64, b: f64| (2.0 - (b - a).abs().max(1e-300).log10().floor()).clamp(0.0, 12.0) as usize;
    let (dx, dy) = (decimals(x0, x1), decimals(y0, y1));
    let fx = move |v: &f64| format!("{:.*}", dx, if v.abs() < 1e-300 { 0.0 } else { *v });
    let fy = move |v: &f64| {
        let s = format!("{:.*}", dy, v);
        if s.trim_start_matches('-').chars().all(|c| c == '0' || c == '.') {
            s.trim_start_matches('-').to_string()
        } else {
            s
        }
    };
    let fx = move |v: &f64| {
        let s = fx(v);
        if s.trim_start_matches('-').chars().all(|c| c == '0' || c == '.') {
            s.trim_start_matches('-').to_string()
        } else {
            s
        }
    };
    let (rich_x, rich_y) = (has_letter_subscript(&f.x_label), has_letter_subscript(&f.y_label));
    let mut mesh = chart.configure_mesh();
    mesh.x_label_formatter(&fx)
        .y_label_formatter(&fy)
        .label_style(("sans-serif", 15))
        .axis_desc_style(("sans-serif", 17))
        .light_line_style(RGBColor(235, 235, 235));
    if !rich_x {
        mesh.x_desc(unicode_subscripts(&f.x_label));
    }
    if !rich_y {
        mesh.y_desc(unicode_subscripts(&f.y_label));
    }
    mesh.draw().map_err(|e| err(&e))?;
    {
        // axis labels with letter subscripts: drawn by us, as the title and legend are
        let (xr, yr) = chart.plotting_area().get_pixel_range();
        let base = root.get_base_pixel();
        let (left, right) = (xr.start - base.0, xr.end - base.0);
        let (top, bottom) = (yr.start - base.1, yr.end - base.1);
        if rich_x {
            let w = rich_width(root, &f.x_label, 17);
            draw_rich(root, &f.x_label, ((left + right - w) / 2, bottom + 24), 17).map_err(|e| err(&e))?;
        }
        if rich_y {
            draw_rich_vertical(root, &f.y_label, (left - 56, (top + bottom) / 2), 17).map_err(|e| err(&e))?;
        }
    }
    for e in &f.elements {
        match e {
            Element::Band { x, lo, hi, color, .. } => {
                let mut pts: Vec<(f64, f64)> = x.iter().zip(hi).map(|(&a, &b)| (a, b)).collect();
                pts.extend(x.iter().zip(lo).rev().map(|(&a, &b)| (a, b)));
                chart
                    .draw_series(std::iter::once(Polygon::new(finite(&pts), color.mix(0.22).filled())))
                    .map_err(|e| err(&e))?;
            }
            Element::Polygon { pts, color, .. } => {
                chart
                    .draw_series(std::iter::once(Polygon::new(finite(pts), color.mix(0.12).filled())))
                    .map_err(|e| err(&e))?;
            }
            Element::Line { pts, color, dashed, .. } => {
                let style = color.stroke_width(2);
                if *dashed {
                    chart.draw_series(DashedLineSeries::new(finite(pts), 8, 6, style)).map_err(|e| err(&e))?;
                } else {
                    chart.draw_series(LineSeries::new(finite(pts), style)).map_err(|e| err(&e))?;
                }
            }
            Element::Markers { pts, text, color, .. } => {
                chart
                    .draw_series(finite(pts).into_iter().map(|p| Circle::new(p, 5, color.filled())))
                    .map_err(|e| err(&e))?;
                for (p, t) in pts.iter().zip(text) {
                    if p.0.is_finite() && p.1.is_finite() && !t.is_empty() {
                        // text set off above right of the marker (pixels), clear of the curves
                        let label = EmptyElement::at(*p)
                            + Text::new(t.clone(), (6, -22), ("sans-serif", 15).into_font().color(&BLACK));
                        chart.draw_series(std::iter::once(label)).map_err(|e| err(&e))?;
                    }
                }
            }
        }
    }
    // the legend in its own column right of the plot (reserved by `legend_width`), off the data
    let (xr, yr) = chart.plotting_area().get_pixel_range();
    let base = root.get_base_pixel();
    let (lx, mut ly) = (xr.end - base.0 + 12, yr.start - base.1 + 8);
    for e in &f.elements {
        let (label, c) = e.label_and_color();
        if label.is_empty() {
            continue;
        }
        match e {
            Element::Band { .. } | Element::Polygon { .. } => {
                root.draw(&Rectangle::new([(lx, ly - 6), (lx + 22, ly + 6)], c.mix(0.3).filled()))
            }
            Element::Line { dashed: true, .. } => {
                root.draw(&PathElement::new(vec![(lx, ly), (lx + 8, ly)], c.stroke_width(2))).map_err(|e| err(&e))?;
                root.draw(&PathElement::new(vec![(lx + 14, ly), (lx + 22, ly)], c.stroke_width(2)))
            }
            Element::Line { .. } => root.draw(&PathElement::new(vec![(lx, ly), (lx + 22, ly)], c.stroke_width(2))),
            Element::Markers { .. } => root.draw(&Circle::new((lx + 11, ly), 5, c.filled())),
        }
        .map_err(|e| err(&e))?;
        draw_rich(root, label, (lx + 30, ly - 9), 15).map_err(|e| err(&e))?;
        ly += 22;
    }
    Ok(())
}

/// The figure as an SVG document.
pub fn to_svg(f: &Figure) -> Result<String, FigureError> {
    super::fonts::register_fonts();
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, f.size).into_drawing_area();
        draw(root, f)?;
    }
    Ok(super::fonts::embed_font(buf))
}

/// `svg` (the figure's, from [`to_svg`]) parsed for rasterising or PDF conversion, with the
/// embedded DejaVu Sans as its only font (the same glyphs as the PNG and the SVG; the font
/// database is built once per process).
fn usvg_tree(f: &Figure, svg: &str) -> Result<svg2pdf::usvg::Tree, FigureError> {
    use std::sync::{Arc, OnceLock};
    static FONTS: OnceLock<Arc<svg2pdf::usvg::fontdb::Database>> = OnceLock::new();
    let fonts = FONTS.get_or_init(|| {
        let mut db = svg2pdf::usvg::fontdb::Database::new();
        db.load_font_data(dejavu::sans::regular().to_vec());
        Arc::new(db)
    });
    let opt = svg2pdf::usvg::Options { fontdb: fonts.clone(), font_family: "DejaVu Sans".into(), ..Default::default() };
    svg2pdf::usvg::Tree::from_str(svg, &opt)
        .map_err(|e| FigureError::Draw { figure: f.title.clone(), reason: format!("SVG not readable: {e}") })
}

/// The figure as a one-page vector PDF (text as text in the embedded, subset DejaVu Sans), from
/// its SVG by `svg2pdf`.
pub fn to_pdf(f: &Figure) -> Result<Vec<u8>, FigureError> {
    pdf_of(f, &usvg_tree(f, &to_svg(f)?)?)
}

fn pdf_of(f: &Figure, tree: &svg2pdf::usvg::Tree) -> Result<Vec<u8>, FigureError> {
    svg2pdf::to_pdf(tree, svg2pdf::ConversionOptions::default(), svg2pdf::PageOptions::default())
        .map_err(|e| FigureError::Draw { figure: f.title.clone(), reason: format!("PDF conversion: {e}") })
}

/// The figure as PNG bytes at `dpi` dots per inch: its SVG rasterised by `resvg` at scale
/// `dpi / 96` (CSS pixels are 1/96 inch), so every size (text, lines, margins) scales together.
pub fn to_png_at_dpi(f: &Figure, dpi: f64) -> Result<Vec<u8>, FigureError> {
    check_dpi(f, dpi)?;
    png_of(f, &usvg_tree(f, &to_svg(f)?)?, dpi)
}

/// The pixel size of `f` at `dpi`, or the error naming the value.
fn check_dpi(f: &Figure, dpi: f64) -> Result<(u32, u32), FigureError> {
    png_size(f.size, dpi).map_err(|reason| FigureError::Draw { figure: f.title.clone(), reason })
}

/// Pixel size of a PNG of a figure of `size` CSS pixels at `dpi`, or why it is refused
/// (checked by `figure` before any work, and by the writer).
pub fn png_size(size: (u32, u32), dpi: f64) -> Result<(u32, u32), String> {
    let scale = dpi / 96.0;
    let (w, h) = ((size.0 as f64 * scale).round(), (size.1 as f64 * scale).round());
    if !(scale.is_finite() && scale > 0.0 && w >= 1.0 && h >= 1.0 && w * h <= 1e8) {
        return Err(format!("--dpi {dpi} gives a {w} x {h} pixel image (at most 1e8 pixels; dpi must be positive)"));
    }
    Ok((w as u32, h as u32))
}

fn png_of(f: &Figure, tree: &svg2pdf::usvg::Tree, dpi: f64) -> Result<Vec<u8>, FigureError> {
    use svg2pdf::usvg::tiny_skia_path::Transform;
    let bad = |reason: String| FigureError::Draw { figure: f.title.clone(), reason };
    let (w, h) = check_dpi(f, dpi)?;
    let scale = (dpi / 96.0) as f32;
    let mut pixmap = resvg::tiny_skia::Pixmap::new(w, h).ok_or_else(|| bad("empty image".into()))?;
    pixmap.fill(resvg::tiny_skia::Color::WHITE);
    resvg::render(tree, Transform::from_scale(scale, scale), &mut pixmap.as_mut());
    pixmap.encode_png().map_err(|e| bad(format!("PNG encoding: {e}")))
}

/// Writes the figure as PNG to `path`.
pub fn write_png(f: &Figure, path: &Path) -> Result<(), FigureError> {
    super::fonts::register_fonts();
    let root = BitMapBackend::new(path, f.size).into_drawing_area();
    draw(root, f)
}

/// Output formats of [`write_figure_as`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// SVG with the DejaVu font embedded.
    Svg,
    /// PNG (`size` pixels).
    Png,
    /// pgfplots code (`.tex`) and its data (`.csv`), set in the paper's fonts by LaTeX.
    Pgf,
    /// One-page vector PDF (font embedded).
    Pdf,
}

/// Writes `stem.svg`, `stem.png`, `stem.tex` (pgfplots) and `stem.csv` (data) for every
/// `(stem, figure)` into `out`, all or none.
pub fn write_figure(figs: &[(String, Figure)], out: &Path) -> Result<Vec<PathBuf>, FigureError> {
    write_figure_as(figs, out, &[Format::Svg, Format::Png, Format::Pgf])
}

/// [`write_figure`] for the chosen formats only.
pub fn write_figure_as(figs: &[(String, Figure)], out: &Path, formats: &[Format]) -> Result<Vec<PathBuf>, FigureError> {
    write_figure_with(figs, out, formats, None)
}

/// [`write_figure_as`] with the PNG rasterised from the SVG at `png_dpi` when given
/// ([`to_png_at_dpi`]; plotters' own bitmap at `size` pixels otherwise).
pub fn write_figure_with(
    figs: &[(String, Figure)],
    out: &Path,
    formats: &[Format],
    png_dpi: Option<f64>,
) -> Result<Vec<PathBuf>, FigureError> {
    let werr =
        |p: &Path, e: &dyn std::fmt::Display| FigureError::Write { path: p.to_path_buf(), reason: e.to_string() };
    let staged = crate::output::StagedDir::new(out).map_err(|e| werr(out, &e))?;
    let mut files = vec![];
    let png_dpi = png_dpi.filter(|_| formats.contains(&Format::Png));
    for (stem, f) in figs {
        if let Some(dpi) = png_dpi {
            check_dpi(f, dpi)?; // before any drawing: a bad value costs nothing
        }
        // the SVG is drawn once and parsed once for every format made from it
        let svg = (formats.contains(&Format::Svg) || formats.contains(&Format::Pdf) || png_dpi.is_some())
            .then(|| to_svg(f))
            .transpose()?;
        let tree = match &svg {
            Some(svg) if formats.contains(&Format::Pdf) || png_dpi.is_some() => Some(usvg_tree(f, svg)?),
            _ => None,
        };
        if let (true, Some(svg)) = (formats.contains(&Format::Svg), &svg) {
            let p = staged.path(&format!("{stem}.svg"));
            std::fs::write(&p, svg).map_err(|e| werr(&p, &e))?;
            files.push(out.join(format!("{stem}.svg")));
        }
        if formats.contains(&Format::Png) {
            let p = staged.path(&format!("{stem}.png"));
            match (png_dpi, &tree) {
                (Some(dpi), Some(tree)) => std::fs::write(&p, png_of(f, tree, dpi)?).map_err(|e| werr(&p, &e))?,
                _ => write_png(f, &p)?,
            }
            files.push(out.join(format!("{stem}.png")));
        }
        if let (true, Some(tree)) = (formats.contains(&Format::Pdf), &tree) {
            let p = staged.path(&format!("{stem}.pdf"));
            std::fs::write(&p, pdf_of(f, tree)?).map_err(|e| werr(&p, &e))?;
            files.push(out.join(format!("{stem}.pdf")));
        }
        if formats.contains(&Format::Pgf) {
            for (ext, text) in [("tex", super::pgf::to_pgf(f)), ("csv", super::pgf::to_csv(f))] {
                let p = staged.path(&format!("{stem}.{ext}"));
                std::fs::write(&p, text).map_err(|e| werr(&p, &e))?;
                files.push(out.join(format!("{stem}.{ext}")));
            }
        }
    }
    staged.commit().map_err(|e| werr(out, &e))?;
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn figure(x_label: &str, y_label: &str) -> Figure {
        let mut f = Figure::new("t", x_label, y_label);
        let pts = (0..20).map(|k| (k as f64, (k as f64 * 0.3).sin())).collect();
        f.elements.push(Element::Line { label: "a".into(), pts, color: BLUE, dashed: false });
        f
    }

    /// The trimmed contents of the SVG's text elements.
    fn svg_texts(svg: &str) -> Vec<String> {
        svg.split("<text")
            .skip(1)
            .filter_map(|t| Some(t.split_once('>')?.1.split_once("</text>")?.0.trim().to_string()))
            .collect()
    }

    #[test]
    fn letter_subscripts_in_axis_labels_are_drawn_as_subscripts() {
        assert!(has_letter_subscript("η_T (s)"));
        assert!(!has_letter_subscript("η_1, z_1"));
        assert!(!has_letter_subscript("theta_best"));
        let svg = to_svg(&figure("η_T (s)", "γ_k")).unwrap();
        // the label's parts are drawn as separate texts, the underscore never
        assert!(!svg.contains("η_T") && !svg.contains("γ_k"), "literal underscore left in an axis label");
        let texts = svg_texts(&svg);
        assert!(texts.iter().any(|t| t == "T") && texts.iter().any(|t| t == "(s)"), "x label parts missing: {texts:?}");
        assert!(texts.iter().any(|t| t == "k"), "y label subscript missing: {texts:?}");
        // negative control: a multi-letter suffix keeps its underscore (not a subscript)
        let svg = to_svg(&figure("t", "theta_best")).unwrap();
        assert!(svg.contains("theta_best"));
    }

    #[test]
    fn digit_subscripts_in_axis_labels_become_unicode_subscripts() {
        let svg = to_svg(&figure("η_1", "z_2")).unwrap();
        assert!(svg.contains("η₁") && svg.contains("z₂"));
    }
}
