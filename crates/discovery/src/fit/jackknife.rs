//! Model-error spread of fitted parameters: a delete-a-group jackknife over contiguous folds
//! of the estimation segment.
//!
//! The Gauss-Newton and sandwich variances of [`crate::fit::levenberg_marquardt`] describe the
//! scatter that noise alone would cause if the model were exact. When it is not (the true
//! plant is discretised differently, the effect's law is only close to the truth, an
//! unmodelled effect lives in some regimes), the best-fitting parameters depend on which part
//! of the record they are fitted to, and that dependence is what the residual statistics cannot
//! see. The jackknife measures it directly: the estimation segment `[0, k_est)` is cut into
//! `g` contiguous folds, the selected model is refitted with each fold left out of the
//! residual (the simulation still runs through it; warm-started from the full estimate, a few
//! Levenberg-Marquardt iterations), and
//!
//! `var_jack = (g - 1) / g * sum_j (theta_(j) - mean_j theta_(j))^2`,
//!
//! the delete-a-group jackknife variance of the full-segment estimate (it contains the noise
//! scatter as well as the model-error spread, with `g - 1` degrees of freedom).
//!
//! The reported 1-sigma is [`combine`]d: `max(s_stat, c s_jack)` with `s_stat` the larger of
//! Gauss-Newton and the sandwich and `c = t_(g-1)(0.975) / 1.96` ([`t_factor`], 1.42 for 5
//! folds): a jackknife variance from `g` groups has `g - 1` degrees of freedom, so its 95 %
//! interval is `+- t_(g-1)(0.975) s_jack`, and the factor keeps `+- 2 sigma` at that coverage.
//! Both parts estimate the same scatter where the model is exact (the jackknife's folds carry
//! the noise too), and the jackknife alone sees the model-error spread: the larger of the two
//! counts the noise once. (Their sum in quadrature counted it twice: on 167 fresh benchmark
//! cases, 87 % of the truths lay within 1 sigma and 99.4 % within 2, against 68 % and 95 %
//! claimed; the larger gives 79 % and 97 %, BENCHMARKS "Sigma: the noise counted once".)
//! `+- 1 sigma` holds more than 68 % by design: the widening is for `+- 2 sigma`. A model error
//! that shifts every fold alike (a bias constant over the record) is seen by no resampling and
//! is not covered; the report says so.
use crate::fit::{fit_estimate, FitSettings, FitStatus, Problem};
use rayon::prelude::*;
use serde::Serialize;

/// The jackknife of one fitted hypothesis.
#[derive(Debug, Clone, Serialize)]
pub struct Jackknife {
    /// Held-out folds `[b0, b1)` (samples of the estimation segment).
    pub folds: Vec<(usize, usize)>,
    /// Estimates with each fold left out: effect parameters, then freed nominal parameters
    /// (physical units); folds whose refit failed, or accepted no step, are left out.
    pub estimates: Vec<Vec<f64>>,
    /// Jackknife standard deviation of each effect parameter (`NaN` where fewer than two
    /// refits succeeded; not yet widened by [`t_factor`]).
    pub std: Vec<f64>,
    /// The same for the freed nominal parameters.
    pub nominal_std: Vec<f64>,
}

/// Contiguous folds of `[0, n)`.
pub fn folds(n: usize, g: usize) -> Vec<(usize, usize)> {
    (0..g).map(|j| (j * n / g, (j + 1) * n / g)).collect()
}

/// Delete-a-group jackknife standard deviation of each coordinate of `estimates` (one row per
/// left-out group): `sqrt((g - 1) / g * sum_j (theta_j - mean)^2)`. `NaN` for fewer than two
/// rows or a non-finite entry.
pub fn jackknife_std(estimates: &[Vec<f64>]) -> Vec<f64> {
    let g = estimates.len();
    let k = estimates.first().map_or(0, |r| r.len());
    (0..k)
        .map(|i| {
            if g < 2 || estimates.iter().any(|r| !r.get(i).is_some_and(|v| v.is_finite())) {
                return f64::NAN;
            }
            let mean = estimates.iter().map(|r| r[i]).sum::<f64>() / g as f64;
            let ss: f64 = estimates.iter().map(|r| (r[i] - mean).powi(2)).sum();
            ((g as f64 - 1.0) / g as f64 * ss).sqrt()
        })
        .collect()
}

