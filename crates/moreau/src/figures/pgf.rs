//! A [`Figure`] as pgfplots code (`stem.tex`, to `\input` into a paper that loads `pgfplots`, so
//! the figure is set in the paper's own fonts) and its data as CSV (`stem.csv`, long format:
//! `element,label,x,y`). Greek letters and subscripts of the labels become math mode; LaTeX's
//! special characters are escaped; the output is ASCII.
use super::canvas::{Element, Figure};
use plotters::style::RGBColor;

/// Text of a label in LaTeX: Greek letters, sub/superscript digits, minus and infinity to math
/// mode, specials escaped; `_X` (one letter, digit or `∞`) and `_{..}` as subscripts. A label
/// with TeX math in it (`$\\delta$ (m)`, as a sweep spec's `label` writes it) keeps its math as
/// written; the text around it is converted.
pub fn tex_text(s: &str) -> String {
    if s.contains('$') && s.matches('$').count().is_multiple_of(2) {
        return s
            .split('$')
            .enumerate()
            .map(|(i, seg)| if i % 2 == 1 { format!("${seg}$") } else { plain_tex(seg) })
            .collect::<String>()
            .replace("$$", "");
    }
    plain_tex(s)
}

fn plain_tex(s: &str) -> String {
    // "gamma infinity", "Xi infinity" as the labels write them: subscripts
    let s = s.replace("γ∞", "γ\u{e000}").replace("Ξ∞", "Ξ\u{e000}").replace("_∞", "\u{e000}");
    let mut out = String::new();
    let chars: Vec<char> = s.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        // `theta_{eng}`: a group subscript, upright when it is a word
        if c == '_' && chars.get(i + 1) == Some(&'{') {
            if let Some(end) = chars[i + 2..].iter().position(|&x| x == '}') {
                let body: String = chars[i + 2..i + 2 + end].iter().collect();
                if body.chars().count() > 1 && body.chars().all(|x| x.is_ascii_alphabetic()) {
                    out.push_str(&format!("$_{{\\mathrm{{{body}}}}}$"));
                } else {
                    out.push_str(&format!("$_{{{}}}$", plain_tex(&body).replace('$', "")));
                }
                i += end + 3;
                continue;
            }
        }
        // `eta_T`-style subscripts: `_` before a letter or digit is a math subscript
        // (a single character: `input_amplitude` keeps its underscore)
        let single = |k: usize| {
            chars.get(k).is_some_and(|n| n.is_ascii_alphanumeric())
                && !chars.get(k + 1).is_some_and(|n| n.is_ascii_alphanumeric())
        };
        if c == '_' && single(i + 1) {
            i += 1;
            continue;
        }
        i += 1;
        if i > 1 && chars[i - 2] == '_' && single(i - 1) {
            out.push_str(&format!("$_{{{c}}}$"));
            continue;
        }
        let math = match c {
            '\u{e000}' => Some("_\\infty".to_string()),
            '−' => Some("-".to_string()),
            '′' => Some("'".to_string()),
            '₀' => Some("_0".to_string()),
            '₁' => Some("_1".to_string()),
            '₂' => Some("_2".to_string()),
            '₃' => Some("_3".to_string()),
            '²' => Some("^2".to_string()),
            '°' => Some("^\\circ".to_string()),
            c => super::tex_symbols::command(c),
        };
        match math {
            Some(m) => {
                out.push('$');
                out.push_str(&m);
                out.push('$');
            }
            None => match c {
                '%' | '&' | '#' | '_' | '{' | '}' | '$' => {
                    out.push('\\');
                    out.push(c);
                }
                '\\' => out.push_str("\\textbackslash{}"),
                '^' => out.push_str("\\^{}"),
                '~' => out.push_str("\\~{}"),
                c if c.is_ascii() => out.push(c),
                _ => out.push('?'),
            },
        }
    }
    // adjacent math groups merge: "$\gamma$$_1$" -> "$\gamma_1$"
    out.replace("$$", "")
}

fn colour(c: &RGBColor) -> String {
    format!("{{rgb,255:red,{};green,{};blue,{}}}", c.0, c.1, c.2)
}

