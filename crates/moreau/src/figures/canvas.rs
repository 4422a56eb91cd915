//! A small figure description (lines, dashed lines, bands, filled polygons, markers) and its
//! rendering with plotters to SVG (PNG and PDF are made from the SVG). Fonts: [`super::fonts`].
//!
//! Layout: sizes are points ([`SizePreset`] for one and two journal columns); the text is 8-9 pt
//! at column width and scales up to the 900 x 600 default; the legend stands in rows below the
//! axes; tick counts, label lines and the legend are fitted to the measured text (the embedded
//! DejaVu Sans), so no text overlaps another or leaves the page, which [`text_boxes`] and
//! [`layout_defects`] check on the rendered SVG (tests/figure_layout.rs).
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

/// Figure sizes for papers in points (one SVG unit is one point in the PDF; a PNG at `--dpi`
/// scales them): one column (3.5 in = 252 pt) and two columns (7.16 in = 515.5 pt, 515 to stay
/// inside) of a two-column journal page. At these sizes the text is 8-9 pt.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SizePreset {
    /// 252 x 216 pt (3.5 x 3 in).
    Column,
    /// 515 x 258 pt (7.16 x 3.58 in).
    TwoColumn,
}

impl SizePreset {
    /// Width and height in points.
    pub fn size(self) -> (u32, u32) {
        match self {
            SizePreset::Column => (252, 216),
            SizePreset::TwoColumn => (515, 258),
        }
    }
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
    /// Size in points (SVG units; the PDF page; PNG pixels at 96 dpi). Default `900 x 600`;
    /// [`SizePreset`] for column widths.
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

    /// Data ranges with 5 % padding; `None` when nothing is finite. With `equal_aspect`, for a
    /// plot area about the figure's size less 110 pixels each way ([`Figure::ranges_in`]).
    pub fn ranges(&self) -> Option<((f64, f64), (f64, f64))> {
        self.ranges_in((self.size.0 as f64 - 110.0).max(10.0), (self.size.1 as f64 - 110.0).max(10.0))
    }

    /// [`Figure::ranges`] for a plot area of `pw x ph` pixels (which `equal_aspect` fills).
    pub fn ranges_in(&self, pw: f64, ph: f64) -> Option<((f64, f64), (f64, f64))> {
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
            let scale = (w / pw).max(h / ph);
            let (cx, cy) = (0.5 * (xr.0 + xr.1), 0.5 * (yr.0 + yr.1));
            xr = (cx - 0.5 * scale * pw, cx + 0.5 * scale * pw);
            yr = (cy - 0.5 * scale * ph, cy + 0.5 * scale * ph);
        }
        Some((xr, yr))
    }
}

/// Text sizes (plotters' font sizes: the SVG's font-size is `size / 1.24`, so 11 is 8.9 pt and
/// 10 is 8.1 pt) and spacings (pixels) of a figure of `size`: those of a 900 x 600 figure,
/// scaled down with the figure but never below 8-9 pt text, so a column-width figure printed
/// at its size has 8-9 pt text.
#[derive(Debug, Clone, Copy)]
struct Style {
    title: u32,
    label: u32,
    tick: u32,
    legend: u32,
    gap: i32,
    tick_mark: i32,
    line: u32,
    marker: u32,
}

/// Drawing units per point: figures are drawn at 4 times their size and the SVG's `viewBox`
/// scales them back, so curves are placed to a quarter point (plotters draws on whole units).
const SUPERSAMPLE: u32 = 4;

impl Style {
    /// The style of a figure of `size` points.
    fn of(size: (u32, u32)) -> Self {
        let k = (size.0 as f64 / 900.0).min(size.1 as f64 / 600.0).min(1.0);
        // a figure no wider than two journal columns is printed at its size, however tall (a
        // stack of panels, `moreau diagnose --size`): its text stays at the 8-9 pt floor
        let k = if size.0 <= SizePreset::TwoColumn.size().0 { k.min(0.5) } else { k };
        let s = |big: f64, least: f64| (big * k).max(least).round() * SUPERSAMPLE as f64;
        Style {
            title: s(22.0, 11.0) as u32,
            label: s(17.0, 11.0) as u32,
            tick: s(15.0, 10.0) as u32,
            legend: s(15.0, 10.0) as u32,
            gap: s(10.0, 4.0) as i32,
            tick_mark: s(5.0, 3.0) as i32,
            line: s(2.0, 1.0) as u32,
            marker: s(5.0, 3.0) as u32,
        }
    }
}

/// DejaVu Sans: the line (ascent 1901 + descent 483 units) per em (2048 units); plotters' width
/// estimates (ab_glyph) are per line height, the SVG's font-size is per em.
const LINE_PER_EM: f64 = 2384.0 / 2048.0;
/// Font size in the SVG of plotters' size 1.
const EM_PER_SIZE: f64 = 1.0 / 1.24;
/// A text line drawn with its anchor's top at `y` (plotters' `VPos::Top`, baseline at
/// `y + 0.76 em`) spans `[y - ABOVE * size, y + BELOW * size]`, and a subscript reaches to
/// `y + BELOW_SUB * size`; drawn lines are placed with [`ABOVE`] and [`line_h`].
const ABOVE: f64 = (1901.0 / 2048.0 - 0.76) * EM_PER_SIZE;
const BELOW_SUB: f64 = 0.45 + 0.7 * (0.76 + 483.0 / 2048.0) * EM_PER_SIZE;

