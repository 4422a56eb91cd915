//! Hypotheses: one or more effects of the physics library with free parameters, their
//! bounds and starting points, derived from the model's structure and the recording's scales
//! (never from how a benchmark was generated).
//!
//! Bounds (all scale-free, from the data and the model):
//! - play widths `[0, range(y)/2]` (loop) or `[0, range(w)/2]` (input);
//! - `gap_width` relative change `[-0.9, s_max - 1]` with `s_max = clamp(2 range(y) /
//!   diam(Theta), 5, 1000)` (a play wider than the output range never moves `z`), fitted
//!   in the logarithm of the scale `1 + relative_change`;
//! - force levels (friction, constant force) up to the force whose static deflection of `y`
//!   equals `range(y)`: `range(y) / |C F^{-1} e_j|` (friction `[0, that]`, force `+-` half of it);
//! - `backlash_inertia` time constant `mass/damping` in `[0, 2 tau_slow]` (damping fixed to 1:
//!   only the ratio is identifiable from `y`, since `z` enters the plant only through `E z`);
//! - `input_delay` in `[0, min(tau_slow, T/20)]` (at least 5 samples);
//! - `input_saturation` limit in `[0.2, 1] max|w|` (1 = no clipping);
//! - `sensor_offset` in `+- range(y)/2` per output;
//! - the friction library on each velocity state (issue 14): `stribeck_friction` as
//!   `(level, static_level - level, stribeck_velocity)` with both levels in the friction bound
//!   and the velocity in `[1e-3, 2] v_rms` (the state's RMS in the nominal run), all in log
//!   coordinates; `asymmetric_coulomb` with both levels in the friction bound; `cogging` as
//!   `(a_sin, a_cos, period)`, the force `a_sin sin(2 pi x/P) + a_cos cos(2 pi x/P)` linear in
//!   the amplitudes (`+-` the friction bound) and the period in a narrow log box about the
//!   best period of a scan of the nominal residual ([`cogging_scan`], 2.5-40 periods over the
//!   recorded position range). Friction levels start at [`FRICTION_DECADES`] of the bound
//!   (down to 1e-4, with 0.2 %) combined with static excesses and Stribeck velocities or level
//!   ratios, screened by the solver. A Stribeck law with equal levels is Coulomb friction and
//!   unequal direction levels are Coulomb friction plus a constant force: BIC's parameter count
//!   prefers the simpler form unless the data show breakaway or asymmetry, and
//!   [`friction_notes`] gives the conversions.
//!
//! Starts over decades: a level-like parameter (play width, friction level, inertia time
//! constant, delay) is fitted in logarithmic coordinates of `theta + 1e-5 upper` (so that 0 is
//! reachable and a step is a relative change at every magnitude) from starts at
//! `{1e-4, 1e-3, 1e-2, 0.1, 0.4, 0.8}` of its bound ([`DECADES`]); the saturation limit gets
//! starts down to 0.1 % below `max |w|`, the gap scale starts at +-0.5 %, +-5 %, -50 %, +70 %
//! and +250 %. The solver screens the starts and iterates the best three. Forces and offsets
//! enter the output linearly and need no decade starts.
use crate::fit::input_effects::InputOp;
use model::effects::{Effect, PlayLocation};
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
    Cogging { state: usize, position_state: usize },
    ConstantForce { state: usize },
    BacklashInertia,
    InputDelay,
    InputSaturation,
    SensorOffset,
    InputOn { op: InputOp, input: usize },
}

