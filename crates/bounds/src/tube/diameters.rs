//! The two sphere maxima of Theorem 2 over the output tube, from above:
//!
//! ```text
//! d                         = max_{|v|=1} sigma_{C Xi_inf + Theta}(v) + sigma_{C Xi_inf + Theta}(-v)   (d)
//! D(C(F Xi_inf + E Theta),{0}) = max_{|v|=1} sigma_{C F Xi_inf}(v) + sigma_Theta(E^T C^T v)           (zinf)
//! ```
//! Support functions of `C Xi_inf` and `C F Xi_inf` by the certified quadrature of
//! [`TubeKernel`]; the maxima by `geometry::sublinear_sphere_max` (both functions are sublinear)
//! with Lipschitz constants built from the kernels' `int ||K(s)|| ds` and `D(Theta, {0})`.
//! Used by `crate::assemble()` and by the Theorem 2 properties of the `theorems` campaign, so the
//! campaign checks the numbers that the report prints.
use crate::error::BoundsError;
use crate::tube::xi_support::SemigroupData;
use crate::tube::{Horizon, TubeKernel, TubeSettings};
use geometry::{sublinear_sphere_max, ConvexSet, Shape, SphereMaxSettings};
use nalgebra::{DMatrix, DVector};
use rounding::Enclosure;

/// `d` and `D(C(F Xi_inf + E Theta),{0})` with the kernels that produced them.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct TubeDiameters {
    /// Kernel of `sigma_{C Xi_inf}`.
    pub tube_C: TubeKernel,
    /// Kernel of `sigma_{C F Xi_inf}`.
    pub tube_CF: TubeKernel,
    /// `upper`: a proven upper bound of `d` (eq. (d)); `lower`: indicative only (best sampled
    /// value minus the quadrature widths), not a bound.
    pub d: Enclosure,
    /// As `d` for `D(C(F Xi_inf + E Theta),{0})` (eq. (zinf)).
    pub d_ftheta: Enclosure,
    /// Both upper values come from valid Lipschitz or conic-combination bounds of upper
    /// quadrature enclosures: false when a value is not finite.
    pub verified: bool,
}

fn sigma_sym(theta: &Shape, v: &[f64]) -> f64 {
    let neg: Vec<f64> = v.iter().map(|x| -x).collect();
    theta.support(v) + theta.support(&neg)
}

/// Computes [`TubeDiameters`] for `F = A + E C` (eq. (F)), output matrix `C`, loop matrix `E`
/// and the backlash set `theta`.
pub fn tube_diameters(
    C: &DMatrix<f64>,
    F: &DMatrix<f64>,
    E: &DMatrix<f64>,
    theta: &Shape,
    tube: &TubeSettings,
    sphere: &SphereMaxSettings,
) -> Result<TubeDiameters, BoundsError> {
    let d_theta = theta.deviation_from_origin().upper;
    tube_diameters_with(C, F, E, theta, d_theta, &SemigroupData::new(F), tube, sphere)
}

/// [`tube_diameters`] with `d_theta = theta.deviation_from_origin().upper` and
/// `sg = SemigroupData::new(F)` computed once by the caller (see
/// [`TubeKernel::with_shared`]); the same numbers, bit for bit.
#[allow(clippy::too_many_arguments)]
pub fn tube_diameters_with(
    C: &DMatrix<f64>,
    F: &DMatrix<f64>,
    E: &DMatrix<f64>,
    theta: &Shape,
    d_theta: f64,
    sg: &SemigroupData,
    tube: &TubeSettings,
    sphere: &SphereMaxSettings,
) -> Result<TubeDiameters, BoundsError> {
    let p = C.nrows();
    let sphere = &sphere.scaled_for_dimension(p);
    let tube_C = TubeKernel::with_shared(C, F, E, theta, d_theta, sg, Horizon::Infinite, tube)?;
    let CF = C * F;
    let tube_CF = TubeKernel::with_shared(&CF, F, E, theta, d_theta, sg, Horizon::Infinite, tube)?;

    let lip_d = 2.0 * (tube_C.lipschitz() + d_theta);
    let d_b = sublinear_sphere_max(
        p,
        |v| {
            let neg: Vec<f64> = v.iter().map(|x| -x).collect();
            tube_C.support_upper(v) + tube_C.support_upper(&neg) + sigma_sym(theta, v)
        },
        lip_d,
        &within_work(sphere, 2 * tube_C.cells()),
    );
    let d_lower = d_b.lower - 2.0 * (tube_C.remainder_bound() + tube_C.tail_bound());

    let CEt = (C * E).transpose();
    let nCE = CEt.iter().map(|x| x * x).sum::<f64>().sqrt();
    let lip_f = tube_CF.lipschitz() + nCE * d_theta * (1.0 + 1e-12);
    let df_b = sublinear_sphere_max(
        p,
        |v| {
            let w = &CEt * DVector::from_column_slice(v);
            tube_CF.support_upper(v) + theta.support(w.as_slice())
        },
        lip_f,
        &within_work(sphere, tube_CF.cells()),
    );
    // the kernel's L = fl(C F) against C F_exact (tube::cf_rounding::cf_support_error)
    let df_b = Enclosure {
        lower: df_b.lower,
        upper: df_b.upper + crate::tube::cf_rounding::cf_support_error(C, F, E, tube.f_radius, sg, d_theta),
    };
    let df_lower = df_b.lower - tube_CF.remainder_bound() - tube_CF.tail_bound();
    // The upper values are proofs when every enclosure they were built from is finite and the
    // sampled maxima lie below them (a sampled value above the bound would expose a broken
    // Lipschitz constant or a non-sublinear function).
    let verified = [d_b.upper, df_b.upper, tube_C.remainder_bound(), tube_C.tail_bound()]
        .iter()
        .chain(&[tube_CF.remainder_bound(), tube_CF.tail_bound(), lip_d, lip_f])
        .all(|x| x.is_finite())
        && d_b.lower <= d_b.upper
        && df_b.lower <= df_b.upper;
    Ok(TubeDiameters {
        tube_C,
        tube_CF,
        d: Enclosure { lower: d_lower, upper: d_b.upper },
        d_ftheta: Enclosure { lower: df_lower, upper: df_b.upper },
        verified,
    })
}

