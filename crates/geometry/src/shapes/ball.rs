//! Closed Euclidean ball `B_r(c)` in any dimension.
use super::{check_finite, fmt_vec};
use crate::linalg::{dist, norm};
use crate::{ConvexSet, Enclosure, GeometryError, StrongConvexity};

/// `{x : |x - c| <= r}`; `R = r` (eq. (R)). `r = 0` gives the singleton `{c}`
/// (the linearised system's `Theta = {0}`).
#[derive(Debug, Clone, PartialEq)]
pub struct Ball {
    pub centre: Vec<f64>,
    pub radius: f64,
}

impl Ball {
    pub fn new(centre: Vec<f64>, radius: f64) -> Result<Self, GeometryError> {
        if centre.is_empty() {
            return Err(GeometryError::UnsupportedDimension { max: usize::MAX, got: 0 });
        }
        check_finite("ball centre", &centre)?;
        check_finite("ball radius", &[radius])?;
        if radius < 0.0 {
            return Err(GeometryError::Negative { what: "ball radius", value: radius });
        }
        Ok(Self { centre, radius })
    }
    /// `B_r(0)` in R^p.
    pub fn centred(p: usize, radius: f64) -> Result<Self, GeometryError> {
        Self::new(vec![0.0; p], radius)
    }
}

impl ConvexSet for Ball {
    fn dim(&self) -> usize {
        self.centre.len()
    }
    fn support(&self, u: &[f64]) -> f64 {
        crate::linalg::dot(&self.centre, u) + self.radius * norm(u)
    }
    fn support_point(&self, u: &[f64], out: &mut [f64]) {
        let n = norm(u);
        let s = if n > 0.0 { self.radius / n } else { 0.0 };
        for i in 0..out.len() {
            out[i] = self.centre[i] + s * u[i];
        }
    }
    #[inline]
    fn project(&self, x: &[f64], out: &mut [f64]) {
        let d = dist(x, &self.centre);
        if d <= self.radius {
            out.copy_from_slice(x);
        } else {
            let s = self.radius / d;
            for i in 0..out.len() {
                out[i] = self.centre[i] + s * (x[i] - self.centre[i]);
            }
        }
    }
    fn contains(&self, x: &[f64], tol: f64) -> bool {
        dist(x, &self.centre) <= self.radius + tol
    }
    fn dist_to_boundary(&self, x: &[f64]) -> f64 {
        (self.radius - dist(x, &self.centre)).max(0.0)
    }
    /// Inward normal at a boundary point: the ray spanned by `c - q`.
    fn project_normal_cone(&self, q: &[f64], v: &[f64], tol: f64, out: &mut [f64]) {
        let d = dist(q, &self.centre);
        if self.radius == 0.0 {
            out.copy_from_slice(v); // singleton: the normal cone is all of R^p
            return;
        }
        if d < self.radius - tol || d == 0.0 {
            out.iter_mut().for_each(|o| *o = 0.0);
            return;
        }
        let mut s = 0.0;
        for i in 0..v.len() {
            s += v[i] * (self.centre[i] - q[i]) / d;
        }
        let s = s.max(0.0);
        for i in 0..v.len() {
            out[i] = s * (self.centre[i] - q[i]) / d;
        }
    }
    fn diameter(&self) -> Enclosure {
        Enclosure::exact(2.0 * self.radius)
    }
    fn deviation_from_origin(&self) -> Enclosure {
        Enclosure::exact(norm(&self.centre) + self.radius)
    }
    fn strong_convexity(&self) -> StrongConvexity {
        StrongConvexity::Exact(self.radius)
    }
    fn describe(&self) -> String {
        format!("ball(centre={}, radius={})", fmt_vec(&self.centre), self.radius)
    }
}