/// Height of a line of rich text (with subscripts) at `size`, rounded up.
fn line_h(size: u32) -> i32 {
    ((ABOVE + BELOW_SUB) * size as f64).ceil() as i32
}

/// Offset from the top of a line's box to its plotters anchor (top-left text at `size`).
fn above(size: u32) -> i32 {
    (ABOVE * size as f64).ceil() as i32
}

/// Width of the plain string `s` at plotters' size `sz` as the SVG (and the PNG and PDF made from
/// it) renders it: plotters' estimate at 64 times the size (whole pixels there), rescaled from
/// line height to em.
fn text_w(s: &str, sz: u32) -> f64 {
    let font = ("sans-serif", 64.0 * sz as f64).into_font();
    let w = font.box_size(s).map(|(w, _)| w as f64).unwrap_or(0.6 * 64.0 * sz as f64 * s.chars().count() as f64);
    w / 64.0 * LINE_PER_EM * EM_PER_SIZE
}

/// Greek letters and symbols of TeX (`\delta` -> `δ`, [`super::tex_symbols`]), a degree sign
/// and the spaces.
fn tex_symbol(name: &str) -> Option<&'static str> {
    match name {
        "circ" => Some("°"),
        "," | ";" | " " | "quad" => Some(" "),
        _ => super::tex_symbols::symbol(name),
    }
}

/// A label as the figures draw it: TeX math (`$...$`, as a sweep spec's `label` writes it:
/// `$\delta$ (m)`) to Unicode (`δ (m)`), Greek commands to letters, `\mathrm{..}` and braces
/// dropped but `_{..}` kept as a subscript ([`rich_runs`]), `-` in math to U+2212; text outside
/// math unchanged. Labels without `$` are returned as they are.
pub fn display_text(s: &str) -> String {
    if !s.contains('$') {
        return s.to_string();
    }
    let mut out = String::new();
    for (i, seg) in s.split('$').enumerate() {
        if i % 2 == 0 {
            out.push_str(seg);
            continue;
        }
        let c: Vec<char> = seg.chars().collect();
        let mut k = 0;
        let mut depth_sub: Vec<bool> = vec![];
        while k < c.len() {
            match c[k] {
                '\\' => {
                    let mut j = k + 1;
                    while j < c.len() && c[j].is_ascii_alphabetic() {
                        j += 1;
                    }
                    if j == k + 1 && j < c.len() {
                        j += 1; // `\,` and other one-character commands
                    }
                    let name: String = c[k + 1..j].iter().collect();
                    match tex_symbol(&name) {
                        Some(u) => out.push_str(u),
                        None if matches!(name.as_str(), "mathrm" | "text" | "mathit" | "mathbf" | "operatorname") => {}
                        None => out.push_str(&name),
                    }
                    k = j;
                    continue;
                }
                '_' if c.get(k + 1) == Some(&'{') => {
                    out.push_str("_{");
                    depth_sub.push(true);
                    k += 2;
                    continue;
                }
                '{' => depth_sub.push(false),
                '}' => {
                    if depth_sub.pop() == Some(true) {
                        out.push('}');
                    }
                }
                '-' => out.push('\u{2212}'),
                '^' => {
                    // superscript digits and minus; other exponents stay as `^x`
                    let (body, next) = match c.get(k + 1) {
                        Some('{') => {
                            let end = c[k + 2..].iter().position(|&x| x == '}').map_or(c.len(), |e| k + 2 + e);
                            (c[k + 2..end].iter().collect::<String>(), (end + 1).min(c.len()))
                        }
                        Some(&x) => (x.to_string(), k + 2),
                        None => (String::new(), k + 1),
                    };
                    let sup: Option<String> = body
                        .chars()
                        .map(|x| match x {
                            '0' => Some('⁰'),
                            '1' => Some('¹'),
                            '2' => Some('²'),
                            '3' => Some('³'),
                            '4'..='9' => char::from_u32(0x2070 + x.to_digit(10).unwrap_or(0)),
                            '-' => Some('⁻'),
                            _ => None,
                        })
                        .collect();
                    match sup {
                        Some(s) if !s.is_empty() => out.push_str(&s),
                        _ => {
                            out.push('^');
                            out.push_str(&body);
                        }
                    }
                    k = next;
                    continue;
                }
                x => out.push(x),
            }
            k += 1;
        }
    }
    out
}

/// A number as figures print it: as written when that is short (`10`, `-2.25`), otherwise 4
/// significant digits ([`crate::sweep::table::sig`]); minus as U+2212.
pub fn num_text(x: f64) -> String {
    let short = format!("{x}");
    let s = if short.len() <= 6 { short } else { crate::sweep::table::sig(x, 4, false) };
    s.replace('-', "\u{2212}")
}

