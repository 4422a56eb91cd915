//! Simulation fit metrics on a segment `[k0, k1)` of the sample grid, per output `i`:
//! `fit_i = 100 (1 - ||y_i - yhat_i|| / ||y_i - mean(y_i)||)` (NRMSE fit, 100 = perfect,
//! 0 = no better than the mean, negative = worse) and `rmse_i = ||y_i - yhat_i|| / sqrt(N)`.
//!
//! Fit % divides by the spread of the measured segment: when the segment is (nearly)
//! constant, the ratio is meaningless (a spread at rounding level gave fit % of -1e16). Such
//! a segment is detected against the output's own scale ([`TOL_CONSTANT`]) and its fit % is
//! left undefined (`None`, JSON `null`); decisions then rest on the RMSE (selection uses
//! SSE ratios throughout, so it is unaffected).
use serde::Serialize;

/// A segment counts as constant when its standard deviation is at most `TOL_CONSTANT` times
/// the standard deviation of the same signal over the whole record (or, for a signal constant
/// throughout, at most `1e-12 max |y|`). Default `1e-3`.
pub const TOL_CONSTANT: f64 = 1e-3;

/// Fit of one simulation on one segment.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Fit {
    /// Fit % per output; `None` where the measured segment is (nearly) constant.
    pub fit_percent: Vec<Option<f64>>,
    /// RMSE per output (units of y).
    pub rmse: Vec<f64>,
    /// Fit % of the velocity `dy/dt` (central differences of y and yhat after a 5-point
    /// moving average of both, same filter on both), per output. Plain fit % saturates
    /// near 100 % when a loop tracks its reference tightly; the derived velocity does not.
    /// `None` where the measured velocity is (nearly) constant on the segment.
    pub velocity_fit_percent: Vec<Option<f64>>,
    /// Outputs (0-based) whose measured segment is (nearly) constant: fit % undefined, judge
    /// by the RMSE.
    pub constant_outputs: Vec<usize>,
}

fn mean_std(a: &[f64]) -> (f64, f64) {
    let n = a.len().max(1) as f64;
    let mean = a.iter().sum::<f64>() / n;
    (mean, (a.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / n).sqrt())
}

/// Whether `a` is (nearly) constant against `scale`, the standard deviation of the same
/// signal over the whole record (see [`TOL_CONSTANT`]).
pub fn is_constant(a: &[f64], scale: f64) -> bool {
    let (_, sd) = mean_std(a);
    let maxabs = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    sd <= (TOL_CONSTANT * scale).max(1e-12 * maxabs).max(f64::MIN_POSITIVE)
}

/// `100 (1 - ||a - b|| / ||a - mean a||)`, or `None` when `a` is (nearly) constant against
/// `scale` ([`is_constant`]).
pub fn fit_percent(a: &[f64], b: &[f64], scale: f64) -> Option<f64> {
    if is_constant(a, scale) {
        return None;
    }
    let (mean, _) = mean_std(a);
    let num = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt();
    let den = a.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>().sqrt();
    Some(100.0 * (1.0 - num / den))
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

/// Fit of `yhat` against `y` (both flat, `p` outputs) on `[k0, k1)`; the scales that decide
/// whether a segment is constant are taken over the whole of `y`.
pub fn fit(y: &[f64], yhat: &[f64], p: usize, k0: usize, k1: usize, dt: f64) -> Fit {
    let mut f = Fit { fit_percent: vec![], rmse: vec![], velocity_fit_percent: vec![], constant_outputs: vec![] };
    let n = y.len() / p.max(1);
    for i in 0..p {
        let whole = column(y, p, i, 0, n);
        let (_, scale) = mean_std(&whole);
        let (_, vscale) = mean_std(&velocity(&whole, dt));
        let a = column(y, p, i, k0, k1);
        let b = column(yhat, p, i, k0, k1);
        let fp = fit_percent(&a, &b, scale);
        if fp.is_none() {
            f.constant_outputs.push(i);
        }
        f.fit_percent.push(fp);
        f.rmse.push(rmse(&a, &b));
        f.velocity_fit_percent.push(fit_percent(&velocity(&a, dt), &velocity(&b, dt), vscale));
    }
    f
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn fit_percent_known_values() {
        let a = [1.0, -1.0, 1.0, -1.0];
        assert_eq!(fit_percent(&a, &a, 1.0), Some(100.0));
        assert!((fit_percent(&a, &[0.0; 4], 1.0).unwrap() - 0.0).abs() < 1e-12);
        assert!((fit_percent(&a, &[0.5, -0.5, 0.5, -0.5], 1.0).unwrap() - 50.0).abs() < 1e-12);
        assert!((rmse(&a, &[0.0; 4]) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn constant_validation_output_leaves_fit_undefined() {
        // A record that moves, then rests at 0.3 with rounding-level wiggle (variance ~1e-32):
        // the plain formula gave about -1.4e16 %; now fit % is None and the RMSE decides.
        let n = 200;
        let y: Vec<f64> = (0..n)
            .map(|k| if k < 140 { (k as f64 * 0.1).sin() } else { 0.3 + if k % 2 == 0 { 1e-16 } else { 0.0 } })
            .collect();
        let yhat: Vec<f64> = y.iter().map(|v| v + 1e-3).collect();
        let f = fit(&y, &yhat, 1, 140, n, 0.01);
        assert_eq!(f.fit_percent, vec![None]);
        assert_eq!(f.constant_outputs, vec![0]);
        assert!((f.rmse[0] - 1e-3).abs() < 1e-12, "{:?}", f.rmse);
        assert!(f.velocity_fit_percent[0].is_none());
        let j = serde_json::to_string(&f).unwrap();
        assert!(j.contains("\"fit_percent\":[null]") && !j.contains("e16"), "{j}");
        // Negative control: the estimation segment moves, so its fit % is defined and finite.
        let g = fit(&y, &yhat, 1, 0, 140, 0.01);
        assert!(g.fit_percent[0].is_some_and(|v| v > 99.0 && v <= 100.0), "{g:?}");
        assert!(g.constant_outputs.is_empty());
        // A segment with a small but real motion (1 % of the record's spread) keeps its fit %.
        let small: Vec<f64> = (0..60).map(|k| 0.01 * (k as f64 * 0.3).sin()).collect();
        assert!(fit_percent(&small, &small, 0.7).is_some());
        // A record constant throughout: undefined for any scale.
        assert!(fit_percent(&[2.0; 50], &[2.1; 50], 0.0).is_none());
    }
}
