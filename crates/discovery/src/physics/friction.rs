//! The friction laws on a velocity state (issue 14): `coulomb_friction`, `stribeck_friction`,
//! `asymmetric_coulomb` and `load_friction` (issue 28: a level that grows with the load a
//! transmission carries, offered where an actuator drives the state: `B_j` or `E_j` nonzero).
//!
//! Bounds: friction levels up to the force whose static deflection of `y` equals `range(y)`,
//! `range(y) / |C F^{-1} e_j|` (the site's force bound). `stribeck_friction` is fitted as
//! `(level, static_level - level, stribeck_velocity)` with both levels in the friction bound
//! and the velocity in `[1e-3, 2] v_rms` (the state's RMS in the nominal run), all in log
//! coordinates; `asymmetric_coulomb` with both levels in the friction bound. Friction levels
//! start at [`FRICTION_DECADES`] of the bound (down to 1e-4, with 0.2 %) combined with static
//! excesses and Stribeck velocities or level ratios, screened by the solver.
//!
//! A Stribeck law with equal levels is Coulomb friction and unequal direction levels are
//! Coulomb friction plus a constant force: BIC's parameter count prefers the simpler form
//! unless the data show breakaway or asymmetry ([`Family::simpler_form`]), and [`notes`] gives
//! the conversions.
use super::parameters::{level, LEVEL_LOG_SHIFT};
use super::{Context, Family, Hypothesis, Kind, Site};
use model::effects::{names, Effect};

const LEVEL: &str = "level";
const STATIC_EXCESS: &str = "static_excess";
const STRIBECK_VELOCITY: &str = "stribeck_velocity";
const LEVEL_POSITIVE: &str = "level_positive";
const LEVEL_NEGATIVE: &str = "level_negative";
const LOAD_COEFFICIENT: &str = "load_coefficient";

/// The largest load coefficient tried: friction equal to the transmitted load (a transmission
/// that does not backdrive).
pub const LOAD_COEFFICIENT_MAX: f64 = 1.0;

/// Load coefficients at which `load_friction` is started.
const LOAD_STARTS: [f64; 3] = [0.03, 0.1, 0.3];

/// The friction laws (see the module documentation).
pub struct Friction;

/// Fractions of the bound at which a friction level is started (the decades, with 0.2 % of
/// the bound, where issue 13's small friction sat).
pub const FRICTION_DECADES: [f64; 7] = [1e-4, 1e-3, 2e-3, 1e-2, 0.1, 0.4, 0.8];

/// `stribeck_friction` on state `j`: `(level, static_level - level, stribeck_velocity)`, the
/// levels in `[0, fs]` and the velocity in `[1e-3, 2] v_scale`, all in logarithmic
/// coordinates; starts: each level decade with a static excess of half and 1.5 times the
/// level and Stribeck velocities of 3 % and 30 % of `v_scale` (screened by the solver).
pub fn stribeck(j: usize, fs: f64, v_scale: f64) -> Hypothesis {
    let h = Hypothesis {
        kind: Kind::StribeckFriction { state: j },
        lower: vec![0.0, 0.0, 1e-3 * v_scale],
        upper: vec![fs, fs, 2.0 * v_scale],
        starts: vec![],
        names: vec![LEVEL, STATIC_EXCESS, STRIBECK_VELOCITY],
        log_shift: vec![Some(LEVEL_LOG_SHIFT * fs), Some(LEVEL_LOG_SHIFT * fs), Some(0.0)],
    };
    let mut starts = Vec::new();
    for f in FRICTION_DECADES {
        for r in [0.5, 1.5] {
            for v in [0.03, 0.3] {
                let t = [f * fs, (r * f * fs).min(fs), v * v_scale];
                starts.push((0..3).map(|i| h.unit_of(i, t[i])).collect());
            }
        }
    }
    Hypothesis { starts, ..h }
}

/// `asymmetric_coulomb` on state `j`: both levels in `[0, fs]` (logarithmic coordinates),
/// started over the decades with ratios 1, 1/3 and 3.
pub fn asymmetric(j: usize, fs: f64) -> Hypothesis {
    let h = Hypothesis {
        kind: Kind::AsymmetricCoulomb { state: j },
        lower: vec![0.0, 0.0],
        upper: vec![fs, fs],
        starts: vec![],
        names: vec![LEVEL_POSITIVE, LEVEL_NEGATIVE],
        log_shift: vec![Some(LEVEL_LOG_SHIFT * fs); 2],
    };
    let mut starts = Vec::new();
    for f in FRICTION_DECADES {
        for (a, b) in [(1.0, 1.0), (1.0, 1.0 / 3.0), (1.0 / 3.0, 1.0)] {
            starts.push(vec![h.unit_of(0, a * f * fs), h.unit_of(1, b * f * fs)]);
        }
    }
    Hypothesis { starts, ..h }
}

