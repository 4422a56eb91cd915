//! Feasibility of the algebraic Lyapunov inequality (ALI), `S(Pi F) <= -lambda Pi`,
//! `Pi > 0`, and the supremum of feasible `lambda` (which is `|mu|`, eq. (lammu), in
//! exact arithmetic).
//!
//! (ALI) is homogeneous in `Pi`, so here (unlike in [`crate::beta_sdp`]) the scale of
//! `Pi` is free and is fixed by `I <= Pi <= max_cond_pi I`; the bound on the condition
//! number makes the SDP compact. For each `lambda` the SDP
//! `max tau  s.t.  -(S(Pi F) + lambda Pi) >= tau I,  I <= Pi <= max_cond_pi I,  tau <= 1`
//! is always feasible and bounded (the cap on `tau` keeps `Pi` away from its upper bound
//! when there is room); `lambda` counts as feasible when the returned `Pi`
//! passes the **rigorous** check of (ALI) ([`crate::verify`]), so the reported supremum is
//! a verified lower bound of the true one (up to the condition-number bound).

use crate::error::{LmiError, Result};
use crate::psd_triangle::{sym_from_entries, symmetric_basis, triangular_number};
use crate::sdp::{LmiBuilder, SdpSettings, SdpStatus};
use crate::spectral_abscissa::{check_F, check_scalar, hurwitz_mu};
use crate::verify::{lyapunov_matrix, psd_margin, symmetrize_upper, Margin};
use nalgebra::DMatrix;

/// Settings of the feasibility problem and of the bisection.
#[derive(Debug, Clone, PartialEq)]
pub struct FeasibilitySettings {
    /// Interior-point settings. Default [`SdpSettings::default`].
    pub sdp: SdpSettings,
    /// Bound on the condition number of `Pi` (`I <= Pi <= max_cond_pi I`). Default `1e6` (at `1e8` Clarabel loses
    /// progress on some infeasible `lambda`s of the paper example).
    pub max_cond_pi: f64,
    /// Bisection stops when the bracket is shorter than `tol_bisection_rel |mu|`. Default `1e-8`.
    pub tol_bisection_rel: f64,
    /// Maximum number of bisection steps. Default `60`.
    pub max_bisection_iter: usize,
}

impl Default for FeasibilitySettings {
    fn default() -> Self {
        Self { sdp: SdpSettings::default(), max_cond_pi: 1e6, tol_bisection_rel: 1e-8, max_bisection_iter: 60 }
    }
}

impl FeasibilitySettings {
    /// `max_cond_pi > 1`, `tol_bisection_rel > 0`, finite.
    pub fn validate(&self) -> Result<()> {
        self.sdp.validate()?;
        if !(self.max_cond_pi.is_finite() && self.max_cond_pi > 1.0) {
            return Err(LmiError::InvalidSetting { name: "max_cond_pi", value: self.max_cond_pi });
        }
        if !(self.tol_bisection_rel.is_finite() && self.tol_bisection_rel > 0.0) {
            return Err(LmiError::InvalidSetting { name: "tol_bisection_rel", value: self.tol_bisection_rel });
        }
        Ok(())
    }
}

/// Outcome of the feasibility SDP at one `lambda`.
#[derive(Debug, Clone, PartialEq)]
pub struct LyapunovFeasibility {
    /// The `lambda` tested.
    pub lambda: f64,
    /// Optimal `tau` (floating point); `tau > 0` means strictly feasible numerically.
    pub tau: f64,
    /// The maximiser `Pi` (symmetric).
    pub Pi: DMatrix<f64>,
    /// Rigorous check of `-(S(Pi F) + lambda Pi) >= 0` for this `Pi`.
    pub lyapunov: Margin,
    /// `lyapunov.verified`.
    pub feasible: bool,
    /// Solver status.
    pub status: SdpStatus,
}

/// Solve the feasibility SDP (module docs) at `lambda >= 0` (any finite `lambda >= 0`;
/// `F` need not be Hurwitz, then nothing is feasible).
pub fn lyapunov_feasibility(
    F: &DMatrix<f64>,
    lambda: f64,
    settings: &FeasibilitySettings,
) -> Result<LyapunovFeasibility> {
    settings.validate()?;
    check_F(F)?;
    check_scalar("lambda", lambda)?;
    if lambda < 0.0 {
        return Err(LmiError::LambdaOutOfRange { lambda, mu: f64::NAN });
    }
    feasibility_checked(F, lambda, settings)
}

fn feasibility_checked(F: &DMatrix<f64>, lambda: f64, settings: &FeasibilitySettings) -> Result<LyapunovFeasibility> {
    let n = F.nrows();
    let m = triangular_number(n);
    let basis = symmetric_basis(n);
    let nvar = m + 1; // [Pi entries, tau]
    let I_n = DMatrix::<f64>::identity(n, n);
    let mut bld = LmiBuilder::new(nvar);
    let Mk: Vec<_> = basis.iter().cloned().map(Some).chain(std::iter::once(None)).collect();
    bld.add_psd(&-&I_n, &Mk);
    let Mk: Vec<_> = basis.iter().map(|B| Some(-B)).chain(std::iter::once(None)).collect();
    bld.add_psd(&(&I_n * settings.max_cond_pi), &Mk);
    let Mk: Vec<_> = basis
        .iter()
        .map(|B| {
            let BF = B * F;
            Some(-((&BF + BF.transpose()) * 0.5 + B * lambda))
        })
        .chain(std::iter::once(Some(-&I_n)))
        .collect();
    bld.add_psd(&DMatrix::zeros(n, n), &Mk);
    // tau <= 1: otherwise tau, homogeneous in Pi, drives Pi onto max_cond_pi I.
    let mut Mk: Vec<Option<DMatrix<f64>>> = vec![None; m];
    Mk.push(Some(DMatrix::from_element(1, 1, -1.0)));
    bld.add_psd(&DMatrix::from_element(1, 1, 1.0), &Mk);
    let mut q = vec![0.0; nvar];
    q[m] = -1.0;
    let sol = bld.solve(&q, &settings.sdp, lambda)?;
    let Pi = symmetrize_upper(&sym_from_entries(&sol.x[..m], n));
    let (N, r) = lyapunov_matrix(F, &Pi, lambda);
    let lyapunov = psd_margin(&N, r);
    Ok(LyapunovFeasibility { lambda, tau: sol.x[m], feasible: lyapunov.verified, Pi, lyapunov, status: sol.status })
}

