//! A convex compact set known only through its support function, e.g. `C Xi_inf + Theta`
//! (eqs. (Xinfsupp), (d)).
use crate::curvature::planar_strong_convexity;
use crate::linalg::{dot, norm};
use crate::{ConvexSet, Enclosure, StrongConvexity};
use std::sync::Arc;

/// Support function closure `u -> sigma_S(u)`.
pub type SupportFn = Arc<dyn Fn(&[f64]) -> f64 + Send + Sync>;

/// A set given by its support function `sigma_S` and an upper bound `D_max >= max_{s in S}|s|`
/// (the Lipschitz constant of `sigma_S`, needed for certified maxima over the sphere).
#[derive(Clone)]
pub struct SupportSet {
    dim: usize,
    sigma: SupportFn,
    radius_bound: f64,
    label: String,
}

impl std::fmt::Debug for SupportSet {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "SupportSet({}, dim={}, |s|<={})", self.label, self.dim, self.radius_bound)
    }
}

impl SupportSet {
    pub fn new(dim: usize, sigma: SupportFn, radius_bound: f64, label: impl Into<String>) -> Self {
        Self { dim, sigma, radius_bound, label: label.into() }
    }
}

/// Support point as the gradient of `sigma` at `u` (central differences, step `1e-6 |u|`;
/// accurate to ~1e-9 relative for sets with a smooth support function, i.e. strictly
/// convex sets).
pub fn support_point_by_gradient<S: ConvexSet + ?Sized>(s: &S, u: &[f64], out: &mut [f64]) {
    let p = u.len();
    let n = norm(u);
    if n == 0.0 {
        out.iter_mut().for_each(|o| *o = 0.0);
        s.support_point(&vec![1.0; p], out);
        return;
    }
    let un: Vec<f64> = u.iter().map(|x| x / n).collect();
    let h = 1e-6;
    let mut e = un.clone();
    for i in 0..p {
        e[i] = un[i] + h;
        let a = s.support(&e);
        e[i] = un[i] - h;
        let b = s.support(&e);
        e[i] = un[i];
        out[i] = (a - b) / (2.0 * h);
    }
}

/// Metric projection through the support function: for `x` outside `S`,
/// `dist(x, S) = max_{|u|=1} u^T x - sigma_S(u)` and `P_S(x)` is the support point at the
/// maximiser. `p = 1`: exact; `p = 2`: grid of 720 angles refined by golden section;
/// `p >= 3`: projected gradient ascent on the sphere from the best of `2p` axis directions.
pub fn project_via_support<S: ConvexSet + ?Sized>(s: &S, x: &[f64], out: &mut [f64]) {
    let p = s.dim();
    let phi = |u: &[f64]| dot(u, x) - s.support(u);
    if p == 1 {
        let hi = s.support(&[1.0]);
        let lo = -s.support(&[-1.0]);
        out[0] = x[0].clamp(lo, hi);
        return;
    }
    let u = if p == 2 {
        let f = |a: f64| phi(&[a.cos(), a.sin()]);
        let n = 720;
        let step = std::f64::consts::TAU / n as f64;
        let (mut ib, mut fb) = (0, f64::NEG_INFINITY);
        for i in 0..n {
            let v = f(i as f64 * step);
            if v > fb {
                fb = v;
                ib = i;
            }
        }
        let (mut a, mut b) = ((ib as f64 - 1.0) * step, (ib as f64 + 1.0) * step);
        let g = 0.5 * (5f64.sqrt() - 1.0);
        let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
        let (mut fc, mut fd) = (f(c), f(d));
        for _ in 0..80 {
            if fc > fd {
                b = d;
                d = c;
                fd = fc;
                c = b - g * (b - a);
                fc = f(c);
            } else {
                a = c;
                c = d;
                fc = fd;
                d = a + g * (b - a);
                fd = f(d);
            }
        }
        let t = 0.5 * (a + b);
        vec![t.cos(), t.sin()]
    } else {
        let mut best = vec![0.0; p];
        let mut fb = f64::NEG_INFINITY;
        for i in 0..p {
            for sgn in [1.0, -1.0] {
                let mut e = vec![0.0; p];
                e[i] = sgn;
                let v = phi(&e);
                if v > fb {
                    fb = v;
                    best = e;
                }
            }
        }
        let mut u = best;
        let mut sp = vec![0.0; p];
        let mut eta = 1.0 / (1.0 + norm(x));
        for _ in 0..2000 {
            s.support_point(&u, &mut sp);
            let grad: Vec<f64> = (0..p).map(|i| x[i] - sp[i]).collect();
            let gu = dot(&grad, &u);
            let tang: Vec<f64> = (0..p).map(|i| grad[i] - gu * u[i]).collect();
            if norm(&tang) <= 1e-13 * (1.0 + norm(x)) {
                break;
            }
            let f0 = phi(&u);
            loop {
                let mut cand: Vec<f64> = (0..p).map(|i| u[i] + eta * tang[i]).collect();
                let cn = norm(&cand);
                cand.iter_mut().for_each(|c| *c /= cn);
                if phi(&cand) >= f0 || eta < 1e-16 {
                    u = cand;
                    eta *= 1.5;
                    break;
                }
                eta *= 0.5;
            }
        }
        u
    };
    if phi(&u) <= 0.0 {
        out.copy_from_slice(x);
    } else {
        s.support_point(&u, out);
    }
}

impl ConvexSet for SupportSet {
    fn dim(&self) -> usize {
        self.dim
    }
    fn support(&self, u: &[f64]) -> f64 {
        (self.sigma)(u)
    }
    fn support_point(&self, u: &[f64], out: &mut [f64]) {
        support_point_by_gradient(self, u, out)
    }
    fn project(&self, x: &[f64], out: &mut [f64]) {
        project_via_support(self, x, out)
    }
    fn deviation_from_origin(&self) -> Enclosure {
        crate::sphere_max(self.dim, |u| self.support(u), self.radius_bound, &Default::default())
    }
    fn strong_convexity(&self) -> StrongConvexity {
        match self.dim {
            1 => StrongConvexity::Exact(0.5 * rounding::add_up(self.support(&[1.0]), self.support(&[-1.0]))),
            2 => planar_strong_convexity(|u| self.support(u)),
            _ => StrongConvexity::Unknown,
        }
    }
    fn describe(&self) -> String {
        format!("set given by its support function ({})", self.label)
    }
}