fn num(v: f64) -> String {
    format!("{v:.9e}")
}

fn coords(pts: &[(f64, f64)]) -> String {
    pts.iter()
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .map(|(x, y)| format!("({},{})", num(*x), num(*y)))
        .collect::<Vec<_>>()
        .join(" ")
}

/// pgfplots code of `f` (a `tikzpicture`; stacked panels ([`Figure::below`]) as axes placed
/// one under the other with the same x range, the x label on the bottom one only).
pub fn to_pgf(f: &Figure) -> String {
    let mut s = String::new();
    s.push_str(&format!(
        "% {} -- written by moreau; needs \\usepackage{{pgfplots}} (compat >= 1.11)\n",
        tex_text(&f.title)
    ));
    s.push_str("\\begin{tikzpicture}\n");
    let panels = f.panels();
    let stacked = panels.len() > 1;
    let shared_x = f.shared_x_range();
    for (k, p) in panels.iter().enumerate() {
        axis(&mut s, p, k, stacked, k + 1 == panels.len(), shared_x);
    }
    s.push_str("\\end{tikzpicture}\n");
    s
}

/// One `axis` environment: panel `k` of the picture.
fn axis(s: &mut String, f: &Figure, k: usize, stacked: bool, bottom: bool, shared_x: Option<(f64, f64)>) {
    s.push_str(&format!("\\begin{{axis}}[\n  name=panel{k},\n"));
    if k > 0 {
        s.push_str(&format!("  at={{(panel{}.below south west)}}, anchor=north west, yshift=-0.6cm,\n", k - 1));
    }
    let height = if stacked { "0.32\\linewidth" } else { "0.55\\linewidth" };
    let width = if stacked { "0.72\\linewidth" } else { "0.9\\linewidth" };
    s.push_str(&format!("  width={width}, height={height}, clip=false,\n"));
    if let Some(((x0, x1), (y0, y1))) = f.ranges() {
        let (x0, x1) = shared_x.filter(|_| stacked).unwrap_or((x0, x1));
        s.push_str(&format!("  xmin={}, xmax={}, ymin={}, ymax={},\n", num(x0), num(x1), num(y0), num(y1)));
    }
    let xlabel = if bottom { tex_text(&f.x_label) } else { String::new() };
    s.push_str(&format!("  xlabel={{{}}}, ylabel={{{}}},\n", xlabel, tex_text(&f.y_label)));
    s.push_str("  legend cell align=left,\n");
    if stacked {
        // the legend right of the panel, off the data and clear of the panel below
        s.push_str("  legend style={font=\\small, at={(1.03,1)}, anchor=north west, draw=none},\n");
    } else {
        // the legend below the axes, off the data
        s.push_str("  legend columns=2,\n");
        s.push_str("  legend style={font=\\small, at={(0.5,-0.18)}, anchor=north, draw=none},\n");
    }
    s.push_str("  scaled ticks=false, tick label style={font=\\small},\n]\n");
    for e in &f.elements {
        let (label, line) = match e {
            Element::Line { label, pts, color, dashed } => (
                label,
                format!(
                    "\\addplot[color={}, thick{}] coordinates {{{}}};",
                    colour(color),
                    if *dashed { ", dashed" } else { "" },
                    coords(pts)
                ),
            ),
            Element::Band { label, x, lo, hi, color } => {
                let mut pts: Vec<(f64, f64)> = x.iter().zip(hi).map(|(&a, &b)| (a, b)).collect();
                pts.extend(x.iter().zip(lo).rev().map(|(&a, &b)| (a, b)));
                (
                    label,
                    format!(
                        "\\addplot[fill={}, fill opacity=0.22, draw=none, area legend{}] coordinates {{{}}} -- cycle;",
                        colour(color),
                        if label.is_empty() { ", forget plot" } else { "" },
                        coords(&pts)
                    ),
                )
            }
            Element::Polygon { label, pts, color } => (
                label,
                format!(
                    "\\addplot[fill={}, fill opacity=0.12, draw=none, area legend{}] coordinates {{{}}} -- cycle;",
                    colour(color),
                    if label.is_empty() { ", forget plot" } else { "" },
                    coords(pts)
                ),
            ),
            Element::Markers { label, pts, color, .. } => (
                label,
                format!(
                    "\\addplot[only marks, mark=*, color={}{}] coordinates {{{}}};",
                    colour(color),
                    if label.is_empty() { ", forget plot" } else { "" },
                    coords(pts)
                ),
            ),
        };
        let line = match e {
            Element::Line { .. } if label.is_empty() => line.replacen("thick", "thick, forget plot", 1),
            _ => line,
        };
        s.push_str(&line);
        s.push('\n');
        if !label.is_empty() {
            s.push_str(&format!("\\addlegendentry{{{}}}\n", tex_text(label)));
        }
        if let Element::Markers { pts, text, .. } = e {
            for (p, t) in pts.iter().zip(text) {
                if p.0.is_finite() && p.1.is_finite() && !t.is_empty() {
                    s.push_str(&format!(
                        "\\node[anchor=south west, font=\\small] at (axis cs:{},{}) {{{}}};\n",
                        num(p.0),
                        num(p.1),
                        tex_text(t)
                    ));
                }
            }
        }
    }
    s.push_str("\\end{axis}\n");
}

