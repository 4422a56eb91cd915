//! The discretisation self-check: sub-steps chosen by convergence, judged against the
//! recording's noise level.
//!
//! The simulator's error has two sources the eigenvalues of `F` alone do not bound: the play's
//! catching-up projection (first order in the step) and stick-slip friction. So the nominal
//! model is simulated at `k` and `2k` sub-steps per sample and `k` is doubled until the
//! change `rms_w(y_k - y_2k)` (weighted as the fit's residuals) is at most `tol` times the
//! noise level. The remaining error of `y_k` is taken as `2 rms_w(y_k - y_2k)` (exact for a
//! first-order method, conservative for higher orders), and an effect must improve the fit
//! by more than that error can account for ([`delta_bic_of_error`]).
//!
//! Noise level: for white noise of variance `s^2`, the `d`-th difference of the samples has
//! variance `binom(2d, d) s^2`, while a signal sampled well above its bandwidth contributes
//! little to high differences; the estimate is the smallest of
//! `sqrt(mean (Delta^d y)^2 / binom(2d, d))`, `d = 1..4` (coloured noise makes it smaller,
//! which only asks for more sub-steps).
use serde::Serialize;

/// `binom(2d, d)` for `d = 1..4`.
const BINOM: [f64; 4] = [2.0, 6.0, 20.0, 70.0];

/// Noise level of each output (units of y) by the difference estimator (module docs).
pub fn noise_level(y: &[f64], p: usize) -> Vec<f64> {
    let n = y.len() / p.max(1);
    (0..p)
        .map(|i| {
            let mut v: Vec<f64> = (0..n).map(|k| y[k * p + i]).collect();
            let mut best = f64::INFINITY;
            for b in BINOM {
                if v.len() < 3 {
                    break;
                }
                v = v.windows(2).map(|w| w[1] - w[0]).collect();
                let ms = v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64;
                best = best.min((ms / b).sqrt());
            }
            if best.is_finite() {
                best
            } else {
                0.0
            }
        })
        .collect()
}

/// The outcome of the sub-step convergence check.
#[derive(Debug, Clone, Serialize)]
pub struct SubstepCheck {
    /// Sub-steps per sample chosen.
    pub substeps: usize,
    /// `(k, rms_w(y_k - y_2k))` for every `k` tried.
    pub ladder: Vec<(usize, f64)>,
    /// Estimated remaining discretisation error of the chosen `k` (weighted RMS, the units
    /// of the fit's residuals): `2 rms_w(y_k - y_2k)`.
    pub error_rms: f64,
    /// Tolerance of the change (weighted RMS): `tol` times the noise level.
    pub tolerance: f64,
    /// Whether the change fell below the tolerance before the largest `k` allowed.
    pub converged: bool,
}

/// Weighted RMS of `a - b` (flat, `k * p + i`, weights per output).
pub fn rms_w(a: &[f64], b: &[f64], weights: &[f64]) -> f64 {
    let p = weights.len().max(1);
    let n = a.len().min(b.len());
    if n == 0 {
        return 0.0;
    }
    let s: f64 = (0..n).map(|i| ((a[i] - b[i]) * weights[i % p]).powi(2)).sum();
    (s / n as f64).sqrt()
}

/// Doubles `k` from `k0` until `rms_w(sim(k) - sim(2k)) <= tolerance` or `k = k_max`
/// (the last check then compares `k_max` with `2 k_max`; `sim` returns the output on the
/// sample grid, `None` if it blew up).
pub fn converge(
    sim: impl Fn(usize) -> Option<Vec<f64>>,
    k0: usize,
    k_max: usize,
    weights: &[f64],
    tolerance: f64,
) -> SubstepCheck {
    let mut k = k0.max(1).min(k_max.max(1));
    let mut ladder = Vec::new();
    let mut cur = sim(k);
    loop {
        let next = sim(2 * k);
        let change = match (&cur, &next) {
            (Some(a), Some(b)) => rms_w(a, b, weights),
            _ => f64::INFINITY,
        };
        ladder.push((k, change));
        if change <= tolerance {
            return SubstepCheck { substeps: k, ladder, error_rms: 2.0 * change, tolerance, converged: true };
        }
        if 2 * k > k_max.max(1) {
            return SubstepCheck { substeps: k, ladder, error_rms: 2.0 * change, tolerance, converged: false };
        }
        k *= 2;
        cur = next;
    }
}

/// The largest BIC gain a discretisation error of weighted RMS `e` can buy on `n` residuals
/// whose mean square is `s2`: `n ln(1 + e^2 / s2)` (an effect that absorbed the error
/// entirely would lower the SSE by at most `n e^2`).
pub fn delta_bic_of_error(e: f64, s2: f64, n: usize) -> f64 {
    if !(e.is_finite() && s2 > 0.0) {
        return if e > 0.0 { f64::INFINITY } else { 0.0 };
    }
    n as f64 * (1.0 + e * e / s2).ln()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench_gen::gauss;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn noise_level_sees_white_noise_under_a_smooth_signal() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let s = 0.01;
        let y: Vec<f64> = (0..5000).map(|k| (k as f64 * 0.05).sin() + s * gauss(&mut rng)).collect();
        let e = noise_level(&y, 1)[0];
        assert!((e / s - 1.0).abs() < 0.1, "estimate {e} for noise {s}");
        // Negative control: the plain standard deviation of y is dominated by the signal.
        let m = y.iter().sum::<f64>() / y.len() as f64;
        let sd = (y.iter().map(|v| (v - m).powi(2)).sum::<f64>() / y.len() as f64).sqrt();
        assert!(sd / s > 50.0);
    }

    #[test]
    fn convergence_doubles_until_the_change_is_small() {
        // A first-order "simulation": y_k = truth + c / k.
        let sim = |k: usize| Some(vec![1.0 + 0.08 / k as f64; 100]);
        let c = converge(sim, 1, 64, &[1.0], 0.011);
        // Change between k and 2k is 0.04 / k: below 0.011 first at k = 4.
        assert_eq!(c.substeps, 4);
        assert!(c.converged);
        // The estimate 2 (y_k - y_2k) is the true error c / k of a first-order method.
        assert!((c.error_rms - 0.08 / 4.0).abs() < 1e-12);
        // Negative control: a cap below the needed k reports non-convergence (and the error
        // of the last k, checked against 2k).
        let c = converge(sim, 1, 2, &[1.0], 0.011);
        assert!(!c.converged && c.substeps == 2 && (c.error_rms - 0.04).abs() < 1e-12, "{c:?}");
    }

    #[test]
    fn bic_gain_of_an_error_grows_with_it() {
        assert_eq!(delta_bic_of_error(0.0, 1.0, 1000), 0.0);
        let a = delta_bic_of_error(0.1, 1.0, 1000);
        assert!((a - 1000.0 * 1.01f64.ln()).abs() < 1e-9);
        assert!(delta_bic_of_error(0.2, 1.0, 1000) > a);
    }
}
