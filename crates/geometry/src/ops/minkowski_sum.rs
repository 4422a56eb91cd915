//! Minkowski sum `S_1 + ... + S_k`: `sigma = sigma_1 + ... + sigma_k`.
use crate::curvature::planar_strong_convexity;
use crate::shapes::support_set::project_via_support;
use crate::{ConvexSet, Enclosure, GeometryError, StrongConvexity};

/// Sum of sets of the same dimension (e.g. `C Xi_inf + Theta` in eq. (d)).
#[derive(Debug)]
pub struct MinkowskiSum {
    parts: Vec<Box<dyn ConvexSet>>,
}

impl MinkowskiSum {
    pub fn new(parts: Vec<Box<dyn ConvexSet>>) -> Result<Self, GeometryError> {
        let first = parts.first().ok_or(GeometryError::NoParts { what: "summand" })?;
        let p = first.dim();
        if let Some(bad) = parts.iter().find(|s| s.dim() != p) {
            return Err(GeometryError::DimensionMismatch { what: "summand dimension", expected: p, got: bad.dim() });
        }
        Ok(Self { parts })
    }
}

impl ConvexSet for MinkowskiSum {
    fn dim(&self) -> usize {
        self.parts[0].dim()
    }
    fn support(&self, u: &[f64]) -> f64 {
        self.parts.iter().map(|s| s.support(u)).sum()
    }
    fn support_point(&self, u: &[f64], out: &mut [f64]) {
        let mut buf = vec![0.0; self.dim()];
        out.iter_mut().for_each(|o| *o = 0.0);
        for s in &self.parts {
            s.support_point(u, &mut buf);
            out.iter_mut().zip(&buf).for_each(|(o, b)| *o += b);
        }
    }
    fn project(&self, x: &[f64], out: &mut [f64]) {
        project_via_support(self, x, out)
    }
    fn deviation_from_origin(&self) -> Enclosure {
        let lip: f64 = self.parts.iter().map(|s| s.deviation_from_origin().upper).sum();
        let b = crate::sphere_max(self.dim(), |u| self.support(u), lip, &Default::default());
        Enclosure::new(b.lower.max(0.0), b.upper.min(lip).max(b.lower))
    }
    /// `R(S_1 + S_2) <= R(S_1) + R(S_2)` (radii of curvature add): a verified upper bound
    /// when every part has one; otherwise the numerical planar value, or unknown.
    fn strong_convexity(&self) -> StrongConvexity {
        if self.dim() == 1 {
            return StrongConvexity::Exact(0.5 * (self.support(&[1.0]) + self.support(&[-1.0])));
        }
        let parts: Vec<StrongConvexity> = self.parts.iter().map(|s| s.strong_convexity()).collect();
        let sum: f64 = parts.iter().map(|r| r.upper()).sum();
        if sum.is_finite() && parts.iter().all(|r| r.is_verified_upper()) {
            StrongConvexity::UpperBound(sum)
        } else if self.dim() == 2 {
            planar_strong_convexity(|u| self.support(u))
        } else {
            StrongConvexity::Unknown
        }
    }
    fn describe(&self) -> String {
        let d: Vec<String> = self.parts.iter().map(|s| s.describe()).collect();
        format!("Minkowski sum of {}", d.join(" + "))
    }
}
