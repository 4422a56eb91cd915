//! Closed-loop simulation of eqs. (xy), (yz), (zdot), the periodic regime for a `T`-periodic
//! input, and the MEASURED convergence rate, so that every bound of the paper can be held
//! against reality.
//!
//! Module map:
//! - [`linear`]: `e^{hA}`, `t Psi(tA)` (eq. (Psi)) and `int_0^h e^{(h-s)A} s ds` from one
//!   augmented matrix exponential ([`linear::expm`]); exact step maps with `w` held or linearly
//!   interpolated ([`linear::step_map`]), the hold declared once as [`InputHold`]
//!   ([`linear::hold`]). **`DMatrix`-based and public for reuse** (discovery:
//!   `StepMap::new(&A, h)`, `apply_held`, `apply_linear`, `SystemStepMap::new(&A, &B, &E, h, hold)`).
//! - [`integrators::catching_up`]: Moreau's scheme `z_{k+1} = P_{y_{k+1} + Theta}(z_k)` with the
//!   exact linear step, any [`geometry::Shape`]; [`Simulator`] picks a fixed-size fast path.
//! - [`integrators::ensemble`]: the same scheme for many trajectories of one system at once
//!   (structure of arrays, SIMD lanes through `pulp`, the single path's arithmetic lane by lane);
//!   used by the measured rate (all pairs in one ensemble).
//! - [`integrators::event_driven`]: the reference integrator (interval: exact piecewise linear;
//!   ball / ellipsoid: exact free phases, RK4 contact phases), events located by bisection.
//! - [`convergence`]: error of catching-up against the reference for a ladder of steps, order.
//! - [`periodic::poincare`]: fixed point of the Poincare map, residual;
//!   [`periodic::linearised`]: `xi_T`, `eta_T` (eqs. (xT) corrected, (xiT), (etaT)) and their
//!   derivatives on a grid (the (loc) check is in `bounds::tube::localisation`).
//! - [`rate::lyapunov_exponent`]: `(1/2) limsup (1/t) ln V`, `V` of eq. (V_Gamma), by
//!   regression over periods with a 95% interval and Benettin renormalisation;
//!   [`rate::path_length`]: path length of `z` per period and `max |z'|`.
//! - [`record`]: the recorded [`record::Trajectory`] of a run and its CSV (written by every
//!   integrator and the extended model);
//!   [`trajectory`]: simulating a model file into one (`simulate_model`: catching-up, or the
//!   extended model for a model with `[[effects]]`; `simulate_catching_up`).
//! - [`extended`]: the model extended by its `[[effects]]` (friction, backlash inertia, input
//!   delay and saturation, sensor offset, extra play) and its fixed-step simulator, the one
//!   used for every model with effects.
//!
//! Layers, bottom up (a module uses only modules on its own or lower lines; no circle):
//! `error`, `linear`, `record` -> `integrators` -> `periodic` -> `extended` -> `trajectory`,
//! `rate` -> `convergence`.
//!
//! Entry points for `bounds`, the theorem campaign and the CLI:
//! - simulation: `Simulator::new(&sys, &CatchingUpSettings { dt, hold })?` then
//!   `sim.run(t0, &mut x, &mut z, steps, |k, t, x, z| ..)` (no allocation per step; fast path for
//!   `(n, p)` in `(2,1) (3,1) (4,1) (4,2) (6,2) (6,3)`, any `Shape`);
//!   `trajectory::simulate_catching_up(&sys, &settings, steps, record_every)`.
//! - `periodic::linearised::linearised_periodic(&sys, &LinearisedSettings)` -> samples of
//!   `xi_T, xi_T', eta_T, eta_T'` on `[0, T]`, `osc_lower()` (valid lower bound of osc when
//!   `exact`), `deta_inf_sampled()` (an estimate, NOT an upper bound).
//! - `rate::lyapunov_exponent::measure_rate(&sys, &RateSettings { pi: Some(Pi), .. }, None)` ->
//!   [`rate::lyapunov_exponent::MeasuredRate`]: `exponent`, `ci_low`, `ci_high`,
//!   `path_length_per_period` (measured liminf), `limsup_z_speed`.
//! - `periodic::poincare::periodic_regime(&sys, &PoincareSettings)`.
#![allow(non_snake_case)]

pub mod convergence;
pub mod error;
pub mod extended;
pub mod integrators;
pub mod linear;
pub mod periodic;
pub mod rate;
pub mod record;
pub mod trajectory;

pub use error::DynamicsError;
pub use integrators::catching_up::{CatchingUpSettings, Simulator};
pub use linear::step_map::{InputHold, StepMap, SystemStepMap};
