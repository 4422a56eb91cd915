//! Intersection of finitely many closed balls `K = cap_i B_{r_i}(c_i)`.
//!
//! Every strongly convex set with constant `R` is an intersection of balls of radius `R`
//! (remark after eq. (R)); finite intersections are the computable version. `R` is the
//! largest radius among the *active* balls (those whose sphere carries part of the boundary).
use super::{check_finite, fmt_vec};
use crate::linalg::{dist, dot, for_each_subset, norm, orthogonal_complement, solve_small};
use crate::normal_cone::project_onto_cone;
use crate::{ConvexSet, Enclosure, GeometryError, StrongConvexity};

/// `cap_i B_{r_i}(c_i)`, nonempty.
#[derive(Debug, Clone, PartialEq)]
pub struct BallIntersection {
    centres: Vec<Vec<f64>>,
    radii: Vec<f64>,
    /// Which balls carry part of the boundary (computed at construction).
    active: Vec<bool>,
    /// Upper bound of `R`: the largest radius among the balls that are not *surely* inactive
    /// (a ball whose sphere might carry a sliver of the boundary within the tolerance of the
    /// activity test counts; the intersection is unchanged by any ball, so any superset of
    /// the active balls gives a valid bound).
    r_upper: f64,
}

/// The sphere `{v : |v - c_i| = r_i, i in S}` written as a sphere of centre `m` and radius
/// `rho` inside the affine subspace `m + span(dirs)`.
struct SphereIntersection {
    m: Vec<f64>,
    rho: f64,
    dirs: Vec<Vec<f64>>,
}

impl BallIntersection {
    pub fn new(centres: Vec<Vec<f64>>, radii: Vec<f64>) -> Result<Self, GeometryError> {
        if centres.is_empty() {
            return Err(GeometryError::NoParts { what: "ball" });
        }
        if radii.len() != centres.len() {
            return Err(GeometryError::DimensionMismatch {
                what: "number of radii vs centres",
                expected: centres.len(),
                got: radii.len(),
            });
        }
        let p = centres[0].len();
        if p == 0 {
            return Err(GeometryError::UnsupportedDimension { max: usize::MAX, got: 0 });
        }
        for c in &centres {
            if c.len() != p {
                return Err(GeometryError::DimensionMismatch { what: "ball centre length", expected: p, got: c.len() });
            }
            check_finite("ball centre", c)?;
        }
        check_finite("ball radius", &radii)?;
        if let Some(&r) = radii.iter().find(|&&r| r < 0.0) {
            return Err(GeometryError::Negative { what: "ball radius", value: r });
        }
        let mut s = Self { centres, radii, active: vec![], r_upper: 0.0 };
        // nonempty: the projection of the first centre must satisfy the KKT conditions
        let mut out = vec![0.0; p];
        if !s.project_exact(&s.centres[0].clone(), &mut out) {
            return Err(GeometryError::EmptyIntersection);
        }
        let k = s.radii.len();
        // farthest distance from centre i of the intersection of the other balls (None: alone)
        let far: Vec<Option<f64>> = (0..k)
            .map(|i| {
                let others: Vec<usize> = (0..k).filter(|&j| j != i).collect();
                (!others.is_empty()).then(|| s.farthest_from(&s.centres[i].clone(), &others))
            })
            .collect();
        s.active = (0..k).map(|i| far[i].is_none_or(|f| f > s.radii[i] * (1.0 + 1e-9) + 1e-14)).collect();
        s.r_upper = (0..k)
            .filter(|&i| far[i].is_none_or(|f| f.is_nan() || f > s.radii[i] * (1.0 - 1e-9) - 1e-14))
            .map(|i| s.radii[i])
            .fold(0.0, f64::max);
        Ok(s)
    }

