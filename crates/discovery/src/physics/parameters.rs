//! A hypothesis' parameters: the box `[lower, upper]`, the solver's unit coordinates (linear,
//! or logarithmic for scale-like parameters whose plausible range spans decades) and the
//! starts, with the builders the families share.
//!
//! Starts over decades: a level-like parameter (play width, friction level, inertia time
//! constant, delay) is fitted in logarithmic coordinates of `theta + 1e-5 upper` (so that 0 is
//! reachable and a step is a relative change at every magnitude) from starts at
//! `{1e-4, 1e-3, 1e-2, 0.1, 0.4, 0.8}` of its bound ([`DECADES`], [`level`]). Forces and
//! offsets enter the output linearly and need no decade starts ([`linear`]).
use super::{Kind, Scales};
use model::effects::Effect;

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
    pub fn starts_at(mut self, theta: &[f64]) -> Self {
        self.starts = theta.iter().map(|t| vec![self.unit_of(0, *t)]).collect();
        self
    }
    /// The effect for parameters `theta` (physical units).
    pub fn effect(&self, theta: &[f64], s: &Scales) -> Effect {
        let _ = s;
        self.kind.effect(theta)
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
pub fn level(kind: Kind, hi: f64, name: &'static str) -> Hypothesis {
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

/// A one-parameter hypothesis in `[lo, hi]`, linear coordinates, started at 10 %, 40 % and
/// 80 % of the box.
pub fn linear(kind: Kind, lo: f64, hi: f64, name: &'static str) -> Hypothesis {
    Hypothesis {
        kind,
        lower: vec![lo],
        upper: vec![hi],
        starts: vec![vec![0.1], vec![0.4], vec![0.8]],
        names: vec![name],
        log_shift: vec![None],
    }
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
