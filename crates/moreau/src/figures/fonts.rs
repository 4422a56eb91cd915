//! The embedded DejaVu font of every figure: registered with plotters before any text is
//! drawn, and embedded in SVG output so the file renders the same on any machine.
use plotters::style::FontStyle;
use std::sync::Once;

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
