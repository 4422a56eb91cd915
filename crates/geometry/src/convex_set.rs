//! The trait every convex compact set of the paper implements.
use crate::linalg::{dist, dot, norm};
use crate::{Enclosure, StrongConvexity};

/// A nonempty convex compact set `S` in `R^p`.
///
/// Points are slices of length [`ConvexSet::dim`]; outputs are written into `out` so that
/// callers in hot loops do not allocate. Methods with a default implementation are generic
/// (support-function based); the shapes override them with closed forms.
pub trait ConvexSet: std::fmt::Debug + Send + Sync {
    /// Dimension `p` of the ambient space.
    fn dim(&self) -> usize;

    /// Support function `sigma_S(u) = max_{s in S} u^T s`, eq. (supp).
    fn support(&self, u: &[f64]) -> f64;

    /// A point `s in S` with `u^T s = sigma_S(u)` (unique for strictly convex sets, `u != 0`).
    fn support_point(&self, u: &[f64], out: &mut [f64]);

    /// Metric projection `P_S(x) = argmin_{v in S} |x - v|`, eq. (P).
    fn project(&self, x: &[f64], out: &mut [f64]);

    /// Membership with an absolute tolerance: `dist(x, S) <= tol`.
    fn contains(&self, x: &[f64], tol: f64) -> bool {
        let mut buf = vec![0.0; self.dim()];
        self.project(x, &mut buf);
        dist(x, &buf) <= tol
    }

    /// Distance `rho(x, boundary S)` from a point of `S` to the boundary (Lemma A1's `r` when
    /// `x` is the midpoint `c` of eq. (c)). Zero for points outside `S`.
    ///
    /// Generic implementation: `min_{|u|=1} (sigma_S(u) - u^T x)` by [`crate::sphere_max`].
    fn dist_to_boundary(&self, x: &[f64]) -> f64 {
        let p = self.dim();
        let lip = self.deviation_from_origin().upper + norm(x);
        let b = crate::sphere_max(p, |u| -(self.support(u) - dot(u, x)), lip, &crate::SphereMaxSettings::default());
        (-b.upper).max(0.0)
    }

    /// Projection of `v` onto the cone `N_S(q)` of *inward* normals at `q in S` (eq. (N)),
    /// as in the backlash law `z' = P_{N_Theta(q)}(y')`, eq. (zdot). `tol` decides when `q`
    /// counts as a boundary point. At interior points the cone is `{0}`.
    ///
    /// Generic implementation (exact for polyhedral sets, first order otherwise): by Moreau's
    /// decomposition the projection onto the *outward* normal cone at `q` equals
    /// `lim_{t -> 0+} (q + t w - P_S(q + t w)) / t`; it is evaluated at `t = 1e-7 (1 + |q|)`.
    fn project_normal_cone(&self, q: &[f64], v: &[f64], tol: f64, out: &mut [f64]) {
        let p = self.dim();
        if self.dist_to_boundary(q) > tol {
            out.iter_mut().for_each(|o| *o = 0.0);
            return;
        }
        let vn = norm(v);
        if vn == 0.0 {
            out.iter_mut().for_each(|o| *o = 0.0);
            return;
        }
        // outward cone applied to -v, then negated: P_N(v) = -P_{-N}(-v)
        let t = 1e-7 * (1.0 + norm(q)) / vn;
        let x: Vec<f64> = (0..p).map(|i| q[i] - t * v[i]).collect();
        let mut px = vec![0.0; p];
        self.project(&x, &mut px);
        for i in 0..p {
            out[i] = -((x[i] - px[i]) / t);
        }
    }

    /// Diameter `max_{s, s' in S} |s - s'| = max_{|u|=1} sigma_S(u) + sigma_S(-u)`.
    fn diameter(&self) -> Enclosure {
        let p = self.dim();
        let lip = 2.0 * self.deviation_from_origin().upper;
        let mut neg = vec![0.0; p];
        crate::sphere_max(
            p,
            |u| {
                neg.iter_mut().zip(u).for_each(|(n, x)| *n = -x);
                self.support(u) + self.support(&neg)
            },
            lip,
            &crate::SphereMaxSettings::default(),
        )
    }

    /// Deviation from the origin `D(S, {0}) = max_{s in S} |s| = max_{|u|=1} sigma_S(u)`
    /// (for `0 in S`), eq. (DTheta0).
    fn deviation_from_origin(&self) -> Enclosure;

    /// Strong-convexity constant `R`, eq. (R).
    fn strong_convexity(&self) -> StrongConvexity;

    /// Short human-readable description, e.g. `ball(c=[0, 0], r=0.1)`.
    fn describe(&self) -> String;
}

/// Boxed sets are sets.
impl<S: ConvexSet + ?Sized> ConvexSet for Box<S> {
    fn dim(&self) -> usize {
        (**self).dim()
    }
    fn support(&self, u: &[f64]) -> f64 {
        (**self).support(u)
    }
    fn support_point(&self, u: &[f64], out: &mut [f64]) {
        (**self).support_point(u, out)
    }
    fn project(&self, x: &[f64], out: &mut [f64]) {
        (**self).project(x, out)
    }
    fn contains(&self, x: &[f64], tol: f64) -> bool {
        (**self).contains(x, tol)
    }
    fn dist_to_boundary(&self, x: &[f64]) -> f64 {
        (**self).dist_to_boundary(x)
    }
    fn project_normal_cone(&self, q: &[f64], v: &[f64], tol: f64, out: &mut [f64]) {
        (**self).project_normal_cone(q, v, tol, out)
    }
    fn diameter(&self) -> Enclosure {
        (**self).diameter()
    }
    fn deviation_from_origin(&self) -> Enclosure {
        (**self).deviation_from_origin()
    }
    fn strong_convexity(&self) -> StrongConvexity {
        (**self).strong_convexity()
    }
    fn describe(&self) -> String {
        (**self).describe()
    }
}

/// Project a vector and return the result (allocating convenience).
pub fn project_vec<S: ConvexSet + ?Sized>(s: &S, x: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; s.dim()];
    s.project(x, &mut out);
    out
}

/// Support point as a new vector (allocating convenience).
pub fn support_point_vec<S: ConvexSet + ?Sized>(s: &S, u: &[f64]) -> Vec<f64> {
    let mut out = vec![0.0; s.dim()];
    s.support_point(u, &mut out);
    out
}
