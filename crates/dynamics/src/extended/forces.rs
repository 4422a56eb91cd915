//! Forces on the state from `[[effects]]`, applied after the linear step of each sub-step:
//! - a constant force `b_j` (`constant_force`), integrated exactly with the linear step;
//! - a cogging force `A sin(2 pi x_pos / P + phase)` (`cogging`), evaluated at the step's
//!   midpoint position of the force-free step and held over the step;
//! - friction on velocity states ([`super::friction`]: `coulomb_friction`,
//!   `asymmetric_coulomb`, `stribeck_friction`, `load_friction`; several on one state add
//!   up), resolved implicitly, the load-dependent level taken at the step's start.
//!
//! Each effect is checked here as it is registered (an error names the effect and the value).
use super::friction::{Friction, LoadRows};
use crate::error::DynamicsError;

/// A cogging force on `state`: `amplitude sin(wavenumber x_pos + phase)`.
#[derive(Debug, Clone)]
struct Cog {
    state: usize,
    pos: usize,
    amplitude: f64,
    wavenumber: f64,
    phase: f64,
}

/// The forces on an `n`-state plant.
#[derive(Debug, Clone)]
pub(super) struct Forces {
    n: usize,
    /// Friction laws, one per velocity state (effects on the same state merged).
    friction: Vec<Friction>,
    /// Cogging forces.
    cogging: Vec<Cog>,
    /// Constant force per state (length n).
    pub(super) force: Vec<f64>,
    pub(super) has_force: bool,
}

/// `state index out of range` for effect `kind` when `state >= n`.
fn check_state(kind: &'static str, state: usize, n: usize) -> Result<(), DynamicsError> {
    if state >= n {
        return Err(DynamicsError::BadEffect { kind, reason: "state index out of range", value: state as f64 });
    }
    Ok(())
}

impl Forces {
    /// No forces on an `n`-state plant.
    pub(super) fn new(n: usize) -> Self {
        Self { n, friction: Vec::new(), cogging: Vec::new(), force: vec![0.0; n], has_force: false }
    }

    /// The friction law of `state`, created empty on first use.
    fn friction_on(&mut self, state: usize) -> &mut Friction {
        let i = match self.friction.iter().position(|f| f.state == state) {
            Some(i) => i,
            None => {
                self.friction.push(Friction::new(state));
                self.friction.len() - 1
            }
        };
        &mut self.friction[i]
    }

    /// `coulomb_friction`: level `|level|` in both directions.
    pub(super) fn coulomb(&mut self, state: usize, level: f64) -> Result<(), DynamicsError> {
        check_state("coulomb_friction", state, self.n)?;
        self.friction_on(state).add_coulomb(level.abs(), level.abs());
        Ok(())
    }

    /// `asymmetric_coulomb`: level `level_positive` moving up, `level_negative` moving down.
    pub(super) fn asymmetric_coulomb(
        &mut self,
        state: usize,
        level_positive: f64,
        level_negative: f64,
    ) -> Result<(), DynamicsError> {
        check_state("asymmetric_coulomb", state, self.n)?;
        for v in [level_positive, level_negative] {
            if !(v >= 0.0 && v.is_finite()) {
                return Err(DynamicsError::BadEffect {
                    kind: "asymmetric_coulomb",
                    reason: "levels must be finite and non-negative",
                    value: v,
                });
            }
        }
        if level_positive > 0.0 || level_negative > 0.0 {
            self.friction_on(state).add_coulomb(level_positive, level_negative);
        }
        Ok(())
    }

    /// `stribeck_friction`: sliding level `level`, breakaway `static_level >= level` decaying
    /// on the scale `stribeck_velocity`, plus `viscous u`.
    pub(super) fn stribeck(
        &mut self,
        state: usize,
        level: f64,
        static_level: f64,
        stribeck_velocity: f64,
        viscous: f64,
    ) -> Result<(), DynamicsError> {
        let bad = |reason, value| Err(DynamicsError::BadEffect { kind: "stribeck_friction", reason, value });
        if state >= self.n {
            return bad("state index out of range", state as f64);
        }
        if !(level >= 0.0 && level.is_finite()) {
            return bad("level must be finite and non-negative", level);
        }
        if !(static_level >= level && static_level.is_finite()) {
            return bad("static_level must be finite and at least level", static_level);
        }
        if !(viscous >= 0.0 && viscous.is_finite()) {
            return bad("viscous must be finite and non-negative", viscous);
        }
        let excess = static_level - level;
        if excess > 0.0 && !(stribeck_velocity > 0.0 && stribeck_velocity.is_finite()) {
            return bad("stribeck_velocity must be finite and positive", stribeck_velocity);
        }
        if static_level > 0.0 || viscous > 0.0 {
            let fr = self.friction_on(state);
            fr.add_coulomb(level, level);
            if excess > 0.0 {
                fr.add_stribeck(excess, stribeck_velocity);
            }
            fr.add_viscous(viscous);
        }
        Ok(())
    }