/// `text` in runs of (text, is_subscript): `_X` with `X` a single letter, digit or `∞` (not
/// followed by a letter or digit) is a subscript, as in `η_T`, `Ξ_∞`; `_{eng}` subscripts a
/// group, as in `θ_{eng}`; `theta_best` keeps its underscore (the rule of
/// [`super::pgf::tex_text`]). Digit subscripts become Unicode subscript digits in plain runs.
fn rich_runs(text: &str) -> Vec<(String, bool)> {
    let chars: Vec<char> = text.chars().collect();
    let mut runs: Vec<(String, bool)> = vec![];
    let mut i = 0;
    let word = |c: &char| c.is_alphanumeric();
    while i < chars.len() {
        if chars[i] == '_' && chars.get(i + 1) == Some(&'{') {
            if let Some(end) = chars[i + 2..].iter().position(|&c| c == '}') {
                runs.push((chars[i + 2..i + 2 + end].iter().collect(), true));
                i += end + 3;
                continue;
            }
        }
        let single = chars.get(i + 1).is_some_and(|c| word(c) || *c == '∞') && !chars.get(i + 2).is_some_and(word);
        if chars[i] == '_' && single {
            let c = chars[i + 1];
            match c.to_digit(10).and_then(|d| char::from_u32(0x2080 + d)) {
                // a digit: the Unicode subscript digit, in the plain run
                Some(u) => match runs.last_mut() {
                    Some((s, false)) => s.push(u),
                    _ => runs.push((u.to_string(), false)),
                },
                None => runs.push((c.to_string(), true)),
            }
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

/// Font size of a run of [`rich_runs`] and its offset across the line (subscripts smaller,
/// set off by 45 % of `size`).
fn run_metrics(size: u32, sub: bool) -> (u32, i32) {
    if sub {
        (size * 7 / 10, (size * 45 / 100) as i32)
    } else {
        (size, 0)
    }
}

/// Width of `text` drawn by [`draw_rich`] at `size` (the label converted by [`display_text`]).
fn rich_width(text: &str, size: u32) -> i32 {
    let w: f64 = rich_runs(&display_text(text)).iter().map(|(s, sub)| text_w(s, run_metrics(size, *sub).0)).sum();
    w.ceil() as i32
}

/// Draws `text` (converted by [`display_text`]) with its anchor's top-left at `at`
/// (`vertical`: rotated a quarter turn counter-clockwise, reading upwards as a y-axis label,
/// `at` the bottom-left of the line), subscripts (see [`rich_runs`]) smaller and set off to the
/// reader's "below". Leading blanks of a run are dropped by the backends: their width is
/// skipped instead.
fn draw_rich_runs<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    text: &str,
    at: (i32, i32),
    size: u32,
    vertical: bool,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    // each run starts on a whole pixel at or after the end of the previous one
    let mut along = 0.0;
    for (s, sub) in rich_runs(&display_text(text)) {
        let (sz, off) = run_metrics(size, sub);
        let (w, lead) = (text_w(&s, sz), text_w(&s, sz) - text_w(s.trim_start(), sz));
        let skip = (along + lead).ceil() as i32;
        let w = w - lead + skip as f64 - along;
        let (font, pos) = if vertical {
            let font = ("sans-serif", sz).into_font().transform(FontTransform::Rotate270).color(&BLACK);
            (font, (at.0 + off, at.1 - skip))
        } else {
            (("sans-serif", sz).into_font().color(&BLACK), (at.0 + skip, at.1 + off))
        };
        area.draw(&Text::new(s.trim_start().to_string(), pos, font))?;
        along += w;
    }
    Ok(())
}

/// Draws `text` with its line's box top-left at `at`, subscripts (see [`rich_runs`]) smaller
/// and lower.
fn draw_rich<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    text: &str,
    at: (i32, i32),
    size: u32,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    draw_rich_runs(area, text, (at.0, at.1 + above(size)), size, false)
}

/// Draws `text` rotated a quarter turn counter-clockwise (a y-axis label): its line's box
/// starts at `left`, centred on `centre_y`.
fn draw_rich_vertical<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    text: &str,
    left: i32,
    centre_y: i32,
    size: u32,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let half = rich_width(text, size) / 2;
    draw_rich_runs(area, text, (left + above(size), centre_y + half), size, true)
}

/// `text` broken at blanks into lines at most `width` wide at `size` (a word wider than that
/// stays whole on its line).
fn wrap(text: &str, size: u32, width: i32) -> Vec<String> {
    let mut lines: Vec<String> = vec![];
    for word in text.split(' ').filter(|w| !w.is_empty()) {
        match lines.last_mut() {
            Some(l) if rich_width(&format!("{l} {word}"), size) <= width => {
                l.push(' ');
                l.push_str(word);
            }
            _ => lines.push(word.to_string()),
        }
    }
    lines
}

fn finite(p: &[(f64, f64)]) -> Vec<(f64, f64)> {
    p.iter().copied().filter(|(x, y)| x.is_finite() && y.is_finite()).collect()
}