/// The data of `f` as CSV (`element,label,x,y`; bands as their closed outline).
pub fn to_csv(f: &Figure) -> String {
    let mut s = String::from("element,label,x,y\n");
    let elements = f.panels().into_iter().flat_map(|p| p.elements.iter());
    for (i, e) in elements.enumerate() {
        let (label, pts): (&str, Vec<(f64, f64)>) = match e {
            Element::Line { label, pts, .. }
            | Element::Polygon { label, pts, .. }
            | Element::Markers { label, pts, .. } => (label, pts.clone()),
            Element::Band { label, x, lo, hi, .. } => {
                let mut p: Vec<(f64, f64)> = x.iter().zip(hi).map(|(&a, &b)| (a, b)).collect();
                p.extend(x.iter().zip(lo).rev().map(|(&a, &b)| (a, b)));
                (label, p)
            }
        };
        let label = label.replace('"', "'");
        for (x, y) in pts {
            s.push_str(&format!("{i},\"{label}\",{},{}\n", num(x), num(y)));
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_become_ascii_latex() {
        assert_eq!(tex_text("ψ(γ)"), "$\\psi$($\\gamma$)");
        assert_eq!(tex_text("γ₁ = 4.3"), "$\\gamma_1$ = 4.3");
        assert_eq!(tex_text("ψ(γ∞)"), "$\\psi$($\\gamma_\\infty$)");
        assert_eq!(tex_text("η_T (orbit), C Ξ∞ + Θ"), "$\\eta_{T}$ (orbit), C $\\Xi_\\infty$ + $\\Theta$");
        assert_eq!(tex_text("limit −λ = −0.3"), "limit $-\\lambda$ = $-$0.3");
        assert_eq!(tex_text("50% of a_b & c"), "50\\% of a$_{b}$ \\& c");
        assert_eq!(tex_text("input_amplitude"), "input\\_amplitude");
        assert!(tex_text("‽").is_ascii());
        assert_eq!(tex_text("θ_{eng} = 1"), "$\\theta_{\\mathrm{eng}}$ = 1");
        assert_eq!(tex_text("tube C Ξ_∞"), "tube C $\\Xi_\\infty$");
        // TeX as a sweep spec writes it is kept; the text around it converted
        assert_eq!(tex_text("$\\delta$ (m)"), "$\\delta$ (m)");
        assert_eq!(tex_text("$A_{21}$ = −3, 50%"), "$A_{21}$ = $-$3, 50\\%");
        // every letter of the shared table (tex_symbols), the preferred command where two exist
        assert_eq!(tex_text("Δ ± ε, φ × 2"), "$\\Delta$ $\\pm$ $\\varepsilon$, $\\varphi$ $\\times$ 2");
        assert_eq!(tex_text("angle (°)"), "angle ($^\\circ$)");
    }
}
