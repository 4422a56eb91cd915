//! Outer search over `lambda in (0, |mu|)` (eq. (lammu)) minimising a user-supplied
//! `theta(lambda, beta)` (the driver passes eq. (theta) built from `alpha`, `gamma_1`,
//! `gamma_inf` through `psi` of eq. (phipsi)).
//!
//! For each `lambda` the minimal `beta` is computed by the SDP of [`crate::beta_sdp`] and
//! **verified** ([`crate::verify`]); `theta` is then evaluated at the verified pair
//! `(lambda_v, b_hat)` (with `lambda_v <= lambda`, `b_hat >= beta`): `theta` is evaluated
//! exactly at a certified pair, so every point of the curve is a valid bound without any
//! monotonicity assumption on `theta`.
//!
//! Search: a uniform grid `lambda_i = |mu| i / (N + 1)`, `i = 1..N`, then golden-section
//! refinement on the bracket around the best grid point. SDP or verification failures
//! at some `lambda` become gaps (reported, and treated as `+inf` by the refinement).

use crate::beta_memo::BetaMemo;
use crate::beta_sdp::{BetaSdpSettings, BetaSdpSolution};
use crate::error::{LmiError, Result};
use crate::spectral_abscissa::{check_system, hurwitz_mu};
use crate::verify::Certificate;
use nalgebra::DMatrix;

/// Settings of the outer search.
#[derive(Debug, Clone, PartialEq)]
pub struct LambdaSearchSettings {
    /// Settings of each beta SDP. Default [`BetaSdpSettings::default`].
    pub beta: BetaSdpSettings,
    /// Number `N` of interior grid points. Default `12`.
    pub grid_points: usize,
    /// Golden-section refinement stops when the bracket is shorter than
    /// `tol_lambda_rel |mu|`. Default `1e-4`.
    pub tol_lambda_rel: f64,
    /// Maximum number of golden-section steps. Default `40`.
    pub max_golden_iter: usize,
}

impl Default for LambdaSearchSettings {
    fn default() -> Self {
        Self { beta: BetaSdpSettings::default(), grid_points: 12, tol_lambda_rel: 1e-4, max_golden_iter: 40 }
    }
}

impl LambdaSearchSettings {
    /// `grid_points >= 2`, `tol_lambda_rel` in `(0, 1)`, nested settings valid.
    pub fn validate(&self) -> Result<()> {
        self.beta.validate()?;
        if self.grid_points < 2 {
            return Err(LmiError::InvalidSetting { name: "grid_points", value: self.grid_points as f64 });
        }
        if !(self.tol_lambda_rel > 0.0 && self.tol_lambda_rel < 1.0) {
            return Err(LmiError::InvalidSetting { name: "tol_lambda_rel", value: self.tol_lambda_rel });
        }
        Ok(())
    }
}

/// A successfully certified point of the curve `theta(lambda)`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct CurveValue {
    /// Verified `lambda_v` (`<=` the requested one).
    pub lambda: f64,
    /// Verified bound `b_hat >= beta`.
    pub beta: f64,
    /// SDP optimum `beta` (floating point).
    pub beta_sdp: f64,
    /// `theta(lambda_v, b_hat)`.
    pub theta: f64,
}

/// One evaluation of the curve: a value or the reason for a gap.
#[derive(Debug, Clone, PartialEq)]
pub struct CurvePoint {
    /// Requested `lambda`.
    pub lambda: f64,
    /// Certified value, or the error that left a gap at this `lambda`.
    pub value: std::result::Result<CurveValue, LmiError>,
}

/// The optimum of the search.
#[derive(Debug, Clone, PartialEq)]
pub struct LambdaOptimum {
    /// Certified value at the optimum.
    pub value: CurveValue,
    /// SDP solution there (`Pi`, status, ...).
    pub solution: BetaSdpSolution,
    /// Its certificate (contains the certified `Pi`).
    pub certificate: Certificate,
}