impl Kind {
    /// The model-file name of the effect.
    pub fn name(&self) -> &'static str {
        match self {
            Kind::Backlash { .. } => "backlash",
            Kind::GapWidth => "gap_width",
            Kind::CoulombFriction { .. } => "coulomb_friction",
            Kind::StribeckFriction { .. } => "stribeck_friction",
            Kind::AsymmetricCoulomb { .. } => "asymmetric_coulomb",
            Kind::Cogging { .. } => "cogging",
            Kind::ConstantForce { .. } => "constant_force",
            Kind::BacklashInertia => "backlash_inertia",
            Kind::InputDelay => "input_delay",
            Kind::InputSaturation => "input_saturation",
            Kind::SensorOffset => "sensor_offset",
            Kind::InputOn { op, .. } => op.name(),
        }
    }
    /// Name with its structural choice, e.g. `coulomb_friction(x2)`.
    pub fn label(&self) -> String {
        match self {
            Kind::Backlash { at_input: true } => "backlash(input)".into(),
            Kind::Backlash { at_input: false } => "backlash(loop)".into(),
            Kind::CoulombFriction { state } => format!("coulomb_friction(x{})", state + 1),
            Kind::StribeckFriction { state } => format!("stribeck_friction(x{})", state + 1),
            Kind::AsymmetricCoulomb { state } => format!("asymmetric_coulomb(x{})", state + 1),
            Kind::Cogging { state, .. } => format!("cogging(x{})", state + 1),
            Kind::ConstantForce { state } => format!("constant_force(x{})", state + 1),
            Kind::InputOn { op, input } => op.label(*input),
            k => k.name().into(),
        }
    }
    /// One-sentence physical description used in reports.
    pub fn description(&self) -> String {
        match self {
            Kind::Backlash { at_input: false } => "Play in the feedback path: the backlash output z stays put until y has crossed the gap, as in loose gears or a slack coupling.".into(),
            Kind::Backlash { at_input: true } => "Play between the command and the plant: the actuator only follows the input after the input has reversed by the width of the play.".into(),
            Kind::GapWidth => "The real play is wider (or narrower) than the model's Theta, e.g. from gear wear or a wrong catalogue value.".into(),
            Kind::CoulombFriction { state } => format!("Dry (Coulomb) friction opposes the motion of velocity state x{}: the motion sticks at rest until the driving force exceeds the friction level.", state + 1),
            Kind::StribeckFriction { state } => format!("Friction with breakaway (stiction) on velocity state x{}: at rest it holds up to a static level above the sliding friction, which falls along a Stribeck curve to the Coulomb level as the speed grows.", state + 1),
            Kind::AsymmetricCoulomb { state } => format!("Dry friction on velocity state x{} whose level depends on the direction of motion (e.g. a seal or guide that drags more one way, or a load that aids one direction).", state + 1),
            Kind::Cogging { state, position_state } => format!("A position-periodic (cogging, detent) force on velocity state x{} that repeats every period of position x{}, as from motor magnets passing stator teeth or a ball screw's pitch.", state + 1, position_state + 1),
            Kind::ConstantForce { state } => format!("A constant force (gravity, a spring preload, an amplifier bias) acts on the derivative of state x{}.", state + 1),
            Kind::BacklashInertia => "The backlash output has mass and damping: after y reverses, z coasts on instead of stopping at once.".into(),
            Kind::InputDelay => "The plant sees the input late (transport, communication or computation delay).".into(),
            Kind::InputSaturation => "The actuator cannot deliver commands beyond a limit (voltage or current saturation).".into(),
            Kind::SensorOffset => "The sensor reads a constant offset from the true output (calibration or zero error).".into(),
            Kind::InputOn { op, input } => op.description(*input),
        }
    }
}

/// Scales of the problem used for bounds.
#[derive(Debug, Clone, Default)]
pub struct Scales {
    pub y_range: Vec<f64>,
    pub w_range: Vec<f64>,
    pub w_absmax: f64,
    /// Slowest time constant `1 / |mu|` of the nominal `F`.
    pub tau_slow: f64,
    pub dt: f64,
    pub duration: f64,
    /// Range of each state over the nominal model's simulation of the record (empty when
    /// unknown; see [`Scales::with_nominal`]).
    pub state_range: Vec<f64>,
    /// Root mean square of each state over the same simulation (velocity scale of the
    /// Stribeck velocity).
    pub state_rms: Vec<f64>,
    /// The nominal simulation and the measured output, for data-derived starts (the cogging
    /// period scan); `None`: the hypotheses that need it are not offered.
    pub nominal: Option<std::sync::Arc<NominalRun>>,
}

/// The nominal model's free-run simulation of the record next to the measured output.
#[derive(Debug, Clone, Default)]
pub struct NominalRun {
    /// States `x[k * n + i]`.
    pub x: Vec<f64>,
    /// Simulated output `y[k * p + i]`.
    pub y_nominal: Vec<f64>,
    /// Measured output `y[k * p + i]`.
    pub y: Vec<f64>,
    /// Estimation samples `k < k_est` (the scan never looks at the validation segment).
    pub k_est: usize,
}

impl Scales {
    /// Adds the state scales and the nominal run: `x` (flat `k * n + i`) and `y_nominal` from
    /// a free-run simulation of the nominal model, `y` the recording's output.
    pub fn with_nominal(mut self, x: &[f64], y_nominal: &[f64], y: &[f64], k_est: usize) -> Self {
        let p = self.y_range.len().max(1);
        let ns = y.len() / p;
        if ns == 0 || !x.len().is_multiple_of(ns) || y_nominal.len() != y.len() {
            return self;
        }
        let n = x.len() / ns;
        let (mut lo, mut hi, mut sq) = (vec![f64::INFINITY; n], vec![f64::NEG_INFINITY; n], vec![0.0; n]);
        for k in 0..ns {
            for i in 0..n {
                let v = x[k * n + i];
                lo[i] = lo[i].min(v);
                hi[i] = hi[i].max(v);
                sq[i] += v * v;
            }
        }
        self.state_range = (0..n).map(|i| hi[i] - lo[i]).collect();
        self.state_rms = sq.iter().map(|v| (v / ns as f64).sqrt()).collect();
        self.nominal = Some(std::sync::Arc::new(NominalRun {
            x: x.to_vec(),
            y_nominal: y_nominal.to_vec(),
            y: y.to_vec(),
            k_est: k_est.min(ns),
        }));
        self
    }
}

