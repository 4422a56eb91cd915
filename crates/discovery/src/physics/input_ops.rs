//! Input operations: `input_delay` and `input_saturation` on the input as a whole, and the
//! input effects on one input of several ([`InputOp`]: a play, a saturation or a delay of
//! that input alone; models with several inputs, e.g. a reference in metres and a motor
//! voltage in volts, where one play width or saturation limit for both means nothing).
//!
//! Bounds: a delay in `[0, min(tau_slow, T/20)]` (at least 5 samples, [`delay_bound`]), a
//! saturation limit in `[0.2, 1] max|w|` (1 = no clipping) started down to 0.1 % below
//! the estimation segment's `max |w|` ([`SATURATION_STARTS`]: a start above it clips nothing
//! where the fit runs); per input `j`, a play of width `[0, range(w_j)/2]`, a
//! limit in `[0.2, 1] max |w_j|` and a delay in the bound of the global delay, with the
//! global hypotheses' starts. A model file's effects act on every input alike, so an effect
//! on one input is applied to the recorded input by [`crate::fit::input_effects`].
use super::parameters::{level, linear};
use super::play::{backlash, WIDTH};
use super::{Context, Family, Hypothesis, Kind, Scales, Site};
use model::effects::{names, Effect, PlayLocation};
use serde::Serialize;

const DELAY: &str = "delay";
const LIMIT: &str = "limit";

/// Fractions of `max |w|` at which a saturation limit is started.
pub const SATURATION_STARTS: [f64; 5] = [0.52, 0.76, 0.96, 0.99, 0.999];

/// An input effect that can act on one input.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum InputOp {
    Play,
    Saturation,
    Delay,
}

impl InputOp {
    /// Model-file name of the effect.
    pub fn name(&self) -> &'static str {
        match self {
            InputOp::Play => names::BACKLASH,
            InputOp::Saturation => names::INPUT_SATURATION,
            InputOp::Delay => names::INPUT_DELAY,
        }
    }
    /// Label with the input, e.g. `input_saturation(w2)`.
    pub fn label(&self, input: usize) -> String {
        match self {
            InputOp::Play => format!("backlash(input w{})", input + 1),
            _ => format!("{}(w{})", self.name(), input + 1),
        }
    }
    pub fn description(&self, input: usize) -> String {
        let j = input + 1;
        match self {
            InputOp::Play => format!("Play between input w{j} and the plant (the other inputs act directly): the plant only follows w{j} after it has reversed by the width of the play."),
            InputOp::Saturation => format!("The actuator behind input w{j} cannot follow it beyond a limit (voltage or current saturation); the other inputs are not clipped."),
            InputOp::Delay => format!("The plant sees input w{j} late (transport, communication or computation delay); the other inputs arrive on time."),
        }
    }
    /// The same effect on every input (what a model file can state).
    pub fn on_every_input(&self, v: f64) -> Effect {
        match self {
            InputOp::Play => backlash(v, PlayLocation::Input),
            InputOp::Saturation => saturation(v),
            InputOp::Delay => delay(v),
        }
    }
}

/// A delay of `v` (negative values clamp to none).
fn delay(v: f64) -> Effect {
    Effect::InputDelay { delay: v.max(0.0) }
}

/// A saturation at `v` (at least `1e-12`).
fn saturation(v: f64) -> Effect {
    Effect::InputSaturation { limit: v.max(1e-12) }
}

/// Upper bound of a delay: `min(tau_slow, T/20)`, at least 5 samples.
pub fn delay_bound(s: &Scales) -> f64 {
    s.tau_slow.min(s.duration / 20.0).max(5.0 * s.dt)
}

/// A saturation limit in `[0.2, 1] absmax`, started at [`SATURATION_STARTS`] of `from`: the
/// largest `|w|` where the fit runs (the estimation segment; a limit above it clips nothing
/// there and the fit cannot move), within the bounds.
fn saturation_hypothesis(kind: Kind, absmax: f64, from: f64) -> Hypothesis {
    let h = linear(kind, 0.2 * absmax, absmax, LIMIT);
    let from = if from > 0.0 { from.min(absmax) } else { absmax };
    let at: Vec<f64> = SATURATION_STARTS.iter().map(|f| (f * from).max(0.2 * absmax)).collect();
    h.starts_at(&at)
}

/// The input operations (see the module documentation).
pub struct InputOps;

impl Family for InputOps {
    fn hypotheses(&self, site: &Site, cx: &Context) -> Vec<Hypothesis> {
        let s = cx.scales;
        match *site {
            Site::Input => vec![
                level(Kind::InputDelay, delay_bound(s), DELAY),
                saturation_hypothesis(Kind::InputSaturation, s.w_absmax, s.w_absmax_est),
            ],
            Site::OneInput { input, absmax, range } => {
                let on = |op| Kind::InputOn { op, input };
                vec![
                    level(on(InputOp::Play), 0.5 * range, WIDTH),
                    saturation_hypothesis(on(InputOp::Saturation), absmax, 0.0),
                    level(on(InputOp::Delay), delay_bound(s), DELAY),
                ]
            }
            _ => vec![],
        }
    }

    fn name(&self, kind: Kind) -> Option<&'static str> {
        match kind {
            Kind::InputDelay => Some(names::INPUT_DELAY),
            Kind::InputSaturation => Some(names::INPUT_SATURATION),
            Kind::InputOn { op, .. } => Some(op.name()),
            _ => None,
        }
    }

    fn label(&self, kind: Kind) -> Option<String> {
        match kind {
            Kind::InputOn { op, input } => Some(op.label(input)),
            k => self.name(k).map(String::from),
        }
    }

    fn description(&self, kind: Kind) -> Option<String> {
        Some(match kind {
            Kind::InputDelay => "The plant sees the input late (transport, communication or computation delay).".into(),
            Kind::InputSaturation => {
                "The actuator cannot deliver commands beyond a limit (voltage or current saturation).".into()
            }
            Kind::InputOn { op, input } => op.description(input),
            _ => return None,
        })
    }

    fn effect(&self, kind: Kind, theta: &[f64]) -> Option<Effect> {
        Some(match kind {
            Kind::InputDelay => delay(theta[0]),
            Kind::InputSaturation => saturation(theta[0]),
            Kind::InputOn { op, .. } => op.on_every_input(theta[0]),
            _ => return None,
        })
    }

    fn main_parameter(&self, effect: &Effect) -> Option<(f64, Option<&'static str>)> {
        match effect {
            Effect::InputDelay { delay } => Some((*delay, Some(DELAY))),
            Effect::InputSaturation { limit } => Some((*limit, Some(LIMIT))),
            _ => None,
        }
    }
}
