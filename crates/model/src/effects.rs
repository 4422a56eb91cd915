//! Optional physics extensions of the nominal model (`[[effects]]` in a model file), used by
//! the `discovery` crate to express what a recording shows and the nominal model lacks.
//! Each effect equals the nominal model when its parameters are zero (or it is absent), so a
//! fitted model is an ordinary model file.
use crate::toml_access::{
    check_keys, describe, f64_at, key, nonneg, opt_f64, opt_nonneg, positive, str_at, vec_at, vec_value,
};
use crate::ModelError;
use toml::{Table, Value};

/// The model-file name of each effect (`kind = "..."` in `[[effects]]`), declared once: the
/// parser, the writer ([`Effect::kind`]) and the diagnosis' physics library all use these.
pub mod names {
    pub const BACKLASH: &str = "backlash";
    pub const GAP_WIDTH: &str = "gap_width";
    pub const COULOMB_FRICTION: &str = "coulomb_friction";
    pub const CONSTANT_FORCE: &str = "constant_force";
    pub const BACKLASH_INERTIA: &str = "backlash_inertia";
    pub const INPUT_DELAY: &str = "input_delay";
    pub const INPUT_SATURATION: &str = "input_saturation";
    pub const SENSOR_OFFSET: &str = "sensor_offset";
    pub const STRIBECK_FRICTION: &str = "stribeck_friction";
    pub const ASYMMETRIC_COULOMB: &str = "asymmetric_coulomb";
    pub const COGGING: &str = "cogging";
    pub const LOAD_FRICTION: &str = "load_friction";
}

/// Where a backlash (play) effect sits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlayLocation {
    /// In the feedback loop, as in the paper (`z in y + [-w/2, w/2]`).
    Loop,
    /// Between the input and the plant (`w` passes through a play operator).
    Input,
}

/// One physical effect. Parameters are in the units of the model's states and input.
#[derive(Debug, Clone, PartialEq)]
pub enum Effect {
    /// A play of total width `width` where the nominal model has none.
    Backlash { width: f64, location: PlayLocation },
    /// Theta scaled by `1 + relative_change`.
    GapWidth { relative_change: f64 },
    /// Coulomb friction of level `level` on the derivative of velocity state `state`,
    /// with stick-slip (the state sticks at zero while the other forces stay below `level`).
    CoulombFriction { state: usize, level: f64 },
    /// Constant bias `force` added to the derivative of state `state`.
    ConstantForce { state: usize, force: f64 },
    /// The backlash output has mass `mass` and damping `damping`: after `y` reverses, `z`
    /// coasts instead of stopping at once.
    BacklashInertia { mass: f64, damping: f64 },
    /// The plant sees `w(t - delay)`.
    InputDelay { delay: f64 },
    /// The plant sees `clamp(w, -limit, limit)`.
    InputSaturation { limit: f64 },
    /// The sensor reads `y + offset`.
    SensorOffset { offset: Vec<f64> },
    /// Friction with a static (breakaway) level and a Stribeck curve on velocity state
    /// `state`: at rest it holds any force up to `static_level`; sliding at velocity `v` it
    /// opposes the motion with `level + (static_level - level) exp(-(v/stribeck_velocity)^2)
    /// + viscous |v|`. With `static_level == level` and `viscous == 0` it is Coulomb friction.
    StribeckFriction { state: usize, level: f64, static_level: f64, stribeck_velocity: f64, viscous: f64 },
    /// Coulomb friction whose level depends on the direction of motion of velocity state
    /// `state`: `level_positive` while it moves up (and the most it holds against a push up),
    /// `level_negative` while it moves down. Equal levels are `coulomb_friction`.
    AsymmetricCoulomb { state: usize, level_positive: f64, level_negative: f64 },
    /// A position-periodic (cogging, detent) force `amplitude sin(2 pi x_pos / period + phase)`
    /// on the derivative of velocity state `state`, `x_pos` being state `position_state`.
    Cogging { state: usize, position_state: usize, amplitude: f64, period: f64, phase: f64 },
    /// Coulomb friction on velocity state `state` whose level grows with the load that a
    /// transmission (a gearbox, a lead screw) carries: `level + load_coefficient |d - e|`,
    /// where `d = B_j w + E_j z` is the actuator's force on `x_j'` (through the input and the
    /// loop) and `e = sum_{i != j} A_ji x_i` the plant's own forces on it (springs, gravity),
    /// evaluated at the start of each step (the load-dependent model M3 of the BAM actuator
    /// models). `load_coefficient = 0` is `coulomb_friction`.
    LoadFriction { state: usize, level: f64, load_coefficient: f64 },
}

