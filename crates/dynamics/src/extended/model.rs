//! The nominal model (eqs. (xy)-(yz)) extended by physical effects: [`ExtendedModel`], compiled
//! from a [`System`]'s `[[effects]]` (plus extra effects under test) for one sample spacing.
//!
//! With `F = A + E C` (eq. (F)) and `q = z - y in Theta`, the plant reads
//! `x' = F x + B w_eff + E q + sum_j e_j (b_j + f_j)`, `y_meas = C x + offset`, where
//! - `w_eff` is `w` delayed (`input_delay`), clamped (`input_saturation`) and passed through a
//!   play operator (`backlash` at the input), in that order ([`super::input`]);
//! - `Theta` is the nominal set scaled by `1 + relative_change` (`gap_width`) and widened by a
//!   play of width `width` (`backlash` in the loop; 1-D, or a ball of radius `width/2` when the
//!   nominal has no play) ([`super::play`]);
//! - `b_j` is a constant force (`constant_force`) plus a cogging force
//!   `A sin(2 pi x_pos / P + phase)` (`cogging`, evaluated at the step's midpoint position
//!   of the force-free step and held over the step) ([`super::forces`]);
//! - `f_j` is friction on velocity state `x_j` (`coulomb_friction`, `stribeck_friction`,
//!   `asymmetric_coulomb`, `load_friction` whose level grows with the transmitted load
//!   `|B_j w + E_j z - sum_{i != j} A_ji x_i|`; several on one state add up), a set-valued law
//!   resolved implicitly per step (Moreau-Jean time stepping; [`super::friction`]);
//! - the play is the catching-up scheme `z_{k+1} = y_{k+1} + P_Theta(z_pred - y_{k+1})`, where
//!   `z_pred = z_k` for a massless backlash output and, with `backlash_inertia`, `z` coasts
//!   with velocity `v` decaying at rate `damping / mass` between contacts (the contact is
//!   inelastic: after a projection `z` moves with `y`, `v` the output's velocity by a
//!   second-order backward difference; `(z_{k+1} - z_k)/h` for p > 1). Between contacts, with
//!   or without inertia, the plant sees `q` change linearly over the step: `z` coasts (or
//!   stays) while `y` moves at its velocity ([`super::simulate`]). Second order in the step
//!   away from contact events; the catching-up scheme of the paper, which holds `q` over the
//!   step, is first order (issue 27 item 5; `tests/extended_simulation.rs`).
//!
//! Compiling checks every effect (an error names the effect and the offending value); the
//! simulation itself is [`super::simulate`].
use super::digital::DigitalLoop;
use super::forces::Forces;
use super::input::{InputPath, Split};
use super::play::{checked_width, Play, PlayEffects};
use super::step_maps::{row_major, StepMaps};
use crate::error::DynamicsError;
use crate::linear::hold::InputHold;
use model::effects::{Effect, PlayLocation};
use model::System;

/// The compiled extended model.
#[derive(Debug, Clone)]
pub struct ExtendedModel {
    pub n: usize,
    pub m: usize,
    pub p: usize,
    /// `C` row-major (`p x n`).
    pub(super) C: Vec<f64>,
    pub(super) maps: StepMaps,
    pub(super) substeps: usize,
    pub(super) play: Play,
    /// `mass / damping` of the backlash output (0: massless).
    pub(super) inertia_tau: f64,
    /// Constant, cogging and friction forces.
    pub(super) forces: Forces,
    /// Delay, saturation, play at the input, and the hold between samples.
    pub(super) input: InputPath,
    pub(super) offset: Vec<f64>,
    /// Set when an input delay puts the input's breakpoints inside a sub-step.
    pub(super) split: Option<Split>,
    /// The digital controller closing the loop (`[controller]`), compiled for the samples.
    pub(super) digital: Option<DigitalLoop>,
}

impl ExtendedModel {
    /// Compiles `sys` (with its own effects) plus `extra` effects for samples `dt` apart,
    /// simulated with `substeps` linear steps per sample.
    pub fn new(sys: &System, extra: &[Effect], dt: f64, substeps: usize) -> Result<Self, DynamicsError> {
        let substeps = substeps.max(1);
        let maps = StepMaps::new(&sys.F(), &sys.B, &sys.E, dt / substeps as f64);
        Self::from_maps(sys, extra, maps, substeps)
    }

