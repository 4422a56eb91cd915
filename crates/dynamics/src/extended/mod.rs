//! Free-run simulation of the nominal model extended by `model::effects` (friction, inertia,
//! delay, saturation, offsets, plays).
//!
//! - [`step_maps`]: the exact linear step of `x' = F x + B w + E q + f` over one step `h`
//!   with `w` interpolated linearly and `q`, `f` held (first-order hold on `w`,
//!   zero-order hold on the backlash deviation `q = z - y` and on forces).
//! - [`model`]: the extended model ([`ExtendedModel`]) and its fixed-step simulator:
//!   catching-up projection `z_{k+1} = y_{k+1} + P_Theta(z_k - y_{k+1})` for the play,
//!   implicit (Moreau-Jean) stick-slip for friction (Coulomb, Stribeck with a static
//!   breakaway level, direction-dependent levels), a cogging force, coasting backlash output for
//!   backlash inertia, and the input effects (delay, saturation, play at the input).
//!
//! The one simulator of models with `[[effects]]`: `moreau simulate`, `periodic`,
//! `convergence`, `figure trajectory` and `discovery` all use it (a model without effects
//! reproduces the catching-up scheme of [`crate::integrators::catching_up`]).
pub mod model;
pub mod step_maps;

pub use model::{
    regime_by_simulation, simulate_trajectory, theta_is_point, ExtendedModel, InputHold, SimOutput, SimulatedRegime,
};
pub use step_maps::StepMaps;