impl Effect {
    /// The name used in model files and reports.
    pub fn kind(&self) -> &'static str {
        match self {
            Effect::Backlash { .. } => names::BACKLASH,
            Effect::GapWidth { .. } => names::GAP_WIDTH,
            Effect::CoulombFriction { .. } => names::COULOMB_FRICTION,
            Effect::ConstantForce { .. } => names::CONSTANT_FORCE,
            Effect::BacklashInertia { .. } => names::BACKLASH_INERTIA,
            Effect::InputDelay { .. } => names::INPUT_DELAY,
            Effect::InputSaturation { .. } => names::INPUT_SATURATION,
            Effect::SensorOffset { .. } => names::SENSOR_OFFSET,
            Effect::StribeckFriction { .. } => names::STRIBECK_FRICTION,
            Effect::AsymmetricCoulomb { .. } => names::ASYMMETRIC_COULOMB,
            Effect::Cogging { .. } => names::COGGING,
            Effect::LoadFriction { .. } => names::LOAD_FRICTION,
        }
    }
}

/// The list of effects of a model (empty for the nominal model).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Effects {
    pub list: Vec<Effect>,
}

fn state_index(t: &Table, prefix: &str, n: usize) -> Result<usize, ModelError> {
    index_at(t, prefix, "state", n)
}

fn index_at(t: &Table, prefix: &str, k: &str, n: usize) -> Result<usize, ModelError> {
    let v = f64_at(t, prefix, k)?;
    if v < 0.0 || v.fract() != 0.0 || v as usize >= n {
        return Err(ModelError::OutOfRange { key: key(prefix, k), value: v, reason: "must be a state index 0..n-1" });
    }
    Ok(v as usize)
}

/// A backlash's `location`: `"loop"` (the default) or `"input"`.
fn play_location(t: &Table, prefix: &str) -> Result<PlayLocation, ModelError> {
    match t.get("location").map(|l| l.as_str()) {
        None | Some(Some("loop")) => Ok(PlayLocation::Loop),
        Some(Some("input")) => Ok(PlayLocation::Input),
        Some(_) => Err(ModelError::WrongType {
            key: key(prefix, "location"),
            expected: "\"loop\" or \"input\"",
            found: describe(&t["location"]),
        }),
    }
}

/// A `stribeck_friction` table: the breakaway level is never below the sliding level, the
/// viscous term is optional (0).
fn stribeck(t: &Table, prefix: &str, n: usize) -> Result<Effect, ModelError> {
    check_keys(t, prefix, "kind, state, level, static_level, stribeck_velocity, viscous")?;
    let state = state_index(t, prefix, n)?;
    let level = nonneg(t, prefix, "level")?;
    let static_level = nonneg(t, prefix, "static_level")?;
    if static_level < level {
        return Err(ModelError::Invalid {
            key: key(prefix, "static_level"),
            value: static_level,
            reason: format!(
                "must be at least `level` = {level} (the breakaway level is never below the sliding level)"
            ),
        });
    }
    let stribeck_velocity = positive(t, prefix, "stribeck_velocity")?;
    let viscous = opt_nonneg(t, prefix, "viscous")?.unwrap_or(0.0);
    Ok(Effect::StribeckFriction { state, level, static_level, stribeck_velocity, viscous })
}

