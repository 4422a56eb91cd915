//! The small statistics of the measurements: a least-squares slope with its standard error and
//! the Student-t quantile of its 95 % interval.

/// Two-sided 95% Student-t quantile (Cornish-Fisher expansion; exact to ~1e-3 for nu >= 3).
pub fn t_quantile_975(nu: usize) -> f64 {
    let z: f64 = 1.959963984540054;
    let v = nu.max(1) as f64;
    match nu {
        1 => 12.706,
        2 => 4.303,
        _ => {
            z + (z.powi(3) + z) / (4.0 * v)
                + (5.0 * z.powi(5) + 16.0 * z.powi(3) + 3.0 * z) / (96.0 * v * v)
                + (3.0 * z.powi(7) + 19.0 * z.powi(5) + 17.0 * z.powi(3) - 15.0 * z) / (384.0 * v.powi(3))
        }
    }
}

/// Least-squares slope of `(t, y)` with its standard error.
pub fn regression_slope(t: &[f64], y: &[f64]) -> (f64, f64) {
    let k = t.len() as f64;
    let tm = t.iter().sum::<f64>() / k;
    let ym = y.iter().sum::<f64>() / k;
    let stt: f64 = t.iter().map(|a| (a - tm) * (a - tm)).sum();
    let sty: f64 = t.iter().zip(y).map(|(a, b)| (a - tm) * (b - ym)).sum();
    let b = sty / stt;
    let ssr: f64 = t.iter().zip(y).map(|(a, c)| (c - ym - b * (a - tm)).powi(2)).sum();
    let se = if t.len() > 2 { (ssr / (k - 2.0) / stt).sqrt() } else { f64::INFINITY };
    (b, se)
}
