//! Simulation fit metrics on a segment `[k0, k1)` of the sample grid, per output `i`:
//! `fit_i = 100 (1 - ||y_i - yhat_i|| / ||y_i - mean(y_i)||)` (NRMSE fit, 100 = perfect,
//! 0 = no better than the mean, negative = worse) and `rmse_i = ||y_i - yhat_i|| / sqrt(N)`.
use serde::Serialize;

/// Fit of one simulation on one segment.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Fit {
    /// Fit % per output.
    pub fit_percent: Vec<f64>,
    /// RMSE per output (units of y).
    pub rmse: Vec<f64>,
    /// Fit % of the velocity `dy/dt` (central differences of y and yhat after a 5-point
    /// moving average of both, same filter on both), per output. Plain fit % saturates
    /// near 100 % when a loop tracks its reference tightly; the derived velocity does not.
    pub velocity_fit_percent: Vec<f64>,
}

/// `100 (1 - ||a - b|| / ||a - mean a||)`.
pub fn fit_percent(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().max(1) as f64;
    let mean = a.iter().sum::<f64>() / n;
    let num = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt();
    let den = a.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>().sqrt();
    if den == 0.0 {
        return if num == 0.0 { 100.0 } else { f64::NEG_INFINITY };
    }
    100.0 * (1.0 - num / den)
}

/// Root mean square of `a - b`.
pub fn rmse(a: &[f64], b: &[f64]) -> f64 {
    (a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>() / a.len().max(1) as f64).sqrt()
}

/// Smoothed central-difference derivative (5-point moving average, then central difference).
pub fn velocity(a: &[f64], dt: f64) -> Vec<f64> {
    let n = a.len();
    let sm: Vec<f64> = (0..n)
        .map(|k| {
            let lo = k.saturating_sub(2);
            let hi = (k + 3).min(n);
            a[lo..hi].iter().sum::<f64>() / (hi - lo) as f64
        })
        .collect();
    (0..n).map(|k| if k == 0 || k + 1 == n { 0.0 } else { (sm[k + 1] - sm[k - 1]) / (2.0 * dt) }).collect()
}

/// Column `i` of a flat row-major signal with `p` columns on `[k0, k1)`.
pub fn column(flat: &[f64], p: usize, i: usize, k0: usize, k1: usize) -> Vec<f64> {
    (k0..k1).map(|k| flat[k * p + i]).collect()
}

/// Fit of `yhat` against `y` (both flat, `p` outputs) on `[k0, k1)`.
pub fn fit(y: &[f64], yhat: &[f64], p: usize, k0: usize, k1: usize, dt: f64) -> Fit {
    let mut f = Fit { fit_percent: vec![], rmse: vec![], velocity_fit_percent: vec![] };
    for i in 0..p {
        let a = column(y, p, i, k0, k1);
        let b = column(yhat, p, i, k0, k1);
        f.fit_percent.push(fit_percent(&a, &b));
        f.rmse.push(rmse(&a, &b));
        f.velocity_fit_percent.push(fit_percent(&velocity(&a, dt), &velocity(&b, dt)));
    }
    f
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn fit_percent_known_values() {
        let a = [1.0, -1.0, 1.0, -1.0];
        assert_eq!(fit_percent(&a, &a), 100.0);
        assert!((fit_percent(&a, &[0.0; 4]) - 0.0).abs() < 1e-12);
        assert!((fit_percent(&a, &[0.5, -0.5, 0.5, -0.5]) - 50.0).abs() < 1e-12);
        assert!((rmse(&a, &[0.0; 4]) - 1.0).abs() < 1e-12);
    }
}
