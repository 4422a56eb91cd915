//! Polytope `{x : a_i^T x <= b_i}`: convex but not strongly convex (`R = infinity`, the
//! paper's footnote case `gamma = 0`), except in R^1 where it is an interval.
use super::{check_finite, fmt_vec};
use crate::linalg::{dist, dot, for_each_subset, norm, orthogonal_complement, solve_small};
use crate::normal_cone::project_onto_cone;
use crate::{ConvexSet, Enclosure, GeometryError, StrongConvexity};

/// Bounded polytope in half-space form; vertices are enumerated at construction.
#[derive(Debug, Clone, PartialEq)]
pub struct Polytope {
    normals: Vec<Vec<f64>>,
    offsets: Vec<f64>,
    vertices: Vec<Vec<f64>>,
    /// `|a_i|` of every row and `max |vertex|` enlarged by a relative `1e-9` (for
    /// [`Polytope::support_upper`]).
    row_norms: Vec<f64>,
    dev_upper: f64,
}

impl Polytope {
    /// `{x : normals[i]^T x <= offsets[i]}`. Checks finiteness, nonzero normals,
    /// boundedness (no recession direction), nonemptiness and a nonempty interior
    /// ([`check_full_dimensional`]).
    pub fn new(normals: Vec<Vec<f64>>, offsets: Vec<f64>) -> Result<Self, GeometryError> {
        if normals.is_empty() {
            return Err(GeometryError::NoParts { what: "half-space" });
        }
        if offsets.len() != normals.len() {
            return Err(GeometryError::DimensionMismatch {
                what: "number of offsets vs normals",
                expected: normals.len(),
                got: offsets.len(),
            });
        }
        let p = normals[0].len();
        if p == 0 {
            return Err(GeometryError::UnsupportedDimension { max: usize::MAX, got: 0 });
        }
        for (i, a) in normals.iter().enumerate() {
            if a.len() != p {
                return Err(GeometryError::DimensionMismatch {
                    what: "polytope normal length",
                    expected: p,
                    got: a.len(),
                });
            }
            check_finite("polytope normal", a)?;
            if norm(a) == 0.0 {
                return Err(GeometryError::ZeroNormal { index: i });
            }
        }
        check_finite("polytope offset", &offsets)?;
        let k = normals.len();
        // boundedness: a nonzero recession direction d (A d <= 0) has an extreme ray with
        // p - 1 linearly independent active rows (or A has rank < p).
        let rank_ok = {
            let c = orthogonal_complement(&normals, p);
            if let Some(d) = c.first() {
                return Err(GeometryError::UnboundedPolytope { direction: d.clone() });
            }
            true
        };
        debug_assert!(rank_ok);
        let mut unbounded: Option<Vec<f64>> = None;
        let tol_dir = |d: &[f64]| normals.iter().all(|a| dot(a, d) <= 1e-12 * norm(a)) && norm(d) > 0.5;
        if p == 1 {
            for d in [[1.0], [-1.0]] {
                if tol_dir(&d) {
                    unbounded = Some(d.to_vec());
                }
            }
        } else {
            for_each_subset(k, p - 1, |idx| {
                let rows: Vec<Vec<f64>> = idx.iter().map(|&i| normals[i].clone()).collect();
                let c = orthogonal_complement(&rows, p);
                if c.len() == 1 {
                    for s in [1.0, -1.0] {
                        let d: Vec<f64> = c[0].iter().map(|x| s * x).collect();
                        if tol_dir(&d) {
                            unbounded = Some(d);
                            return false;
                        }
                    }
                }
                true
            });
        }
        if let Some(direction) = unbounded {
            return Err(GeometryError::UnboundedPolytope { direction });
        }
        let mut vertices: Vec<Vec<f64>> = Vec::new();
        let scale = offsets.iter().fold(1.0f64, |a, b| a.max(b.abs()));
        for_each_subset(k, p, |idx| {
            let mut m = vec![0.0; p * p];
            let mut r = vec![0.0; p];
            for (a, &i) in idx.iter().enumerate() {
                m[a * p..(a + 1) * p].copy_from_slice(&normals[i]);
                r[a] = offsets[i];
            }
            if solve_small(&mut m, &mut r, p, 1e-12)
                && normals.iter().zip(&offsets).all(|(a, b)| dot(a, &r) <= b + 1e-10 * scale * norm(a).max(1.0))
                && !vertices.iter().any(|v| dist(v, &r) <= 1e-12 * scale)
            {
                vertices.push(r);
            }
            true
        });
        if vertices.is_empty() {
            return Err(GeometryError::EmptyPolytope);
        }
        check_full_dimensional(&normals, &vertices)?;
        let row_norms = normals.iter().map(|a| norm(a)).collect();
        let dev_upper = vertices.iter().map(|v| norm(v)).fold(0.0, f64::max) * (1.0 + 1e-9);
        Ok(Self { normals, offsets, vertices, row_norms, dev_upper })
    }

