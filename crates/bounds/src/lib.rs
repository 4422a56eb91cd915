//! `bounds`: the paper's certified quantities, each computed in the safe direction and flagged
//! verified only when the computation that produced it proves it.
//!
//! Module map (the paper's sections, in order):
//! - [`stationary`]: Section 3, Theorem 1: `Phi(t)` (eq. (Phi)) and the set `R(T)` of
//!   `T`-stationary backlash outputs (eqs. (stat), (stat1)) by a conic program;
//! - [`tube`]: Section 4, Lemma 2: support functions of `Xi(t)`, `Xi_inf` (eqs. (Xsupp),
//!   (Xinfsupp)) with rigorous quadrature remainders and the tail bound (DXX);
//! - [`orbit`]: Section 5, Theorem 2: the linearised periodic orbit `eta_T` (eqs. (xiT),
//!   (etaT)), `osc` (eq. (mho)), `||eta_T'||_inf`, and the path bounds (path), (path1), (path2);
//! - [`exponent`]: Section 6: `alpha` (eq. (alpha)), `psi` (eq. (phipsi)) and `theta` as the
//!   convex combination of eq. (theta);
//! - [`beyond_paper`]: the bounds that are ours, not the paper's: `theta*`, `theta_profile`,
//!   `theta_engaged`, the speed profile and the pinned speed (p = 1) they use (proofs in
//!   `proofs-notes/theta-*.md`);
//! - [`mod@assemble`]: [`assemble()`], every quantity of one model as a list of named stages
//!   (plant -> tubes -> orbit -> gammas -> certificate -> theta -> path lengths -> beyond the
//!   paper -> stationary, measured -> report), with its [`settings`] ([`ThetaSettings`]);
//! - [`report`]: the one declaration of every reported quantity ([`report::QUANTITIES`]): key,
//!   symbol, equation, bound direction; text tables, JSON keys and sweep columns derive from it;
//!   the report of one model, [`ThetaReport`], and its JSON ([`report::theta_report`]);
//! - [`error`]: why a quantity does not exist ([`BoundsError`]).
//!
//! # Example
//! theta of the worked example of NOTES.md (`examples/worked-example.toml`), built in code
//! (also `examples/theta_in_ten_lines.rs`):
//! ```
//! use geometry::{Interval, Shape};
//! use model::{Input, System};
//! use nalgebra::dmatrix;
//!
//! let sys = System::builder()
//!     .A(dmatrix![0.0, 1.0; -2.0, -0.6])
//!     .B(dmatrix![0.0; 1.0])
//!     .C(dmatrix![1.0, 0.0])
//!     .E(dmatrix![0.0; 1.0])
//!     .theta(Shape::Interval(Interval::symmetric(0.1).unwrap()))
//!     .input(Input::Sine { amplitudes: vec![1.0], omega: 1.0, phase: 0.0 })
//!     .build()
//!     .unwrap();
//! let report = bounds::assemble(&sys, &bounds::ThetaSettings::bound_only()).unwrap();
//! // NOTES.md: theta = -0.0172, certified.
//! assert!((report.theta + 0.0172).abs() < 5e-4);
//! assert!(report.theta_verified && report.convergence_guaranteed);
//! assert_eq!(report.quantity("theta").unwrap().value, report.theta);
//! ```
#![allow(non_snake_case)]

pub mod assemble;
pub mod beyond_paper;
pub mod equations;
pub mod error;
pub mod exponent;
pub mod orbit;
pub mod report;
pub mod settings;
pub mod stationary;
pub mod tube;

pub use assemble::{assemble, assemble_memo, Memo};
pub use error::BoundsError;
pub use exponent::Psi;
pub use report::{BoundKind, Quantity};
pub use report::{MeasuredSide, ThetaReport};
pub use settings::ThetaSettings;
