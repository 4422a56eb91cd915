//! The nominal model (eqs. (xy)-(yz)) extended by physical effects, and its fixed-step
//! free-run simulator.
//!
//! With `F = A + E C` (eq. (F)) and `q = z - y in Theta`, the plant reads
//! `x' = F x + B w_eff + E q + sum_j e_j (b_j + f_j)`, `y_meas = C x + offset`, where
//! - `w_eff` is `w` delayed (`input_delay`), clamped (`input_saturation`) and passed through a
//!   play operator (`backlash` at the input), in that order;
//! - `Theta` is the nominal set scaled by `1 + relative_change` (`gap_width`) and widened by a
//!   play of width `width` (`backlash` in the loop; 1-D, or a ball of radius `width/2` when the
//!   nominal has no play);
//! - `b_j` is a constant force (`constant_force`) plus a cogging force
//!   `A sin(2 pi x_pos / P + phase)` (`cogging`, evaluated at the step's midpoint position
//!   of the force-free step and held over the step);
//! - `f_j` is friction on velocity state `x_j` (`coulomb_friction`, `stribeck_friction`,
//!   `asymmetric_coulomb`; several on one state add up), a set-valued law: at rest
//!   `f in [-S_+, S_-]` (the static, breakaway levels; `S = level` for Coulomb), sliding in
//!   direction `d` `f = -d L_d(|v|)` with the sliding curve
//!   `L_d(u) = c_d + sum_i (s_i - c) exp(-(u / v_i)^2) + viscous u` (Stribeck). It is resolved
//!   implicitly per step (Moreau-Jean time stepping): with `a` the velocity reached without
//!   friction and `g = Psi_jj`, the state sticks (`x_j = 0`, `f = -a / g`) when
//!   `-g S_- <= a <= g S_+`, otherwise it slides with the `u > 0` solving
//!   `u + g L_d(u) = |a|` (closed form for Coulomb levels, safeguarded Newton on the bracket
//!   `[(|a| - g S_d), (|a| - g c_d)] / (1 + g viscous)` otherwise), `f = -d L_d(u)`.
//!   Static friction is thus the breakaway threshold from rest, the Stribeck curve the
//!   force while sliding, and a mass that slows down to zero is caught by the static level;
//! - the play is the catching-up scheme `z_{k+1} = y_{k+1} + P_Theta(z_pred - y_{k+1})`, where
//!   `z_pred = z_k` for a massless backlash output and, with `backlash_inertia`, `z` coasts
//!   with velocity `v` decaying at rate `damping / mass` between contacts (the contact is
//!   inelastic: after a projection `v = (z_{k+1} - z_k)/h`).
use crate::extended::StepMaps;
use crate::DynamicsError;
use geometry::{ConvexSet, Shape};
use model::effects::{Effect, PlayLocation};
use model::System;

/// How the play is projected.
#[derive(Debug, Clone)]
enum Play {
    /// `Theta = {0}`: `z = y`.
    None,
    /// 1-D interval `[lo, hi]`.
    Interval { lo: f64, hi: f64 },
    /// Ball of radius `r` about 0 (a play added where the nominal, p > 1, has none).
    Ball { r: f64 },
    /// `s Theta` for a general nominal shape: `P_{s Theta}(v) = s P_Theta(v / s)`.
    Scaled { shape: Shape, s: f64 },
}

/// The compiled extended model.
#[derive(Debug, Clone)]
pub struct ExtendedModel {
    pub n: usize,
    pub m: usize,
    pub p: usize,
    C: Vec<f64>,
    maps: StepMaps,
    substeps: usize,
    play: Play,
    input_play: Option<f64>,
    /// Friction laws, one per velocity state (effects on the same state merged).
    friction: Vec<Friction>,
    /// Cogging forces.
    cogging: Vec<Cog>,
    /// Constant force per state (length n).
    force: Vec<f64>,
    has_force: bool,
    /// `mass / damping` of the backlash output (0: massless).
    inertia_tau: f64,
    delay: f64,
    saturation: Option<f64>,
    offset: Vec<f64>,
    hold: InputHold,
    /// Set when an input delay puts the input's breakpoints inside a sub-step.
    split: Option<Split>,
}

