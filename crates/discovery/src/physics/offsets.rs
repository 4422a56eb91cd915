//! Offsets: `constant_force` on a velocity state (gravity, a spring preload, an amplifier
//! bias) and `sensor_offset` on the outputs (calibration or zero error).
//!
//! Bounds: a force `+-` half the site's force bound, an offset `+- range(y)/2` per output.
//! Both enter the output linearly and need no decade starts.
use super::parameters::linear;
use super::{Context, Family, Hypothesis, Kind, Site};
use model::effects::{names, Effect};

const FORCE: &str = "force";
const OFFSET: &str = "offset";

/// The offsets (see the module documentation).
pub struct Offsets;

impl Family for Offsets {
    fn hypotheses(&self, site: &Site, cx: &Context) -> Vec<Hypothesis> {
        match *site {
            Site::Velocity { state, force_bound: fs, .. } => {
                let mut h = linear(Kind::ConstantForce { state }, -0.5 * fs, 0.5 * fs, FORCE);
                h.starts = vec![vec![0.3], vec![0.5], vec![0.7]];
                vec![h]
            }
            Site::Sensor => {
                let s = cx.scales;
                let p = s.y_range.len();
                vec![Hypothesis {
                    kind: Kind::SensorOffset,
                    lower: s.y_range.iter().map(|r| -0.5 * r).collect(),
                    upper: s.y_range.iter().map(|r| 0.5 * r).collect(),
                    starts: vec![vec![0.5; p], vec![0.3; p], vec![0.7; p]],
                    names: vec![OFFSET; p],
                    log_shift: vec![None; p],
                }]
            }
            _ => vec![],
        }
    }

    fn name(&self, kind: Kind) -> Option<&'static str> {
        match kind {
            Kind::ConstantForce { .. } => Some(names::CONSTANT_FORCE),
            Kind::SensorOffset => Some(names::SENSOR_OFFSET),
            _ => None,
        }
    }

    fn label(&self, kind: Kind) -> Option<String> {
        match kind {
            Kind::ConstantForce { state } => Some(format!("{}(x{})", names::CONSTANT_FORCE, state + 1)),
            k => self.name(k).map(String::from),
        }
    }

    fn description(&self, kind: Kind) -> Option<String> {
        Some(match kind {
            Kind::ConstantForce { state } => format!(
                "A constant force (gravity, a spring preload, an amplifier bias) acts on the derivative of state x{}.",
                state + 1
            ),
            Kind::SensorOffset => {
                "The sensor reads a constant offset from the true output (calibration or zero error).".into()
            }
            _ => return None,
        })
    }

    fn effect(&self, kind: Kind, theta: &[f64]) -> Option<Effect> {
        Some(match kind {
            Kind::ConstantForce { state } => Effect::ConstantForce { state, force: theta[0] },
            Kind::SensorOffset => Effect::SensorOffset { offset: theta.to_vec() },
            _ => return None,
        })
    }

    fn main_parameter(&self, effect: &Effect) -> Option<(f64, Option<&'static str>)> {
        match effect {
            Effect::ConstantForce { force, .. } => Some((*force, Some(FORCE))),
            Effect::SensorOffset { offset } => Some((offset[0], Some(OFFSET))),
            _ => None,
        }
    }
}
