//! Simulation fit metrics on a segment `[k0, k1)` of the sample grid, per output `i`:
//! `fit_i = 100 (1 - ||y_i - yhat_i|| / ||y_i - mean(y_i)||)` (NRMSE fit, 100 = perfect,
//! 0 = no better than the mean, negative = worse) and `rmse_i = ||y_i - yhat_i|| / sqrt(N)`.
//!
//! Fit % divides by the spread of the measured segment: when the segment is (nearly)
//! constant, the ratio is meaningless (a spread at rounding level gave fit % of -1e16). Such
//! a segment is detected against the output's own scale ([`TOL_CONSTANT`]) and its fit % is
//! left undefined (`None`, JSON `null`); decisions then rest on the RMSE (selection uses
//! SSE ratios throughout, so it is unaffected).
//!
//! Servo-grade metrics: a tightly tracking position loop fits 99.9 % whether or not the model
//! is right, so fit % hides the result. [`headline_rmse`] then states the RMSE in the output's units
//! (`[signals] y = "m"` in the model file) before -> after, and the same for the derived
//! velocity ([`velocity`]: a filtered differentiation, identical on measurement and
//! simulation) with its own fit %.
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
    /// RMSE of the derived velocity (units of y per second), per output.
    pub velocity_rmse: Vec<f64>,
    /// Outputs (0-based) whose measured segment is (nearly) constant: fit % undefined, judge
    /// by the RMSE.
    pub constant_outputs: Vec<usize>,
    /// Fit % of the tracking error `e = w_ref - y` per output, when the model names each
    /// output's reference input (`[signals] reference = "w1"`; empty otherwise): the share of
    /// the loop's own error the model predicts. Its RMSE is the output's (`e - e_hat = y_hat -
    /// y`); its fit % does not saturate as the output's does in a tight loop. See
    /// [`tracking_fit`].
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub tracking_fit_percent: Vec<Option<f64>>,
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

/// Smoothed central-difference derivative (5-point moving average, then central difference):
/// the FIR differentiator `v_k = (sum_{j=-2..2} a_{k+1+j} - a_{k-1+j}) / (10 dt)`, exact for
/// a linear ramp, with gain `|sin(w dt) sin(5 w dt / 2)| / (5 dt sin(w dt / 2))` (a low-pass
/// differentiator: first zero at a fifth of the sampling rate), so quantisation and sensor
/// noise are not amplified as by a plain difference. The end samples (where the window is
/// cut) are averaged over what is there; the first and last velocity are 0.
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

/// Fit % of the tracking error on `[k0, k1)`: for output `i` with reference input
/// `reference[i]`, `e = w_ref - y` against `e_hat = w_ref - yhat` ([`fit_percent`], the scale
/// deciding "constant" taken over the whole record). `y`, `yhat` flat with `p` columns, `w`
/// flat with `m` columns; empty when `reference` is.
pub fn tracking_fit(
    y: &[f64],
    yhat: &[f64],
    w: &[f64],
    (p, m): (usize, usize),
    reference: &[usize],
    k0: usize,
    k1: usize,
) -> Vec<Option<f64>> {
    let n = y.len() / p.max(1);
    reference
        .iter()
        .enumerate()
        .take(p)
        .map(|(i, &j)| {
            if j >= m || w.len() < n * m {
                return None;
            }
            let err = |out: &[f64], k: usize| w[k * m + j] - out[k * p + i];
            let whole: Vec<f64> = (0..n).map(|k| err(y, k)).collect();
            let (_, scale) = mean_std(&whole);
            let a: Vec<f64> = (k0..k1).map(|k| err(y, k)).collect();
            let b: Vec<f64> = (k0..k1).map(|k| err(yhat, k)).collect();
            fit_percent(&a, &b, scale)
        })
        .collect()
}

/// Fit of `yhat` against `y` (both flat, `p` outputs) on `[k0, k1)`; the scales that decide
/// whether a segment is constant are taken over the whole of `y`.
pub fn fit(y: &[f64], yhat: &[f64], p: usize, k0: usize, k1: usize, dt: f64) -> Fit {
    let mut f = Fit {
        fit_percent: vec![],
        rmse: vec![],
        velocity_fit_percent: vec![],
        velocity_rmse: vec![],
        constant_outputs: vec![],
        tracking_fit_percent: vec![],
    };
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
        let (va, vb) = (velocity(&a, dt), velocity(&b, dt));
        f.velocity_fit_percent.push(fit_percent(&va, &vb, vscale));
        f.velocity_rmse.push(rmse(&va, &vb));
    }
    f
}

/// Units that take an SI prefix in reports (others are printed in scientific notation).
const SI_UNITS: [&str; 12] = ["m", "rad", "V", "A", "N", "Nm", "N m", "s", "W", "Pa", "m/s", "rad/s"];