/// Decimals of the tick labels of the range `[a, b]` (as many as the range needs).
fn decimals(a: f64, b: f64) -> usize {
    (2.0 - (b - a).abs().max(1e-300).log10().floor()).clamp(0.0, 12.0) as usize
}

/// A tick label: `decimals` decimals, no "-0.0", minus as U+2212.
fn tick_text(v: f64, decimals: usize) -> String {
    let s = format!("{:.*}", decimals, v);
    let s = if s.trim_start_matches('-').chars().all(|c| c == '0' || c == '.') {
        s.trim_start_matches('-').to_string()
    } else {
        s
    };
    s.replace('-', "\u{2212}")
}

/// Decimals that write every tick of `[a, b]` (at most `n` ticks, as plotters places them)
/// exactly: `0.1, 0.2` one, `0.25` two, `5, 10` none.
fn tick_decimals(a: f64, b: f64, n: usize) -> usize {
    use plotters::coord::ranged1d::Ranged;
    let ticks = plotters::coord::types::RangedCoordf64::from(a..b).key_points(n);
    (0..12)
        .find(|&d| {
            let k = 10f64.powi(d as i32);
            ticks.iter().all(|v| (v * k - (v * k).round()).abs() < 1e-6 * (1.0 + (v * k).abs()))
        })
        .unwrap_or(12)
        .min(decimals(a, b))
}

