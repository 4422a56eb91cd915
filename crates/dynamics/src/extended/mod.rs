//! Free-run simulation of the nominal model extended by `model::effects` (friction, inertia,
//! delay, saturation, offsets, plays).
//!
//! Module map (arrows point down: each file uses only those below it):
//! - [`model`]: the extended model ([`ExtendedModel`]): the plant equations with effects, and
//!   compiling a `model::System`'s `[[effects]]` into the parts below (each effect checked).
//! - [`simulate`]: its fixed-step simulator (one sub-step = input, linear step and forces,
//!   play), [`simulate_trajectory`] for a model file and [`regime_by_simulation`] under a
//!   periodic input.
//! - [`merge`]: a run from a perturbed initial state beside the base run until the two
//!   merge (the initial-state columns of a finite-difference Jacobian).
//! - [`digital`]: the loop closed by a digital controller (`[controller]`): ticks every
//!   `period`, computation delay, the command held between ticks.
//! - [`play`]: the play in the loop, the catching-up projection
//!   `z_{k+1} = y_{k+1} + P_Theta(z_pred - y_{k+1})` (gap width, loop backlash, backlash
//!   inertia).
//! - [`forces`]: constant force, cogging, and the friction laws of [`friction`]
//!   (implicit Moreau-Jean stick-slip: Coulomb, Stribeck with a static breakaway level,
//!   direction-dependent levels).
//! - [`input`]: the input path (delay, saturation, play at the input) and the hold between
//!   samples ([`InputHold`], declared once in [`crate::linear::hold`]).
//! - [`step_maps`]: the exact linear step of `x' = F x + B w + E q + f` over one step `h`
//!   with `w` interpolated linearly and `q`, `f` held (first-order hold on `w`,
//!   zero-order hold on the backlash deviation `q = z - y` and on forces).
//!
//! The one simulator of models with `[[effects]]`: `moreau simulate`, `periodic`,
//! `convergence`, `figure trajectory` and `discovery` all use it (a model without effects
//! reproduces the catching-up scheme of [`crate::integrators::catching_up`]).
pub mod digital;
pub mod forces;
pub mod friction;
pub mod input;
pub mod merge;
pub mod model;
pub mod play;
pub mod simulate;
pub mod step_maps;

pub use self::model::ExtendedModel;
pub use crate::linear::hold::InputHold;
pub use digital::closed_loop_mu;
pub use merge::MergedRun;
pub use play::theta_is_point;
pub use simulate::{regime_by_simulation, simulate_trajectory, SimOutput, SimulatedRegime};
pub use step_maps::StepMaps;