    pub fn centres(&self) -> &[Vec<f64>] {
        &self.centres
    }
    pub fn radii(&self) -> &[f64] {
        &self.radii
    }
    /// Proven upper bound of `sigma(u)` ([`super::upper`]): the split certificate at the computed
    /// maximiser over the balls whose sphere passes through it, and the single-ball bounds
    /// `sigma <= sigma_{B_i}`; the smallest.
    pub fn support_upper(&self, u: &[f64]) -> f64 {
        let single = (0..self.radii.len())
            .map(|i| super::upper::ball_support_upper(&self.centres[i], self.radii[i], u))
            .fold(f64::INFINITY, f64::min);
        let mut s = vec![0.0; self.dim()];
        self.support_point(u, &mut s);
        let on: Vec<usize> = (0..self.radii.len())
            .filter(|&i| dist(&s, &self.centres[i]) >= self.radii[i] * (1.0 - 1e-7) - 1e-14)
            .collect();
        let cs: Vec<&[f64]> = on.iter().map(|&i| self.centres[i].as_slice()).collect();
        let rs: Vec<f64> = on.iter().map(|&i| self.radii[i]).collect();
        match super::upper::split_support_upper(&cs, &rs, &s, u) {
            Some(b) => b.min(single),
            None => single,
        }
    }
    /// Whether ball `i` carries part of the boundary.
    pub fn active(&self) -> &[bool] {
        &self.active
    }

    fn feasible(&self, v: &[f64], among: &[usize]) -> bool {
        among.iter().all(|&j| dist(v, &self.centres[j]) <= self.radii[j] * (1.0 + 1e-10) + 1e-13)
    }

    /// Intersection of the spheres in `set` (indices), if nonempty.
    fn sphere_intersection(&self, set: &[usize]) -> Option<SphereIntersection> {
        let p = self.dim();
        let c0 = &self.centres[set[0]];
        let r0 = self.radii[set[0]];
        let rows: Vec<Vec<f64>> =
            set[1..].iter().map(|&i| (0..p).map(|d| 2.0 * (self.centres[i][d] - c0[d])).collect()).collect();
        let rhs: Vec<f64> = set[1..]
            .iter()
            .map(|&i| {
                let ci = &self.centres[i];
                dot(ci, ci) - dot(c0, c0) - self.radii[i] * self.radii[i] + r0 * r0
            })
            .collect();
        let k = rows.len();
        let mut m = c0.clone();
        if k > 0 {
            // m = c0 + A^T (A A^T)^{-1} (b - A c0)
            let mut gram = vec![0.0; k * k];
            let mut res: Vec<f64> = (0..k).map(|a| rhs[a] - dot(&rows[a], c0)).collect();
            for a in 0..k {
                for b in 0..k {
                    gram[a * k + b] = dot(&rows[a], &rows[b]);
                }
            }
            if !solve_small(&mut gram, &mut res, k, 1e-12) {
                return None;
            }
            for a in 0..k {
                for d in 0..p {
                    m[d] += rows[a][d] * res[a];
                }
            }
        }
        let rho2 = r0 * r0 - dist(&m, c0).powi(2);
        if rho2 < -1e-12 * r0 * r0.max(1.0) {
            return None;
        }
        Some(SphereIntersection { m, rho: rho2.max(0.0).sqrt(), dirs: orthogonal_complement(&rows, p) })
    }

    /// Calls `f` with every critical point `m +- rho w` of `v -> g(v)^T v`-type objectives on
    /// every sphere intersection of at most `p` of the balls in `among`, where `w` is the unit
    /// projection of `dir(m)` onto the subspace. Only points feasible for `among` are passed.
    fn for_each_critical(&self, among: &[usize], dir: &dyn Fn(&[f64]) -> Vec<f64>, f: &mut dyn FnMut(&[f64])) {
        let p = self.dim();
        for size in 1..=among.len().min(p) {
            for_each_subset(among.len(), size, |sub| {
                let set: Vec<usize> = sub.iter().map(|&a| among[a]).collect();
                if let Some(si) = self.sphere_intersection(&set) {
                    let g = dir(&si.m);
                    let mut w = vec![0.0; p];
                    for b in &si.dirs {
                        let c = dot(b, &g);
                        w.iter_mut().zip(b).for_each(|(x, y)| *x += c * y);
                    }
                    let wn = norm(&w);
                    if wn > 1e-14 * norm(&g).max(1e-300) {
                        w.iter_mut().for_each(|x| *x /= wn);
                    } else if let Some(b) = si.dirs.first() {
                        w.copy_from_slice(b);
                    } else {
                        w.iter_mut().for_each(|x| *x = 0.0);
                    }
                    for sign in [1.0, -1.0] {
                        let v: Vec<f64> = (0..p).map(|d| si.m[d] + sign * si.rho * w[d]).collect();
                        if self.feasible(&v, among) {
                            f(&v);
                        }
                    }
                }
                true
            });
        }
    }