/// Result of a simulation on the sample grid.
#[derive(Debug, Clone)]
pub struct SimOutput {
    /// `y_meas[k]` flat, `k * p + i`.
    pub y: Vec<f64>,
    /// Whether the play is in contact (`q` on the boundary of Theta) at sample `k`.
    pub contact: Vec<bool>,
    /// The backlash output `z[k]` flat, `k * p + i` (equal to `C x` without a play).
    pub z: Vec<f64>,
    /// Whether the state was finite throughout.
    pub finite: bool,
    /// Root mean square of each state over the run (scales for fitting).
    pub x_rms: Vec<f64>,
    /// The state `x[k]` flat, `k * n + i`.
    pub x: Vec<f64>,
}

fn row_major(m: &nalgebra::DMatrix<f64>) -> Vec<f64> {
    let mut v = Vec::with_capacity(m.len());
    for i in 0..m.nrows() {
        for j in 0..m.ncols() {
            v.push(m[(i, j)]);
        }
    }
    v
}

/// Whether the nominal `Theta` is the singleton `{0}`.
pub fn theta_is_point(sys: &System) -> bool {
    sys.theta.deviation_from_origin().upper <= 0.0
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
        let (n, m, p) = (sys.n(), sys.m(), sys.p());
        let mut scale = 1.0;
        let mut loop_width = 0.0;
        let mut me = Self {
            n,
            m,
            p,
            C: row_major(&sys.C),
            maps,
            substeps,
            play: Play::None,
            input_play: None,
            friction: Vec::new(),
            cogging: Vec::new(),
            force: vec![0.0; n],
            has_force: false,
            inertia_tau: 0.0,
            delay: 0.0,
            saturation: None,
            offset: vec![0.0; p],
            hold: InputHold::Foh,
            split: None,
        };
        for e in sys.effects.list.iter().chain(extra) {
            match e {
                Effect::Backlash { width, location } => {
                    if !(*width >= 0.0 && width.is_finite()) {
                        return Err(DynamicsError::BadEffect {
                            kind: "backlash",
                            reason: "width must be finite and non-negative",
                            value: *width,
                        });
                    }
                    match location {
                        PlayLocation::Loop => loop_width += width,
                        PlayLocation::Input => me.input_play = Some(me.input_play.unwrap_or(0.0) + width),
                    }
                }
                Effect::GapWidth { relative_change } => {
                    if *relative_change <= -1.0 {
                        return Err(DynamicsError::BadEffect {
                            kind: "gap_width",
                            reason: "relative_change must exceed -1",
                            value: *relative_change,
                        });
                    }
                    scale *= 1.0 + relative_change;
                }
                Effect::CoulombFriction { state, level } => {
                    if *state >= n {
                        return Err(DynamicsError::BadEffect {
                            kind: "coulomb_friction",
                            reason: "state index out of range",
                            value: *state as f64,
                        });
                    }
                    me.friction_on(*state).add_coulomb(level.abs(), level.abs());
                }
                Effect::AsymmetricCoulomb { state, level_positive, level_negative } => {
                    if *state >= n {
                        return Err(DynamicsError::BadEffect {
                            kind: "asymmetric_coulomb",
                            reason: "state index out of range",
                            value: *state as f64,
                        });
                    }
                    for v in [level_positive, level_negative] {
                        if !(*v >= 0.0 && v.is_finite()) {
                            return Err(DynamicsError::BadEffect {
                                kind: "asymmetric_coulomb",
                                reason: "levels must be finite and non-negative",
                                value: *v,
                            });
                        }
                    }
                    if *level_positive > 0.0 || *level_negative > 0.0 {
                        me.friction_on(*state).add_coulomb(*level_positive, *level_negative);
                    }
                }
                Effect::StribeckFriction { state, level, static_level, stribeck_velocity, viscous } => {
                    let bad =
                        |reason, value| Err(DynamicsError::BadEffect { kind: "stribeck_friction", reason, value });
                    if *state >= n {
                        return bad("state index out of range", *state as f64);
                    }
                    if !(*level >= 0.0 && level.is_finite()) {
                        return bad("level must be finite and non-negative", *level);
                    }
                    if !(*static_level >= *level && static_level.is_finite()) {
                        return bad("static_level must be finite and at least level", *static_level);
                    }
                    if !(*viscous >= 0.0 && viscous.is_finite()) {
                        return bad("viscous must be finite and non-negative", *viscous);
                    }
                    let excess = static_level - level;
                    if excess > 0.0 && !(*stribeck_velocity > 0.0 && stribeck_velocity.is_finite()) {
                        return bad("stribeck_velocity must be finite and positive", *stribeck_velocity);
                    }
                    if *static_level > 0.0 || *viscous > 0.0 {
                        let fr = me.friction_on(*state);
                        fr.add_coulomb(*level, *level);
                        if excess > 0.0 {
                            fr.excess.push((excess, 1.0 / stribeck_velocity));
                            fr.static_extra += excess;
                        }
                        fr.viscous += viscous;
                    }
                }
                Effect::Cogging { state, position_state, amplitude, period, phase } => {
                    let bad = |reason, value| Err(DynamicsError::BadEffect { kind: "cogging", reason, value });
                    if *state >= n {
                        return bad("state index out of range", *state as f64);
                    }
                    if *position_state >= n {
                        return bad("position_state index out of range", *position_state as f64);
                    }
                    if !(*period > 0.0 && period.is_finite()) {
                        return bad("period must be finite and positive", *period);
                    }
                    if !(amplitude.is_finite() && phase.is_finite()) {
                        return bad(
                            "amplitude and phase must be finite",
                            if amplitude.is_finite() { *phase } else { *amplitude },
                        );
                    }
                    if *amplitude != 0.0 {
                        me.cogging.push(Cog {
                            state: *state,
                            pos: *position_state,
                            amplitude: *amplitude,
                            wavenumber: std::f64::consts::TAU / period,
                            phase: *phase,
                        });
                    }
                }
                Effect::ConstantForce { state, force } => {
                    if *state >= n {
                        return Err(DynamicsError::BadEffect {
                            kind: "constant_force",
                            reason: "state index out of range",
                            value: *state as f64,
                        });
                    }
                    me.force[*state] += force;
                    me.has_force = true;
                }
                Effect::BacklashInertia { mass, damping } => {
                    me.inertia_tau = if *mass <= 0.0 {
                        0.0
                    } else if *damping <= 0.0 {
                        f64::INFINITY
                    } else {
                        mass / damping
                    };
                }
                Effect::InputDelay { delay } => me.delay += delay.max(0.0),
                Effect::InputSaturation { limit } => me.saturation = Some(limit.abs()),
                Effect::SensorOffset { offset } => {
                    for (o, v) in me.offset.iter_mut().zip(offset) {
                        *o += v;
                    }
                }
            }
        }
        let point = theta_is_point(sys);
        me.play = match (&sys.theta, point) {
            (_, true) if loop_width <= 0.0 => Play::None,
            (_, true) => {
                if p == 1 {
                    Play::Interval { lo: -0.5 * loop_width, hi: 0.5 * loop_width }
                } else {
                    Play::Ball { r: 0.5 * loop_width }
                }
            }
            (Shape::Interval(iv), false) => {
                let (lo, hi) = (iv.lo * scale - 0.5 * loop_width, iv.hi * scale + 0.5 * loop_width);
                Play::Interval { lo, hi }
            }
            (shape, false) => {
                if loop_width > 0.0 {
                    return Err(DynamicsError::BadEffect {
                        kind: "backlash",
                        reason: "a loop play can only be added to a 1-D nominal play or where the nominal has none",
                        value: loop_width,
                    });
                }
                Play::Scaled { shape: shape.clone(), s: scale }
            }
        };
        if me.delay > 0.0 {
            // Breakpoints of the delayed input at t_k + delay: fraction `phi` of a sample
            // interval, in sub-step `s` at fraction `at` of it.
            let h = me.maps.h;
            let sub = me.substeps as f64;
            let pos = (me.delay / (h * sub)).fract() * sub;
            let (si, at) = (pos.floor(), pos - pos.floor());
            if at > 1e-9 && at < 1.0 - 1e-9 {
                let F = sys.F();
                me.split = Some(Split {
                    substep: (si as usize).min(me.substeps - 1),
                    at,
                    first: StepMaps::new(&F, &sys.B, &sys.E, at * h),
                    second: StepMaps::new(&F, &sys.B, &sys.E, (1.0 - at) * h),
                });
            }
        }
        Ok(me)
    }

    /// The same model with input hold `hold` between samples (default: first-order hold).
    pub fn with_hold(mut self, hold: InputHold) -> Self {
        self.hold = hold;
        self
    }

    /// The input hold between samples.
    pub fn hold(&self) -> InputHold {
        self.hold
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
        let m = self.m;
        let n = w.len() / m;
        let mut out = w.to_vec();
        if self.delay > 0.0 {
            let sh = self.delay / dt;
            for k in 0..n {
                let s = k as f64 - sh;
                for j in 0..m {
                    out[k * m + j] = if s <= 0.0 {
                        w[j]
                    } else {
                        let i = s.floor() as usize;
                        let a = s - i as f64;
                        let i1 = (i + 1).min(n - 1);
                        w[i * m + j] * (1.0 - a) + w[i1 * m + j] * a
                    };
                }
            }
        }
        if let Some(l) = self.saturation {
            out.iter_mut().for_each(|v| *v = v.clamp(-l, l));
        }
        if let Some(width) = self.input_play {
            let r = 0.5 * width;
            let mut u: Vec<f64> = out[..m].to_vec();
            for k in 0..n {
                for j in 0..m {
                    let v = out[k * m + j];
                    u[j] = u[j].clamp(v - r, v + r);
                    out[k * m + j] = u[j];
                }
            }
        }
        out
    }

    #[inline]
    fn project_q(&self, v: &mut [f64], scratch: &mut [f64]) -> bool {
        match &self.play {
            Play::None => {
                v.iter_mut().for_each(|x| *x = 0.0);
                true
            }
            Play::Interval { lo, hi } => {
                let c = v[0].clamp(*lo, *hi);
                let hit = c != v[0] || v[0] <= *lo || v[0] >= *hi;
                v[0] = c;
                hit
            }
            Play::Ball { r } => {
                let nr = v.iter().map(|x| x * x).sum::<f64>().sqrt();
                if nr >= *r {
                    let f = if nr > 0.0 { r / nr } else { 0.0 };
                    v.iter_mut().for_each(|x| *x *= f);
                    true
                } else {
                    false
                }
            }
            Play::Scaled { shape, s } => {
                if *s <= 0.0 {
                    v.iter_mut().for_each(|x| *x = 0.0);
                    return true;
                }
                let u: Vec<f64> = v.iter().map(|x| x / s).collect();
                shape.project(&u, scratch);
                let mut moved = false;
                for (a, b) in v.iter_mut().zip(scratch.iter()) {
                    let nb = b * s;
                    moved |= (*a - nb).abs() > 1e-15 * (1.0 + a.abs());
                    *a = nb;
                }
                moved || shape.dist_to_boundary(&u) <= 1e-12
            }
        }
    }

    /// Free-run simulation from `x0` (with `q0 = 0`, i.e. `z0 = C x0`) driven by the measured
    /// input `w` (flat, `k * m + j`, sample spacing `dt`, the spacing the model was compiled
    /// for). Returns `y_meas` on the sample grid.
    pub fn simulate(&self, w: &[f64], dt: f64, x0: &[f64]) -> SimOutput {
        self.simulate_from(w, dt, x0, None)
    }

    /// The sensor offset added to `y = C x` (sum of the `sensor_offset` effects).
    pub fn sensor_offset(&self) -> &[f64] {
        &self.offset
    }

    /// As [`ExtendedModel::simulate`] from `(x0, z0)`; `z0 = None` starts at rest in the play
    /// (`z0 = C x0`). `z0 - C x0` is taken as it is (it should lie in the play's set).
    ///
    /// Between samples the input follows the model's [`InputHold`]: linear interpolation of
    /// the samples (first-order hold, the default) or the sample held until the next one
    /// (zero-order hold). Either is integrated exactly by the linear step maps: an input delay
    /// moves the input's breakpoints to `t_k + delay`, and the sub-step that contains one is
    /// split there (two extra step maps, computed once per model). Saturation and a play at
    /// the input act on the held samples exactly (ZOH) or on the sub-step knots (FOH).
    pub fn simulate_from(&self, w: &[f64], dt: f64, x0: &[f64], z0: Option<&[f64]>) -> SimOutput {
        let (n, m, p) = (self.n, self.m, self.p);
        let ns = w.len() / m;
        let mut x = x0.to_vec();
        let mut xn = vec![0.0; n];
        let mut q = vec![0.0; p];
        let mut z = vec![0.0; p];
        let mut y = vec![0.0; p];
        let mut v = vec![0.0; p];
        let mut scratch = vec![0.0; p];
        let mut qp = vec![0.0; p];
        let mut out = SimOutput {
            y: vec![0.0; ns * p],
            contact: vec![false; ns],
            z: vec![0.0; ns * p],
            finite: true,
            x_rms: vec![0.0; n],
            x: vec![0.0; ns * n],
        };
        let cx = |x: &[f64], y: &mut [f64]| {
            for i in 0..p {
                y[i] = (0..n).map(|j| self.C[i * n + j] * x[j]).sum();
            }
        };
        cx(&x, &mut y);
        z.copy_from_slice(&y);
        let has_play = self.has_play();
        if let (Some(z0), true) = (z0, has_play) {
            z.copy_from_slice(z0);
            for i in 0..p {
                q[i] = z[i] - y[i];
            }
        }
        if ns == 0 {
            return out;
        }
        let sub = self.substeps;
        let main = Piece::new(&self.maps, &self.force, self.inertia_tau);
        let split = self.split.as_ref().map(|sp| {
            (
                sp.substep,
                sp.at,
                Piece::new(&sp.first, &self.force, self.inertia_tau),
                Piece::new(&sp.second, &self.force, self.inertia_tau),
            )
        });
        let shift = self.delay / dt;
        // Zero-order hold: saturation and input play act on the held samples exactly.
        let held: Vec<f64> = match self.hold {
            InputHold::Zoh => {
                let mut hv = w.to_vec();
                if let Some(l) = self.saturation {
                    hv.iter_mut().for_each(|v| *v = v.clamp(-l, l));
                }
                if let Some(width) = self.input_play {
                    let r = 0.5 * width;
                    let mut u: Vec<f64> = hv[..m].to_vec();
                    for k in 0..ns {
                        for j in 0..m {
                            u[j] = u[j].clamp(hv[k * m + j] - r, hv[k * m + j] + r);
                            hv[k * m + j] = u[j];
                        }
                    }
                }
                hv
            }
            InputHold::Foh => Vec::new(),
        };
        // First-order hold: the delayed, interpolated input at sample time `tau` (in samples),
        // saturated and passed through the input play (state `uplay`).
        let foh_at = |tau: f64, uplay: &mut [f64], outv: &mut [f64]| {
            for j in 0..m {
                let raw = if tau <= 0.0 {
                    w[j]
                } else {
                    let i = tau.floor() as usize;
                    if i + 1 >= ns {
                        w[(ns - 1) * m + j]
                    } else {
                        let a = tau - i as f64;
                        w[i * m + j] * (1.0 - a) + w[(i + 1) * m + j] * a
                    }
                };
                let mut u = match self.saturation {
                    Some(l) => raw.clamp(-l, l),
                    None => raw,
                };
                if let Some(width) = self.input_play {
                    let r = 0.5 * width;
                    uplay[j] = uplay[j].clamp(u - r, u + r);
                    u = uplay[j];
                }
                outv[j] = u;
            }
        };
        let mut uplay: Vec<f64> = (0..m).map(|j| self.saturation.map_or(w[j], |l| w[j].clamp(-l, l))).collect();
        let mut ucur = vec![0.0; m];
        foh_at(-shift, &mut uplay, &mut ucur);
        let mut unext = vec![0.0; m];
        let mut w0 = vec![0.0; m];
        let mut dw = vec![0.0; m];
        for k in 0..ns {
            for i in 0..p {
                out.y[k * p + i] = y[i] + self.offset[i];
                out.z[k * p + i] = z[i];
            }
            for i in 0..n {
                out.x_rms[i] += x[i] * x[i];
                out.x[k * n + i] = x[i];
            }
            if k + 1 == ns {
                break;
            }
            for s in 0..sub {
                let f0 = s as f64 / sub as f64;
                let f1 = (s + 1) as f64 / sub as f64;
                let pieces: [(f64, f64, &Piece); 2];
                let np = match &split {
                    Some((ss, at, a, b)) if *ss == s => {
                        let fm = f0 + at / sub as f64;
                        pieces = [(f0, fm, a), (fm, f1, b)];
                        2
                    }
                    _ => {
                        pieces = [(f0, f1, &main), (f1, f1, &main)];
                        1
                    }
                };
                for (pi, &(fa, fb, pc)) in pieces[..np].iter().enumerate() {
                    match self.hold {
                        InputHold::Zoh => {
                            let tau = k as f64 + 0.5 * (fa + fb) - shift;
                            let idx = if tau <= 0.0 { 0 } else { (tau.floor() as usize).min(ns - 1) };
                            w0.copy_from_slice(&held[idx * m..(idx + 1) * m]);
                            dw.iter_mut().for_each(|d| *d = 0.0);
                        }
                        InputHold::Foh => {
                            foh_at(k as f64 + fb - shift, &mut uplay, &mut unext);
                            for j in 0..m {
                                w0[j] = ucur[j];
                                dw[j] = unext[j] - ucur[j];
                            }
                            ucur.copy_from_slice(&unext);
                        }
                    }
                    let mp = pc.maps;
                    for i in 0..n {
                        let mut acc = 0.0;
                        for j in 0..n {
                            acc += mp.Phi[i * n + j] * x[j];
                        }
                        for j in 0..m {
                            acc += mp.PsiB[i * m + j] * w0[j] + mp.Psi1B[i * m + j] * dw[j];
                        }
                        for j in 0..p {
                            acc += mp.PsiE[i * p + j] * q[j];
                        }
                        if self.has_force {
                            acc += pc.fb[i];
                        }
                        xn[i] = acc;
                    }
                    for cg in &self.cogging {
                        // Midpoint position of the force-free step.
                        let xp = 0.5 * (x[cg.pos] + xn[cg.pos]);
                        let f = cg.amplitude * (cg.wavenumber * xp + cg.phase).sin();
                        for (i, v) in xn.iter_mut().enumerate() {
                            *v += mp.Psi[i * n + cg.state] * f;
                        }
                    }
                    for fr in &self.friction {
                        let j = fr.state;
                        let (f, stuck) = fr.force(xn[j], mp.Psi[j * n + j]);
                        for (i, v) in xn.iter_mut().enumerate() {
                            *v += mp.Psi[i * n + j] * f;
                        }
                        if stuck {
                            // Exactly at rest (`a - g (a / g)` may round to a few ulps).
                            xn[j] = 0.0;
                        }
                    }
                    std::mem::swap(&mut x, &mut xn);
                    cx(&x, &mut y);
                    if has_play {
                        // z_pred: massless output stays; with inertia it coasts.
                        for i in 0..p {
                            scratch[i] = z[i] + v[i] * pc.coast;
                            q[i] = scratch[i] - y[i];
                        }
                        // The deviation before projection: the contact is decided on `q` itself
                        // (comparing `y + q` with `z_pred` would see rounding of `y + (z - y)` as
                        // a contact and slow the coasting decay spuriously).
                        qp.copy_from_slice(&q);
                        let hit = self.project_q(&mut q, &mut scratch);
                        for i in 0..p {
                            let znew = y[i] + q[i];
                            if self.inertia_tau > 0.0 {
                                v[i] = if q[i] != qp[i] { (znew - z[i]) / mp.h } else { v[i] * pc.decay };
                            }
                            z[i] = znew;
                        }
                        if s + 1 == sub && pi + 1 == np {
                            out.contact[k + 1] = hit;
                        }
                    } else {
                        z.copy_from_slice(&y);
                    }
                }
            }
            if !x.iter().all(|v| v.is_finite()) {
                out.finite = false;
                for kk in k + 1..ns {
                    for i in 0..p {
                        out.y[kk * p + i] = f64::NAN;
                    }
                }
                break;
            }
        }
        out.x_rms.iter_mut().for_each(|v| *v = (*v / ns as f64).sqrt());
        out
    }
}