    /// `load_friction`: level `level + load_coefficient |d - e|` on `state`, the load's rows
    /// taken from `sys` ([`LoadRows`]).
    pub(super) fn load_friction(
        &mut self,
        state: usize,
        level: f64,
        load_coefficient: f64,
        sys: &model::System,
    ) -> Result<(), DynamicsError> {
        check_state("load_friction", state, self.n)?;
        let bad = |reason, value| Err(DynamicsError::BadEffect { kind: "load_friction", reason, value });
        if !(level >= 0.0 && level.is_finite()) {
            return bad("level must be finite and non-negative", level);
        }
        if !(load_coefficient >= 0.0 && load_coefficient.is_finite()) {
            return bad("load_coefficient must be finite and non-negative", load_coefficient);
        }
        let fr = self.friction_on(state);
        fr.add_coulomb(level, level);
        if load_coefficient > 0.0 {
            let mut a: Vec<f64> = sys.A.row(state).iter().copied().collect();
            a[state] = 0.0;
            let b = sys.B.row(state).iter().copied().collect();
            let e = sys.E.row(state).iter().copied().collect();
            fr.add_load(load_coefficient, LoadRows { a, b, e });
        }
        Ok(())
    }

    /// `cogging` on `state` at the position `position_state`.
    pub(super) fn cogging(
        &mut self,
        state: usize,
        position_state: usize,
        amplitude: f64,
        period: f64,
        phase: f64,
    ) -> Result<(), DynamicsError> {
        let bad = |reason, value| Err(DynamicsError::BadEffect { kind: "cogging", reason, value });
        if state >= self.n {
            return bad("state index out of range", state as f64);
        }
        if position_state >= self.n {
            return bad("position_state index out of range", position_state as f64);
        }
        if !(period > 0.0 && period.is_finite()) {
            return bad("period must be finite and positive", period);
        }
        if !(amplitude.is_finite() && phase.is_finite()) {
            return bad("amplitude and phase must be finite", if amplitude.is_finite() { phase } else { amplitude });
        }
        if amplitude != 0.0 {
            self.cogging.push(Cog {
                state,
                pos: position_state,
                amplitude,
                wavenumber: std::f64::consts::TAU / period,
                phase,
            });
        }
        Ok(())
    }

    /// `constant_force` on `state`.
    pub(super) fn constant(&mut self, state: usize, force: f64) -> Result<(), DynamicsError> {
        check_state("constant_force", state, self.n)?;
        self.force[state] += force;
        self.has_force = true;
        Ok(())
    }

    /// Adds the cogging forces, then the friction forces, to the end state `xn` of a linear
    /// step from `x` (`Psi` row-major `n x n`, the step's `int_0^h e^{sF} ds`; `w`, `z`: the
    /// input and the loop's output at the step's start, for a load-dependent level).
    #[inline(always)]
    pub(super) fn apply(&self, x: &[f64], xn: &mut [f64], Psi: &[f64], w: &[f64], z: &[f64]) {
        let n = self.n;
        for cg in &self.cogging {
            // Midpoint position of the force-free step.
            let xp = 0.5 * (x[cg.pos] + xn[cg.pos]);
            let f = cg.amplitude * (cg.wavenumber * xp + cg.phase).sin();
            for (i, v) in xn.iter_mut().enumerate() {
                *v += Psi[i * n + cg.state] * f;
            }
        }
        for fr in &self.friction {
            let j = fr.state;
            let (f, stuck) = fr.force(xn[j], Psi[j * n + j], fr.load_level(x, w, z));
            for (i, v) in xn.iter_mut().enumerate() {
                *v += Psi[i * n + j] * f;
            }
            if stuck {
                // Exactly at rest (`a - g (a / g)` may round to a few ulps).
                xn[j] = 0.0;
            }
        }
    }
}
