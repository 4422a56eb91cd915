//! Residual analysis of a simulation error `e = y - yhat`: whiteness (autocorrelation) and
//! independence from the input (cross-correlation), with confidence bounds.
//!
//! Normalised autocorrelation `r_e(tau) = sum_k e_k e_{k+tau} / sum_k e_k^2`. Under the
//! hypothesis that `e` is white, `sqrt(N) r_e(tau)` is approximately standard normal for
//! `tau >= 1`, so the 99 % bound is `2.576 / sqrt(N)` and the portmanteau statistic
//! `Q = N sum_{tau=1}^{M} r_e(tau)^2` is approximately chi-square with `M` degrees of freedom.
//! For the cross-correlation `r_eu(tau)` with a (possibly coloured) input, the variance of
//! `sqrt(N) r_eu(tau)` is `P = sum_k r_e(k) r_u(k)` (Ljung, System Identification, 16.6); the
//! bound is `2.576 sqrt(P / N)` and `Q_eu = N / P sum_{|tau| <= M} r_eu(tau)^2` ~ chi2(2M+1).
use serde::Serialize;

/// Result of the whiteness / cross-correlation tests.
#[derive(Debug, Clone, Serialize)]
pub struct ResidualTests {
    /// Lags tested (M).
    pub lags: usize,
    /// Lag spacing in samples (the residual is decimated so that M lags span the slowest
    /// time constant).
    pub lag_step: usize,
    /// Autocorrelation `r_e(tau)`, `tau = 1..M` (times `lag_step` samples).
    pub autocorr: Vec<f64>,
    /// Its 99 % bound `2.576 / sqrt(N)`.
    pub autocorr_bound: f64,
    /// Portmanteau statistic and its 99 % chi-square threshold.
    pub q_auto: f64,
    pub q_auto_threshold: f64,
    /// Cross-correlation with each input, `tau = -M..M`.
    pub crosscorr: Vec<Vec<f64>>,
    pub crosscorr_bound: Vec<f64>,
    pub q_cross: Vec<f64>,
    pub q_cross_threshold: f64,
    /// `e` white at the 1 % level.
    pub white: bool,
    /// `e` uncorrelated with every input at the 1 % level.
    pub uncorrelated: bool,
    /// Mean of the residual and its 99 % bound `2.576 std(e) / sqrt(N)` (a constant offset is
    /// invisible to the centred correlations, so it is tested on its own).
    pub mean: f64,
    pub mean_bound: f64,
    pub zero_mean: bool,
}

/// Upper `alpha` quantile of chi-square with `k` degrees of freedom (Wilson-Hilferty).
pub fn chi2_quantile(k: usize, z: f64) -> f64 {
    let k = k as f64;
    let a = 2.0 / (9.0 * k);
    k * (1.0 - a + z * a.sqrt()).powi(3)
}

fn xcorr(a: &[f64], b: &[f64], tau: isize) -> f64 {
    let n = a.len() as isize;
    let mut s = 0.0;
    for k in 0..n {
        let j = k + tau;
        if j >= 0 && j < n {
            s += a[k as usize] * b[j as usize];
        }
    }
    s
}

fn centred(a: &[f64]) -> Vec<f64> {
    let m = a.iter().sum::<f64>() / a.len() as f64;
    a.iter().map(|x| x - m).collect()
}