    /// `max_{v in cap_{j in among} B_j} |v - a|`, exact by enumeration of critical points
    /// (a convex function is maximised at an extreme point, which is a critical point of the
    /// distance on the intersection of its active spheres).
    fn farthest_from(&self, a: &[f64], among: &[usize]) -> f64 {
        let mut best = 0.0f64;
        let a2 = a.to_vec();
        self.for_each_critical(among, &|m| m.iter().zip(&a2).map(|(x, y)| x - y).collect(), &mut |v| {
            best = best.max(dist(v, a))
        });
        best
    }

    /// Projection by exact active-set enumeration on the concave dual
    /// `g(lambda) = min_v |v - x|^2 + sum_i lambda_i (|v - c_i|^2 - r_i^2)`, maximised by
    /// damped Newton over each candidate active set `I` (`|I| <= p`). The first `I` whose
    /// maximiser has `lambda_I >= 0` and a primal point feasible for every ball satisfies the
    /// KKT conditions, hence is the projection. Returns `false` if no candidate qualifies.
    fn project_exact(&self, x: &[f64], out: &mut [f64]) -> bool {
        let p = self.dim();
        let all: Vec<usize> = (0..self.radii.len()).collect();
        if self.feasible(x, &all) {
            out.copy_from_slice(x);
            return true;
        }
        let mut done = false;
        for size in 1..=all.len().min(p) {
            for_each_subset(all.len(), size, |set| {
                if let Some(v) = self.dual_newton(x, set) {
                    if self.feasible(&v, &all) {
                        out.copy_from_slice(&v);
                        done = true;
                        return false;
                    }
                }
                true
            });
            if done {
                return true;
            }
        }
        false
    }

    fn dual_newton(&self, x: &[f64], set: &[usize]) -> Option<Vec<f64>> {
        let p = self.dim();
        let k = set.len();
        let mut lam = vec![0.0; k];
        let primal = |lam: &[f64]| -> (Vec<f64>, f64) {
            let s = 1.0 + lam.iter().sum::<f64>();
            let v: Vec<f64> = (0..p)
                .map(|d| (x[d] + set.iter().zip(lam).map(|(&i, l)| l * self.centres[i][d]).sum::<f64>()) / s)
                .collect();
            let g = dist(&v, x).powi(2)
                + set
                    .iter()
                    .zip(lam)
                    .map(|(&i, l)| l * (dist(&v, &self.centres[i]).powi(2) - self.radii[i].powi(2)))
                    .sum::<f64>();
            (v, g)
        };
        let scale = set
            .iter()
            .map(|&i| self.radii[i] * self.radii[i] + dot(&self.centres[i], &self.centres[i]))
            .fold(dot(x, x), f64::max)
            .max(1e-300);
        let (mut v, mut g) = primal(&lam);
        for _ in 0..100 {
            let s = 1.0 + lam.iter().sum::<f64>();
            let grad: Vec<f64> =
                set.iter().map(|&i| dist(&v, &self.centres[i]).powi(2) - self.radii[i].powi(2)).collect();
            if grad.iter().all(|gr| gr.abs() <= 1e-15 * scale) {
                break;
            }
            // Newton direction: delta = (s/2) G^{-1} grad, G_ij = (v - c_i).(v - c_j)
            let mut gram = vec![0.0; k * k];
            for a in 0..k {
                for b in 0..k {
                    let (ca, cb) = (&self.centres[set[a]], &self.centres[set[b]]);
                    gram[a * k + b] = (0..p).map(|d| (v[d] - ca[d]) * (v[d] - cb[d])).sum();
                }
            }
            let mut delta = grad.clone();
            if !solve_small(&mut gram, &mut delta, k, 1e-13) {
                return None;
            }
            delta.iter_mut().for_each(|d| *d *= 0.5 * s);
            let slope: f64 = grad.iter().zip(&delta).map(|(a, b)| a * b).sum();
            let mut step = 1.0;
            let mut accepted = false;
            for _ in 0..60 {
                let trial: Vec<f64> = lam.iter().zip(&delta).map(|(l, d)| l + step * d).collect();
                if 1.0 + trial.iter().sum::<f64>() > 0.0 {
                    let (tv, tg) = primal(&trial);
                    if tg >= g + 1e-4 * step * slope || (tg - g).abs() <= 1e-15 * scale {
                        lam = trial;
                        v = tv;
                        g = tg;
                        accepted = true;
                        break;
                    }
                }
                step *= 0.5;
            }
            if !accepted {
                break;
            }
        }
        let grad_ok =
            set.iter().all(|&i| (dist(&v, &self.centres[i]).powi(2) - self.radii[i].powi(2)).abs() <= 1e-10 * scale);
        let lam_ok = lam.iter().all(|&l| l >= -1e-12);
        (grad_ok && lam_ok).then_some(v)
    }
}