/// Friction on one velocity state (see the module documentation): Coulomb levels per
/// direction, Stribeck excess terms and a viscous increment.
#[derive(Debug, Clone)]
struct Friction {
    state: usize,
    /// Sliding (Coulomb) level while moving up / down.
    pos: f64,
    neg: f64,
    /// Stribeck terms `(s_i - c, 1 / v_i)`.
    excess: Vec<(f64, f64)>,
    /// `sum_i (s_i - c)`: static levels are `pos + static_extra`, `neg + static_extra`.
    static_extra: f64,
    viscous: f64,
}

impl Friction {
    fn add_coulomb(&mut self, pos: f64, neg: f64) {
        self.pos += pos;
        self.neg += neg;
    }

    /// Sliding level at speed `u >= 0` above the Coulomb level `c`, and its derivative.
    #[inline]
    fn curve(&self, u: f64) -> (f64, f64) {
        let (mut l, mut dl) = (self.viscous * u, self.viscous);
        for &(ds, iv) in &self.excess {
            let r = u * iv;
            let e = ds * (-r * r).exp();
            l += e;
            dl -= 2.0 * r * iv * e;
        }
        (l, dl)
    }

    /// The friction force over a step whose friction-free end velocity is `a`, with
    /// `g = Psi_jj` (implicit: the end velocity is `a + g f`), and whether the state sticks.
    #[inline]
    fn force(&self, a: f64, g: f64) -> (f64, bool) {
        let (s_pos, s_neg) = (self.pos + self.static_extra, self.neg + self.static_extra);
        if a <= g * s_pos && a >= -g * s_neg {
            // Sticks (the static levels hold the remaining force).
            return (-a / g, true);
        }
        let (d, c) = if a > 0.0 { (1.0, self.pos) } else { (-1.0, self.neg) };
        if self.excess.is_empty() && self.viscous == 0.0 {
            return (-c * d, false);
        }
        // Slides: u + g (c + curve(u)) = |a|, u in [lo, hi].
        let t = a.abs();
        let den = 1.0 + g * self.viscous;
        let (mut lo, mut hi) = (((t - g * (c + self.static_extra)) / den).max(0.0), ((t - g * c) / den).max(0.0));
        let phi = |u: f64| {
            let (l, dl) = self.curve(u);
            (u + g * (c + l) - t, 1.0 + g * dl)
        };
        let mut u = hi;
        for _ in 0..60 {
            let (r, dr) = phi(u);
            if r == 0.0 {
                break;
            }
            if r > 0.0 {
                hi = u;
            } else {
                lo = u;
            }
            let mut un = u - r / dr;
            if !(dr > 0.0 && un > lo && un < hi) {
                un = 0.5 * (lo + hi);
            }
            if (un - u).abs() <= 1e-15 * (1.0 + u.abs()) || hi - lo <= 1e-15 * (1.0 + hi) {
                u = un;
                break;
            }
            u = un;
        }
        let (l, _) = self.curve(u);
        (-d * (c + l), false)
    }
}