/// Runs the tests on residual `e` and inputs `u[j]` (each a series of the same length),
/// decimated by `lag_step` (averaging blocks), with `lags` lags.
pub fn test(e: &[f64], u: &[Vec<f64>], lags: usize, lag_step: usize) -> ResidualTests {
    let dec =
        |a: &[f64]| -> Vec<f64> { a.chunks(lag_step.max(1)).map(|c| c.iter().sum::<f64>() / c.len() as f64).collect() };
    let raw = dec(e);
    let n = raw.len();
    let mean = raw.iter().sum::<f64>() / n as f64;
    let e = centred(&raw);
    let sd = (e.iter().map(|x| x * x).sum::<f64>() / n as f64).sqrt();
    let mean_bound = 2.576 * sd / (n as f64).sqrt();
    let m = lags.min(n / 4).max(1);
    let ee = xcorr(&e, &e, 0).max(1e-300);
    let r_e: Vec<f64> = (0..=m).map(|t| xcorr(&e, &e, t as isize) / ee).collect();
    let nf = n as f64;
    let z99 = 2.576;
    let q_auto = nf * r_e[1..].iter().map(|r| r * r).sum::<f64>();
    let q_auto_threshold = chi2_quantile(m, 2.326);
    let mut crosscorr = Vec::new();
    let mut bounds = Vec::new();
    let mut q_cross = Vec::new();
    for uj in u {
        let uj = centred(&dec(uj));
        let uu = xcorr(&uj, &uj, 0).max(1e-300);
        let r_u: Vec<f64> = (0..=m).map(|t| xcorr(&uj, &uj, t as isize) / uu).collect();
        let pvar = (r_e[0] * r_u[0] + 2.0 * (1..=m).map(|k| r_e[k] * r_u[k]).sum::<f64>()).max(1e-3);
        let norm = (ee * uu).sqrt();
        let c: Vec<f64> = (-(m as isize)..=m as isize).map(|t| xcorr(&e, &uj, t) / norm).collect();
        q_cross.push(nf / pvar * c.iter().map(|r| r * r).sum::<f64>());
        bounds.push(z99 * (pvar / nf).sqrt());
        crosscorr.push(c);
    }
    let q_cross_threshold = chi2_quantile(2 * m + 1, 2.326);
    let white = q_auto <= q_auto_threshold;
    let uncorrelated = q_cross.iter().all(|&q| q <= q_cross_threshold);
    ResidualTests {
        lags: m,
        lag_step,
        autocorr: r_e[1..].to_vec(),
        autocorr_bound: z99 / nf.sqrt(),
        q_auto,
        q_auto_threshold,
        crosscorr,
        crosscorr_bound: bounds,
        q_cross,
        q_cross_threshold,
        white,
        uncorrelated,
        mean,
        mean_bound,
        zero_mean: mean.abs() <= mean_bound,
    }
}

/// The tests of every output of a time-major residual `e` (`n` samples of `p` outputs) against
/// every input of `w` (`n` samples of `m` inputs): white, uncorrelated and zero-mean only when
/// every output is; the statistics are those of the first output.
pub fn test_outputs(e: &[f64], w: &[f64], n: usize, m: usize, p: usize, lags: usize, lag_step: usize) -> ResidualTests {
    let mut t: Option<ResidualTests> = None;
    let us: Vec<Vec<f64>> = (0..m).map(|j| (0..n).map(|k| w[k * m + j]).collect()).collect();
    for i in 0..p {
        let ei: Vec<f64> = (0..n).map(|k| e[k * p + i]).collect();
        let ti = test(&ei, &us, lags, lag_step);
        t = Some(match t {
            None => ti,
            Some(prev) => {
                let (white, unc, zm) =
                    (prev.white && ti.white, prev.uncorrelated && ti.uncorrelated, prev.zero_mean && ti.zero_mean);
                ResidualTests { white, uncorrelated: unc, zero_mean: zm, ..prev }
            }
        });
    }
    t.expect("p >= 1")
}

/// Whether some output's mean of the time-major residual `e` (`n` samples of `p` outputs) is
/// off zero beyond its 1 % bound (blocks of `lag_step` samples, as [`test`]) widened for the
/// output's AR(1) noise colour `rho[i]`: a mean of AR(1) noise has `(1 + rho) / (1 - rho)` times
/// the variance of a mean of white noise. A missing offset leaves a residual that is white
/// about a non-zero mean.
pub fn mean_off_zero(e: &[f64], n: usize, p: usize, rho: &[f64], lag_step: usize) -> bool {
    (0..p).any(|i| {
        let ei: Vec<f64> = (0..n).map(|k| e[k * p + i]).collect();
        let t = test(&ei, &[], 1, lag_step);
        let r = rho.get(i).copied().unwrap_or(0.0).clamp(0.0, 0.99);
        t.mean.abs() > t.mean_bound * ((1.0 + r) / (1.0 - r)).sqrt()
    })
}

