//! Model selection: BIC with a significance margin plus improvement on the validation
//! segment, and ties between hypotheses that explain the data equally well.
//!
//! `BIC = N log(SSE / N) + k log N` with `N` the number of estimation residuals and `k` the
//! number of free parameters (effect parameters + `n` initial states). A hypothesis beats the
//! current model when `BIC_current - BIC >= margin_bic` (default 10: "very strong" on the
//! Kass-Raftery scale) AND its validation SSE is at most `1 - min_val_gain` times the
//! current one (default gain 0.1). Two hypotheses whose BIC differ by less than `tie_bic`
//! (default 6) are reported as indistinguishable on this recording.
use serde::Serialize;

/// Settings of selection.
#[derive(Debug, Clone)]
pub struct SelectSettings {
    pub margin_bic: f64,
    pub min_val_gain: f64,
    pub tie_bic: f64,
}

impl Default for SelectSettings {
    fn default() -> Self {
        Self { margin_bic: 10.0, min_val_gain: 0.1, tie_bic: 6.0 }
    }
}

/// `N log(SSE/N) + k log N`.
pub fn bic(sse: f64, n: usize, k: usize) -> f64 {
    let nf = n.max(1) as f64;
    nf * (sse.max(1e-300) / nf).ln() + k as f64 * nf.ln()
}

/// Whether a candidate (BIC `b`, validation SSE `v`) beats the current (`b0`, `v0`).
pub fn beats(b: f64, v: f64, b0: f64, v0: f64, s: &SelectSettings) -> bool {
    b0 - b >= s.margin_bic && v <= (1.0 - s.min_val_gain) * v0
}

/// Summary of one decision, for the report.
#[derive(Debug, Clone, Serialize)]
pub struct Decision {
    pub margin_bic: f64,
    pub min_val_gain: f64,
    pub tie_bic: f64,
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn margin_and_validation_both_required() {
        let s = SelectSettings::default();
        let b0 = bic(100.0, 1000, 2);
        assert!(beats(bic(50.0, 1000, 3), 5.0, b0, 10.0, &s));
        // Better BIC but no validation gain: rejected (overfitting guard).
        assert!(!beats(bic(50.0, 1000, 3), 9.5, b0, 10.0, &s));
        // Tiny estimation gain: the extra parameter does not pay.
        assert!(!beats(bic(99.9, 1000, 3), 5.0, b0, 10.0, &s));
    }
}