/// `load_friction` on state `j`: `(level, load_coefficient)`, the level in `[0, fs]` and the
/// coefficient in `[0, LOAD_COEFFICIENT_MAX]`, both in logarithmic coordinates; started over
/// the level decades with coefficients [`LOAD_STARTS`].
pub fn load(j: usize, fs: f64) -> Hypothesis {
    let h = Hypothesis {
        kind: Kind::LoadFriction { state: j },
        lower: vec![0.0, 0.0],
        upper: vec![fs, LOAD_COEFFICIENT_MAX],
        starts: vec![],
        names: vec![LEVEL, LOAD_COEFFICIENT],
        log_shift: vec![Some(LEVEL_LOG_SHIFT * fs), Some(LEVEL_LOG_SHIFT * LOAD_COEFFICIENT_MAX)],
    };
    let mut starts = Vec::new();
    for f in FRICTION_DECADES {
        for k in LOAD_STARTS {
            starts.push(vec![h.unit_of(0, f * fs), h.unit_of(1, k)]);
        }
    }
    Hypothesis { starts, ..h }
}

/// Whether an actuator drives velocity state `j` (`B_j` or `E_j` nonzero): only then can a
/// transmission carry a load to it.
fn actuated(sys: &model::System, j: usize) -> bool {
    sys.B.row(j).iter().chain(sys.E.row(j).iter()).any(|v| *v != 0.0)
}

impl Family for Friction {
    fn hypotheses(&self, site: &Site, cx: &Context) -> Vec<Hypothesis> {
        let &Site::Velocity { state: j, force_bound: fs, velocity_scale, .. } = site else { return vec![] };
        let mut laws = vec![
            level(Kind::CoulombFriction { state: j }, fs, LEVEL),
            stribeck(j, fs, velocity_scale),
            asymmetric(j, fs),
        ];
        if actuated(cx.sys, j) {
            laws.push(load(j, fs));
        }
        laws
    }

