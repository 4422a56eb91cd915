//! The rounding of the product `L = fl(C F)` against `C F_exact` in the tube kernels of
//! `C F Xi_inf` (eq. (zinf)): its norm ([`cf_error`]) and its effect on a support integral
//! ([`cf_support_error`]). Used by the paper's diameter `D(C(F Xi_inf + E Theta),{0})`
//! ([`crate::tube::diameters`]) and by the pinned speed and engaged history beyond the paper
//! ([`crate::beyond_paper::engaged_speed`]).
use crate::tube::xi_support::perturbed_integral_excess;
use crate::tube::SemigroupData;
use dynamics::linear::expm::frobenius_up;
use nalgebra::DMatrix;
use rounding::{gamma, pad_up, UNIT_ROUNDOFF};

/// Relative margin of the enclosures of the `C F` terms ([`pad_up`], [`rounding::pad_down`]):
/// `8u`, on top of an absolute `MIN_POSITIVE` (each value is one sum of a few terms).
pub(crate) const PAD: f64 = 8.0 * UNIT_ROUNDOFF;

/// Upper bound of `||C F_exact - fl(C F)||_F` for the computed `F` with `||F_exact - F||_2 <=
/// f_radius` (the product's rounding `gamma_n ||C|| ||F||` and `||C|| f_radius`).
pub fn cf_error(C: &DMatrix<f64>, F: &DMatrix<f64>, f_radius: f64) -> f64 {
    // n eps / (1 - n eps) = gamma_{2n}
    let g = gamma(2 * F.nrows());
    pad_up(frobenius_up(C) * (f_radius + g * frobenius_up(F)) * (1.0 + 1e-10), PAD)
}

/// Upper bound of the effect of `L = fl(C F)` (instead of `C F_exact`) on a support integral
/// `int_0^inf sigma_Theta((L e^{sF_exact} E)^T v) ds`, `|v| = 1`: `D(Theta, {0}) ||dL|| ||E||
/// int ||e^{s F_exact}||`, with `int ||e^{s F_exact}|| <= I + eps I^2 / (1 - eps I)` (`I` the
/// proven integral for `F`, `eps = f_radius`). Infinite when `F` has no proven semigroup bound.
pub fn cf_support_error(
    C: &DMatrix<f64>,
    F: &DMatrix<f64>,
    E: &DMatrix<f64>,
    f_radius: f64,
    sg: &SemigroupData,
    d_theta: f64,
) -> f64 {
    let Some(b) = sg.exp_norm() else { return f64::INFINITY };
    let i = b.integral;
    let i_exact = i + perturbed_integral_excess(i, f_radius);
    pad_up(d_theta * cf_error(C, F, f_radius) * frobenius_up(E) * i_exact * (1.0 + 1e-10), PAD)
}