/// One effect hypothesis: effect parameters in the box `[lower, upper]`.
#[derive(Debug, Clone)]
pub struct Hypothesis {
    pub kind: Kind,
    pub lower: Vec<f64>,
    pub upper: Vec<f64>,
    /// Starting points in the solver's unit coordinates `u in [0, 1]` (see [`Hypothesis::param_at`]).
    pub starts: Vec<Vec<f64>>,
    /// Parameter names (as in the model file, in the order of the parameter vector).
    pub names: Vec<&'static str>,
    /// How each parameter is mapped to `[0, 1]`: `None` linearly, `Some(c)` logarithmically
    /// in `theta + c` (for scale-like parameters whose plausible range spans decades, so
    /// that a step means the same relative change across the range).
    pub log_shift: Vec<Option<f64>>,
}

impl Hypothesis {
    /// Parameter `i` from unit coordinate `u`: `lower + u (upper - lower)`, or with a log
    /// shift `c`: `theta + c = (lower + c) ((upper + c) / (lower + c))^u`.
    pub fn param_at(&self, i: usize, u: f64) -> f64 {
        let (lo, hi) = (self.lower[i], self.upper[i]);
        match self.log_shift[i] {
            None => lo + u * (hi - lo),
            Some(c) => (lo + c) * ((hi + c) / (lo + c)).powf(u) - c,
        }
    }
    /// Inverse of [`Hypothesis::param_at`], clamped to `[0, 1]`.
    pub fn unit_of(&self, i: usize, theta: f64) -> f64 {
        let (lo, hi) = (self.lower[i], self.upper[i]);
        let u = match self.log_shift[i] {
            None => (theta - lo) / (hi - lo).max(1e-300),
            Some(c) => ((theta + c).max(1e-300) / (lo + c)).ln() / ((hi + c) / (lo + c)).ln(),
        };
        if u.is_finite() {
            u.clamp(0.0, 1.0)
        } else {
            0.0
        }
    }
    /// `d theta_i / d u` at `u` (maps the solver's covariance to physical units).
    pub fn slope(&self, i: usize, u: f64) -> f64 {
        let (lo, hi) = (self.lower[i], self.upper[i]);
        match self.log_shift[i] {
            None => hi - lo,
            Some(c) => (self.param_at(i, u) + c) * ((hi + c) / (lo + c)).ln(),
        }
    }
    /// Sets the starts from physical parameter values (one parameter per hypothesis).
    fn starts_at(mut self, theta: &[f64]) -> Self {
        self.starts = theta.iter().map(|t| vec![self.unit_of(0, *t)]).collect();
        self
    }
    /// The effect for parameters `theta` (physical units).
    pub fn effect(&self, theta: &[f64], s: &Scales) -> Effect {
        let _ = s;
        match self.kind {
            Kind::Backlash { at_input } => Effect::Backlash {
                width: theta[0].max(0.0),
                location: if at_input { PlayLocation::Input } else { PlayLocation::Loop },
            },
            Kind::GapWidth => Effect::GapWidth { relative_change: theta[0] },
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
            Kind::Cogging { state, position_state } => Effect::Cogging {
                state,
                position_state,
                amplitude: theta[0].hypot(theta[1]),
                period: theta[2].max(1e-300),
                phase: theta[1].atan2(theta[0]),
            },
            Kind::ConstantForce { state } => Effect::ConstantForce { state, force: theta[0] },
            Kind::BacklashInertia => Effect::BacklashInertia { mass: theta[0].max(0.0), damping: 1.0 },
            Kind::InputDelay => Effect::InputDelay { delay: theta[0].max(0.0) },
            Kind::InputSaturation => Effect::InputSaturation { limit: theta[0].max(1e-12) },
            Kind::SensorOffset => Effect::SensorOffset { offset: theta.to_vec() },
            // Not expressible per input in a model file: the same effect on every input
            // (the fit applies it to its input only, see `fit::input_effects`).
            Kind::InputOn { op, .. } => op.on_every_input(theta[0]),
        }
    }
    pub fn k(&self) -> usize {
        self.lower.len()
    }
}

/// Fractions of the bound at which a level-like parameter is started.
pub const DECADES: [f64; 6] = [1e-4, 1e-3, 1e-2, 0.1, 0.4, 0.8];

