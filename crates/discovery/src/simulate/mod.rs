//! Free-run simulation of the nominal model extended by [`model::effects`].
//!
//! - [`step_maps`]: the exact linear step of `x' = F x + B w + E q + f` over one step `h`
//!   with `w` interpolated linearly and `q`, `f` held (first-order hold on `w`,
//!   zero-order hold on the backlash deviation `q = z - y` and on forces).
//! - [`extended`]: the extended model ([`ExtendedModel`]) and its fixed-step simulator:
//!   catching-up projection `z_{k+1} = y_{k+1} + P_Theta(z_k - y_{k+1})` for the play,
//!   implicit (Moreau-Jean) stick-slip for Coulomb friction, coasting backlash output for
//!   backlash inertia, and the input effects (delay, saturation, play at the input).
//!
//! These step maps are the ones `dynamics` is to provide for the nominal model (`e^{hA}`,
//! `h Psi(hA)`); the extended-model stepping stays here because `dynamics` knows only the
//! nominal paper model.
pub mod extended;
pub mod step_maps;

pub use extended::{ExtendedModel, SimOutput};
pub use step_maps::StepMaps;
