//! Shared line plots (SVG and PNG) with the embedded DejaVu font: several series, labelled
//! axes, optional shaded time windows. Everything is drawn in memory / a staging path so that
//! callers can write files atomically (`output::StagedDir`).
use anyhow::{anyhow, Result};
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::path::Path;
use std::sync::Once;

/// One curve.
#[derive(Debug, Clone)]
pub struct Series {
    pub label: String,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
}

/// A line plot: title, axis labels, curves and shaded windows `[t0, t1]` (e.g. contact phases
/// or the regression window).
#[derive(Debug, Clone, Default)]
pub struct LinePlot {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
    pub windows: Vec<(f64, f64)>,
    /// Pixel size. Default (if zero) `1000 x 600`.
    pub size: (u32, u32),
}

static FONTS: Once = Once::new();

/// Registers every font family used (`sans-serif`, `serif`, `monospace` all map to DejaVu
/// Sans) before drawing any text; needed by the SVG backend too (BUILD-NOTES.md).
pub fn register_fonts() {
    FONTS.call_once(|| {
        for fam in ["sans-serif", "serif", "monospace"] {
            let _ = plotters::style::register_font(fam, FontStyle::Normal, dejavu::sans::regular());
            let _ = plotters::style::register_font(fam, FontStyle::Bold, dejavu::sans::bold());
            let _ = plotters::style::register_font(fam, FontStyle::Italic, dejavu::sans::oblique());
            let _ = plotters::style::register_font(fam, FontStyle::Oblique, dejavu::sans::oblique());
        }
    });
}

/// `svg` (as plotters writes it, `font-family="sans-serif"` on each text) with the DejaVu Sans
/// font embedded: an `@font-face` rule whose source is the font file itself as a base64 data
/// URL (regular weight: every text of the figures is), and a style rule (which overrides the presentation attributes) setting it on every
/// text, so the file renders with the same font on any machine, as its PNG twin does.
pub fn embed_font(svg: String) -> String {
    use base64::Engine;
    static STYLE: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    let style = STYLE.get_or_init(|| {
        let b64 = |bytes: &[u8]| base64::engine::general_purpose::STANDARD.encode(bytes);
        format!(
            "<defs><style>@font-face{{font-family:\"DejaVu Sans\";src:url(data:font/ttf;base64,{})}} \
             text{{font-family:\"DejaVu Sans\",sans-serif}}</style></defs>",
            b64(dejavu::sans::regular())
        )
    });
    match svg.find("<svg").and_then(|i| svg[i..].find('>').map(|j| i + j + 1)) {
        Some(at) => format!("{}\n{}{}", &svg[..at], style, &svg[at..]),
        None => svg,
    }
}

fn ranges(p: &LinePlot) -> Result<((f64, f64), (f64, f64))> {
    let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
    for s in &p.series {
        for (&x, &y) in s.x.iter().zip(&s.y) {
            if x.is_finite() && y.is_finite() {
                x0 = x0.min(x);
                x1 = x1.max(x);
                y0 = y0.min(y);
                y1 = y1.max(y);
            }
        }
    }
    if !(x0 <= x1 && y0 <= y1) {
        return Err(anyhow!("plot `{}` has no finite points", p.title));
    }
    if x1 - x0 < 1e-300 {
        x1 = x0 + 1.0;
    }
    let pad = ((y1 - y0) * 0.05).max(1e-12 * (1.0 + y0.abs()));
    Ok(((x0, x1), (y0 - pad, y1 + pad)))
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, plotters::coord::Shift>, p: &LinePlot) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let ((x0, x1), (y0, y1)) = ranges(p)?;
    root.fill(&WHITE).map_err(|e| anyhow!("plot: {e:?}"))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(&p.title, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(|e| anyhow!("plot: {e:?}"))?;
    chart
        .configure_mesh()
        .x_desc(p.x_label.as_str())
        .y_desc(p.y_label.as_str())
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(|e| anyhow!("plot: {e:?}"))?;
    for &(a, b) in &p.windows {
        chart
            .draw_series(std::iter::once(Rectangle::new(
                [(a.max(x0), y0), (b.min(x1), y1)],
                RGBColor(200, 200, 200).mix(0.35).filled(),
            )))
            .map_err(|e| anyhow!("plot: {e:?}"))?;
    }
    for (i, s) in p.series.iter().enumerate() {
        let c = Palette99::pick(i).to_rgba();
        chart
            .draw_series(LineSeries::new(
                s.x.iter().zip(&s.y).filter(|(x, y)| x.is_finite() && y.is_finite()).map(|(&x, &y)| (x, y)),
                c.stroke_width(2),
            ))
            .map_err(|e| anyhow!("plot: {e:?}"))?
            .label(s.label.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
    }
    if p.series.len() > 1 || p.series.iter().any(|s| !s.label.is_empty()) {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .label_font(("sans-serif", 14))
            .draw()
            .map_err(|e| anyhow!("plot: {e:?}"))?;
    }
    root.present().map_err(|e| anyhow!("plot: {e:?}"))?;
    Ok(())
}

fn size(p: &LinePlot) -> (u32, u32) {
    if p.size.0 == 0 || p.size.1 == 0 {
        (1000, 600)
    } else {
        p.size
    }
}

/// The plot as an SVG document.
pub fn to_svg_string(p: &LinePlot) -> Result<String> {
    register_fonts();
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, size(p)).into_drawing_area();
        draw(root, p)?;
    }
    Ok(embed_font(buf))
}

/// Writes the plot as PNG to `path` (use a staging path for atomic output).
pub fn write_png(p: &LinePlot, path: &Path) -> Result<()> {
    register_fonts();
    let root = BitMapBackend::new(path, size(p)).into_drawing_area();
    draw(root, p)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn svg_and_png_render_with_text() {
        let x: Vec<f64> = (0..100).map(|i| i as f64 * 0.1).collect();
        let p = LinePlot {
            title: "test".into(),
            x_label: "t".into(),
            y_label: "y".into(),
            series: vec![
                Series { label: "sin".into(), x: x.clone(), y: x.iter().map(|t| t.sin()).collect() },
                Series { label: "cos".into(), x: x.clone(), y: x.iter().map(|t| t.cos()).collect() },
            ],
            windows: vec![(1.0, 2.0)],
            size: (0, 0),
        };
        let svg = to_svg_string(&p).unwrap();
        assert!(svg.contains("<svg") && svg.contains("sin") && svg.contains("<text"));
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("a.png");
        write_png(&p, &f).unwrap();
        assert!(std::fs::metadata(&f).unwrap().len() > 1000);
        let empty = LinePlot { series: vec![Series { label: "nan".into(), x: vec![f64::NAN], y: vec![1.0] }], ..p };
        assert!(to_svg_string(&empty).is_err());
    }
}