/// `v` in `unit` for a report: with an SI prefix for the usual units (`1.6e-5 m` ->
/// `16.0 um`), else `1.600e-5 unit` (no unit: the number alone).
pub fn fmt_quantity(v: f64, unit: &str) -> String {
    if !v.is_finite() {
        return format!("{v}{}", if unit.is_empty() { String::new() } else { format!(" {unit}") });
    }
    if SI_UNITS.contains(&unit) && v != 0.0 {
        let prefixes = [(1e-9, "n"), (1e-6, "u"), (1e-3, "m"), (1.0, ""), (1e3, "k"), (1e6, "M")];
        let a = v.abs();
        let (f, pre) = prefixes.iter().rev().find(|(f, _)| a >= *f).copied().unwrap_or(prefixes[0]);
        let x = v / f;
        let digits = if x.abs() >= 99.95 {
            0
        } else if x.abs() >= 9.995 {
            1
        } else {
            2
        };
        return format!("{x:.digits$} {pre}{unit}");
    }
    if unit.is_empty() {
        format!("{v:.4e}")
    } else {
        format!("{v:.4e} {unit}")
    }
}

/// Scale of a figure axis whose data reach `max_abs` in `unit`: `(divisor, axis unit)`, the
/// data to be divided by `divisor`. The usual units (and their `/s` rates) take an SI prefix
/// (`2e-5 rad` -> `(1e-6, "urad")`, ticks `-20 .. 20`; the data lie in 0.1 .. 100 of the
/// axis unit); other units and unitless data small or large get a power of 1000 written into
/// the label (`(1e-6, "1e-6 deg")`, `(1e-6,
/// "x 1e-6")`); else `(1, unit)`.
pub fn axis_scale(max_abs: f64, unit: &str) -> (f64, String) {
    // the data in 0.1 .. 100 of the chosen unit
    let pow = if max_abs.is_finite() && max_abs > 0.0 { ((max_abs.log10() + 1.0) / 3.0).floor() as i32 } else { 0 };
    let base = unit.strip_suffix("/s").unwrap_or(unit);
    if SI_UNITS.contains(&base) && (-3..=2).contains(&pow) {
        let pre = ["n", "u", "m", "", "k", "M"][(pow + 3) as usize];
        return (10f64.powi(3 * pow), format!("{pre}{unit}"));
    }
    if pow == 0 {
        return (1.0, unit.to_string());
    }
    let f = 10f64.powi(3 * pow);
    if unit.is_empty() {
        (f, format!("x 1e{}", 3 * pow))
    } else {
        (f, format!("1e{} {unit}", 3 * pow))
    }
}

/// Unit of the derivative of a signal in `unit` (`m` -> `m/s`; none -> `1/s`).
pub fn per_second(unit: &str) -> String {
    if unit.is_empty() {
        "1/s".into()
    } else {
        format!("{unit}/s")
    }
}

/// Whether the servo-grade headline applies: some validation fit % above `threshold`.
pub fn saturated(before: &Fit, after: &Fit, threshold: f64) -> bool {
    before.fit_percent.iter().chain(&after.fit_percent).flatten().any(|f| *f > threshold)
}

fn pct(v: Option<f64>) -> String {
    v.map_or(
        "undefined".into(),
        |x| if x.abs() >= 99.0 && x.abs() < 100.0 { format!("{x:.2}") } else { format!("{x:.1}") },
    )
}