    /// As [`ExtendedModel::new`] with step maps already computed for `dt / substeps`.
    pub fn from_maps(sys: &System, extra: &[Effect], maps: StepMaps, substeps: usize) -> Result<Self, DynamicsError> {
        let (n, p) = (sys.n(), sys.p());
        let mut play = PlayEffects::default();
        let mut forces = Forces::new(n);
        let mut input = InputPath::default();
        let mut offset = vec![0.0; p];
        for e in sys.effects.list.iter().chain(extra) {
            match e {
                Effect::Backlash { width, location } => {
                    let width = checked_width(*width)?;
                    match location {
                        PlayLocation::Loop => play.widen(width),
                        PlayLocation::Input => input.add_play(width),
                    }
                }
                Effect::GapWidth { relative_change } => play.scale_gap(*relative_change)?,
                Effect::BacklashInertia { mass, damping } => play.set_inertia(*mass, *damping),
                Effect::CoulombFriction { state, level } => forces.coulomb(*state, *level)?,
                Effect::AsymmetricCoulomb { state, level_positive, level_negative } => {
                    forces.asymmetric_coulomb(*state, *level_positive, *level_negative)?
                }
                Effect::StribeckFriction { state, level, static_level, stribeck_velocity, viscous } => {
                    forces.stribeck(*state, *level, *static_level, *stribeck_velocity, *viscous)?
                }
                Effect::LoadFriction { state, level, load_coefficient } => {
                    forces.load_friction(*state, *level, *load_coefficient, sys)?
                }
                Effect::Cogging { state, position_state, amplitude, period, phase } => {
                    forces.cogging(*state, *position_state, *amplitude, *period, *phase)?
                }
                Effect::ConstantForce { state, force } => forces.constant(*state, *force)?,
                Effect::InputDelay { delay } => input.add_delay(*delay),
                Effect::InputSaturation { limit } => input.saturate(*limit),
                Effect::SensorOffset { offset: o } => {
                    for (a, v) in offset.iter_mut().zip(o) {
                        *a += v;
                    }
                }
            }
        }
        let compiled_play = play.compile(sys, p)?;
        let dt = maps.h * substeps as f64;
        let digital = sys.controller.as_ref().map(|c| DigitalLoop::new(c, dt)).transpose()?;
        let split = if input.delay > 0.0 { Split::for_delay(sys, input.delay, maps.h, substeps) } else { None };
        Ok(Self {
            n,
            m: sys.m(),
            p,
            C: row_major(&sys.C),
            maps,
            substeps,
            play: compiled_play,
            inertia_tau: play.inertia_tau,
            forces,
            input,
            offset,
            split,
            digital,
        })
    }

    /// The same model with input hold `hold` between samples (default: first-order hold).
    pub fn with_hold(mut self, hold: InputHold) -> Self {
        self.input.hold = hold;
        self
    }

    /// The input hold between samples.
    pub fn hold(&self) -> InputHold {
        self.input.hold
    }

    /// Whether a digital controller closes the loop (`[controller]`).
    pub fn has_controller(&self) -> bool {
        self.digital.is_some()
    }

    /// Whether the model has a play in the loop.
    pub fn has_play(&self) -> bool {
        !matches!(self.play, Play::None)
    }

    /// The effective input `w_eff` on the sample grid (flat, `k * m + j`), from the measured
    /// `w` (flat), with linear interpolation for the delay (for figures and checks; the
    /// simulator evaluates the input between samples itself, by the model's hold): delay (linear interpolation, first value held before the start), saturation,
    /// input play (play operator started centred).
    pub fn effective_input(&self, w: &[f64], dt: f64) -> Vec<f64> {
        self.input.effective_input(w, dt, self.m)
    }

    /// The sensor offset added to `y = C x` (sum of the `sensor_offset` effects).
    pub fn sensor_offset(&self) -> &[f64] {
        &self.offset
    }
}
