//! Interval `[lo, hi]` in R^1: ordinary gear backlash `Theta = [-delta, delta]`.
use super::check_finite;
use crate::{ConvexSet, Enclosure, GeometryError, StrongConvexity};

/// `[lo, hi]`, a ball in R^1 of radius `(hi - lo)/2`, hence `R = (hi - lo)/2` (NOTES.md).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    pub lo: f64,
    pub hi: f64,
}

impl Interval {
    pub fn new(lo: f64, hi: f64) -> Result<Self, GeometryError> {
        check_finite("interval end", &[lo, hi])?;
        if lo > hi {
            return Err(GeometryError::EmptyInterval { lo, hi });
        }
        Ok(Self { lo, hi })
    }
    /// The symmetric gap `[-delta, delta]`.
    pub fn symmetric(delta: f64) -> Result<Self, GeometryError> {
        if delta < 0.0 {
            return Err(GeometryError::Negative { what: "interval half-width", value: delta });
        }
        Self::new(-delta, delta)
    }
    #[inline]
    pub fn clamp(&self, x: f64) -> f64 {
        x.clamp(self.lo, self.hi)
    }
}

impl ConvexSet for Interval {
    fn dim(&self) -> usize {
        1
    }
    fn support(&self, u: &[f64]) -> f64 {
        if u[0] >= 0.0 {
            u[0] * self.hi
        } else {
            u[0] * self.lo
        }
    }
    fn support_point(&self, u: &[f64], out: &mut [f64]) {
        out[0] = if u[0] >= 0.0 { self.hi } else { self.lo };
    }
    #[inline]
    fn project(&self, x: &[f64], out: &mut [f64]) {
        out[0] = self.clamp(x[0]);
    }
    fn contains(&self, x: &[f64], tol: f64) -> bool {
        x[0] >= self.lo - tol && x[0] <= self.hi + tol
    }
    fn dist_to_boundary(&self, x: &[f64]) -> f64 {
        (x[0] - self.lo).min(self.hi - x[0]).max(0.0)
    }
    /// Inward normals: `{s >= 0}` at `lo`, `{s <= 0}` at `hi`, `{0}` inside (all of R if
    /// `lo == hi`).
    fn project_normal_cone(&self, q: &[f64], v: &[f64], tol: f64, out: &mut [f64]) {
        let at_lo = q[0] <= self.lo + tol;
        let at_hi = q[0] >= self.hi - tol;
        out[0] = match (at_lo, at_hi) {
            (true, true) => v[0],
            (true, false) => v[0].max(0.0),
            (false, true) => v[0].min(0.0),
            (false, false) => 0.0,
        };
    }
    /// `hi - lo`, rounded upward (the lower end rounded to nearest).
    fn diameter(&self) -> Enclosure {
        let up = rounding::add_up(self.hi, -self.lo);
        Enclosure::new((self.hi - self.lo).min(up), up)
    }
    fn deviation_from_origin(&self) -> Enclosure {
        Enclosure::exact(self.lo.abs().max(self.hi.abs()))
    }
    /// `R = (hi - lo)/2`, the difference rounded upward (TwoSum), the halving exact.
    fn strong_convexity(&self) -> StrongConvexity {
        StrongConvexity::Exact(0.5 * rounding::add_up(self.hi, -self.lo))
    }
    fn describe(&self) -> String {
        format!("interval [{}, {}]", self.lo, self.hi)
    }
}
