//! The physics library: every effect the diagnosis can add to a nominal model, one file per
//! family, each declaring once its effects' names, labels, descriptions, parameters, bounds,
//! starts and their conversion to the model file's `[[effects]]` entry
//! ([`model::effects::Effect`]).
//!
//! - [`play`]: `backlash` (in the loop or at the input), `gap_width`, `backlash_inertia`;
//! - [`friction`]: the friction laws `coulomb_friction`, `stribeck_friction`,
//!   `asymmetric_coulomb`, `load_friction` on a velocity state;
//! - [`cogging`]: a position-periodic force on a velocity state (period from a scan of the
//!   nominal residual);
//! - [`offsets`]: `constant_force` on a velocity state, `sensor_offset` on the outputs;
//! - [`input_ops`]: `input_delay`, `input_saturation` and the input effects on one input of
//!   several ([`input_ops::InputOp`]).
//!
//! Each family implements [`Family`]; [`FAMILIES`] lists them, and the library composes them
//! (modelled on pysindy's `feature_library/`: each library implements one interface, the
//! model composes them): [`crate::hypothesis`] asks every family, in the order of
//! [`FAMILIES`], for its hypotheses at each [`Site`] of the model, and a [`Kind`] is named,
//! described and converted by the family that claims it. Adding a law is one new file, its
//! [`Kind`] variant and one line in [`FAMILIES`] (and, for an effect the model file does not
//! know yet, its variant and name in [`model::effects`]).
//!
//! Shared by the families: [`parameters`] (a hypothesis' parameter box, its unit and
//! logarithmic coordinates, starts over decades) and [`scales`] (the recording's and the
//! nominal run's scales the bounds derive from).
pub mod cogging;
pub mod friction;
pub mod input_ops;
pub mod offsets;
pub mod parameters;
pub mod play;
pub mod scales;

pub use input_ops::InputOp;
pub use parameters::{Hypothesis, DECADES, LEVEL_LOG_SHIFT};
pub use scales::{NominalRun, Scales};

use model::effects::Effect;
use model::System;
use serde::Serialize;

/// A structural choice of effect (parameters apart). `InputOn`: an input effect on one input
/// only (models with several inputs; applied to the recorded input by
/// [`crate::fit::input_effects`], not by the simulator).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Kind {
    Backlash { at_input: bool },
    GapWidth,
    CoulombFriction { state: usize },
    StribeckFriction { state: usize },
    AsymmetricCoulomb { state: usize },
    LoadFriction { state: usize },
    Cogging { state: usize, position_state: usize },
    ConstantForce { state: usize },
    BacklashInertia,
    InputDelay,
    InputSaturation,
    SensorOffset,
    InputOn { op: InputOp, input: usize },
}

impl Kind {
    /// The family that declares this kind.
    fn family(&self) -> &'static dyn Family {
        *FAMILIES.iter().find(|f| f.name(*self).is_some()).expect("every kind belongs to a family of FAMILIES")
    }
    /// The model-file name of the effect.
    pub fn name(&self) -> &'static str {
        self.family().name(*self).expect("claimed by its family")
    }
    /// Name with its structural choice, e.g. `coulomb_friction(x2)`.
    pub fn label(&self) -> String {
        self.family().label(*self).expect("claimed by its family")
    }
    /// One-sentence physical description used in reports.
    pub fn description(&self) -> String {
        self.family().description(*self).expect("claimed by its family")
    }
    /// The model-file effect at parameters `theta` (physical units). An effect on one input
    /// of several is not expressible in a model file: it becomes the same effect on every
    /// input (the fit applies it to its input only, see [`crate::fit::input_effects`]).
    pub fn effect(&self, theta: &[f64]) -> Effect {
        self.family().effect(*self, theta).expect("claimed by its family")
    }
    /// The simpler single hypothesis that this kind generalises (nested at some parameter
    /// values), if any.
    pub fn simpler_form(&self) -> Option<Kind> {
        self.family().simpler_form(*self)
    }
}

/// Where in the model a family's hypotheses act. The library tries the sites in the order
/// [`crate::hypothesis`] lists them (the play, each velocity state, the input, the sensor;
/// then each input of several), and at each site the families in the order of [`FAMILIES`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Site {
    /// The play element (the loop's backlash, its gap and its inertia, or a play at the input).
    Play,
    /// A velocity state: forces on its derivative.
    Velocity {
        state: usize,
        /// Force bound: the force whose static deflection of `y` equals `range(y)`.
        force_bound: f64,
        /// Velocity scale (the state's RMS over the nominal run, else `range(y) / tau_slow`).
        velocity_scale: f64,
        /// The position state whose derivative is a multiple of this state alone, if any.
        position_state: Option<usize>,
    },
    /// The input signal as a whole (every input alike).
    Input,
    /// The measured outputs.
    Sensor,
    /// Input `input` alone, of a model with several inputs.
    OneInput {
        input: usize,
        /// `max |w_input|` over the record.
        absmax: f64,
        /// `range(w_input)` over the record.
        range: f64,
    },
}