/// A `cogging` table: the force acts on velocity state `state`, its period is in another state.
fn cogging(t: &Table, prefix: &str, n: usize) -> Result<Effect, ModelError> {
    check_keys(t, prefix, "kind, state, position_state, amplitude, period, phase")?;
    let state = state_index(t, prefix, n)?;
    let position_state = index_at(t, prefix, "position_state", n)?;
    if position_state == state {
        return Err(ModelError::Invalid {
            key: key(prefix, "position_state"),
            value: position_state as f64,
            reason: format!(
                "must differ from `state` = {state} (the force acts on the velocity, the period is in the position)"
            ),
        });
    }
    Ok(Effect::Cogging {
        state,
        position_state,
        amplitude: f64_at(t, prefix, "amplitude")?,
        period: positive(t, prefix, "period")?,
        phase: opt_f64(t, prefix, "phase")?.unwrap_or(0.0),
    })
}

impl Effect {
    /// One `[[effects]]` table at key `prefix` (e.g. `effects[2]`), checked.
    fn parse_one(t: &Table, prefix: &str, n: usize, p: usize) -> Result<Self, ModelError> {
        let prefix = prefix.to_string();
        let kind = str_at(t, &prefix, "kind")?;
        let e = match kind {
            names::BACKLASH => {
                check_keys(t, &prefix, "kind, width, location")?;
                Effect::Backlash { width: nonneg(t, &prefix, "width")?, location: play_location(t, &prefix)? }
            }
            names::GAP_WIDTH => {
                check_keys(t, &prefix, "kind, relative_change")?;
                let r = f64_at(t, &prefix, "relative_change")?;
                if r <= -1.0 {
                    return Err(ModelError::OutOfRange { key: key(&prefix, "relative_change"), value: r, reason: "must exceed -1" });
                }
                Effect::GapWidth { relative_change: r }
            }
            names::COULOMB_FRICTION => {
                check_keys(t, &prefix, "kind, state, level")?;
                Effect::CoulombFriction { state: state_index(t, &prefix, n)?, level: nonneg(t, &prefix, "level")? }
            }
            names::CONSTANT_FORCE => {
                check_keys(t, &prefix, "kind, state, force")?;
                Effect::ConstantForce { state: state_index(t, &prefix, n)?, force: f64_at(t, &prefix, "force")? }
            }
            names::BACKLASH_INERTIA => {
                check_keys(t, &prefix, "kind, mass, damping")?;
                Effect::BacklashInertia { mass: nonneg(t, &prefix, "mass")?, damping: nonneg(t, &prefix, "damping")? }
            }
            names::INPUT_DELAY => {
                check_keys(t, &prefix, "kind, delay")?;
                Effect::InputDelay { delay: nonneg(t, &prefix, "delay")? }
            }
            names::INPUT_SATURATION => {
                check_keys(t, &prefix, "kind, limit")?;
                Effect::InputSaturation { limit: positive(t, &prefix, "limit")? }
            }
            names::SENSOR_OFFSET => {
                check_keys(t, &prefix, "kind, offset")?;
                let o = vec_at(t, &prefix, "offset")?;
                ModelError::check_length(key(&prefix, "offset"), o.len(), "p", p)?;
                Effect::SensorOffset { offset: o }
            }
            names::STRIBECK_FRICTION => stribeck(t, &prefix, n)?,
            names::ASYMMETRIC_COULOMB => {
                check_keys(t, &prefix, "kind, state, level_positive, level_negative")?;
                Effect::AsymmetricCoulomb {
                    state: state_index(t, &prefix, n)?,
                    level_positive: nonneg(t, &prefix, "level_positive")?,
                    level_negative: nonneg(t, &prefix, "level_negative")?,
                }
            }
            names::COGGING => cogging(t, &prefix, n)?,
            names::LOAD_FRICTION => {
                check_keys(t, &prefix, "kind, state, level, load_coefficient")?;
                Effect::LoadFriction {
                    state: state_index(t, &prefix, n)?,
                    level: nonneg(t, &prefix, "level")?,
                    load_coefficient: nonneg(t, &prefix, "load_coefficient")?,
                }
            }
            other => {
                return Err(ModelError::WrongType {
                    key: key(&prefix, "kind"),
                    expected: "one of backlash, gap_width, coulomb_friction, stribeck_friction, asymmetric_coulomb, load_friction, cogging, constant_force, backlash_inertia, input_delay, input_saturation, sensor_offset",
                    found: format!("{other:?}"),
                })
            }
        };
        Ok(e)
    }
}