impl ConvexSet for BallIntersection {
    fn dim(&self) -> usize {
        self.centres[0].len()
    }
    fn support(&self, u: &[f64]) -> f64 {
        let mut s = vec![0.0; self.dim()];
        self.support_point(u, &mut s);
        dot(u, &s)
    }
    /// Exact: the maximiser of `u^T v` is a critical point on the intersection of its active
    /// spheres (at most `p` of them by Caratheodory), so enumeration finds it.
    fn support_point(&self, u: &[f64], out: &mut [f64]) {
        let all: Vec<usize> = (0..self.radii.len()).collect();
        let mut best = f64::NEG_INFINITY;
        let uu = u.to_vec();
        self.for_each_critical(&all, &|_| uu.clone(), &mut |v| {
            let val = dot(u, v);
            if val > best {
                best = val;
                out.copy_from_slice(v);
            }
        });
    }
    fn project(&self, x: &[f64], out: &mut [f64]) {
        if !self.project_exact(x, out) {
            // numerical trouble only (degenerate configurations): Dykstra's algorithm
            let p = self.dim();
            let k = self.radii.len();
            let mut v = x.to_vec();
            let mut incr = vec![vec![0.0; p]; k];
            for _ in 0..20_000 {
                for i in 0..k {
                    let y: Vec<f64> = (0..p).map(|d| v[d] + incr[i][d]).collect();
                    let d = dist(&y, &self.centres[i]);
                    let r = self.radii[i];
                    let pr: Vec<f64> = if d <= r {
                        y.clone()
                    } else {
                        (0..p).map(|j| self.centres[i][j] + r / d * (y[j] - self.centres[i][j])).collect()
                    };
                    incr[i] = (0..p).map(|j| y[j] - pr[j]).collect();
                    v = pr;
                }
            }
            out.copy_from_slice(&v);
        }
    }
    fn contains(&self, x: &[f64], tol: f64) -> bool {
        if self.centres.iter().zip(&self.radii).all(|(c, r)| dist(x, c) <= *r) {
            return true;
        }
        let mut p = vec![0.0; self.dim()];
        self.project(x, &mut p);
        dist(x, &p) <= tol
    }
    /// Exact: `dist(x, boundary K) = min_i (r_i - |x - c_i|)` for `x in K`.
    fn dist_to_boundary(&self, x: &[f64]) -> f64 {
        self.centres.iter().zip(&self.radii).map(|(c, r)| r - dist(x, c)).fold(f64::INFINITY, f64::min).max(0.0)
    }
    fn project_normal_cone(&self, q: &[f64], v: &[f64], tol: f64, out: &mut [f64]) {
        let gens: Vec<Vec<f64>> = self
            .centres
            .iter()
            .zip(&self.radii)
            .filter(|(c, r)| dist(q, c) >= *r - tol)
            .map(|(c, _)| {
                let d = dist(q, c).max(f64::MIN_POSITIVE);
                c.iter().zip(q).map(|(ci, qi)| (ci - qi) / d).collect()
            })
            .collect();
        project_onto_cone(&gens, v, out);
    }
    fn deviation_from_origin(&self) -> Enclosure {
        let all: Vec<usize> = (0..self.radii.len()).collect();
        Enclosure::exact(self.farthest_from(&vec![0.0; self.dim()], &all))
    }
    /// `R` = largest radius among the active balls: on an active sphere the boundary has
    /// curvature `1/r_i`, so `R >= r_i`; and `K` is an intersection of balls of radius
    /// `<= max active r_i`. Returned from above: balls within the activity test's tolerance of
    /// being active count as active (`r_upper`).
    fn strong_convexity(&self) -> StrongConvexity {
        StrongConvexity::Exact(self.r_upper)
    }
    fn describe(&self) -> String {
        let parts: Vec<String> =
            self.centres.iter().zip(&self.radii).map(|(c, r)| format!("B({}, {r})", fmt_vec(c))).collect();
        format!("intersection of balls {}", parts.join(" & "))
    }
}