    fn name(&self, kind: Kind) -> Option<&'static str> {
        match kind {
            Kind::CoulombFriction { .. } => Some(names::COULOMB_FRICTION),
            Kind::StribeckFriction { .. } => Some(names::STRIBECK_FRICTION),
            Kind::AsymmetricCoulomb { .. } => Some(names::ASYMMETRIC_COULOMB),
            Kind::LoadFriction { .. } => Some(names::LOAD_FRICTION),
            _ => None,
        }
    }

    fn label(&self, kind: Kind) -> Option<String> {
        match kind {
            Kind::CoulombFriction { state }
            | Kind::StribeckFriction { state }
            | Kind::AsymmetricCoulomb { state }
            | Kind::LoadFriction { state } => Some(format!("{}(x{})", self.name(kind)?, state + 1)),
            _ => None,
        }
    }

    fn description(&self, kind: Kind) -> Option<String> {
        Some(match kind {
            Kind::CoulombFriction { state } => format!("Dry (Coulomb) friction opposes the motion of velocity state x{}: the motion sticks at rest until the driving force exceeds the friction level.", state + 1),
            Kind::StribeckFriction { state } => format!("Friction with breakaway (stiction) on velocity state x{}: at rest it holds up to a static level above the sliding friction, which falls along a Stribeck curve to the Coulomb level as the speed grows.", state + 1),
            Kind::AsymmetricCoulomb { state } => format!("Dry friction on velocity state x{} whose level depends on the direction of motion (e.g. a seal or guide that drags more one way, or a load that aids one direction).", state + 1),
            Kind::LoadFriction { state } => format!("Dry friction on velocity state x{} that grows with the load the transmission carries (a gearbox or lead screw that holds more the harder the actuator pushes against the load, down to not backdriving at all).", state + 1),
            _ => return None,
        })
    }

    fn effect(&self, kind: Kind, theta: &[f64]) -> Option<Effect> {
        Some(match kind {
            Kind::CoulombFriction { state } => Effect::CoulombFriction { state, level: theta[0].max(0.0) },
            Kind::StribeckFriction { state } => {
                let level = theta[0].max(0.0);
                Effect::StribeckFriction {
                    state,
                    level,
                    static_level: level + theta[1].max(0.0),
                    stribeck_velocity: theta[2].max(1e-300),
                    viscous: 0.0,
                }
            }
            Kind::AsymmetricCoulomb { state } => Effect::AsymmetricCoulomb {
                state,
                level_positive: theta[0].max(0.0),
                level_negative: theta[1].max(0.0),
            },
            Kind::LoadFriction { state } => {
                Effect::LoadFriction { state, level: theta[0].max(0.0), load_coefficient: theta[1].max(0.0) }
            }
            _ => return None,
        })
    }

    /// Stribeck friction (static level = sliding level), direction-dependent friction (equal
    /// levels) and load-dependent friction (coefficient 0) all contain Coulomb friction on the
    /// same state.
    fn simpler_form(&self, kind: Kind) -> Option<Kind> {
        match kind {
            Kind::StribeckFriction { state } | Kind::AsymmetricCoulomb { state } | Kind::LoadFriction { state } => {
                Some(Kind::CoulombFriction { state })
            }
            _ => None,
        }
    }

    /// From a Coulomb level `L`: a Stribeck law with its sliding level at 0.6 and 0.9 `L`, a
    /// static excess of 0.8, 1.5 and 2.5 times that and Stribeck velocities of 1-30 % of the
    /// velocity scale (the Coulomb reading lies between the sliding and the static level); a
    /// direction-dependent law with levels `L` split 1:1, 1.3:0.7 and 1.6:0.4 either way.
    fn starts_from_simpler(&self, h: &Hypothesis, simpler: &[f64]) -> Option<Vec<Vec<f64>>> {
        let l = *simpler.first()?;
        let unit = |t: [f64; 3], k: usize| (0..k).map(|i| h.unit_of(i, t[i])).collect::<Vec<f64>>();
        match h.kind {
            Kind::StribeckFriction { .. } => {
                let v_scale = 0.5 * h.upper[2];
                let mut starts = Vec::new();
                for a in [0.6, 0.9] {
                    for r in [0.8, 1.5, 2.5] {
                        for v in [0.01, 0.03, 0.1, 0.3] {
                            starts.push(unit([a * l, r * a * l, v * v_scale], 3));
                        }
                    }
                }
                Some(starts)
            }
            Kind::AsymmetricCoulomb { .. } => Some(
                [(1.0, 1.0), (1.3, 0.7), (0.7, 1.3), (1.6, 0.4), (0.4, 1.6)]
                    .iter()
                    .map(|&(a, b)| unit([a * l, b * l, 0.0], 2))
                    .collect(),
            ),
            // Part of the Coulomb reading is the load's: the level at 1, 0.6 and 0.3 `L`.
            Kind::LoadFriction { .. } => Some(
                [1.0, 0.6, 0.3]
                    .iter()
                    .flat_map(|&a| LOAD_STARTS.iter().map(move |&k| vec![h.unit_of(0, a * l), h.unit_of(1, k)]))
                    .collect(),
            ),
            _ => None,
        }
    }

    /// A Coulomb level from a generalisation's estimate: a Stribeck law's sliding level, its
    /// static level and their mean; a direction-dependent law's mean level and each of its
    /// two; a load-dependent law's level without and with a third more for the load's part.
    fn starts_from_general(&self, simple: &Hypothesis, kind: Kind, general: &[f64]) -> Option<Vec<Vec<f64>>> {
        // (the simpler form of every friction generalisation is Coulomb friction on its state)
        if kind.simpler_form() != Some(simple.kind) {
            return None;
        }
        let levels = match (kind, general) {
            (Kind::StribeckFriction { .. }, &[l, ex, _]) => [l, l + ex, l + 0.5 * ex],
            (Kind::AsymmetricCoulomb { .. }, &[lp, ln]) => [0.5 * (lp + ln), lp, ln],
            (Kind::LoadFriction { .. }, &[l, _]) => [l, 1.33 * l, 1.67 * l],
            _ => return None,
        };
        Some(levels.iter().filter(|l| l.is_finite() && **l > 0.0).map(|&l| vec![simple.unit_of(0, l)]).collect())
    }

    fn main_parameter(&self, effect: &Effect) -> Option<(f64, Option<&'static str>)> {
        match effect {
            Effect::CoulombFriction { level, .. } => Some((*level, Some(LEVEL))),
            Effect::StribeckFriction { static_level, .. } => Some((*static_level, None)),
            Effect::AsymmetricCoulomb { level_positive, .. } => Some((*level_positive, Some(LEVEL_POSITIVE))),
            Effect::LoadFriction { load_coefficient, .. } => Some((*load_coefficient, Some(LOAD_COEFFICIENT))),
            _ => None,
        }
    }

    fn every_parameter(&self, effect: &Effect) -> Option<Vec<(&'static str, f64)>> {
        match effect {
            Effect::StribeckFriction { level, static_level, stribeck_velocity, .. } => {
                Some(vec![("static_level", *static_level), (LEVEL, *level), (STRIBECK_VELOCITY, *stribeck_velocity)])
            }
            Effect::AsymmetricCoulomb { level_positive, level_negative, .. } => {
                Some(vec![(LEVEL_POSITIVE, *level_positive), (LEVEL_NEGATIVE, *level_negative)])
            }
            Effect::LoadFriction { level, load_coefficient, .. } => {
                Some(vec![(LOAD_COEFFICIENT, *load_coefficient), (LEVEL, *level)])
            }
            _ => None,
        }
    }
}

