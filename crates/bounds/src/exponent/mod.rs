//! The convergence exponent bound `theta` of eq. (theta) (Section 6 of the paper) and its
//! parts:
//! - [`alpha`]: `alpha = lambda_min(S(C E))`, eq. (alpha), from below;
//! - [`psi`]: `psi(gamma)`, eq. (phipsi), and `theta` as a convex combination of `psi(0)` and
//!   `psi(gamma_inf)`.
//!
//! Every quantity of one model is put together by [`crate::assemble()`]; the bounds beyond the
//! paper are in [`crate::beyond_paper`]. (This module was `bounds::theta`; it is named for the
//! rate so that `theta` means only the set `Theta` of the model.)
pub mod alpha;
pub mod psi;

pub use alpha::Alpha;
pub use psi::Psi;