/// A cogging force on `state`: `amplitude sin(wavenumber x_pos + phase)`.
#[derive(Debug, Clone)]
struct Cog {
    state: usize,
    pos: usize,
    amplitude: f64,
    wavenumber: f64,
    phase: f64,
}

impl ExtendedModel {
    /// The friction law of `state`, created empty on first use.
    fn friction_on(&mut self, state: usize) -> &mut Friction {
        let i = match self.friction.iter().position(|f| f.state == state) {
            Some(i) => i,
            None => {
                self.friction.push(Friction {
                    state,
                    pos: 0.0,
                    neg: 0.0,
                    excess: Vec::new(),
                    static_extra: 0.0,
                    viscous: 0.0,
                });
                self.friction.len() - 1
            }
        };
        &mut self.friction[i]
    }
}

/// How the recorded input behaves between its samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum InputHold {
    /// Linear interpolation between samples (first-order hold).
    #[default]
    Foh,
    /// Each sample held until the next (zero-order hold, a digital controller's command).
    Zoh,
}

impl InputHold {
    pub fn name(&self) -> &'static str {
        match self {
            InputHold::Foh => "foh",
            InputHold::Zoh => "zoh",
        }
    }
}

/// The sub-step of every sample interval that contains the delayed input's breakpoint
/// `t_k + delay`, split there: `first` covers `at h`, `second` `(1 - at) h`.
#[derive(Debug, Clone)]
struct Split {
    substep: usize,
    at: f64,
    first: StepMaps,
    second: StepMaps,
}

