//! Tubular localisation of Section 4 (Lemma 2): `x(t) in xi(t) + Xi(t)`, eq. (xX), with the
//! support functions of `Xi(t)` and `Xi_inf` (eqs. (Xsupp), (Xinfsupp)) and the tail bound
//! (DXX). See [`xi_support`]; the tube diameters `d` (eq. (d)) and `D(C(F Xi_inf + E Theta),{0})`
//! (eq. (zinf)) of Theorem 2: [`diameters`]; the check of (loc) for a periodic state:
//! [`localisation`]; the rounding of `fl(C F)` in the kernels of `C F Xi_inf`: [`cf_rounding`].
//! (The signed speed of the backlash for `p = 1`, which reuses these kernels, is beyond the
//! paper: [`crate::beyond_paper::engaged_speed`].)
pub mod cf_rounding;
pub mod diameters;
pub mod localisation;
pub mod xi_support;

pub use diameters::{tube_diameters, tube_diameters_with, OutputTube, TubeDiameters};
pub use geometry::sublinear_sphere_max;
pub use xi_support::{dxx_bound, exp_norm_integral, Horizon, SemigroupData, TubeKernel, TubeSettings};