/// What a family sees of the problem when it states its hypotheses.
#[derive(Debug, Clone, Copy)]
pub struct Context<'a> {
    pub sys: &'a System,
    pub scales: &'a Scales,
    /// The hypotheses allowed, by label or name (`None`: every one;
    /// `DiagnoseSettings::library`).
    pub library: Option<&'a [String]>,
}

impl Context<'_> {
    /// Whether the library allows `kind` (see [`in_library`]). A family whose hypothesis costs
    /// work to state (the cogging scan runs over the record) asks before doing it.
    pub fn allows(&self, kind: Kind) -> bool {
        self.library.is_none_or(|lib| in_library(lib, kind))
    }
}

/// Whether `kind` is among `library`'s entries, by label (`coulomb_friction(x2)`) or by name
/// (`coulomb_friction`, every state).
pub fn in_library(library: &[String], kind: Kind) -> bool {
    library.iter().any(|l| *l == kind.label() || l == kind.name())
}

/// One family of effects (one file of this folder).
///
/// Every method but [`Family::hypotheses`] answers `None` for a kind or effect of another
/// family; a kind belongs to the family whose [`Family::name`] answers.
pub trait Family: Sync {
    /// The family's hypotheses at `site`, in the order tried (none where it does not act).
    fn hypotheses(&self, site: &Site, cx: &Context) -> Vec<Hypothesis>;
    /// Model-file name of `kind`.
    fn name(&self, kind: Kind) -> Option<&'static str>;
    /// Name with the structural choice (the name alone unless overridden).
    fn label(&self, kind: Kind) -> Option<String> {
        self.name(kind).map(String::from)
    }
    /// One-sentence physical description used in reports.
    fn description(&self, kind: Kind) -> Option<String>;
    /// The model-file effect of `kind` at parameters `theta` (physical units).
    fn effect(&self, kind: Kind, theta: &[f64]) -> Option<Effect>;
    /// The simpler hypothesis that `kind` generalises (nested at some parameter values).
    fn simpler_form(&self, _kind: Kind) -> Option<Kind> {
        None
    }
    /// Starts (unit coordinates of `h`) around the simpler form's estimate `simpler` (physical
    /// units), for a generalisation whose own starts ended no better than what it nests;
    /// `None` where `h` generalises nothing.
    fn starts_from_simpler(&self, _h: &Hypothesis, _simpler: &[f64]) -> Option<Vec<Vec<f64>>> {
        None
    }
    /// Starts (unit coordinates of `simple`) from the estimate `general` (physical units) of a
    /// generalisation of kind `kind` of `simple`, for a simpler form whose own starts ended at
    /// another minimum; `None` where `kind` does not generalise `simple`.
    fn starts_from_general(&self, _simple: &Hypothesis, _kind: Kind, _general: &[f64]) -> Option<Vec<Vec<f64>>> {
        None
    }
    /// The main parameter of a model-file `effect` (the one that sets its size, which a
    /// benchmark sets and scores) and the hypothesis parameter that estimates it (`None` where
    /// the main parameter is derived from several).
    fn main_parameter(&self, effect: &Effect) -> Option<(f64, Option<&'static str>)>;
    /// Every identifiable parameter `(name, value)` of a model-file `effect`, for the effects
    /// scored by more than their main parameter (the friction library); `None` otherwise.
    fn every_parameter(&self, _effect: &Effect) -> Option<Vec<(&'static str, f64)>> {
        None
    }
}

/// The library: its families, in the order their hypotheses are tried at each site.
pub static FAMILIES: [&dyn Family; 5] =
    [&play::Play, &friction::Friction, &cogging::Cogging, &offsets::Offsets, &input_ops::InputOps];

/// The hypotheses of every family at each of `sites`, sites first, families second.
pub fn hypotheses_at(sites: &[Site], cx: &Context) -> Vec<Hypothesis> {
    sites
        .iter()
        .flat_map(|site| FAMILIES.iter().flat_map(move |f| f.hypotheses(site, cx)))
        .filter(|h| cx.allows(h.kind))
        .collect()
}

/// The main parameter of a model-file effect and the hypothesis parameter that estimates it
/// (see [`Family::main_parameter`]).
pub fn main_parameter(effect: &Effect) -> (f64, Option<&'static str>) {
    FAMILIES.iter().find_map(|f| f.main_parameter(effect)).expect("every effect belongs to a family of FAMILIES")
}

/// Starts for the generalisation `h` around its simpler form's estimate (see
/// [`Family::starts_from_simpler`]).
pub fn starts_from_simpler(h: &Hypothesis, simpler: &[f64]) -> Option<Vec<Vec<f64>>> {
    h.kind.family().starts_from_simpler(h, simpler)
}

/// Starts for the simpler form `simple` from the estimate of its generalisation `kind` (see
/// [`Family::starts_from_general`]).
pub fn starts_from_general(simple: &Hypothesis, kind: Kind, general: &[f64]) -> Option<Vec<Vec<f64>>> {
    simple.kind.family().starts_from_general(simple, kind, general)
}

/// The main parameter of `kind` at hypothesis parameters `theta` where it is derived from
/// several of them (a Stribeck law's static level, a cogging force's amplitude): its name, its
/// value and its gradient in `theta` (central differences); `None` where the main parameter is
/// one of the hypothesis parameters (its sigma is that parameter's).
pub fn derived_main(kind: Kind, theta: &[f64]) -> Option<(&'static str, f64, Vec<f64>)> {
    let at = |t: &[f64]| main_parameter(&kind.effect(t)).0;
    let effect = kind.effect(theta);
    if main_parameter(&effect).1.is_some() {
        return None;
    }
    let name = every_parameter(&effect)?.first()?.0;
    let gradient = (0..theta.len())
        .map(|i| {
            let h = 1e-6 * theta[i].abs().max(1e-9);
            let (mut up, mut down) = (theta.to_vec(), theta.to_vec());
            up[i] += h;
            down[i] -= h;
            (at(&up) - at(&down)) / (2.0 * h)
        })
        .collect();
    Some((name, at(theta), gradient))
}

/// Every identifiable parameter of a model-file effect (see [`Family::every_parameter`]).
pub fn every_parameter(effect: &Effect) -> Option<Vec<(&'static str, f64)>> {
    FAMILIES.iter().find_map(|f| f.every_parameter(effect))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_belongs_to_exactly_one_family() {
        let kinds = [
            Kind::Backlash { at_input: true },
            Kind::Backlash { at_input: false },
            Kind::GapWidth,
            Kind::CoulombFriction { state: 1 },
            Kind::StribeckFriction { state: 1 },
            Kind::AsymmetricCoulomb { state: 1 },
            Kind::LoadFriction { state: 1 },
            Kind::Cogging { state: 1, position_state: 0 },
            Kind::ConstantForce { state: 1 },
            Kind::BacklashInertia,
            Kind::InputDelay,
            Kind::InputSaturation,
            Kind::SensorOffset,
            Kind::InputOn { op: InputOp::Play, input: 1 },
            Kind::InputOn { op: InputOp::Saturation, input: 1 },
            Kind::InputOn { op: InputOp::Delay, input: 1 },
        ];
        for k in kinds {
            assert_eq!(FAMILIES.iter().filter(|f| f.name(k).is_some()).count(), 1, "{k:?}");
            // the model-file name of the effect is the kind's name (per-input effects: the
            // same effect on every input)
            let theta = [0.5, 0.5, 0.5];
            assert_eq!(k.effect(&theta).kind(), k.name(), "{k:?}");
            let e = k.effect(&theta);
            assert_eq!(FAMILIES.iter().filter(|f| f.main_parameter(&e).is_some()).count(), 1, "{k:?}");
            // a derived main parameter has the value of the main parameter
            if let Some((_, v, _)) = derived_main(k, &theta) {
                assert_eq!(v, main_parameter(&e).0, "{k:?}");
            }
        }
    }

    #[test]
    fn derived_main_parameters_have_their_gradients() {
        // Stribeck: static level = level + static excess.
        let (name, v, g) = derived_main(Kind::StribeckFriction { state: 1 }, &[2.0, 1.5, 0.3]).unwrap();
        assert_eq!((name, v), ("static_level", 3.5));
        for (gi, want) in g.iter().zip([1.0, 1.0, 0.0]) {
            assert!((gi - want).abs() < 1e-6, "{g:?}");
        }
        // Cogging: amplitude = hypot(a_sin, a_cos).
        let (name, v, g) = derived_main(Kind::Cogging { state: 1, position_state: 0 }, &[3.0, -4.0, 0.2]).unwrap();
        assert_eq!((name, v), ("amplitude", 5.0));
        for (gi, want) in g.iter().zip([0.6, -0.8, 0.0]) {
            assert!((gi - want).abs() < 1e-6, "{g:?}");
        }
        // negative control: a main parameter that is a hypothesis parameter is not derived
        assert!(derived_main(Kind::CoulombFriction { state: 1 }, &[2.0]).is_none());
        assert!(derived_main(Kind::AsymmetricCoulomb { state: 1 }, &[2.0, 1.0]).is_none());
    }
}