impl Effects {
    /// Parses `[[effects]]` entries; `n` and `p` are the model's state and output dimensions.
    pub(crate) fn parse(v: Option<&Value>, n: usize, p: usize) -> Result<Self, ModelError> {
        let Some(v) = v else { return Ok(Self::default()) };
        let Value::Array(items) = v else {
            return Err(ModelError::WrongType {
                key: "effects".into(),
                expected: "an array of tables ([[effects]])",
                found: describe(v),
            });
        };
        let mut list = Vec::new();
        for (i, it) in items.iter().enumerate() {
            let prefix = format!("effects[{i}]");
            let Value::Table(t) = it else {
                return Err(ModelError::WrongType { key: prefix, expected: "a table", found: describe(it) });
            };
            list.push(Effect::parse_one(t, &prefix, n, p)?);
        }
        Ok(Self { list })
    }

    pub(crate) fn to_value(&self) -> Option<Value> {
        if self.list.is_empty() {
            return None;
        }
        let items = self
            .list
            .iter()
            .map(|e| {
                let mut t = Table::new();
                t.insert("kind".into(), Value::String(e.kind().into()));
                for (k, v) in e.fields() {
                    t.insert(k.into(), v);
                }
                Value::Table(t)
            })
            .collect();
        Some(Value::Array(items))
    }
}

impl Effect {
    /// The keys and values of the effect's `[[effects]]` table other than `kind`, in the order
    /// the file format documents them (defaults left out: `viscous = 0`).
    pub fn fields(&self) -> Vec<(&'static str, Value)> {
        let int = |i: &usize| Value::Integer(*i as i64);
        let f = |x: &f64| Value::Float(*x);
        match self {
            Effect::Backlash { width, location } => vec![
                ("width", f(width)),
                ("location", Value::String(if *location == PlayLocation::Loop { "loop" } else { "input" }.into())),
            ],
            Effect::GapWidth { relative_change } => vec![("relative_change", f(relative_change))],
            Effect::CoulombFriction { state, level } => vec![("state", int(state)), ("level", f(level))],
            Effect::ConstantForce { state, force } => vec![("state", int(state)), ("force", f(force))],
            Effect::BacklashInertia { mass, damping } => vec![("mass", f(mass)), ("damping", f(damping))],
            Effect::InputDelay { delay } => vec![("delay", f(delay))],
            Effect::InputSaturation { limit } => vec![("limit", f(limit))],
            Effect::SensorOffset { offset } => vec![("offset", vec_value(offset))],
            Effect::StribeckFriction { state, level, static_level, stribeck_velocity, viscous } => {
                let mut v = vec![
                    ("state", int(state)),
                    ("level", f(level)),
                    ("static_level", f(static_level)),
                    ("stribeck_velocity", f(stribeck_velocity)),
                ];
                if *viscous != 0.0 {
                    v.push(("viscous", f(viscous)));
                }
                v
            }
            Effect::AsymmetricCoulomb { state, level_positive, level_negative } => vec![
                ("state", int(state)),
                ("level_positive", f(level_positive)),
                ("level_negative", f(level_negative)),
            ],
            Effect::LoadFriction { state, level, load_coefficient } => {
                vec![("state", int(state)), ("level", f(level)), ("load_coefficient", f(load_coefficient))]
            }
            Effect::Cogging { state, position_state, amplitude, period, phase } => vec![
                ("state", int(state)),
                ("position_state", int(position_state)),
                ("amplitude", f(amplitude)),
                ("period", f(period)),
                ("phase", f(phase)),
            ],
        }
    }

