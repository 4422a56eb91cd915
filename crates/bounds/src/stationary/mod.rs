//! Stationary initial conditions of the backlash output, Section 3 (Theorem 1):
//! - [`phi`]: `Phi(t) = I_p - t C Psi(tA) E`, eq. (Phi) (the paper's `I_n` is a typo), and the
//!   first `t` where it becomes singular;
//! - [`rest_set`]: the set `R(T)` of eqs. (stat), (stat1) as a convex feasibility problem over a
//!   time grid, a point of it and its confirmation by simulation.
pub mod phi;
pub mod rest_set;

pub use phi::{phi, scan_phi, PhiScan};
pub use rest_set::{confirm_at_rest, rest_set, RestSet, RestSetSettings};
