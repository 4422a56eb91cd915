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
//! - `sensor_offset` in `+- range(y)/2` per output.
//!
//! Starts over decades: a level-like parameter (play width, friction level, inertia time
//! constant, delay) is fitted in logarithmic coordinates of `theta + 1e-5 upper` (so that 0 is
//! reachable and a step is a relative change at every magnitude) from starts at
//! `{1e-4, 1e-3, 1e-2, 0.1, 0.4, 0.8}` of its bound ([`DECADES`]); the saturation limit gets
//! starts down to 0.1 % below `max |w|`, the gap scale starts at +-0.5 %, +-5 %, -50 %, +70 %
//! and +250 %. The solver screens the starts and iterates the best three. Forces and offsets
//! enter the output linearly and need no decade starts.
use model::effects::{Effect, PlayLocation};
use model::System;
use serde::Serialize;

/// A structural choice of effect (parameters apart).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Kind {
    Backlash { at_input: bool },
    GapWidth,
    CoulombFriction { state: usize },
    ConstantForce { state: usize },
    BacklashInertia,
    InputDelay,
    InputSaturation,
    SensorOffset,
}

impl Kind {
    /// The model-file name of the effect.
    pub fn name(&self) -> &'static str {
        match self {
            Kind::Backlash { .. } => "backlash",
            Kind::GapWidth => "gap_width",
            Kind::CoulombFriction { .. } => "coulomb_friction",
            Kind::ConstantForce { .. } => "constant_force",
            Kind::BacklashInertia => "backlash_inertia",
            Kind::InputDelay => "input_delay",
            Kind::InputSaturation => "input_saturation",
            Kind::SensorOffset => "sensor_offset",
        }
    }
    /// Name with its structural choice, e.g. `coulomb_friction(x2)`.
    pub fn label(&self) -> String {
        match self {
            Kind::Backlash { at_input: true } => "backlash(input)".into(),
            Kind::Backlash { at_input: false } => "backlash(loop)".into(),
            Kind::CoulombFriction { state } => format!("coulomb_friction(x{})", state + 1),
            Kind::ConstantForce { state } => format!("constant_force(x{})", state + 1),
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
            Kind::ConstantForce { state } => format!("A constant force (gravity, a spring preload, an amplifier bias) acts on the derivative of state x{}.", state + 1),
            Kind::BacklashInertia => "The backlash output has mass and damping: after y reverses, z coasts on instead of stopping at once.".into(),
            Kind::InputDelay => "The plant sees the input late (transport, communication or computation delay).".into(),
            Kind::InputSaturation => "The actuator cannot deliver commands beyond a limit (voltage or current saturation).".into(),
            Kind::SensorOffset => "The sensor reads a constant offset from the true output (calibration or zero error).".into(),
        }
    }
}

/// Scales of the problem used for bounds.
#[derive(Debug, Clone)]
pub struct Scales {
    pub y_range: Vec<f64>,
    pub w_range: Vec<f64>,
    pub w_absmax: f64,
    /// Slowest time constant `1 / |mu|` of the nominal `F`.
    pub tau_slow: f64,
    pub dt: f64,
    pub duration: f64,
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
            Kind::ConstantForce { state } => Effect::ConstantForce { state, force: theta[0] },
            Kind::BacklashInertia => Effect::BacklashInertia { mass: theta[0].max(0.0), damping: 1.0 },
            Kind::InputDelay => Effect::InputDelay { delay: theta[0].max(0.0) },
            Kind::InputSaturation => Effect::InputSaturation { limit: theta[0].max(1e-12) },
            Kind::SensorOffset => Effect::SensorOffset { offset: theta.to_vec() },
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
    for j in velocity_states(sys) {
        let fs = static_gain(sys, j).map(|g| yr / g).unwrap_or_else(|| s.w_absmax * sys.B.row(j).amax()).max(1e-12);
        out.push(level(Kind::CoulombFriction { state: j }, fs, "level"));
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
}
