//! Labelled quantities: every number of the theta report carries its symbol, the equation
//! label of `strongly-convex-backlash.tex`, the direction in which it bounds the true value,
//! and whether that bound is verified.

/// How a reported number relates to the true quantity.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BoundKind {
    /// Exact up to floating-point rounding.
    Exact,
    /// An upper bound of the true value.
    Upper,
    /// A lower bound of the true value.
    Lower,
    /// Measured or sampled: no bound claimed.
    Estimate,
}

impl BoundKind {
    pub fn as_str(&self) -> &'static str {
        match self {
            BoundKind::Exact => "exact",
            BoundKind::Upper => "upper bound",
            BoundKind::Lower => "lower bound",
            BoundKind::Estimate => "estimate",
        }
    }
}

/// One labelled number.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Quantity {
    /// Stable snake_case key (also the JSON key of the value).
    pub key: &'static str,
    /// The paper's symbol in ASCII.
    pub symbol: &'static str,
    /// Equation label(s) in the paper.
    pub label: &'static str,
    pub value: f64,
    pub kind: BoundKind,
    /// True when the bound in `kind` is proven (up to floating-point rounding of closed forms).
    pub verified: bool,
    /// How it was obtained (short).
    pub note: String,
}

impl Quantity {
    pub fn new(
        key: &'static str,
        symbol: &'static str,
        label: &'static str,
        value: f64,
        kind: BoundKind,
        verified: bool,
        note: impl Into<String>,
    ) -> Self {
        Self { key, symbol, label, value, kind, verified, note: note.into() }
    }
}

/// Formats `v` compactly for the readable report.
pub fn fmt_value(v: f64) -> String {
    if v.is_nan() {
        "n/a".into()
    } else if v.is_infinite() {
        if v > 0.0 {
            "inf".into()
        } else {
            "-inf".into()
        }
    } else if v == 0.0 || (v.abs() >= 1e-3 && v.abs() < 1e5) {
        format!("{v:.6}")
    } else {
        format!("{v:.4e}")
    }
}

/// A plain-text table: symbol, label, value, kind, verified.
pub fn render_table(rows: &[Quantity]) -> String {
    let mut s = String::new();
    let w_sym = rows.iter().map(|q| q.symbol.len()).max().unwrap_or(6).max(6);
    let w_lab = rows.iter().map(|q| q.label.len()).max().unwrap_or(5).max(5);
    s.push_str(&format!(
        "{:<w_sym$}  {:<w_lab$}  {:>14}  {:<12}  {:<8}  {}\n",
        "symbol", "eq.", "value", "kind", "verified", "how"
    ));
    for q in rows {
        s.push_str(&format!(
            "{:<w_sym$}  {:<w_lab$}  {:>14}  {:<12}  {:<8}  {}\n",
            q.symbol,
            q.label,
            fmt_value(q.value),
            q.kind.as_str(),
            if q.verified { "yes" } else { "no" },
            q.note
        ));
    }
    s
}