/// `t_(dof)(0.975) / z(0.975)`: the factor by which a standard deviation estimated with `dof`
/// degrees of freedom is widened so that `+- 2` of it keeps 95 % coverage (Student's t; a
/// table to 30 degrees of freedom, the Cornish-Fisher expansion beyond). `NaN` for `dof = 0`.
pub fn t_factor(dof: usize) -> f64 {
    const T975: [f64; 30] = [
        12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160, 2.145, 2.131,
        2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048, 2.045, 2.042,
    ];
    let z = 1.959_963_985;
    match dof {
        0 => f64::NAN,
        1..=30 => T975[dof - 1] / z,
        _ => {
            let v = dof as f64;
            (z + (z.powi(3) + z) / (4.0 * v) + (5.0 * z.powi(5) + 16.0 * z.powi(3) + 3.0 * z) / (96.0 * v * v)) / z
        }
    }
}

/// The jackknife's part of the reported sigma: its standard deviation from `groups` refits
/// times [`t_factor`]`(groups - 1)`.
pub fn jackknife_part(jack: f64, groups: usize) -> f64 {
    jack * t_factor(groups.saturating_sub(1))
}

/// The reported 1-sigma from the statistical one (`max(Gauss-Newton, sandwich)`) and the
/// jackknife's part ([`jackknife_part`]): the larger, since both estimate the noise scatter and
/// the jackknife adds the model-error spread. A `NaN` jackknife (too few refits) leaves `stat`;
/// a `NaN` `stat` (not identifiable) stays `NaN`.
pub fn combine(stat: f64, jack: f64) -> f64 {
    if !jack.is_finite() || stat.is_nan() {
        return stat;
    }
    stat.max(jack)
}

/// The full-segment estimate the folds are refitted from (physical units).
#[derive(Debug, Clone, Copy)]
pub struct Estimate<'b> {
    /// Effect parameters.
    pub theta: &'b [f64],
    /// Freed nominal parameters (empty without a grey-box refit).
    pub nominal: &'b [f64],
    /// Initial state.
    pub x0: &'b [f64],
}