/// Result of the bisection for the supremum of feasible `lambda`.
#[derive(Debug, Clone, PartialEq)]
pub struct LambdaSupremum {
    /// Largest `lambda` found with a rigorously verified (ALI) certificate.
    pub lambda_sup: f64,
    /// Smallest `lambda` found without one (upper end of the final bracket).
    pub lambda_not_verified: f64,
    /// `|mu|`, eq. (stab): the exact supremum.
    pub abs_mu: f64,
    /// `(|mu| - lambda_sup) / |mu|`.
    pub relative_gap: f64,
    /// The certified `Pi` at `lambda_sup`.
    pub Pi: DMatrix<f64>,
    /// Number of SDPs solved.
    pub sdp_solves: usize,
}

/// Bisection on `lambda in [0, 2 |mu|]` for the supremum of `lambda` with a verified
/// (ALI) certificate. Errors with [`LmiError::NotHurwitz`] when `mu >= 0`. SDP failures
/// count as "not verified".
pub fn sup_feasible_lambda(F: &DMatrix<f64>, settings: &FeasibilitySettings) -> Result<LambdaSupremum> {
    settings.validate()?;
    check_F(F)?;
    let mu = hurwitz_mu(F)?;
    let abs_mu = -mu;
    let mut lo = 0.0;
    let mut hi = 2.0 * abs_mu;
    let mut Pi_lo = DMatrix::<f64>::identity(F.nrows(), F.nrows());
    let mut solves = 0;
    // Start from a feasible point well inside, for a certified Pi even if bisection stalls.
    for _ in 0..settings.max_bisection_iter {
        if hi - lo <= settings.tol_bisection_rel * abs_mu {
            break;
        }
        let mid = 0.5 * (lo + hi);
        solves += 1;
        match feasibility_checked(F, mid, settings) {
            Ok(r) if r.feasible => {
                lo = mid;
                Pi_lo = r.Pi;
            }
            _ => hi = mid,
        }
    }
    Ok(LambdaSupremum {
        lambda_sup: lo,
        lambda_not_verified: hi,
        abs_mu,
        relative_gap: (abs_mu - lo) / abs_mu,
        Pi: Pi_lo,
        sdp_solves: solves,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::{paper_example, random_hurwitz_system};

    #[test]
    fn sup_lambda_equals_abs_mu() {
        let (F, _, _) = paper_example();
        let s = sup_feasible_lambda(&F, &FeasibilitySettings::default()).unwrap();
        assert!(s.lambda_sup <= s.abs_mu * (1.0 + 1e-12), "{s:?}");
        assert!(s.relative_gap < 1e-6, "{s:?}");
        for seed in [1u64, 2] {
            let (F, _, _) = random_hurwitz_system(seed, 4, 1);
            let s = sup_feasible_lambda(&F, &FeasibilitySettings::default()).unwrap();
            assert!(s.relative_gap > -1e-9 && s.relative_gap < 1e-4, "seed {seed}: {s:?}");
        }
    }

    #[test]
    fn feasible_below_infeasible_above() {
        let (F, _, _) = paper_example();
        let st = FeasibilitySettings::default();
        let below = lyapunov_feasibility(&F, 0.29, &st).unwrap();
        assert!(below.feasible && below.tau > 0.0);
        let above = lyapunov_feasibility(&F, 0.31, &st).unwrap();
        assert!(!above.feasible && above.tau < 0.0);
    }

    #[test]
    fn jordan_block_sup_is_limited_by_condition_bound() {
        // F = [[-1, 1], [0, -1]] (defective): sup over Pi with cond <= kappa is < 1 = |mu|,
        // approaching 1 as kappa grows.
        let F = DMatrix::from_row_slice(2, 2, &[-1.0, 1.0, 0.0, -1.0]);
        let tight = FeasibilitySettings { max_cond_pi: 1e2, tol_bisection_rel: 1e-4, ..Default::default() };
        let loose = FeasibilitySettings { max_cond_pi: 1e6, tol_bisection_rel: 1e-4, ..Default::default() };
        let a = sup_feasible_lambda(&F, &tight).unwrap();
        let b = sup_feasible_lambda(&F, &loose).unwrap();
        assert!(a.lambda_sup < b.lambda_sup && b.lambda_sup < 1.0, "{a:?} {b:?}");
        assert!(a.relative_gap > 1e-3);
    }

    #[test]
    fn not_hurwitz_is_error() {
        let F = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 1.0, 0.0]);
        assert!(
            matches!(sup_feasible_lambda(&F, &FeasibilitySettings::default()), Err(LmiError::NotHurwitz { mu }) if (mu - 1.0).abs() < 1e-12)
        );
    }
}