/// Width of the widest tick label of the range `[a, b]` at `size` (with [`decimals`], at least
/// as many as [`tick_decimals`]).
fn widest_tick(a: f64, b: f64, size: u32) -> i32 {
    let d = decimals(a, b);
    let m = a.abs().max(b.abs());
    [a, b, -m].iter().map(|&v| text_w(&tick_text(v, d), size)).fold(0.0, f64::max).ceil() as i32
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, plotters::coord::Shift>, f: &Figure) -> Result<(), FigureError>
where
    DB::ErrorType: 'static,
{
    let err = |e: &dyn std::fmt::Debug| FigureError::Draw { figure: f.title.clone(), reason: format!("{e:?}") };
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let st = Style::of(f.size);
    let body = if f.title.is_empty() {
        root.clone()
    } else {
        // the title centred above the plot, broken into lines that fit the width
        let (w, _) = root.dim_in_pixel();
        let lines = wrap(&f.title, st.title, w as i32 - 2 * st.gap);
        let lh = line_h(st.title);
        let height = st.gap / 2 + lh * lines.len() as i32;
        for (i, l) in lines.iter().enumerate() {
            let tw = rich_width(l, st.title);
            draw_rich(&root, l, ((w as i32 - tw) / 2, st.gap / 2 + lh * i as i32), st.title).map_err(|e| err(&e))?;
        }
        root.split_vertically(height).1
    };
    if f.below.is_empty() {
        draw_panel(&body, f, None, None)?;
    } else {
        let xr = f.shared_x_range().ok_or_else(|| FigureError::NoData { figure: f.title.clone() })?;
        // the x-axis label under the bottom panel only
        let n = f.panels().len();
        let panels: Vec<Figure> = f
            .panels()
            .into_iter()
            .enumerate()
            .map(|(i, p)| {
                let mut p = p.clone();
                if i + 1 < n {
                    p.x_label.clear();
                }
                p
            })
            .collect();
        let areas = body.split_evenly((panels.len(), 1));
        // one left edge for every panel, so their plot areas line up
        let left = panels
            .iter()
            .zip(&areas)
            .filter_map(|(p, a)| Some(PanelLayout::of(p, a.dim_in_pixel(), Some(xr))?.y_area))
            .max();
        for (area, p) in areas.iter().zip(&panels) {
            // an empty panel (no finite data) is left blank rather than failing the figure
            if p.ranges().is_some() {
                draw_panel(area, p, Some(xr), left)?;
            }
        }
    }
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

/// Where the parts of a panel go (pixels): the y-axis area (labels and ticks) left of the plot,
/// the x-axis area below it, the legend under that in rows, margins that keep the outermost
/// tick labels on the page.
#[derive(Debug, Clone)]
struct PanelLayout {
    st: Style,
    ranges: ((f64, f64), (f64, f64)),
    y_area: i32,
    x_area: i32,
    top: i32,
    right: i32,
    /// The axis labels broken into lines that fit the plot's width and height.
    x_lines: Vec<String>,
    y_lines: Vec<String>,
    /// Legend rows: indices of the elements, left to right.
    legend: Vec<Vec<usize>>,
    legend_row: i32,
    /// Width of each element's legend entry (swatch, gap, label).
    entry_w: Vec<i32>,
    /// Entries left out of a legend too tall for the panel (said at the end of the last row).
    more: usize,
}

/// The text that ends a legend that leaves out `n` entries.
fn more_text(n: usize) -> String {
    format!("+ {n} more")
}

impl PanelLayout {
    /// The layout of `f` in an area of `dim` pixels (`None` when nothing is finite).
    fn of(f: &Figure, dim: (u32, u32), x_range: Option<(f64, f64)>) -> Option<Self> {
        let st = Style::of(f.size);
        let (w, h) = (dim.0 as i32, dim.1 as i32);
        let swatch = 2 * st.legend as i32;
        let entry_w: Vec<i32> = f
            .elements
            .iter()
            .map(|e| {
                let l = e.label_and_color().0;
                if l.is_empty() {
                    0
                } else {
                    swatch + st.gap / 2 + rich_width(l, st.legend)
                }
            })
            .collect();
        // the legend flows in rows across the width
        let row_max = w - 2 * st.gap;
        let mut legend: Vec<Vec<usize>> = vec![];
        let mut row_w = 0;
        for (i, &ew) in entry_w.iter().enumerate().filter(|(_, &ew)| ew > 0) {
            match legend.last_mut() {
                Some(row) if row_w + 2 * st.gap + ew <= row_max => {
                    row.push(i);
                    row_w += 2 * st.gap + ew;
                }
                _ => {
                    legend.push(vec![i]);
                    row_w = ew;
                }
            }
        }
        let legend_row = line_h(st.legend) + st.gap / 3;
        let th = line_h(st.tick);
        let top = st.gap / 2 + th / 2 + 1;
        let x_axis = 2 * st.tick_mark + th;
        let (lh, gap) = (line_h(st.label), st.gap / 2);
        let label_h = |lines: &[String]| if lines.is_empty() { 0 } else { gap + lh * lines.len() as i32 };
        // a legend too tall leaves the plot two fifths of the panel: its last rows are left
        // out and counted at the end of the last row kept
        let mut more = 0;
        let keep = ((h - top - x_axis - label_h(&[String::new()]) - gap - (2 * h / 5).max(3 * th)) / legend_row).max(1);
        if legend.len() as i32 > keep {
            for row in legend.drain(keep as usize..) {
                more += row.len();
            }
            if let Some(last) = legend.last_mut() {
                while !last.is_empty() {
                    let used: i32 = last.iter().map(|&i| entry_w[i] + 2 * st.gap).sum();
                    if used + rich_width(&more_text(more + 1), st.legend) <= row_max {
                        break;
                    }
                    last.pop();
                    more += 1;
                }
            }
        }
        let legend_h = legend.len() as i32 * legend_row;
        let mut ranges = f.ranges()?;
        let (mut y_area, mut x_area, mut right) = (0, 0, 0);
        let (mut x_lines, mut y_lines) = (wrap(&f.x_label, st.label, w), wrap(&f.y_label, st.label, h));
        // three times: the labels wrap to the plot's size, which follows the labels and the
        // tick labels; with equal aspect the ranges follow the plot area
        for _ in 0..3 {
            let ((x0, x1), (y0, y1)) = ranges;
            let (x0, x1) = x_range.unwrap_or((x0, x1));
            y_area = label_h(&y_lines) + gap + widest_tick(y0, y1, st.tick) + 2 * st.tick_mark;
            x_area = x_axis + label_h(&x_lines);
            right = gap.max(widest_tick(x0, x1, st.tick) / 2 + 2);
            let pw = (w - gap - y_area - right).max(10);
            let ph = (h - top - x_area - legend_h - gap).max(10);
            ranges = f.ranges_in(pw as f64, ph as f64)?;
            x_lines = wrap(&f.x_label, st.label, pw);
            y_lines = wrap(&f.y_label, st.label, ph + top);
        }
        Some(Self { st, ranges, y_area, x_area, top, right, x_lines, y_lines, legend, legend_row, entry_w, more })
    }
}

/// One panel of `f` in `root`: its own y range, the x range `x_range` when given (stacked
/// panels), the y-axis area at least `left` wide when given (panels lined up).
fn draw_panel<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    f: &Figure,
    x_range: Option<(f64, f64)>,
    left: Option<i32>,
) -> Result<(), FigureError>
where
    DB::ErrorType: 'static,
{
    let err = |e: &dyn std::fmt::Debug| FigureError::Draw { figure: f.title.clone(), reason: format!("{e:?}") };
    let lay = PanelLayout::of(f, root.dim_in_pixel(), x_range)
        .ok_or_else(|| FigureError::NoData { figure: f.title.clone() })?;
    let st = lay.st;
    let ((x0, x1), (y0, y1)) = lay.ranges;
    let (x0, x1) = x_range.unwrap_or((x0, x1));
    let y_area = lay.y_area.max(left.unwrap_or(0));
    let legend_h = lay.legend.len() as i32 * lay.legend_row;
    let mut builder = ChartBuilder::on(root);
    let mut chart = builder
        .margin_top(lay.top)
        .margin_left(st.gap / 2)
        .margin_right(lay.right)
        .margin_bottom(st.gap / 2 + legend_h)
        .x_label_area_size(lay.x_area)
        .y_label_area_size(y_area)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|e| err(&e))?;
    let (xr, yr) = chart.plotting_area().get_pixel_range();
    let base = root.get_base_pixel();
    let plot = PlotBox { l: xr.start - base.0, r: xr.end - base.0, t: yr.start - base.1, b: yr.end - base.1 };
    draw_mesh(&mut chart, &st, plot, (x0, x1), (y0, y1)).map_err(|e| err(&e))?;
    draw_axis_labels(root, &lay, plot, y_area).map_err(|e| err(&e))?;
    draw_elements(root, &mut chart, f, &st, plot).map_err(|e| err(&e))?;
    draw_legend(root, f, &lay, plot).map_err(|e| err(&e))
}