/// Result of [`optimise_lambda`].
#[derive(Debug, Clone, PartialEq)]
pub struct LambdaSearch {
    /// Best certified point.
    pub optimum: LambdaOptimum,
    /// Every evaluation, sorted by requested `lambda` (grid and refinement).
    pub curve: Vec<CurvePoint>,
    /// Requested `lambda`s that failed, with the reason (also in `curve`).
    pub gaps: Vec<(f64, LmiError)>,
    /// `|mu|`.
    pub abs_mu: f64,
}

/// Minimise `theta(lambda, beta)` over `lambda in (0, |mu|)`, see the module docs.
///
/// Errors: input validation, [`LmiError::NotHurwitz`], [`LmiError::NoCertificate`] when
/// no `lambda` produced a certificate. A NaN from `theta` makes a gap
/// ([`LmiError::ThetaNaN`]).
pub fn optimise_lambda<T>(
    F: &DMatrix<f64>,
    E: &DMatrix<f64>,
    C: &DMatrix<f64>,
    theta: T,
    settings: &LambdaSearchSettings,
) -> Result<LambdaSearch>
where
    T: FnMut(f64, f64) -> f64,
{
    optimise_lambda_memo(F, E, C, theta, settings, &mut BetaMemo::new())
}

/// [`optimise_lambda`] with the beta SDPs taken from (and added to) `memo`: several searches
/// over one problem with different objectives solve each `lambda` once ([`BetaMemo`]). The
/// result is the one [`optimise_lambda`] gives, bit for bit.
pub fn optimise_lambda_memo<T>(
    F: &DMatrix<f64>,
    E: &DMatrix<f64>,
    C: &DMatrix<f64>,
    mut theta: T,
    settings: &LambdaSearchSettings,
    memo: &mut BetaMemo,
) -> Result<LambdaSearch>
where
    T: FnMut(f64, f64) -> f64,
{
    settings.validate()?;
    check_system(F, E, C)?;
    let mu = hurwitz_mu(F)?;
    let abs_mu = -mu;
    let mut curve: Vec<CurvePoint> = Vec::new();
    let mut best: Option<LambdaOptimum> = None;

    let mut eval = |lambda: f64, curve: &mut Vec<CurvePoint>, best: &mut Option<LambdaOptimum>| -> f64 {
        let value = memo.certified(F, E, C, lambda, mu, &settings.beta).and_then(|cb| {
            let (l, b) = (cb.certificate.lambda, cb.certificate.b_hat);
            let t = theta(l, b);
            if t.is_nan() {
                return Err(LmiError::ThetaNaN { lambda: l, beta: b });
            }
            let v = CurveValue { lambda: l, beta: b, beta_sdp: cb.solution.beta, theta: t };
            if best.as_ref().is_none_or(|o| t < o.value.theta) {
                *best = Some(LambdaOptimum { value: v, solution: cb.solution, certificate: cb.certificate });
            }
            Ok(v)
        });
        let t = value.as_ref().map(|v| v.theta).unwrap_or(f64::INFINITY);
        curve.push(CurvePoint { lambda, value });
        t
    };

    let N = settings.grid_points;
    let h = abs_mu / (N as f64 + 1.0);
    let mut grid_vals = Vec::with_capacity(N);
    for i in 1..=N {
        grid_vals.push(eval(h * i as f64, &mut curve, &mut best));
    }
    let failures = grid_vals.iter().filter(|t| !t.is_finite()).count();
    // Best grid index (ties: smallest lambda).
    let ibest = grid_vals
        .iter()
        .enumerate()
        .filter(|(_, t)| t.is_finite())
        .min_by(|a, b| a.1.total_cmp(b.1))
        .map(|(i, _)| i + 1);
    if let Some(i) = ibest {
        // Golden section on [lambda_{i-1}, lambda_{i+1}] (endpoints 0 and |mu| never evaluated).
        let phi = 0.5 * (5f64.sqrt() - 1.0);
        let (mut a, mut c) = (h * (i as f64 - 1.0), h * (i as f64 + 1.0));
        let mut x1 = c - phi * (c - a);
        let mut x2 = a + phi * (c - a);
        let mut f1 = eval(x1, &mut curve, &mut best);
        let mut f2 = eval(x2, &mut curve, &mut best);
        for _ in 0..settings.max_golden_iter {
            if c - a <= settings.tol_lambda_rel * abs_mu {
                break;
            }
            if f1 <= f2 {
                c = x2;
                x2 = x1;
                f2 = f1;
                x1 = c - phi * (c - a);
                f1 = eval(x1, &mut curve, &mut best);
            } else {
                a = x1;
                x1 = x2;
                f1 = f2;
                x2 = a + phi * (c - a);
                f2 = eval(x2, &mut curve, &mut best);
            }
        }
    }
    curve.sort_by(|p, q| p.lambda.total_cmp(&q.lambda));
    let gaps: Vec<(f64, LmiError)> =
        curve.iter().filter_map(|p| p.value.as_ref().err().map(|e| (p.lambda, e.clone()))).collect();
    match best {
        Some(optimum) => Ok(LambdaSearch { optimum, curve, gaps, abs_mu }),
        None => Err(LmiError::NoCertificate { abs_mu, failures: failures.max(gaps.len()) }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::paper_example;
    use approx::assert_relative_eq;

    /// psi(0) of eq. (psilim) as theta: sqrt(beta + (alpha - lambda)^2/4) - (alpha + lambda)/2.
    fn psi0(alpha: f64) -> impl Fn(f64, f64) -> f64 {
        move |l: f64, b: f64| (b + 0.25 * (alpha - l).powi(2)).sqrt() - 0.5 * (alpha + l)
    }

    #[test]
    fn finds_interior_minimum_and_curve_is_consistent() {
        let (F, E, C) = paper_example();
        let s = LambdaSearchSettings::default();
        let res = optimise_lambda(&F, &E, &C, psi0(0.0), &s).unwrap();
        assert_relative_eq!(res.abs_mu, 0.3, epsilon = 1e-12);
        let opt = res.optimum.value;
        assert!(opt.lambda > 0.0 && opt.lambda < 0.3);
        assert!(res.optimum.certificate.verified);
        // The optimum is no worse than every certified curve point.
        let ok: Vec<CurveValue> = res.curve.iter().filter_map(|p| p.value.as_ref().ok().copied()).collect();
        assert!(ok.len() >= s.grid_points);
        for v in &ok {
            assert!(opt.theta <= v.theta + 1e-15);
            assert_relative_eq!(v.theta, psi0(0.0)(v.lambda, v.beta), max_relative = 1e-14);
        }
        // Golden refinement: the optimum is at least as good as the best grid point and
        // the neighbouring evaluations bracket it.
        assert!(res.curve.len() > s.grid_points);
        assert!(res.gaps.is_empty(), "{:?}", res.gaps);
    }

    #[test]
    fn failures_become_gaps_not_panics() {
        let (F, E, C) = paper_example();
        // theta returning NaN on part of the interval creates gaps; the search still works.
        let res = optimise_lambda(
            &F,
            &E,
            &C,
            |l, b| if l > 0.2 { f64::NAN } else { b - l },
            &LambdaSearchSettings::default(),
        )
        .unwrap();
        assert!(!res.gaps.is_empty());
        assert!(res.gaps.iter().all(|(l, e)| *l > 0.2 && matches!(e, LmiError::ThetaNaN { .. })));
        assert!(res.optimum.value.lambda <= 0.2);
        // All evaluations fail: an error value.
        let r = optimise_lambda(&F, &E, &C, |_, _| f64::NAN, &LambdaSearchSettings::default());
        assert!(matches!(r, Err(LmiError::NoCertificate { .. })));
        // Iteration limit at every lambda also gives gaps -> NoCertificate.
        let mut st = LambdaSearchSettings::default();
        st.beta.sdp.max_iter = 1;
        let r = optimise_lambda(&F, &E, &C, psi0(0.0), &st);
        assert!(matches!(r, Err(LmiError::NoCertificate { failures, .. }) if failures == st.grid_points));
    }
}