    /// The box `prod_i [lower_i, upper_i]` (each `lower_i < upper_i`).
    pub fn from_box(lower: &[f64], upper: &[f64]) -> Result<Self, GeometryError> {
        if lower.len() != upper.len() {
            return Err(GeometryError::DimensionMismatch {
                what: "box upper vs lower length",
                expected: lower.len(),
                got: upper.len(),
            });
        }
        let p = lower.len();
        let mut normals = Vec::new();
        let mut offsets = Vec::new();
        for i in 0..p {
            let mut e = vec![0.0; p];
            e[i] = 1.0;
            normals.push(e.clone());
            offsets.push(upper[i]);
            e[i] = -1.0;
            normals.push(e);
            offsets.push(-lower[i]);
        }
        Self::new(normals, offsets)
    }

    pub fn vertices(&self) -> &[Vec<f64>] {
        &self.vertices
    }
    pub fn normals(&self) -> &[Vec<f64>] {
        &self.normals
    }
    pub fn offsets(&self) -> &[f64] {
        &self.offsets
    }

    fn feasible(&self, v: &[f64]) -> bool {
        self.normals.iter().zip(&self.offsets).all(|(a, b)| dot(a, v) <= b + 1e-12 * (1.0 + b.abs()) * norm(a).max(1.0))
    }
}

/// Width, relative to the diameter, below which a polytope counts as having an empty interior.
pub const MIN_RELATIVE_WIDTH: f64 = 1e-9;

/// Refuses a polytope with an empty interior (all vertices on a line in R^2, a single point,
/// a box with `lower_i = upper_i`). A nonempty `{x : A x <= b}` with empty interior has an
/// implicit equality: a row `i` with `a_i^T x = b_i` on the whole set, so its width across that
/// row, `(max_v a_i^T v - min_v a_i^T v) / |a_i|` over the vertices, is zero. A width below
/// [`MIN_RELATIVE_WIDTH`] times the diameter (or a diameter of zero) is refused.
fn check_full_dimensional(normals: &[Vec<f64>], vertices: &[Vec<f64>]) -> Result<(), GeometryError> {
    let mut diameter: f64 = 0.0;
    for (i, u) in vertices.iter().enumerate() {
        for v in &vertices[i + 1..] {
            diameter = diameter.max(dist(u, v));
        }
    }
    for (index, a) in normals.iter().enumerate() {
        let (lo, hi) = vertices
            .iter()
            .map(|v| dot(a, v))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)));
        let width = (hi - lo) / norm(a);
        if !(width > MIN_RELATIVE_WIDTH * diameter) || diameter == 0.0 {
            return Err(GeometryError::DegeneratePolytope { index, width, diameter });
        }
    }
    Ok(())
}

impl Polytope {
    /// Proven upper bound of `sigma(u)` by the Lagrangian certificate at the computed maximising
    /// vertex ([`super::upper::polytope_support_upper`]), with `D(S,{0})` from the vertices
    /// enlarged by a relative `1e-9` (it only multiplies the certificate's residual).
    pub fn support_upper(&self, u: &[f64]) -> f64 {
        let best = self.vertices.iter().max_by(|a, b| dot(u, a).total_cmp(&dot(u, b))).unwrap();
        super::upper::polytope_support_upper(&self.normals, &self.row_norms, &self.offsets, best, self.dev_upper, u)
    }
}