/// The plotting area's pixel box within its panel: left, right, top and bottom edges.
#[derive(Debug, Clone, Copy)]
struct PlotBox {
    l: i32,
    r: i32,
    t: i32,
    b: i32,
}

type Chart<'a, DB> =
    ChartContext<'a, DB, Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>>;
type DrawResult<DB> = Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

/// Grid, axes and tick labels: as many ticks as fit their labels, at least two labelled ones
/// on the y axis where their labels fit one above the other.
fn draw_mesh<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    st: &Style,
    plot: PlotBox,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
) -> DrawResult<DB> {
    let nx = ((plot.r - plot.l) / (widest_tick(x0, x1, st.tick) + 2 * st.gap).max(1)).clamp(2, 12) as usize;
    let ny = ((plot.b - plot.t) / (2 * line_h(st.tick)).max(1)).clamp(2, 12) as usize;
    // a short panel's two "nice" ticks over [-0.45, 0.35] are 0 alone
    let fit = ((plot.b - plot.t) / line_h(st.tick).max(1)).clamp(2, 12) as usize;
    let ny = (ny..=fit.max(ny))
        .find(|&n| plotters::coord::types::RangedCoordf64::from(y0..y1).key_points(n).len() >= 2)
        .unwrap_or(ny);
    let (dx, dy) = (tick_decimals(x0, x1, nx), tick_decimals(y0, y1, ny));
    let fx = move |v: &f64| tick_text(*v, dx);
    let fy = move |v: &f64| tick_text(*v, dy);
    chart
        .configure_mesh()
        .x_labels(nx)
        .y_labels(ny)
        .x_label_formatter(&fx)
        .y_label_formatter(&fy)
        .set_all_tick_mark_size(st.tick_mark)
        .label_style(("sans-serif", st.tick))
        .light_line_style(RGBColor(235, 235, 235))
        .axis_style(BLACK.stroke_width((st.line / 2).max(1)))
        .draw()
}

/// The axis labels: the x label centred under the tick labels, the y label left of them (each
/// broken into lines when longer than the plot).
fn draw_axis_labels<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    lay: &PanelLayout,
    plot: PlotBox,
    y_area: i32,
) -> DrawResult<DB> {
    let st = lay.st;
    let lh = line_h(st.label);
    let x_label_top = plot.b + 2 * st.tick_mark + line_h(st.tick) + st.gap / 2;
    for (i, l) in lay.x_lines.iter().enumerate() {
        let xw = rich_width(l, st.label);
        draw_rich(root, l, ((plot.l + plot.r - xw) / 2, x_label_top + lh * i as i32), st.label)?;
    }
    for (i, l) in lay.y_lines.iter().enumerate() {
        let left = plot.l - y_area + st.gap / 2 + lh * i as i32;
        draw_rich_vertical(root, l, left, (plot.t + plot.b) / 2, st.label)?;
    }
    Ok(())
}

/// The figure's bands, polygons, lines and markers (with their texts).
fn draw_elements<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    chart: &mut Chart<'_, DB>,
    f: &Figure,
    st: &Style,
    plot: PlotBox,
) -> DrawResult<DB> {
    let dash = ((4 * st.line) as f64 * 2.0).max(4.0);
    let mut placed: Vec<(i32, i32, i32, i32)> = vec![];
    for e in &f.elements {
        match e {
            Element::Band { x, lo, hi, color, .. } => {
                let mut pts: Vec<(f64, f64)> = x.iter().zip(hi).map(|(&a, &b)| (a, b)).collect();
                pts.extend(x.iter().zip(lo).rev().map(|(&a, &b)| (a, b)));
                chart.draw_series(std::iter::once(Polygon::new(finite(&pts), color.mix(0.22).filled())))?;
            }
            Element::Polygon { pts, color, .. } => {
                chart.draw_series(std::iter::once(Polygon::new(finite(pts), color.mix(0.12).filled())))?;
            }
            Element::Line { pts, color, dashed, .. } => {
                let style = color.stroke_width(st.line);
                if *dashed {
                    chart.draw_series(DashedLineSeries::new(finite(pts), dash as u32, (0.75 * dash) as u32, style))?;
                } else {
                    chart.draw_series(LineSeries::new(finite(pts), style))?;
                }
            }
            Element::Markers { pts, text, color, .. } => {
                chart.draw_series(finite(pts).into_iter().map(|p| Circle::new(p, st.marker, color.filled())))?;
                let base = root.get_base_pixel();
                for (p, t) in pts.iter().zip(text) {
                    if !(p.0.is_finite() && p.1.is_finite()) || t.is_empty() {
                        continue;
                    }
                    let c = chart.backend_coord(p);
                    let at = marker_text_place((c.0 - base.0, c.1 - base.1), t, st, plot, &placed);
                    placed.push((at.0, at.1, at.0 + rich_width(t, st.legend), at.1 + line_h(st.legend)));
                    draw_rich(root, t, at, st.legend)?;
                }
            }
        }
    }
    Ok(())
}