/// A time-major residual `e` (`n` samples of `p` outputs) with an AR(1) filter removed from
/// each output: `e_k - rho e_{k-1}`, `rho` the output's lag-one autocorrelation (clamped to
/// [0, 0.99]); the filtered residual and the `rho` of each output. Coloured measurement noise
/// (AR(1)) leaves an exact model's residual non-white, and its filtered residual white; a model
/// error the filter cannot account for leaves the filtered residual non-white too.
pub fn prewhiten_ar1(e: &[f64], n: usize, p: usize) -> (Vec<f64>, Vec<f64>) {
    let mut out = vec![0.0; e.len()];
    let mut rhos = Vec::with_capacity(p);
    for i in 0..p {
        let col = centred(&(0..n).map(|k| e[k * p + i]).collect::<Vec<_>>());
        let rho = (xcorr(&col, &col, 1) / xcorr(&col, &col, 0).max(1e-300)).clamp(0.0, 0.99);
        for k in 1..n {
            out[k * p + i] = col[k] - rho * col[k - 1];
        }
        out[i] = col[0] * (1.0 - rho * rho).sqrt();
        rhos.push(rho);
    }
    (out, rhos)
}

/// The largest lag-one autocorrelation over the outputs of a time-major residual `e` (`n`
/// samples of `p` outputs), clamped to [0, 0.99] as in [`prewhiten_ar1`].
pub fn ar1_rho(e: &[f64], n: usize, p: usize) -> f64 {
    prewhiten_ar1(e, n, p).1.into_iter().fold(0.0, f64::max)
}

/// `(1 - rho)/(1 + rho)`: the share of independent samples in AR(1)-coloured residuals with
/// lag-one autocorrelation `rho` (clamped to [0, 0.99]; a NaN counts as white). BIC differences
/// counted as if every residual were independent are overstated by its inverse.
pub fn independent_share(rho: f64) -> f64 {
    let rho = if rho.is_finite() { rho.clamp(0.0, 0.99) } else { 0.0 };
    (1.0 - rho) / (1.0 + rho)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn white_noise_passes_and_filtered_noise_fails() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let e: Vec<f64> = (0..4000).map(|_| rng.random::<f64>() - 0.5).collect();
        let u: Vec<f64> = (0..4000).map(|k| (k as f64 * 0.05).sin()).collect();
        let t = test(&e, std::slice::from_ref(&u), 20, 1);
        assert!(t.white && t.uncorrelated, "{t:?}");
        // Negative controls: coloured residual, residual driven by the input.
        let mut f = vec![0.0; e.len()];
        for k in 1..e.len() {
            f[k] = 0.8 * f[k - 1] + e[k];
        }
        assert!(!test(&f, std::slice::from_ref(&u), 20, 1).white);
        let g: Vec<f64> = e.iter().zip(&u).map(|(a, b)| a + 0.3 * b).collect();
        assert!(!test(&g, std::slice::from_ref(&u), 20, 1).uncorrelated);
        // A constant offset passes the centred tests but not the mean test.
        let o: Vec<f64> = e.iter().map(|a| a + 0.05).collect();
        let t = test(&o, &[u], 20, 1);
        assert!(t.white && !t.zero_mean, "{t:?}");
    }

    /// Two outputs, time-major: white noise about zero passes; an offset on the second output
    /// alone is found; AR(1) noise (0.9) about zero passes once its colour widens the bound and
    /// fails without (negative control: the widening is what lets coloured noise through).
    #[test]
    fn mean_off_zero_finds_an_offset_on_any_output_and_allows_for_colour() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let n = 4000;
        let e: Vec<f64> = (0..2 * n).map(|_| rng.random::<f64>() - 0.5).collect();
        assert!(!mean_off_zero(&e, n, 2, &[0.0, 0.0], 1));
        let off: Vec<f64> = e.iter().enumerate().map(|(j, v)| v + if j % 2 == 1 { 0.05 } else { 0.0 }).collect();
        assert!(mean_off_zero(&off, n, 2, &[0.0, 0.0], 1));
        let (mut found_plain, mut found_widened) = (0, 0);
        for seed in 0..20 {
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(100 + seed);
            let mut f = vec![0.0; n];
            for k in 1..n {
                f[k] = 0.9 * f[k - 1] + rng.random::<f64>() - 0.5;
            }
            found_plain += usize::from(mean_off_zero(&f, n, 1, &[0.0], 1));
            found_widened += usize::from(mean_off_zero(&f, n, 1, &[0.9], 1));
        }
        assert!(found_widened <= 1, "{found_widened} of 20 coloured records called off zero");
        assert!(found_plain >= 5, "only {found_plain} of 20: the widening is not what passes them");
    }

    #[test]
    fn chi2_quantile_close_to_table() {
        // chi2_{0.99}(20) = 37.566
        assert!((chi2_quantile(20, 2.326) - 37.566).abs() < 0.2);
    }
}