/// The servo-grade headline: per output, the validation RMSE in its unit before -> after
/// (with fit %), and the derived velocity's RMSE and fit % before -> after.
pub fn headline_rmse(before: &Fit, after: &Fit, units: &[String]) -> String {
    let p = before.rmse.len();
    (0..p)
        .map(|i| {
            let u = units.get(i).map_or("", |s| s.as_str());
            let vu = per_second(u);
            let tracking = match (before.tracking_fit_percent.get(i), after.tracking_fit_percent.get(i)) {
                (Some(b), Some(a)) => format!("; tracking-error fit {} -> {} %", pct(*b), pct(*a)),
                _ => String::new(),
            };
            format!(
                "{}validation RMSE {} -> {} (fit {} -> {} %); velocity RMSE {} -> {} (velocity fit {} -> {} %){tracking}",
                if p > 1 { format!("y{}: ", i + 1) } else { String::new() },
                fmt_quantity(before.rmse[i], u),
                fmt_quantity(after.rmse[i], u),
                pct(before.fit_percent[i]),
                pct(after.fit_percent[i]),
                fmt_quantity(before.velocity_rmse[i], &vu),
                fmt_quantity(after.velocity_rmse[i], &vu),
                pct(before.velocity_fit_percent[i]),
                pct(after.velocity_fit_percent[i]),
            )
        })
        .collect::<Vec<_>>()
        .join("; ")
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
    fn velocity_is_exact_on_a_ramp_and_quantities_take_prefixes() {
        let dt = 1e-3;
        let a: Vec<f64> = (0..50).map(|k| 2.5 * k as f64 * dt).collect();
        let v = velocity(&a, dt);
        for (k, x) in v.iter().enumerate().take(47).skip(3) {
            assert!((x - 2.5).abs() < 1e-9, "k = {k}: {x}");
        }
        // Noise is attenuated: alternating +-1 (the Nyquist rate) gives a small velocity
        // against the plain difference's 2 / dt.
        let alt: Vec<f64> = (0..50).map(|k| if k % 2 == 0 { 1.0 } else { -1.0 }).collect();
        let va = velocity(&alt, dt);
        assert!(va[10..40].iter().all(|x| x.abs() <= 0.2 / dt + 1e-9), "{:?}", &va[10..14]);
        assert_eq!(fmt_quantity(1.6e-5, "m"), "16.0 um");
        assert_eq!(fmt_quantity(3.1e-6, "m"), "3.10 um");
        assert_eq!(fmt_quantity(0.52, "rad"), "520 mrad");
        assert_eq!(fmt_quantity(2.0e-3, "m/s"), "2.00 mm/s");
        assert_eq!(fmt_quantity(1.5e-5, ""), "1.5000e-5");
        assert_eq!(fmt_quantity(1.5e-5, "deg"), "1.5000e-5 deg");
        assert_eq!(per_second("m"), "m/s");
        // figure axes: +-2e-5 rad in urad (no "0.0 / -0.0 / 0.0" ticks), rates too
        assert_eq!(axis_scale(2e-5, "rad"), (1e-6, "urad".to_string()));
        assert_eq!(axis_scale(0.05, "rad"), (1e-3, "mrad".to_string()));
        assert_eq!(axis_scale(0.4, "rad"), (1.0, "rad".to_string()));
        assert_eq!(axis_scale(3.0, "rad/s"), (1.0, "rad/s".to_string()));
        assert_eq!(axis_scale(2e-5, ""), (1e-6, "x 1e-6".to_string()));
        assert_eq!(axis_scale(2e-5, "deg"), (1e-6, "1e-6 deg".to_string()));
        assert_eq!(axis_scale(0.4, ""), (1.0, String::new()));
        let f = |r: f64, fp: f64| Fit {
            fit_percent: vec![Some(fp)],
            rmse: vec![r],
            velocity_fit_percent: vec![Some(80.0)],
            velocity_rmse: vec![r * 10.0],
            constant_outputs: vec![],
            tracking_fit_percent: vec![],
        };
        let (b, a) = (f(1.6e-5, 99.91), f(3.1e-6, 99.98));
        assert!(saturated(&b, &a, 99.0));
        let h = headline_rmse(&b, &a, &["m".to_string()]);
        assert!(h.contains("RMSE 16.0 um -> 3.10 um") && h.contains("velocity RMSE 160 um/s"), "{h}");
        // Negative control: a loose fit is not saturated.
        assert!(!saturated(&f(0.1, 80.0), &f(0.05, 90.0), 99.0));
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

    #[test]
    fn tracking_error_fit_does_not_saturate_in_a_tight_loop() {
        // y tracks w within a small error e; a model that predicts e well and one that claims
        // perfect tracking both fit y above 99 %, only the tracking-error fit tells them apart
        let n = 400;
        let w: Vec<f64> = (0..n).map(|k| (k as f64 * 0.05).sin()).collect();
        let e: Vec<f64> = (0..n).map(|k| 0.005 * (k as f64 * 0.05).cos()).collect();
        let y: Vec<f64> = w.iter().zip(&e).map(|(a, b)| a - b).collect();
        let good: Vec<f64> = w.iter().zip(&e).map(|(a, b)| a - 0.9 * b).collect();
        let perfect = w.clone();
        let (fg, fp) = (fit(&y, &good, 1, 0, n, 0.05), fit(&y, &perfect, 1, 0, n, 0.05));
        assert!(fg.fit_percent[0].unwrap() > 99.0 && fp.fit_percent[0].unwrap() > 99.0);
        let tg = tracking_fit(&y, &good, &w, (1, 1), &[0], 0, n);
        let tp = tracking_fit(&y, &perfect, &w, (1, 1), &[0], 0, n);
        assert!((tg[0].unwrap() - 90.0).abs() < 0.1, "{tg:?}");
        assert!(tp[0].unwrap().abs() < 5.0, "a model claiming perfect tracking predicts none of the error: {tp:?}");
        // no reference named: nothing computed
        assert!(tracking_fit(&y, &good, &w, (1, 1), &[], 0, n).is_empty());
    }
}