/// Where a marker's text goes: the first place (above right, above left, below right, below
/// left of the marker at `(cx, cy)`) inside the plot and clear of the texts `placed` before,
/// else the first inside the plot, else clamped into it.
fn marker_text_place(
    (cx, cy): (i32, i32),
    t: &str,
    st: &Style,
    plot: PlotBox,
    placed: &[(i32, i32, i32, i32)],
) -> (i32, i32) {
    let (w, h, r) = (rich_width(t, st.legend), line_h(st.legend), st.marker as i32 + 2);
    let candidates = [(cx + r, cy - r - h), (cx - r - w, cy - r - h), (cx + r, cy + r), (cx - r - w, cy + r)];
    let inside = |&(x, y): &(i32, i32)| x >= plot.l && y >= plot.t && x + w <= plot.r && y + h <= plot.b;
    let free = |&(x, y): &(i32, i32)| placed.iter().all(|&(a, b, c, d)| x + w <= a || c <= x || y + h <= b || d <= y);
    candidates
        .iter()
        .find(|c| inside(c) && free(c))
        .or_else(|| candidates.iter().find(|c| inside(c)))
        .copied()
        .unwrap_or((cx.clamp(plot.l, (plot.r - w).max(plot.l)), (cy - r - h).clamp(plot.t, (plot.b - h).max(plot.t))))
}

/// The legend in rows below the x-axis label, off the data; the last row ends with "+ k more"
/// when entries were left out.
fn draw_legend<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    f: &Figure,
    lay: &PanelLayout,
    plot: PlotBox,
) -> DrawResult<DB> {
    let st = lay.st;
    let sw = 2 * st.legend as i32;
    let mut ly = plot.b + lay.x_area + st.gap / 2;
    let more = (lay.more > 0).then(|| more_text(lay.more));
    for (r, row) in lay.legend.iter().enumerate() {
        let more = more.as_ref().filter(|_| r + 1 == lay.legend.len());
        let widths: Vec<i32> =
            row.iter().map(|&i| lay.entry_w[i]).chain(more.map(|t| rich_width(t, st.legend))).collect();
        let row_w: i32 = widths.iter().sum::<i32>() + 2 * st.gap * (widths.len() as i32 - 1);
        let mut lx = (plot.l + plot.r - row_w) / 2;
        lx = lx.min(root.dim_in_pixel().0 as i32 - st.gap / 2 - row_w).max(st.gap / 2);
        let cy = ly + line_h(st.legend) / 2;
        for &i in row {
            let e = &f.elements[i];
            let (label, c) = e.label_and_color();
            let m = st.marker as i32;
            match e {
                Element::Band { .. } | Element::Polygon { .. } => {
                    root.draw(&Rectangle::new([(lx, cy - m), (lx + sw, cy + m)], c.mix(0.3).filled()))
                }
                Element::Line { dashed: true, .. } => {
                    root.draw(&PathElement::new(vec![(lx, cy), (lx + sw * 2 / 5, cy)], c.stroke_width(st.line)))?;
                    root.draw(&PathElement::new(vec![(lx + sw * 3 / 5, cy), (lx + sw, cy)], c.stroke_width(st.line)))
                }
                Element::Line { .. } => {
                    root.draw(&PathElement::new(vec![(lx, cy), (lx + sw, cy)], c.stroke_width(st.line)))
                }
                Element::Markers { .. } => root.draw(&Circle::new((lx + sw / 2, cy), st.marker, c.filled())),
            }?;
            draw_rich(root, label, (lx + sw + st.gap / 2, ly), st.legend)?;
            lx += lay.entry_w[i] + 2 * st.gap;
        }
        if let Some(t) = more {
            draw_rich(root, t, (lx, ly), st.legend)?;
        }
        ly += lay.legend_row;
    }
    Ok(())
}

