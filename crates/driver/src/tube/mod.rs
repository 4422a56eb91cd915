//! Tubular localisation of Section 4 (Lemma 2): `x(t) in xi(t) + Xi(t)`, eq. (xX), with the
//! support functions of `Xi(t)` and `Xi_inf` (eqs. (Xsupp), (Xinfsupp)) and the tail bound
//! (DXX). See [`xi_support`].
pub mod sublinear_max;
pub mod xi_support;

pub use sublinear_max::sublinear_sphere_max;
pub use xi_support::{dxx_bound, exp_norm_integral, Horizon, TubeKernel, TubeSettings};