/// Per-step constants of one step length.
struct Piece<'a> {
    maps: &'a StepMaps,
    /// `Psi b` (constant force).
    fb: Vec<f64>,
    decay: f64,
    coast: f64,
}

impl<'a> Piece<'a> {
    fn new(maps: &'a StepMaps, force: &[f64], inertia_tau: f64) -> Self {
        let n = maps.n;
        let h = maps.h;
        let decay = if inertia_tau > 0.0 && inertia_tau.is_finite() { (-h / inertia_tau).exp() } else { 1.0 };
        let coast = if inertia_tau > 0.0 {
            if inertia_tau.is_finite() {
                inertia_tau * (1.0 - decay)
            } else {
                h
            }
        } else {
            0.0
        };
        let fb = (0..n).map(|i| (0..n).map(|j| maps.Psi[i * n + j] * force[j]).sum()).collect();
        Self { maps, fb, decay, coast }
    }
}

/// Simulates `sys` with its own `[[effects]]` from `(sys.x0, sys.z0)` for `steps` steps of `h`
/// (the input sampled at `k h` and interpolated linearly in between, as the catching-up
/// scheme does), recording every `record_every`-th sample and the last. The trajectory's `y`
/// includes the sensor offset. Without effects this is the catching-up scheme of eq. (zdot)
/// (a test checks the two agree).
pub fn simulate_trajectory(
    sys: &System,
    h: f64,
    steps: usize,
    record_every: usize,
) -> Result<crate::trajectory::Trajectory, DynamicsError> {
    crate::error::check_dt(h)?;
    let (n, m, p) = (sys.n(), sys.m(), sys.p());
    let ns = steps + 1;
    let mut w = vec![0.0; ns * m];
    for k in 0..ns {
        sys.input.eval(k as f64 * h, &mut w[k * m..(k + 1) * m]);
    }
    let ext = ExtendedModel::new(sys, &[], h, 1)?;
    let out = ext.simulate_from(&w, h, sys.x0.as_slice(), Some(sys.z0.as_slice()));
    if !out.finite {
        let k = (0..ns).find(|&k| !out.x[k * n..(k + 1) * n].iter().all(|v| v.is_finite())).unwrap_or(steps);
        return Err(DynamicsError::NonFinite { t: k as f64 * h });
    }
    let every = record_every.max(1);
    let mut tr = crate::trajectory::Trajectory::new(n, m, p);
    tr.y_offset = ext.sensor_offset().to_vec();
    for k in (0..ns).filter(|&k| k % every == 0 || k == steps) {
        tr.push(k as f64 * h, &w[k * m..(k + 1) * m], &out.x[k * n..(k + 1) * n], &out.z[k * p..(k + 1) * p]);
    }
    Ok(tr)
}

