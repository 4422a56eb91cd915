//! The dominant Floquet multiplier of the periodic regime, measured from the same pairs of
//! trajectories as [`super::lyapunov_exponent`], without the oscillation of `ln V`.
//!
//! When the slowest multipliers of the regime are a complex pair `rho e^{+-i phi}`, the
//! difference of two trajectories turns by `phi` per period inside an ellipse, so `ln V` wobbles
//! around its trend and a regression over a finite window is off by up to the wobble's amplitude
//! over the window length; its Student-t interval, which treats the wobble as independent noise,
//! is far narrower than that error. This module reads the differences `d_j = (X, Q)` at the ends
//! of the periods instead, fits the linear map `d_j -> d_{j+1}` on the subspace they span (dynamic
//! mode decomposition: `D1 ~ M D0`, `M` restricted to the leading left singular vectors of `D0`),
//! and reports `ln rho(M) / T`. For a regime with a fixed switching structure the map between
//! nearby trajectories over one period is the monodromy matrix up to `O(|d|)`, so `rho(M)` is the
//! dominant multiplier whatever its phase.
//!
//! The interval: the window is cut into three consecutive blocks and the map fitted on each; the
//! spread of the three exponents (Student-t, 2 degrees of freedom) measures what the finite
//! separation and the not yet decayed faster modes leave. The stepping error is not in it: run
//! with `RateSettings::step_check` to add it.
use nalgebra::{DMatrix, DVector};
use serde::Serialize;

/// Relative prediction residual at which the rank of the fitted map stops growing.
const RANK_RESIDUAL: f64 = 1e-7;
/// Singular values below this fraction of the largest are noise (the pairs' nonlinear terms and
/// the stepping's kinks are ~1e-5..1e-3 of the differences), not modes.
const RANK_FLOOR: f64 = 1e-6;
/// Blocks of the window for the interval.
const BLOCKS: usize = 3;

/// The dominant multiplier's exponent `ln rho / T` with its interval.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MultiplierRate {
    pub exponent: f64,
    pub ci_low: f64,
    pub ci_high: f64,
    pub std_error: f64,
    /// Rank of the fitted map (number of modes the differences still carry).
    pub rank: usize,
    /// Relative residual `|D1 - M D0|_F / |D1|_F` of the fit over the whole window.
    pub residual: f64,
    /// Moduli of the fitted multipliers, largest first.
    pub moduli: Vec<f64>,
    /// True when the largest two have the same modulus and a non-zero phase (a complex pair).
    pub complex_pair: bool,
}

/// One period of one pair: the difference at the start (after any renormalisation) and at the
/// end (before it).
#[derive(Debug, Clone)]
pub struct Transition {
    pub start: DVector<f64>,
    pub end: DVector<f64>,
}

struct Fit {
    rho: f64,
    rank: usize,
    residual: f64,
    eig: Vec<nalgebra::Complex<f64>>,
}

/// Fits `end ~ M start` over `transitions` (each column scaled by `1 / |start|`) with rank
/// `rank` (at most the number of usable singular values), or, when `None`, the smallest rank
/// whose residual is below [`RANK_RESIDUAL`] or which one more mode does not halve.
fn fit(transitions: &[&Transition], rank: Option<usize>) -> Option<Fit> {
    let m = transitions.first()?.start.len();
    let k = transitions.len();
    let mut d0 = DMatrix::<f64>::zeros(m, k);
    let mut d1 = DMatrix::<f64>::zeros(m, k);
    for (c, t) in transitions.iter().enumerate() {
        let s = t.start.norm();
        if !(s > 0.0 && s.is_finite()) {
            return None;
        }
        d0.set_column(c, &(&t.start / s));
        d1.set_column(c, &(&t.end / s));
    }
    let svd = d0.clone().svd(true, true);
    let (u, vt) = (svd.u?, svd.v_t?);
    // nalgebra's singular values are not sorted: order them
    let mut order: Vec<usize> = (0..svd.singular_values.len()).collect();
    order.sort_by(|&a, &b| svd.singular_values[b].total_cmp(&svd.singular_values[a]));
    let s1 = svd.singular_values[order[0]];
    let usable = order.iter().take_while(|&&i| svd.singular_values[i] > RANK_FLOOR * s1).count();
    let norm1 = d1.norm();
    let fit_rank = |r: usize| -> Fit {
        let ur = DMatrix::from_fn(m, r, |i, j| u[(i, order[j])]);
        let vr = DMatrix::from_fn(k, r, |i, j| vt[(order[j], i)]);
        let sinv = DMatrix::from_fn(r, r, |i, j| if i == j { 1.0 / svd.singular_values[order[i]] } else { 0.0 });
        let a = ur.transpose() * &d1 * &vr * sinv;
        let pred = &ur * &a * ur.transpose() * &d0;
        let residual = (&d1 - pred).norm() / norm1;
        let eig: Vec<_> = a.complex_eigenvalues().iter().copied().collect();
        let rho = eig.iter().map(|z| z.norm()).fold(0.0, f64::max);
        Fit { rho, rank: r, residual, eig }
    };
    match rank {
        Some(r) => (usable >= 1).then(|| fit_rank(r.clamp(1, usable))),
        None => {
            // the smallest rank after which one more mode no longer halves the residual: the
            // modes beyond it fit the nonlinear and stepping noise, not the map
            let mut best = fit_rank(1);
            for r in 2..=usable {
                if best.residual < RANK_RESIDUAL {
                    break;
                }
                let f = fit_rank(r);
                if f.residual > 0.5 * best.residual {
                    break;
                }
                best = f;
            }
            Some(best)
        }
    }
}

