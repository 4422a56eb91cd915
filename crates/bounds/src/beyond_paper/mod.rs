//! The bounds beyond the paper: everything here is ours, not the paper's (the paper's
//! quantities live in [`crate::stationary`], [`crate::tube`], [`crate::orbit`] and
//! [`crate::exponent`]). Each is a valid bound of the same exponent as eq. (theta), at most the
//! paper's `theta`, with its proof in `proofs-notes/`:
//! - `theta*`: eq. (theta) with `gamma_1*` from the strongest proven path bound and `gamma_inf*`
//!   from the pinned speed (proofs-notes/theta-star.md);
//! - `theta_profile`: the chord argument of eq. (theta) resolved in time over the cells of a
//!   speed profile ([`speed_profile`], proofs-notes/theta-profile.md);
//! - `floquet` (p = 1): a verified enclosure of the periodic regime and its Floquet exponent, the
//!   local exponent that brackets the true one from the other side of `theta_best`
//!   (proofs-notes/floquet-enclosure.md);
//! - `theta_engaged`: `theta_profile` with speed floors on the cells where the backlash is
//!   provably engaged (p = 1: proofs-notes/theta-engaged.md; balls and ellipsoids in R^2 and
//!   R^3, the normal component of `y'` at the contact point: [`contact_floors`],
//!   proofs-notes/theta-engaged-balls.md).
//!
//! Modules: [`extensions`] (the stage of [`crate::assemble`] that computes them from the
//! paper's quantities), [`speed_profile`] (the time-resolved speed bounds) and
//! [`engaged_speed`] (p = 1: (zinf) with the backlash's side pinned, [`EngagedSpeed`], and the
//! engaged history, [`EngagedHistory`], from the paper's tube kernels of [`crate::tube`]) and
//! [`contact_floors`] (p >= 2, balls and ellipsoids: floors from the contact normal).
pub mod contact_floors;
pub mod engaged_speed;
pub mod extensions;
pub mod floquet;
pub mod speed_profile;

pub use contact_floors::{ContactFloors, ContactGeometry};
pub use engaged_speed::{EngagedHistory, EngagedSpeed};

pub(crate) use extensions::{extensions, pinned_speed, Extensions, FromPaper};
pub use speed_profile::{ProfileEvidence, SpeedProfile};
