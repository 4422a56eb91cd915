//! Linear image `M S = {M s : s in S}`: `sigma_{MS}(u) = sigma_S(M^T u)`.
use crate::curvature::planar_strong_convexity;
use crate::shapes::support_set::project_via_support;
use crate::{ConvexSet, Enclosure, GeometryError, StrongConvexity};
use nalgebra::DMatrix;

/// `M S` for a `q x p` matrix `M` and a set `S` in R^p (e.g. `C Xi_inf` in eq. (d)).
#[derive(Debug)]
pub struct LinearImage<S: ConvexSet> {
    m: DMatrix<f64>,
    set: S,
    norm_m: f64,
}

impl<S: ConvexSet> LinearImage<S> {
    pub fn new(m: DMatrix<f64>, set: S) -> Result<Self, GeometryError> {
        if m.ncols() != set.dim() {
            return Err(GeometryError::DimensionMismatch {
                what: "columns of M vs dimension of S",
                expected: set.dim(),
                got: m.ncols(),
            });
        }
        if let Some(&value) = m.iter().find(|x| !x.is_finite()) {
            return Err(GeometryError::NotFinite { what: "matrix entry", value });
        }
        // spectral norm, inflated to be a safe upper bound
        let norm_m = m.clone().singular_values().max() * (1.0 + 1e-12) + f64::MIN_POSITIVE;
        Ok(Self { m, set, norm_m })
    }
    fn mt_u(&self, u: &[f64]) -> Vec<f64> {
        (0..self.m.ncols()).map(|j| (0..self.m.nrows()).map(|i| self.m[(i, j)] * u[i]).sum()).collect()
    }
}

impl<S: ConvexSet> ConvexSet for LinearImage<S> {
    fn dim(&self) -> usize {
        self.m.nrows()
    }
    fn support(&self, u: &[f64]) -> f64 {
        self.set.support(&self.mt_u(u))
    }
    fn support_point(&self, u: &[f64], out: &mut [f64]) {
        let mut s = vec![0.0; self.set.dim()];
        self.set.support_point(&self.mt_u(u), &mut s);
        for i in 0..self.m.nrows() {
            out[i] = (0..self.m.ncols()).map(|j| self.m[(i, j)] * s[j]).sum();
        }
    }
    fn project(&self, x: &[f64], out: &mut [f64]) {
        project_via_support(self, x, out)
    }
    fn deviation_from_origin(&self) -> Enclosure {
        let lip = self.norm_m * self.set.deviation_from_origin().upper;
        let b = crate::sphere_max(self.dim(), |u| self.support(u), lip, &Default::default());
        Enclosure::new(b.lower.max(0.0), b.upper.min(lip).max(b.lower))
    }
    fn strong_convexity(&self) -> StrongConvexity {
        match self.dim() {
            1 => StrongConvexity::Exact(0.5 * (self.support(&[1.0]) + self.support(&[-1.0]))),
            2 => planar_strong_convexity(|u| self.support(u)),
            _ => StrongConvexity::Unknown,
        }
    }
    fn describe(&self) -> String {
        format!("linear image ({}x{}) of {}", self.m.nrows(), self.m.ncols(), self.set.describe())
    }
}