/// Refits the hypothesis of `full` with each of `g` contiguous folds of `[0, k_est)` left out.
/// `problem(fold)` builds the problem with that fold excluded (the same hypothesis and freed
/// nominal parameters as the full fit, residual on `[0, k_est)`); `x_scale` as for [`fit`]
/// (empty: the initial state is fixed at `full.x0`); `iters` Levenberg-Marquardt iterations
/// from the full estimate.
#[allow(clippy::too_many_arguments)]
pub fn refit_folds<'a, F>(
    problem: F,
    full: Estimate,
    x_scale: &[f64],
    k_est: usize,
    g: usize,
    iters: usize,
    settings: &FitSettings,
    parallel: bool,
) -> Jackknife
where
    F: Fn((usize, usize)) -> Problem<'a> + Sync,
{
    let fl = folds(k_est, g);
    let fs = FitSettings { max_iter_start: iters, max_iter: 0, ..settings.clone() };
    let one = |&f: &(usize, usize)| -> Option<Vec<f64>> {
        let mut pb = problem(f);
        // The freed nominal parameters start from the full fit, as the effects do.
        if let Some(r) = pb.refit.as_mut() {
            r.values = full.nominal.to_vec();
        }
        let r = fit_estimate(&pb, full.x0, x_scale, Some(full.theta), &fs);
        if !r.sse.is_finite() || r.status == FitStatus::Failed {
            return None;
        }
        // A refit that accepted no step is no estimate: the optimum without the fold is closer
        // than the solver can resolve (e.g. the kinked cost of stick-slip on a long record).
        // Counting it would claim a zero spread that was never measured.
        if r.theta == full.theta && r.nominal == full.nominal {
            return None;
        }
        Some(r.theta.iter().chain(&r.nominal).copied().collect())
    };
    let est: Vec<Option<Vec<f64>>> =
        if parallel { fl.par_iter().map(one).collect() } else { fl.iter().map(one).collect() };
    let estimates: Vec<Vec<f64>> = est.into_iter().flatten().collect();
    let k = full.theta.len();
    let all = if estimates.len() < 2 { vec![f64::NAN; k + full.nominal.len()] } else { jackknife_std(&estimates) };
    Jackknife { folds: fl, estimates, std: all[..k].to_vec(), nominal_std: all[k..].to_vec() }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jackknife_of_a_mean_is_the_standard_error() {
        // Delete-a-group jackknife of a sample mean over g equal groups: the leave-one-group-out
        // means give exactly s_groupmeans / sqrt(g), the standard error of the overall mean.
        let groups = [[1.0, 3.0], [2.0, 6.0], [0.0, 4.0], [5.0, 1.0], [2.0, 2.0]];
        let all: Vec<f64> = groups.iter().flatten().copied().collect();
        let g = groups.len();
        let loo: Vec<Vec<f64>> = (0..g)
            .map(|j| {
                let v: Vec<f64> =
                    groups.iter().enumerate().filter(|(i, _)| *i != j).flat_map(|(_, r)| r.iter().copied()).collect();
                vec![v.iter().sum::<f64>() / v.len() as f64]
            })
            .collect();
        let jack = jackknife_std(&loo)[0];
        let gm: Vec<f64> = groups.iter().map(|r| (r[0] + r[1]) / 2.0).collect();
        let gmean = gm.iter().sum::<f64>() / g as f64;
        let s2 = gm.iter().map(|m| (m - gmean).powi(2)).sum::<f64>() / (g as f64 - 1.0);
        let se = (s2 / g as f64).sqrt();
        assert!((jack - se).abs() < 1e-12, "jackknife {jack} vs standard error {se} (n = {})", all.len());
        // Identical estimates: zero spread; too few: undefined.
        assert_eq!(jackknife_std(&[vec![2.0], vec![2.0], vec![2.0]])[0], 0.0);
        assert!(jackknife_std(&[vec![2.0]])[0].is_nan());
        assert!(jackknife_std(&[vec![2.0], vec![f64::NAN]])[0].is_nan());
    }

    #[test]
    fn the_combined_sigma_is_the_larger_part() {
        for (s, j) in [(1.0, 0.0), (1.0, 3.0), (0.2, 0.1), (0.0, 0.5)] {
            assert_eq!(combine(s, j), f64::max(s, j), "combine({s}, {j})");
        }
        // Negative control: the noise is not counted twice (the quadrature sum was 1.414 here).
        assert_eq!(combine(1.0, 1.0), 1.0);
        // A zero-spread jackknife (or a failed one) cannot shrink the statistical sigma.
        assert_eq!(combine(0.3, 0.0), 0.3);
        assert_eq!(combine(0.3, f64::NAN), 0.3);
        assert!(combine(f64::NAN, 0.2).is_nan());
    }

    #[test]
    fn t_factor_matches_students_t() {
        // t_4(0.975) = 2.776: five folds widen the jackknife part by 1.416.
        assert!((t_factor(4) - 2.776 / 1.959_963_985).abs() < 1e-9);
        assert!((jackknife_part(1.0, 5) - 1.416).abs() < 1e-3);
        // The expansion continues the table (t_30 = 2.042, t_40 = 2.021, t_120 = 1.980) and
        // tends to 1.
        assert!((t_factor(31) * 1.959_963_985 - 2.040).abs() < 2e-3);
        assert!((t_factor(40) * 1.959_963_985 - 2.021).abs() < 2e-3);
        assert!((t_factor(120) * 1.959_963_985 - 1.980).abs() < 2e-3);
        assert!((2..200).all(|d| t_factor(d) < t_factor(d - 1)) && t_factor(100_000) > 1.0);
        assert!(t_factor(0).is_nan());
    }

    #[test]
    fn folds_cover_the_segment_contiguously() {
        let f = folds(1003, 5);
        assert_eq!(f.first().unwrap().0, 0);
        assert_eq!(f.last().unwrap().1, 1003);
        assert!(f.windows(2).all(|w| w[0].1 == w[1].0 && w[0].1 > w[0].0));
    }
}