/// The dominant multiplier from the transitions of all pairs over the measured window
/// (`per_pair[pair][j]`, `j` counting periods after the transient); `None` when the window is
/// too short (fewer than two transitions per block) or the differences vanished.
pub fn dominant_multiplier(per_pair: &[Vec<Transition>], period: f64) -> Option<MultiplierRate> {
    let len = per_pair.iter().map(Vec::len).min()?;
    if len < 2 * BLOCKS {
        return None;
    }
    let all: Vec<&Transition> = per_pair.iter().flat_map(|p| p.iter()).collect();
    let whole = fit(&all, None)?;
    if !(whole.rho > 0.0 && whole.rho.is_finite()) {
        return None;
    }
    let exponent = whole.rho.ln() / period;
    let block_len = len / BLOCKS;
    let blocks: Vec<f64> = (0..BLOCKS)
        .filter_map(|b| {
            let cols: Vec<&Transition> =
                per_pair.iter().flat_map(|p| p[b * block_len..(b + 1) * block_len].iter()).collect();
            let rank = whole.rank.min(cols.len().saturating_sub(1)).max(1);
            fit(&cols, Some(rank)).map(|f| f.rho.ln() / period).filter(|e| e.is_finite())
        })
        .collect();
    let std_error = if blocks.len() == BLOCKS {
        let mean = blocks.iter().sum::<f64>() / BLOCKS as f64;
        let var = blocks.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (BLOCKS - 1) as f64;
        // the whole-window fit is not worse than the blocks' mean: standard error of the mean
        (var / BLOCKS as f64).sqrt()
    } else {
        f64::INFINITY
    };
    // a floor for the rounding of ln rho (an exponent of 1e-17 relative is not a measurement)
    let std_error = std_error.max(4.0 * f64::EPSILON * exponent.abs().max(1.0 / period));
    let half = crate::rate::statistics::t_quantile_975(BLOCKS - 1) * std_error;
    let mut moduli: Vec<f64> = whole.eig.iter().map(|z| z.norm()).collect();
    moduli.sort_by(|a, b| b.total_cmp(a));
    let top = whole.eig.iter().copied().max_by(|a, b| a.norm().total_cmp(&b.norm()));
    let complex_pair = top.is_some_and(|z| z.im.abs() > 1e-9 * z.norm());
    Some(MultiplierRate {
        exponent,
        ci_low: exponent - half,
        ci_high: exponent + half,
        std_error,
        rank: whole.rank,
        residual: whole.residual,
        moduli,
        complex_pair,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn transitions(m: &DMatrix<f64>, d0: &DVector<f64>, periods: usize, renorm: bool) -> Vec<Transition> {
        let mut d = d0.clone();
        (0..periods)
            .map(|_| {
                let end = m * &d;
                let t = Transition { start: d.clone(), end: end.clone() };
                d = if renorm { &end / end.norm() } else { end };
                t
            })
            .collect()
    }

    /// A complex pair `0.5 e^{+-0.3 i}` beside a real 0.1: the regression of `ln |d|^2` wobbles,
    /// the fitted map finds `ln 0.5` to rounding.
    #[test]
    fn complex_pair_is_found_exactly() {
        let (r, phi) = (0.5_f64, 0.3_f64);
        // a rotation in a skewed basis, so |d| oscillates
        let basis = DMatrix::from_row_slice(3, 3, &[1.0, 0.9, 0.0, 0.0, 0.2, 0.0, 0.3, 0.1, 1.0]);
        let core = DMatrix::from_row_slice(
            3,
            3,
            &[r * phi.cos(), -r * phi.sin(), 0.0, r * phi.sin(), r * phi.cos(), 0.0, 0.0, 0.0, 0.1],
        );
        let m = &basis * core * basis.clone().try_inverse().unwrap();
        let pairs = vec![
            transitions(&m, &DVector::from_vec(vec![1.0, 0.2, -0.4]), 21, true),
            transitions(&m, &DVector::from_vec(vec![-0.3, 1.0, 0.5]), 21, true),
        ];
        let got = dominant_multiplier(&pairs, 2.0).unwrap();
        let truth = r.ln() / 2.0;
        assert!((got.exponent - truth).abs() < 1e-9, "{} vs {truth}", got.exponent);
        assert!(got.ci_low <= truth && truth <= got.ci_high);
        assert!(got.complex_pair);
        // negative control: the wobble of ln |d| moves the regression's slope off the truth by
        // far more than the fitted map's error
        let logs: Vec<f64> = pairs[0]
            .iter()
            .scan(0.0, |acc, t| {
                *acc += (t.end.norm() / t.start.norm()).ln();
                Some(*acc)
            })
            .collect();
        let ts: Vec<f64> = (1..=logs.len()).map(|j| 2.0 * j as f64).collect();
        let (b, _) = crate::rate::statistics::regression_slope(&ts, &logs);
        assert!((b - truth).abs() > 1e-3, "the regression happens to be exact: {b} vs {truth}");
    }

    /// A real dominant multiplier with a slower-decaying second mode still present.
    #[test]
    fn real_dominant_with_a_second_mode() {
        let m = DMatrix::from_row_slice(2, 2, &[0.8, 0.3, 0.0, 0.4]);
        let pairs = vec![transitions(&m, &DVector::from_vec(vec![0.1, 1.0]), 12, false)];
        let got = dominant_multiplier(&pairs, 1.0).unwrap();
        assert!((got.exponent - 0.8_f64.ln()).abs() < 1e-9, "{}", got.exponent);
        assert!(!got.complex_pair);
        assert_eq!(got.rank, 2);
    }

    #[test]
    fn too_short_a_window_gives_none() {
        let m = DMatrix::from_row_slice(1, 1, &[0.5]);
        let pairs = vec![transitions(&m, &DVector::from_vec(vec![1.0]), 4, false)];
        assert!(dominant_multiplier(&pairs, 1.0).is_none());
    }
}
