//! The Greek letters and math symbols of TeX, declared once for both directions: a label's TeX
//! math drawn in SVG/PNG/PDF ([`super::canvas::display_text`]: `\delta` -> `δ`) and a label's
//! Unicode set by LaTeX in pgf ([`super::pgf::tex_text`]: `δ` -> `$\delta$`). Where two
//! commands give one symbol, the first listed is the one pgf writes (`\varepsilon`, `\varphi`).

/// (TeX command without the backslash, the symbol).
const SYMBOLS: &[(&str, &str)] = &[
    ("alpha", "α"),
    ("beta", "β"),
    ("gamma", "γ"),
    ("delta", "δ"),
    ("varepsilon", "ε"),
    ("epsilon", "ε"),
    ("zeta", "ζ"),
    ("eta", "η"),
    ("theta", "θ"),
    ("vartheta", "θ"),
    ("kappa", "κ"),
    ("lambda", "λ"),
    ("mu", "μ"),
    ("nu", "ν"),
    ("xi", "ξ"),
    ("pi", "π"),
    ("rho", "ρ"),
    ("sigma", "σ"),
    ("tau", "τ"),
    ("varphi", "φ"),
    ("phi", "φ"),
    ("chi", "χ"),
    ("psi", "ψ"),
    ("omega", "ω"),
    ("Gamma", "Γ"),
    ("Delta", "Δ"),
    ("Theta", "Θ"),
    ("Lambda", "Λ"),
    ("Xi", "Ξ"),
    ("Pi", "Π"),
    ("Sigma", "Σ"),
    ("Phi", "Φ"),
    ("Psi", "Ψ"),
    ("Omega", "Ω"),
    ("infty", "∞"),
    ("cdot", "·"),
    ("times", "×"),
    ("le", "≤"),
    ("leq", "≤"),
    ("ge", "≥"),
    ("geq", "≥"),
    ("pm", "±"),
];

/// The symbol of TeX command `name` (`delta` -> `δ`).
pub fn symbol(name: &str) -> Option<&'static str> {
    SYMBOLS.iter().find(|(n, _)| *n == name).map(|(_, s)| *s)
}

/// The TeX command of symbol `c`, with its backslash (`δ` -> `\delta`).
pub fn command(c: char) -> Option<String> {
    let mut buf = [0u8; 4];
    let c = &*c.encode_utf8(&mut buf);
    SYMBOLS.iter().find(|(_, s)| *s == c).map(|(n, _)| format!("\\{n}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every symbol goes to a command and back to itself; the preferred command of a symbol
    /// with two is the first listed.
    #[test]
    fn both_directions_agree() {
        for (_, s) in SYMBOLS {
            let c = s.chars().next().unwrap();
            let cmd = command(c).unwrap();
            assert_eq!(symbol(&cmd[1..]), Some(*s), "{cmd}");
        }
        assert_eq!(command('ε').as_deref(), Some("\\varepsilon"));
        assert_eq!(command('φ').as_deref(), Some("\\varphi"));
        assert_eq!(symbol("epsilon"), Some("ε"));
        assert_eq!(command('a'), None);
        assert_eq!(symbol("mathrm"), None);
    }
}