    /// The effect with key `key` (element `element` of an array key) set to `x`, checked as
    /// the parser checks a file's effect (`n`, `p`: the model's state and output dimensions).
    /// `prefix` names the effect in errors (`effects[2]`).
    pub fn with_number(
        &self,
        prefix: &str,
        key: &str,
        element: Option<usize>,
        x: f64,
        n: usize,
        p: usize,
    ) -> Result<Effect, ModelError> {
        let mut t = Table::new();
        t.insert("kind".into(), Value::String(self.kind().into()));
        for (k, v) in self.fields() {
            t.insert(k.into(), v);
        }
        let slot = match (t.get_mut(key), element) {
            (Some(Value::Array(a)), Some(e)) => a.get_mut(e),
            (Some(v), None) => Some(v),
            _ => None,
        };
        match slot {
            Some(v) => *v = Value::Float(x),
            None if key == "viscous" && element.is_none() => {
                t.insert(key.into(), Value::Float(x));
            }
            None => return Err(ModelError::Missing { key: format!("{prefix}.{key}") }),
        }
        Effect::parse_one(&t, prefix, n, p)
    }

    /// The effect in the model file's own words, one line: its `kind` and its keys, e.g.
    /// `coulomb_friction on state 1, level 0.2` or `input_delay: delay 0.05` (numbers in the
    /// shortest form that reads back to the same value).
    pub fn describe(&self) -> String {
        fn show(v: &Value) -> String {
            match v {
                Value::Float(x) => format!("{x}"),
                Value::Integer(i) => format!("{i}"),
                Value::String(s) => s.clone(),
                Value::Array(a) => format!("[{}]", a.iter().map(show).collect::<Vec<_>>().join(", ")),
                other => other.to_string(),
            }
        }
        let fields = self.fields();
        let (state, rest): (Vec<_>, Vec<_>) = fields.iter().partition(|(k, _)| *k == "state");
        let rest: Vec<String> = rest.iter().map(|(k, v)| format!("{k} {}", show(v))).collect();
        match state.first() {
            Some((_, s)) if rest.is_empty() => format!("{} on state {}", self.kind(), show(s)),
            Some((_, s)) => format!("{} on state {}, {}", self.kind(), show(s), rest.join(", ")),
            None => format!("{}: {}", self.kind(), rest.join(", ")),
        }
    }
}

#[cfg(test)]
mod describe_tests {
    use super::*;

    #[test]
    fn effects_are_described_in_the_model_files_words() {
        assert_eq!(
            Effect::CoulombFriction { state: 1, level: 0.2 }.describe(),
            "coulomb_friction on state 1, level 0.2"
        );
        assert_eq!(Effect::InputDelay { delay: 0.05 }.describe(), "input_delay: delay 0.05");
        assert_eq!(Effect::SensorOffset { offset: vec![0.1, -2.0] }.describe(), "sensor_offset: offset [0.1, -2]");
        assert_eq!(
            Effect::Backlash { width: 0.3, location: PlayLocation::Input }.describe(),
            "backlash: width 0.3, location input"
        );
        // every described key is a key of the file (the parser accepts what describe names)
        let e = Effect::Cogging { state: 1, position_state: 0, amplitude: 0.5, period: 0.25, phase: 0.0 };
        assert_eq!(e.describe(), "cogging on state 1, position_state 0, amplitude 0.5, period 0.25, phase 0");
    }
}