/// The figure as an SVG document.
pub fn to_svg(f: &Figure) -> Result<String, FigureError> {
    super::fonts::register_fonts();
    let mut buf = String::new();
    {
        let big = (f.size.0 * SUPERSAMPLE, f.size.1 * SUPERSAMPLE);
        let root = SVGBackend::with_string(&mut buf, big).into_drawing_area();
        draw(root, f)?;
        // the page in points, the drawing in quarter points
        let (drawn, page) = (
            format!("width=\"{}\" height=\"{}\"", big.0, big.1),
            format!("width=\"{}\" height=\"{}\"", f.size.0, f.size.1),
        );
        buf = buf.replacen(&drawn, &page, 1);
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

/// A text element of a rendered figure: its string and its box in SVG user units (points in
/// the PDF, CSS pixels in the PNG at 96 dpi), as laid out by usvg with the embedded DejaVu Sans
/// (the box of the line: advance width by ascent to descent, not the ink).
#[derive(Debug, Clone, PartialEq)]
pub struct TextBox {
    pub text: String,
    pub x0: f64,
    pub y0: f64,
    pub x1: f64,
    pub y1: f64,
}

impl TextBox {
    /// Whether the two boxes share an area (touching edges do not count).
    pub fn overlaps(&self, o: &TextBox) -> bool {
        const EPS: f64 = 0.01;
        self.x0 + EPS < o.x1 && o.x0 + EPS < self.x1 && self.y0 + EPS < o.y1 && o.y0 + EPS < self.y1
    }
}

/// Every non-blank text element of `f` as it renders (its SVG parsed by usvg, as for the PNG and
/// PDF), in drawing order.
pub fn text_boxes(f: &Figure) -> Result<Vec<TextBox>, FigureError> {
    fn collect(g: &svg2pdf::usvg::Group, out: &mut Vec<TextBox>) {
        for n in g.children() {
            match n {
                svg2pdf::usvg::Node::Group(g) => collect(g, out),
                svg2pdf::usvg::Node::Text(t) => {
                    let text: String = t.chunks().iter().map(|c| c.text()).collect();
                    let r = t.abs_bounding_box();
                    if !text.trim().is_empty() {
                        out.push(TextBox {
                            text,
                            x0: r.left() as f64,
                            y0: r.top() as f64,
                            x1: r.right() as f64,
                            y1: r.bottom() as f64,
                        });
                    }
                }
                _ => {}
            }
        }
    }
    let tree = usvg_tree(f, &to_svg(f)?)?;
    let mut out = vec![];
    collect(tree.root(), &mut out);
    Ok(out)
}

/// What is wrong with the text of a page of `size`: every pair of overlapping boxes and every
/// box not wholly on the page, one line each (empty: a clean layout).
pub fn layout_defects(boxes: &[TextBox], size: (u32, u32)) -> Vec<String> {
    let mut out = vec![];
    let (w, h) = (size.0 as f64, size.1 as f64);
    for (i, a) in boxes.iter().enumerate() {
        if a.x0 < 0.0 || a.y0 < 0.0 || a.x1 > w || a.y1 > h {
            out.push(format!(
                "`{}` at [{:.1}, {:.1}] x [{:.1}, {:.1}] is not inside the {w} x {h} page",
                a.text, a.x0, a.x1, a.y0, a.y1
            ));
        }
        for b in &boxes[i + 1..] {
            if a.overlaps(b) {
                out.push(format!(
                    "`{}` [{:.1}, {:.1}] x [{:.1}, {:.1}] overlaps `{}` [{:.1}, {:.1}] x [{:.1}, {:.1}]",
                    a.text, a.x0, a.x1, a.y0, a.y1, b.text, b.x0, b.x1, b.y0, b.y1
                ));
            }
        }
    }
    out
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

/// Writes the figure as PNG to `path`: its SVG rasterised at 96 dpi (`size` pixels), so the PNG
/// shows the SVG's layout and glyphs.
pub fn write_png(f: &Figure, path: &Path) -> Result<(), FigureError> {
    let png = to_png_at_dpi(f, 96.0)?;
    std::fs::write(path, png).map_err(|e| FigureError::Write { path: path.to_path_buf(), reason: e.to_string() })
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
/// ([`to_png_at_dpi`]; at 96 dpi, `size` pixels, otherwise).
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
    // the PNG is the SVG rasterised, at 96 dpi (`size` pixels) unless `png_dpi` says otherwise
    let png_dpi = formats.contains(&Format::Png).then_some(png_dpi.unwrap_or(96.0));
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
    fn tex_labels_are_drawn_as_unicode_and_tick_minus_signs_are_minus_signs() {
        assert_eq!(display_text("$\\delta$ (m)"), "δ (m)");
        assert_eq!(display_text("$\\theta_{\\mathrm{best}}/\\mathrm{measured}$"), "θ_{best}/measured");
        assert_eq!(display_text("$A_{21}$ = $-3$"), "A_{21} = \u{2212}3");
        assert_eq!(display_text("$10^{-3}$ s"), "10⁻³ s");
        assert_eq!(display_text("no math_here"), "no math_here");
        assert_eq!(rich_runs("θ_{eng} = 1"), [("θ".to_string(), false), ("eng".into(), true), (" = 1".into(), false)]);
        assert_eq!(rich_runs("Ξ_∞"), [("Ξ".to_string(), false), ("∞".into(), true)]);
        assert_eq!(tick_text(-0.25, 2), "\u{2212}0.25");
        assert_eq!(tick_text(-0.0001, 2), "0.00", "no negative zero");
        let svg = to_svg(&figure("$\\delta$ (m)", "θ_{eng}")).unwrap();
        let texts = svg_texts(&svg);
        assert!(texts.iter().any(|t| t == "δ (m)") && texts.iter().any(|t| t == "eng"), "{texts:?}");
        assert!(texts.iter().any(|t| t.starts_with('\u{2212}')), "a negative tick with U+2212: {texts:?}");
        assert!(!texts.iter().any(|t| t.starts_with('-') || t.contains('$')), "hyphen minus or TeX left: {texts:?}");
    }

    #[test]
    fn digit_subscripts_in_axis_labels_become_unicode_subscripts() {
        let svg = to_svg(&figure("η_1", "z_2")).unwrap();
        assert!(svg.contains("η₁") && svg.contains("z₂"));
    }
}
