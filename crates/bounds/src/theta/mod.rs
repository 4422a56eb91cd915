//! The convergence exponent bound `theta` of eq. (theta) and its parts:
//! - [`alpha`]: `alpha = lambda_min(S(C E))`, eq. (alpha), from below;
//! - [`psi`]: `psi(gamma)`, eq. (phipsi), and `theta` as a convex combination of `psi(0)` and
//!   `psi(gamma_inf)`;
//! - [`assemble`]: every quantity of Theorems 1 and 2 and Section 6 for one model.
pub mod alpha;
pub mod assemble;
pub mod psi;
pub mod speed_profile;

pub use assemble::{assemble, MeasuredSide, ThetaReport, ThetaSettings};
pub use psi::Psi;
pub use speed_profile::SpeedProfile;