/// Most kernel cells visited by one sphere maximum (evaluations x cells per evaluation). A
/// tube of a stiff or strongly coupled plant can need tens of thousands of cells; with the full
/// evaluation budget its maximum took 40 s (fuzz finding, n = p = 4 with 30,276 cells). Beyond
/// this work the evaluation budget shrinks: the maximum stays a proven upper bound, only wider
/// (`geometry::sublinear_sphere_max` is valid whenever its budget runs out). The examples visit
/// at most 8.5e7 cells (`ellipsoid-p3`), so their numbers are unchanged.
const SPHERE_WORK: usize = 100_000_000;

/// Fewest evaluations one sphere maximum keeps under [`SPHERE_WORK`].
const MIN_SPHERE_EVALS: usize = 200;

/// `sphere` with its evaluation budget cut so that `max_evals x cells_per_eval` stays within
/// [`SPHERE_WORK`] (never below [`MIN_SPHERE_EVALS`]).
fn within_work(sphere: &SphereMaxSettings, cells_per_eval: usize) -> SphereMaxSettings {
    let affordable = (SPHERE_WORK / cells_per_eval.max(1)).max(MIN_SPHERE_EVALS);
    SphereMaxSettings { max_evals: sphere.max_evals.min(affordable), ..sphere.clone() }
}

/// The cross-section `C Xi_inf + Theta` of the tube around the orbit `eta_T` (Fig. loop of the
/// paper): its support function from above, for figures and for callers that need the tube
/// without the rest of the theta computation.
#[derive(Debug, Clone)]
pub struct OutputTube {
    /// Kernel of `sigma_{C Xi_inf}`.
    pub kernel: TubeKernel,
    /// The backlash set `Theta`.
    pub theta: Shape,
}

impl OutputTube {
    /// Builds the kernel of `sigma_{C Xi_inf}` for `sys` (`F = A + E C`, eq. (F)).
    pub fn new(sys: &model::System, tube: &TubeSettings) -> Result<Self, BoundsError> {
        let kernel = TubeKernel::new(&sys.C, &sys.F(), &sys.E, &sys.theta, Horizon::Infinite, tube)?;
        Ok(Self { kernel, theta: sys.theta.clone() })
    }

    /// Enclosure of `sigma_{C Xi_inf}(v)` (eq. (Xinfsupp) with `u = C^T v`).
    pub fn tube_support(&self, v: &[f64]) -> Enclosure {
        self.kernel.support_bounds(v)
    }

    /// Upper bound of `sigma_{C Xi_inf + Theta}(v)`.
    pub fn support_upper(&self, v: &[f64]) -> f64 {
        self.kernel.support_upper(v) + self.theta.support(v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sphere_budget_is_cut_only_beyond_the_work_limit() {
        let s = SphereMaxSettings { tol_abs: 1e-9, tol_rel: 1e-6, max_evals: 20_000 };
        // ellipsoid-p3's largest maximum (2 x 2,128 cells): unchanged
        assert_eq!(within_work(&s, 2 * 2128).max_evals, 20_000);
        // the fuzz finding's 30,276 cells: cut to what 1e8 visits allow
        assert_eq!(within_work(&s, 30_276).max_evals, SPHERE_WORK / 30_276);
        assert!(within_work(&s, 30_276).max_evals < 20_000);
        // never below the floor, and no division by zero for an empty kernel
        assert_eq!(within_work(&s, 400_000 * 2).max_evals, MIN_SPHERE_EVALS);
        assert_eq!(within_work(&s, 0).max_evals, 20_000);
        assert_eq!(within_work(&s, 30_276).tol_rel, s.tol_rel);
    }
}