impl ConvexSet for Polytope {
    fn dim(&self) -> usize {
        self.normals[0].len()
    }
    fn support(&self, u: &[f64]) -> f64 {
        self.vertices.iter().map(|v| dot(u, v)).fold(f64::NEG_INFINITY, f64::max)
    }
    fn support_point(&self, u: &[f64], out: &mut [f64]) {
        let best = self.vertices.iter().max_by(|a, b| dot(u, a).total_cmp(&dot(u, b))).unwrap();
        out.copy_from_slice(best);
    }
    /// Exact active-set enumeration: for a candidate active set `I` the projection onto
    /// `{a_i^T v = b_i, i in I}` is `x - A_I^T nu`; it is the answer iff `nu >= 0` and the
    /// point is feasible (KKT conditions of a convex QP).
    fn project(&self, x: &[f64], out: &mut [f64]) {
        let p = self.dim();
        if self.feasible(x) {
            out.copy_from_slice(x);
            return;
        }
        let k = self.normals.len();
        let mut best: Option<(f64, Vec<f64>)> = None;
        for size in 1..=p.min(k) {
            for_each_subset(k, size, |idx| {
                let mut gram = vec![0.0; size * size];
                let mut nu = vec![0.0; size];
                for (a, &i) in idx.iter().enumerate() {
                    nu[a] = dot(&self.normals[i], x) - self.offsets[i];
                    for (b, &j) in idx.iter().enumerate() {
                        gram[a * size + b] = dot(&self.normals[i], &self.normals[j]);
                    }
                }
                if !solve_small(&mut gram, &mut nu, size, 1e-12) || nu.iter().any(|&n| n < 0.0) {
                    return true;
                }
                let mut v = x.to_vec();
                for (a, &i) in idx.iter().enumerate() {
                    for d in 0..p {
                        v[d] -= nu[a] * self.normals[i][d];
                    }
                }
                if self.feasible(&v) {
                    let dd = dist(&v, x);
                    if best.as_ref().is_none_or(|(b, _)| dd < *b) {
                        best = Some((dd, v));
                    }
                    return false;
                }
                true
            });
            if best.is_some() {
                break;
            }
        }
        match best {
            Some((_, v)) => out.copy_from_slice(&v),
            // rounding-only fallback: the nearest vertex
            None => out.copy_from_slice(self.vertices.iter().min_by(|a, b| dist(a, x).total_cmp(&dist(b, x))).unwrap()),
        }
    }
    fn dist_to_boundary(&self, x: &[f64]) -> f64 {
        self.normals
            .iter()
            .zip(&self.offsets)
            .map(|(a, b)| (b - dot(a, x)) / norm(a))
            .fold(f64::INFINITY, f64::min)
            .max(0.0)
    }
    fn project_normal_cone(&self, q: &[f64], v: &[f64], tol: f64, out: &mut [f64]) {
        let gens: Vec<Vec<f64>> = self
            .normals
            .iter()
            .zip(&self.offsets)
            .filter(|(a, b)| (*b - dot(a, q)) / norm(a) <= tol)
            .map(|(a, _)| {
                let n = norm(a);
                a.iter().map(|x| -x / n).collect()
            })
            .collect();
        project_onto_cone(&gens, v, out);
    }
    fn diameter(&self) -> Enclosure {
        let mut d = 0.0f64;
        for (i, a) in self.vertices.iter().enumerate() {
            for b in &self.vertices[i + 1..] {
                d = d.max(dist(a, b));
            }
        }
        Enclosure::exact(d)
    }
    fn deviation_from_origin(&self) -> Enclosure {
        Enclosure::exact(self.vertices.iter().map(|v| norm(v)).fold(0.0, f64::max))
    }
    fn strong_convexity(&self) -> StrongConvexity {
        if self.dim() == 1 {
            // Half the length, the difference rounded upward.
            let hi = self.vertices.iter().map(|v| v[0]).fold(f64::NEG_INFINITY, f64::max);
            let lo = self.vertices.iter().map(|v| v[0]).fold(f64::INFINITY, f64::min);
            StrongConvexity::Exact(0.5 * rounding::add_up(hi, -lo))
        } else {
            StrongConvexity::Infinite
        }
    }
    fn describe(&self) -> String {
        let vs: Vec<String> = self.vertices.iter().map(|v| fmt_vec(v)).collect();
        format!("polytope with {} facets and vertices {}", self.normals.len(), vs.join(" "))
    }
}
