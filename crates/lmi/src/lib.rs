//! `lmi`: the Lyapunov matrix `Pi` of Section 6 of the paper by semidefinite
//! programming (Clarabel, PSD cones used directly) with rigorously verified certificates.
//!
//! Objects, one module each:
//! - [`spectral_abscissa`]: `mu = max Re eig(F)`, eq. (stab), input validation;
//! - [`sdp`]: the conic layer over Clarabel ([`ConicProgram`]), shared with Theorem 1's set;
//! - [`status`]: the solver status [`SdpStatus`], mirrored from Clarabel;
//! - [`psd_triangle`]: Clarabel's scaled upper-triangle storage of symmetric matrices;
//! - [`feasibility`]: (ALI) `S(Pi F) <= -lambda Pi`, `Pi > 0`, and the supremum of `lambda`;
//! - [`beta_sdp`]: minimal `beta = lambda_max(H^T Pi^{-1} H)`, eq. (bet), for given `lambda`;
//! - [`beta_memo`]: the beta SDPs of several lambda searches over one problem, solved once each;
//! - [`verify`]: floating-point-rigorous proof of `Pi > 0`, (ALI) and `beta <= b_hat`;
//! - [`lambda_search`]: `lambda in (0, |mu|)` minimising a user `theta(lambda, beta)`, eq. (theta);
//! - [`fixtures`]: seeded test systems; [`error`]: the error enum.
#![allow(non_snake_case)]
// `!(x > 0.0)` is deliberate: it is also true for NaN, which must never pass a check.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

// Link OpenBLAS (LAPACK for Clarabel's PSD cones).
extern crate openblas_src;

pub mod beta_memo;
pub mod beta_sdp;
pub mod error;
pub mod feasibility;
pub mod fixtures;
pub mod lambda_search;
pub mod psd_triangle;
pub mod sdp;
pub mod spectral_abscissa;
pub mod status;
pub mod verify;

pub use beta_memo::BetaMemo;
pub use beta_sdp::{certified_beta, pi_scale, solve_beta_sdp, BetaSdpSettings, BetaSdpSolution, CertifiedBeta};
pub use error::{LmiError, Result};
pub use feasibility::{
    lyapunov_feasibility, sup_feasible_lambda, FeasibilitySettings, LambdaSupremum, LyapunovFeasibility,
};
pub use lambda_search::{
    optimise_lambda, optimise_lambda_memo, CurvePoint, CurveValue, LambdaOptimum, LambdaSearch, LambdaSearchSettings,
};
pub use sdp::{ConicOutcome, ConicProgram, SdpSettings, SdpStatus};
pub use spectral_abscissa::{hurwitz_mu, spectral_abscissa};
pub use verify::{certify, check_certificate, Certificate, Margin, VerifySettings};