/// The static over the sliding level as the Stribeck note words it: a ratio, or, where the
/// sliding level is zero (or the ratio beyond a million), that the friction acts only near
/// rest (a ratio of 2.8e302 was printed for a sliding level fitted at 0).
fn level_ratio(static_level: f64, level: f64) -> String {
    let r = static_level / level;
    if level > 0.0 && r.is_finite() && r < 1e6 {
        format!("ratio {r:.2}")
    } else {
        "no sliding friction: it acts near rest only".into()
    }
}

/// Notes on observational equivalences among the friction effects of a fitted model
/// (`effects`) and on ties (`ties`, hypothesis labels) that involve them: a Stribeck law
/// whose static level equals its sliding level is Coulomb friction, and direction-dependent
/// Coulomb levels are Coulomb friction plus a constant force on the same state.
pub fn notes(effects: &[Effect], ties: &[String]) -> Vec<String> {
    let mut out = Vec::new();
    for e in effects {
        match e {
            Effect::AsymmetricCoulomb { state, level_positive: a, level_negative: b } => out.push(format!(
                "asymmetric_coulomb(x{0}) with levels {a:.4e} (moving up) and {b:.4e} (down) is the same model as coulomb_friction(x{0}) at {1:.4e} plus constant_force(x{0}) {2:.4e}: direction-dependent friction and a constant load (gravity on an inclined axis, a preload) cannot be told apart from the motion alone; physics must.",
                state + 1,
                0.5 * (a + b),
                -0.5 * (a - b)
            )),
            Effect::StribeckFriction { state, level, static_level, stribeck_velocity, .. } => out.push(format!(
                "stribeck_friction(x{}): static (breakaway) level {static_level:.4e} against the sliding (Coulomb) level {level:.4e} ({}), Stribeck velocity {stribeck_velocity:.3e}: the recording shows breakaway; with equal levels it would be coulomb_friction, which BIC prefers when the data do not show it.",
                state + 1,
                level_ratio(*static_level, *level)
            )),
            _ => {}
        }
    }
    // Coulomb friction plus a constant force on one state: the asymmetric form.
    for e in effects {
        if let Effect::CoulombFriction { state, level } = e {
            if let Some(b) = effects.iter().find_map(|f| match f {
                Effect::ConstantForce { state: s, force } if s == state => Some(*force),
                _ => None,
            }) {
                if b.abs() <= *level {
                    out.push(format!(
                        "coulomb_friction(x{0}) {level:.4e} plus constant_force(x{0}) {b:.4e} is the same model as asymmetric_coulomb(x{0}) with levels {1:.4e} (moving up) and {2:.4e} (down): physics must tell a constant load from direction-dependent friction.",
                        state + 1,
                        level - b,
                        level + b
                    ));
                }
            }
        }
    }
    let friction = |t: &str| {
        [names::COULOMB_FRICTION, names::STRIBECK_FRICTION, names::ASYMMETRIC_COULOMB].iter().any(|k| t.starts_with(k))
    };
    let chosen_friction = effects.iter().any(|e| {
        matches!(e, Effect::CoulombFriction { .. } | Effect::StribeckFriction { .. } | Effect::AsymmetricCoulomb { .. })
    });
    if chosen_friction && ties.iter().any(|t| friction(t)) {
        out.push(format!(
            "Friction laws tied on this recording ({}): the simplest is reported; a recording with slow reversals and starts from rest would show whether the breakaway level exceeds the sliding level (Stribeck) or the levels differ by direction.",
            ties.iter().filter(|t| friction(t)).cloned().collect::<Vec<_>>().join(", ")
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_stribeck_note_words_a_zero_sliding_level() {
        assert_eq!(level_ratio(3.0, 2.0), "ratio 1.50");
        // negative controls: a zero sliding level, a ratio past a million
        assert!(level_ratio(281.0, 0.0).contains("near rest only"));
        assert!(level_ratio(281.0, 1e-10).contains("near rest only"));
    }
    use crate::physics::Scales;

    #[test]
    fn friction_library_parameters_map_to_their_effects() {
        let s = Scales::default();
        let st = stribeck(1, 2.0, 0.5);
        // Static level = level + excess; the velocity box is positive, in log coordinates.
        assert_eq!(
            st.effect(&[0.3, 0.2, 0.05], &s),
            Effect::StribeckFriction { state: 1, level: 0.3, static_level: 0.5, stribeck_velocity: 0.05, viscous: 0.0 }
        );
        assert!(st.lower[2] > 0.0 && st.upper[2] == 1.0);
        // Starts reach 0.2 % of the bound (issue 13's small friction) and stay in the box.
        let lv: Vec<f64> = st.starts.iter().map(|u| st.param_at(0, u[0])).collect();
        assert!(lv.iter().any(|v| (v / 2.0 - 2e-3).abs() < 1e-9), "{lv:?}");
        assert!(st.starts.iter().flatten().all(|u| (0.0..=1.0).contains(u)));
        let asym = asymmetric(1, 2.0);
        assert_eq!(
            asym.effect(&[0.3, 0.1], &s),
            Effect::AsymmetricCoulomb { state: 1, level_positive: 0.3, level_negative: 0.1 }
        );
    }

    #[test]
    fn coulomb_friction_restarts_from_its_generalisations_levels() {
        let coulomb = level(Kind::CoulombFriction { state: 1 }, 2.0, LEVEL);
        let levels = |kind: Kind, general: &[f64]| -> Vec<f64> {
            let starts = Friction.starts_from_general(&coulomb, kind, general).expect("a generalisation");
            starts.iter().map(|u| coulomb.param_at(0, u[0])).collect()
        };
        let close = |a: &[f64], b: &[f64]| a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-9);
        // Stribeck [level, static excess, velocity]: sliding, static and their mean
        let st = levels(Kind::StribeckFriction { state: 1 }, &[0.3, 0.2, 0.05]);
        assert!(close(&st, &[0.3, 0.5, 0.4]), "{st:?}");
        // direction-dependent: the mean level, then each
        let asym = levels(Kind::AsymmetricCoulomb { state: 1 }, &[0.33, 0.36]);
        assert!(close(&asym, &[0.345, 0.33, 0.36]), "{asym:?}");
        let load = levels(Kind::LoadFriction { state: 1 }, &[0.3, 0.1]);
        assert!(close(&load, &[0.3, 0.399, 0.501]), "{load:?}");
        // negative controls: another state's law, a kind that generalises nothing, a
        // generalisation handed as the simpler form
        assert!(Friction.starts_from_general(&coulomb, Kind::AsymmetricCoulomb { state: 3 }, &[0.3, 0.3]).is_none());
        assert!(Friction.starts_from_general(&coulomb, Kind::CoulombFriction { state: 1 }, &[0.3]).is_none());
        let asym_h = asymmetric(1, 2.0);
        assert!(Friction
            .starts_from_general(&asym_h, Kind::StribeckFriction { state: 1 }, &[0.3, 0.2, 0.05])
            .is_none());
    }

    #[test]
    fn friction_notes_give_the_conversions() {
        let n = notes(&[Effect::AsymmetricCoulomb { state: 1, level_positive: 0.5, level_negative: 0.1 }], &[]);
        assert!(n[0].contains("coulomb_friction(x2) at 3.0000e-1 plus constant_force(x2) -2.0000e-1"), "{n:?}");
        let n = notes(
            &[Effect::CoulombFriction { state: 1, level: 0.3 }, Effect::ConstantForce { state: 1, force: -0.2 }],
            &[],
        );
        assert!(n[0].contains("asymmetric_coulomb(x2) with levels 5.0000e-1 (moving up) and 1.0000e-1"), "{n:?}");
        let n = notes(&[Effect::CoulombFriction { state: 1, level: 0.3 }], &["stribeck_friction(x2)".into()]);
        assert!(n[0].contains("tied") && n[0].contains("stribeck_friction(x2)"), "{n:?}");
        // Negative control: nothing to say about a lone Coulomb friction or a force elsewhere.
        assert!(notes(&[Effect::CoulombFriction { state: 1, level: 0.3 }], &[]).is_empty());
        let other = [Effect::CoulombFriction { state: 1, level: 0.3 }, Effect::ConstantForce { state: 3, force: 0.1 }];
        assert!(notes(&other, &[]).is_empty());
    }
}