/// The regime reached by simulating a model with `[[effects]]` under a `T`-periodic input (the
/// paper's uniqueness argument does not cover effects, so no fixed point is claimed: the
/// residuals say whether successive periods still differ).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[non_exhaustive]
pub struct SimulatedRegime {
    pub period: f64,
    pub h: f64,
    pub steps_per_period: usize,
    pub periods: usize,
    /// State at the start of the last simulated period.
    pub x0: Vec<f64>,
    pub z0: Vec<f64>,
    /// `max |(x, z)(kT) - (x, z)((k-1)T)|_inf` for `k = 1..=periods`.
    pub residuals: Vec<f64>,
    /// Path length of `z` over the last period.
    pub path_length_last_period: f64,
    /// `max |z'|` over the last period (difference quotients).
    pub max_z_speed_last_period: f64,
}

/// Simulates `periods` periods of `sys` (with its effects) at a step close to `dt` dividing
/// the period; see [`SimulatedRegime`].
pub fn regime_by_simulation(sys: &System, dt: f64, periods: usize) -> Result<SimulatedRegime, DynamicsError> {
    let T = sys.period().ok_or(DynamicsError::NotPeriodic { kind: sys.input.kind() })?;
    if periods == 0 {
        return Err(DynamicsError::ZeroPeriods { periods });
    }
    let (spp, h) = crate::periodic::steps_per_period(T, dt)?;
    let tr = simulate_trajectory(sys, h, spp * periods, 1)?;
    let state = |k: usize| -> Vec<f64> { tr.x_at(k).iter().chain(tr.z_at(k)).copied().collect() };
    let residuals = (1..=periods)
        .map(|k| {
            let (a, b) = (state(k * spp), state((k - 1) * spp));
            a.iter().zip(&b).map(|(u, v)| (u - v).abs()).fold(0.0, f64::max)
        })
        .collect();
    let start = (periods - 1) * spp;
    let (mut path, mut speed) = (0.0f64, 0.0f64);
    for k in start..start + spp {
        let dz = geometry::linalg::dist(tr.z_at(k + 1), tr.z_at(k));
        path += dz;
        speed = speed.max(dz / h);
    }
    Ok(SimulatedRegime {
        period: T,
        h,
        steps_per_period: spp,
        periods,
        x0: tr.x_at(start).to_vec(),
        z0: tr.z_at(start).to_vec(),
        residuals,
        path_length_last_period: path,
        max_z_speed_last_period: speed,
    })
}