/// Shift of the logarithmic coordinates of a level-like parameter, relative to its bound.
pub const LEVEL_LOG_SHIFT: f64 = 1e-5;

/// A level-like hypothesis in `[0, hi]`: logarithmic coordinates and starts over decades.
fn level(kind: Kind, hi: f64, name: &'static str) -> Hypothesis {
    let h = Hypothesis {
        kind,
        lower: vec![0.0],
        upper: vec![hi],
        starts: vec![],
        names: vec![name],
        log_shift: vec![Some(LEVEL_LOG_SHIFT * hi)],
    };
    let at: Vec<f64> = DECADES.iter().map(|f| f * hi).collect();
    h.starts_at(&at)
}

/// Fractions of the bound at which a friction level is started (the decades, with 0.2 % of
/// the bound, where issue 13's small friction sat).
pub const FRICTION_DECADES: [f64; 7] = [1e-4, 1e-3, 2e-3, 1e-2, 0.1, 0.4, 0.8];

/// `stribeck_friction` on state `j`: `(level, static_level - level, stribeck_velocity)`, the
/// levels in `[0, fs]` and the velocity in `[1e-3, 2] v_scale`, all in logarithmic
/// coordinates; starts: each level decade with a static excess of half and 1.5 times the
/// level and Stribeck velocities of 3 % and 30 % of `v_scale` (screened by the solver).
fn stribeck(j: usize, fs: f64, v_scale: f64) -> Hypothesis {
    let h = Hypothesis {
        kind: Kind::StribeckFriction { state: j },
        lower: vec![0.0, 0.0, 1e-3 * v_scale],
        upper: vec![fs, fs, 2.0 * v_scale],
        starts: vec![],
        names: vec!["level", "static_excess", "stribeck_velocity"],
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
fn asymmetric(j: usize, fs: f64) -> Hypothesis {
    let h = Hypothesis {
        kind: Kind::AsymmetricCoulomb { state: j },
        lower: vec![0.0, 0.0],
        upper: vec![fs, fs],
        starts: vec![],
        names: vec!["level_positive", "level_negative"],
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

/// Fewest and most cogging periods over the recorded position range that the cogging
/// hypothesis considers (fewer than 2.5 look like a smooth position-dependent force, a
/// nonlinear spring that absorbs other mismatch; more than 40 need a finer position record
/// than the benchmark's).
pub const COGGING_PERIODS: (f64, f64) = (2.5, 40.0);

/// The position signal of state `pos` on the estimation segment: the measured output where a
/// row of `C` reads that state alone, else the nominal simulation's state.
fn position_signal(sys: &System, run: &NominalRun, pos: usize) -> Vec<f64> {
    let (n, p) = (sys.n(), sys.p());
    let direct = (0..p).find(|&r| (0..n).all(|c| (c == pos) == (sys.C[(r, c)] != 0.0)));
    match direct {
        Some(r) => (0..run.k_est).map(|k| run.y[k * p + r] / sys.C[(r, pos)]).collect(),
        None => (0..run.k_est).map(|k| run.x[k * n + pos]).collect(),
    }
}

/// Scan for a cogging period: for periods `P` from `range / 40` to `range / 2.5` of the
/// position (log grid, step `P / (6 range)`, so the phase at the ends of the range is off
/// by at most `pi / 6` between neighbours), the linearised response of the output to the two
/// force regressors `sin(2 pi x_pos / P)`, `cos(2 pi x_pos / P)` on velocity state `vel`
/// (the contact dynamics `F = A + E C`, the regressor held over each sample) is fitted to
/// the nominal residual by least squares. Returns the period with the largest reduction of
/// the residual and its two amplitudes, or `None` without a nominal run.
pub fn cogging_scan(sys: &System, s: &Scales, pos: usize, vel: usize) -> Option<(f64, f64, f64)> {
    let run = s.nominal.as_ref()?;
    let (n, p) = (sys.n(), sys.p());
    let ke = run.k_est;
    if ke < 10 || s.dt <= 0.0 {
        return None;
    }
    let xp = position_signal(sys, run, pos);
    let range = xp.iter().copied().fold(f64::NEG_INFINITY, f64::max) - xp.iter().copied().fold(f64::INFINITY, f64::min);
    if !(range > 0.0 && range.is_finite()) {
        return None;
    }
    // Weighted residual (outputs weigh alike).
    let wts: Vec<f64> = (0..p)
        .map(|i| {
            let m = (0..ke).map(|k| run.y[k * p + i]).sum::<f64>() / ke as f64;
            let v = (0..ke).map(|k| (run.y[k * p + i] - m).powi(2)).sum::<f64>() / ke as f64;
            1.0 / v.sqrt().max(1e-300)
        })
        .collect();
    let e: Vec<f64> = (0..ke * p).map(|i| (run.y[i] - run.y_nominal[i]) * wts[i % p]).collect();
    let maps = dynamics::extended::StepMaps::new(&sys.F(), &sys.B, &sys.E, s.dt);
    let col: Vec<f64> = (0..n).map(|i| maps.Psi[i * n + vel]).collect();
    let response = |u: &[f64], out: &mut Vec<f64>| {
        out.clear();
        let mut x = vec![0.0; n];
        let mut xn = vec![0.0; n];
        for k in 0..ke {
            for (r, wr) in wts.iter().enumerate() {
                out.push(wr * (0..n).map(|c| sys.C[(r, c)] * x[c]).sum::<f64>());
            }
            let uk = if k + 1 < ke { 0.5 * (u[k] + u[k + 1]) } else { u[k] };
            for i in 0..n {
                xn[i] = (0..n).map(|c| maps.Phi[i * n + c] * x[c]).sum::<f64>() + col[i] * uk;
            }
            std::mem::swap(&mut x, &mut xn);
        }
    };
    let (pmin, pmax) = (range / COGGING_PERIODS.1, range / COGGING_PERIODS.0);
    let mut best: Option<(f64, f64, f64, f64)> = None;
    let (mut rs, mut rc) = (Vec::with_capacity(ke * p), Vec::with_capacity(ke * p));
    let mut per = pmin;
    while per <= pmax {
        let kw = std::f64::consts::TAU / per;
        let us: Vec<f64> = xp.iter().map(|x| (kw * x).sin()).collect();
        let uc: Vec<f64> = xp.iter().map(|x| (kw * x).cos()).collect();
        response(&us, &mut rs);
        response(&uc, &mut rc);
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(u, v)| u * v).sum::<f64>();
        let (hss, hsc, hcc) = (dot(&rs, &rs), dot(&rs, &rc), dot(&rc, &rc));
        let (gs, gc) = (dot(&rs, &e), dot(&rc, &e));
        let det = hss * hcc - hsc * hsc;
        if det > 1e-12 * (hss * hcc).max(1e-300) {
            let (a_s, a_c) = ((hcc * gs - hsc * gc) / det, (hss * gc - hsc * gs) / det);
            let gain = a_s * gs + a_c * gc;
            if best.is_none_or(|b| gain > b.0) {
                best = Some((gain, per, a_s, a_c));
            }
        }
        per *= 1.0 + per / (6.0 * range);
    }
    best.map(|(_, per, a_s, a_c)| (per, a_s, a_c))
}

/// Position-velocity pairs `(i, j)`: `x_i' = a x_j` alone (see [`velocity_states`]).
pub fn position_velocity_pairs(sys: &System) -> Vec<(usize, usize)> {
    let n = sys.n();
    let mut out = Vec::new();
    for i in 0..n {
        let nz: Vec<usize> = (0..n).filter(|&j| sys.A[(i, j)] != 0.0).collect();
        let b0 = (0..sys.m()).all(|j| sys.B[(i, j)] == 0.0) && (0..sys.p()).all(|j| sys.E[(i, j)] == 0.0);
        if nz.len() == 1 && nz[0] != i && b0 && !out.iter().any(|&(_, j)| j == nz[0]) {
            out.push((i, nz[0]));
        }
    }
    out
}

/// `cogging` on velocity state `vel` with position state `pos`: amplitudes of the sine and
/// cosine parts in `[-fs, fs]` (linear: the force is linear in them) and the period in a
/// log box of `+- 3` scan steps about the scan's best period ([`cogging_scan`]), started at
/// the scan's amplitudes, half and 1.5 times them. `None` without a scan.
fn cogging(sys: &System, s: &Scales, pos: usize, vel: usize, fs: f64) -> Option<Hypothesis> {
    let (per, a_s, a_c) = cogging_scan(sys, s, pos, vel)?;
    let run = s.nominal.as_ref()?;
    let xp = position_signal(sys, run, pos);
    let range = xp.iter().copied().fold(f64::NEG_INFINITY, f64::max) - xp.iter().copied().fold(f64::INFINITY, f64::min);
    let step = per / (6.0 * range);
    let h = Hypothesis {
        kind: Kind::Cogging { state: vel, position_state: pos },
        lower: vec![-fs, -fs, per * (1.0 - 3.0 * step)],
        upper: vec![fs, fs, per * (1.0 + 3.0 * step)],
        starts: vec![],
        names: vec!["amplitude_sin", "amplitude_cos", "period"],
        log_shift: vec![None, None, Some(0.0)],
    };
    let starts =
        [1.0, 0.5, 1.5].iter().map(|f| vec![h.unit_of(0, f * a_s), h.unit_of(1, f * a_c), h.unit_of(2, per)]).collect();
    Some(Hypothesis { starts, ..h })
}

/// Largest held-out SSE ratio of a generalisation against its simpler form
/// ([`simpler_form`]): it must cut the simpler form's held-out error by 7 % (a new effect
/// needs 10 % against the model it extends). Chosen on development seeds between the
/// spurious asymmetry or breakaway fitted to coloured noise (ratios 0.954 and above) and the
/// weakest true ones (0.909-0.922).
pub const NESTED_MAX_CV_RATIO: f64 = 0.93;

/// Largest held-out SSE ratio at which a generalisation is still accepted when it lowers the
/// held-out error in **every** fold (at least [`NESTED_MIN_FOLDS`]): a generalisation fitted to
/// noise raises or lowers each fold's error at random (an extra free parameter rather raises
/// it), so all of five folds lower has probability at most `1/32`. Chosen on development seeds
/// 951-953: true Stribeck and direction-dependent friction under coloured noise gave ratios
/// 0.94-0.98 with every fold lower (0.933-0.994 per fold), spurious ones at most four of five
/// folds lower.
pub const NESTED_CONSISTENT_MAX_CV_RATIO: f64 = 0.99;

/// Fewest folds for the every-fold rule of [`NESTED_CONSISTENT_MAX_CV_RATIO`].
pub const NESTED_MIN_FOLDS: usize = 5;

/// Whether held-out folds support a generalisation over its simpler form ([`simpler_form`]):
/// per-fold held-out SSEs `sse` (generalisation) and `sse_simple`. Accepted when the total
/// ratio is at most [`NESTED_MAX_CV_RATIO`], or at most [`NESTED_CONSISTENT_MAX_CV_RATIO`] with
/// every one of at least [`NESTED_MIN_FOLDS`] folds lower.
pub fn nested_supported(sse: &[f64], sse_simple: &[f64]) -> bool {
    let (a, b): (f64, f64) = (sse.iter().sum(), sse_simple.iter().sum());
    if !b.is_finite() {
        // the simpler form could not be scored on the folds: nothing to prefer it by
        return true;
    }
    if !a.is_finite() || b <= 0.0 || sse.len() != sse_simple.len() {
        return false;
    }
    let ratio = a / b;
    let every_fold = sse.len() >= NESTED_MIN_FOLDS && sse.iter().zip(sse_simple).all(|(x, y)| x < y);
    ratio <= NESTED_MAX_CV_RATIO || (every_fold && ratio <= NESTED_CONSISTENT_MAX_CV_RATIO)
}

/// The simpler single hypothesis that `kind` generalises (nested at some parameter values):
/// Stribeck friction (static level = sliding level) and direction-dependent friction (equal
/// levels) both contain Coulomb friction on the same state. The diagnosis accepts the
/// generalisation only where it also beats the simpler form on held-out folds.
pub fn simpler_form(kind: Kind) -> Option<Kind> {
    match kind {
        Kind::StribeckFriction { state } | Kind::AsymmetricCoulomb { state } => Some(Kind::CoulombFriction { state }),
        _ => None,
    }
}

/// Notes on observational equivalences among the friction effects of a fitted model
/// (`effects`) and on ties (`ties`, hypothesis labels) that involve them: a Stribeck law
/// whose static level equals its sliding level is Coulomb friction, and direction-dependent
/// Coulomb levels are Coulomb friction plus a constant force on the same state.
pub fn friction_notes(effects: &[Effect], ties: &[String]) -> Vec<String> {
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
                "stribeck_friction(x{}): static (breakaway) level {static_level:.4e} against the sliding (Coulomb) level {level:.4e} (ratio {:.2}), Stribeck velocity {stribeck_velocity:.3e}: the recording shows breakaway; with equal levels it would be coulomb_friction, which BIC prefers when the data do not show it.",
                state + 1,
                static_level / level.max(1e-300)
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
    let friction =
        |t: &str| ["coulomb_friction", "stribeck_friction", "asymmetric_coulomb"].iter().any(|k| t.starts_with(k));
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

/// Velocity-like states: `x_j` such that some other state's derivative is a multiple of
/// `x_j` alone (`A` row `i` has its only non-zero at `j`, `B`, `E` rows `i` zero). When the
/// model has none, every state is a candidate.
pub fn velocity_states(sys: &System) -> Vec<usize> {
    let n = sys.n();
    let mut out = Vec::new();
    for i in 0..n {
        let nz: Vec<usize> = (0..n).filter(|&j| sys.A[(i, j)] != 0.0).collect();
        let b0 = (0..sys.m()).all(|j| sys.B[(i, j)] == 0.0) && (0..sys.p()).all(|j| sys.E[(i, j)] == 0.0);
        if nz.len() == 1 && nz[0] != i && b0 && !out.contains(&nz[0]) {
            out.push(nz[0]);
        }
    }
    if out.is_empty() {
        out = (0..n).collect();
    }
    out.sort();
    out
}

/// Static gain `|C F^{-1} e_j|` from a force on state `j` to `y` (None if `F` is singular or
/// the gain vanishes).
fn static_gain(sys: &System, j: usize) -> Option<f64> {
    let Finv = sys.F().try_inverse()?;
    let g = (&sys.C * Finv.column(j)).norm();
    (g > 1e-12).then_some(g)
}

/// All single-effect hypotheses applicable to `sys`.
pub fn candidates(sys: &System, s: &Scales) -> Vec<Hypothesis> {
    let point = dynamics::extended::theta_is_point(sys);
    let e_nonzero = sys.E.iter().any(|v| *v != 0.0);
    let yr = s.y_range.iter().copied().fold(0.0, f64::max).max(1e-12);
    let wr = s.w_range.iter().copied().fold(0.0, f64::max).max(1e-12);
    let one = |kind, lo: f64, hi: f64, name| Hypothesis {
        kind,
        lower: vec![lo],
        upper: vec![hi],
        starts: vec![vec![0.1], vec![0.4], vec![0.8]],
        names: vec![name],
        log_shift: vec![None],
    };
    let mut out = Vec::new();
    if point && e_nonzero {
        out.push(level(Kind::Backlash { at_input: false }, 0.5 * yr, "width"));
    }
    out.push(level(Kind::Backlash { at_input: true }, 0.5 * wr, "width"));
    if !point {
        // Scale 1 + relative_change from 0.1 up to the scale at which the play is wider than
        // the whole output range (beyond it z never moves and the scale is not identifiable),
        // at least 5; fitted in log scale.
        let diam = geometry::ConvexSet::diameter(&sys.theta).lower;
        let smax = if diam > 0.0 { (2.0 * yr / diam).clamp(5.0, 1e3) } else { 5.0 };
        let mut h = one(Kind::GapWidth, -0.9, smax - 1.0, "relative_change");
        h.log_shift = vec![Some(1.0)];
        out.push(h.starts_at(&[-0.5, -0.05, -0.005, 0.005, 0.05, 0.7, 2.5]));
        out.push(level(Kind::BacklashInertia, 2.0 * s.tau_slow, "mass"));
    }
    let pairs = position_velocity_pairs(sys);
    for j in velocity_states(sys) {
        let fs = static_gain(sys, j).map(|g| yr / g).unwrap_or_else(|| s.w_absmax * sys.B.row(j).amax()).max(1e-12);
        out.push(level(Kind::CoulombFriction { state: j }, fs, "level"));
        // Velocity scale: the state's RMS over the nominal run, else range(y) / tau_slow.
        let v_scale = s
            .state_rms
            .get(j)
            .copied()
            .filter(|v| *v > 0.0 && v.is_finite())
            .unwrap_or_else(|| yr / s.tau_slow.max(1e-12));
        out.push(stribeck(j, fs, v_scale));
        out.push(asymmetric(j, fs));
        if let Some(&(pos, _)) = pairs.iter().find(|&&(_, v)| v == j) {
            out.extend(cogging(sys, s, pos, j, fs));
        }
        let mut h = one(Kind::ConstantForce { state: j }, -0.5 * fs, 0.5 * fs, "force");
        h.starts = vec![vec![0.3], vec![0.5], vec![0.7]];
        out.push(h);
    }
    let dmax = s.tau_slow.min(s.duration / 20.0).max(5.0 * s.dt);
    out.push(level(Kind::InputDelay, dmax, "delay"));
    let h = one(Kind::InputSaturation, 0.2 * s.w_absmax, s.w_absmax, "limit");
    let wm = s.w_absmax;
    out.push(h.starts_at(&[0.52 * wm, 0.76 * wm, 0.96 * wm, 0.99 * wm, 0.999 * wm]));
    let p = s.y_range.len();
    out.push(Hypothesis {
        kind: Kind::SensorOffset,
        lower: s.y_range.iter().map(|r| -0.5 * r).collect(),
        upper: s.y_range.iter().map(|r| 0.5 * r).collect(),
        starts: vec![vec![0.5; p], vec![0.3; p], vec![0.7; p]],
        names: vec!["offset"; p],
        log_shift: vec![None; p],
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nested_generalisation_needs_a_large_gain_or_every_fold_lower() {
        let simple = [1.0; 5];
        // a large gain passes even with one fold worse
        assert!(nested_supported(&[0.8, 0.8, 0.8, 0.9, 1.05], &simple));
        // a small gain in every fold (a true breakaway under coloured noise, seed 951) passes
        assert!(nested_supported(&[0.933, 0.933, 0.945, 0.953, 0.933], &simple));
        // negative controls: the same small mean gain with one fold worse (a fit to noise, seed
        // 953), a consistent but negligible gain, too few folds for the every-fold rule
        assert!(!nested_supported(&[0.972, 0.897, 0.948, 1.056, 0.982], &simple));
        assert!(!nested_supported(&[0.995; 5], &simple));
        assert!(!nested_supported(&[0.95; 4], &[1.0; 4]));
        // an unscorable generalisation never passes; an unscorable simpler form is no rival
        assert!(!nested_supported(&[f64::INFINITY, 0.5, 0.5, 0.5, 0.5], &simple));
        assert!(nested_supported(&[0.9; 5], &[f64::INFINITY; 5]));
    }

    #[test]
    fn unit_coordinates_round_trip_and_slope_matches_differences() {
        let h = Hypothesis {
            kind: Kind::GapWidth,
            lower: vec![-0.9, 0.0],
            upper: vec![29.0, 2.0],
            starts: vec![],
            names: vec!["relative_change", "x"],
            log_shift: vec![Some(1.0), None],
        };
        // Log map: u = 0 -> scale 0.1, u = 1 -> scale 30, u = 1/2 -> geometric mean.
        assert!((h.param_at(0, 0.0) + 0.9).abs() < 1e-12);
        assert!((h.param_at(0, 1.0) - 29.0).abs() < 1e-9);
        assert!((h.param_at(0, 0.5) + 1.0 - 3f64.sqrt()).abs() < 1e-12);
        for (i, t) in [(0, -0.5), (0, 0.0), (0, 7.1), (1, 0.3)] {
            let u = h.unit_of(i, t);
            assert!((h.param_at(i, u) - t).abs() < 1e-9 * (1.0 + t.abs()), "{i} {t}");
            let d = (h.param_at(i, u + 1e-6) - h.param_at(i, u - 1e-6)) / 2e-6;
            assert!((h.slope(i, u) - d).abs() < 1e-5 * d.abs(), "slope {} vs {d}", h.slope(i, u));
        }
        // Out of the box: clamped.
        assert_eq!(h.unit_of(0, 100.0), 1.0);
        assert_eq!(h.unit_of(1, -1.0), 0.0);
        // Negative control: the linear map of the same box does not give the geometric mean.
        let lin = Hypothesis { log_shift: vec![None, None], ..h.clone() };
        assert!((lin.param_at(0, 0.5) + 1.0 - 3f64.sqrt()).abs() > 1.0);
    }

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
        // Cogging: a_s sin + a_c cos = R sin(. + phase).
        let cog = Hypothesis {
            kind: Kind::Cogging { state: 1, position_state: 0 },
            lower: vec![-1.0, -1.0, 0.1],
            upper: vec![1.0, 1.0, 1.0],
            starts: vec![],
            names: vec!["amplitude_sin", "amplitude_cos", "period"],
            log_shift: vec![None, None, Some(0.0)],
        };
        let Effect::Cogging { amplitude, period, phase, position_state, .. } = cog.effect(&[0.3, -0.4, 0.25], &s)
        else {
            panic!("not cogging")
        };
        assert_eq!((position_state, period), (0, 0.25));
        for t in [0.0, 0.7, 2.9] {
            let a = 0.3 * f64::sin(t) - 0.4 * f64::cos(t);
            assert!((amplitude * (t + phase).sin() - a).abs() < 1e-12);
        }
    }

    #[test]
    fn friction_notes_give_the_conversions() {
        let n =
            friction_notes(&[Effect::AsymmetricCoulomb { state: 1, level_positive: 0.5, level_negative: 0.1 }], &[]);
        assert!(n[0].contains("coulomb_friction(x2) at 3.0000e-1 plus constant_force(x2) -2.0000e-1"), "{n:?}");
        let n = friction_notes(
            &[Effect::CoulombFriction { state: 1, level: 0.3 }, Effect::ConstantForce { state: 1, force: -0.2 }],
            &[],
        );
        assert!(n[0].contains("asymmetric_coulomb(x2) with levels 5.0000e-1 (moving up) and 1.0000e-1"), "{n:?}");
        let n = friction_notes(&[Effect::CoulombFriction { state: 1, level: 0.3 }], &["stribeck_friction(x2)".into()]);
        assert!(n[0].contains("tied") && n[0].contains("stribeck_friction(x2)"), "{n:?}");
        // Negative control: nothing to say about a lone Coulomb friction or a force elsewhere.
        assert!(friction_notes(&[Effect::CoulombFriction { state: 1, level: 0.3 }], &[]).is_empty());
        let other = [Effect::CoulombFriction { state: 1, level: 0.3 }, Effect::ConstantForce { state: 3, force: 0.1 }];
        assert!(friction_notes(&other, &[]).is_empty());
    }
}
