//! Proptest strategies (feature `proptest-support`), shared by the property tests of every
//! crate: random convex compacts `Theta` containing the origin (eq. (0inZ)), with bounded
//! conditioning, and random points with inward normals on them (eq. (N)).
//!
//! Strategies generate *parameters* ([`SetParams`], [`PointParams`]) rather than sets, so that
//! proptest shrinks towards simple shapes (axis-aligned, centred, unit scale); the set is
//! built by [`SetParams::build`]. Every generated set contains `0` with a margin, so it can
//! be the backlash set of a model file.
use crate::{Ball, BallIntersection, ConvexSet, Ellipsoid, Interval, Polytope, Shape};
use nalgebra::DMatrix;
use proptest::prelude::*;

/// Largest dimension the strategies generate.
pub const MAX_P: usize = 4;

/// The parametric shapes of `crate::Shape`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SetKind {
    Interval,
    Ball,
    Ellipsoid,
    BallIntersection,
    Polytope,
}

impl SetKind {
    /// Strongly convex kinds (finite `R`, eq. (R)).
    pub const STRONGLY_CONVEX: [SetKind; 4] =
        [SetKind::Interval, SetKind::Ball, SetKind::Ellipsoid, SetKind::BallIntersection];
    /// All kinds (polytopes have `R = infinity`).
    pub const ALL: [SetKind; 5] =
        [SetKind::Interval, SetKind::Ball, SetKind::Ellipsoid, SetKind::BallIntersection, SetKind::Polytope];
}

/// What kind of sets a strategy draws.
#[derive(Debug, Clone)]
pub struct SetStrategyConfig {
    /// Kinds to draw from (uniformly). Default: [`SetKind::ALL`].
    pub kinds: Vec<SetKind>,
    /// Largest dimension `p` (at most [`MAX_P`]). Default `4`.
    pub max_dim: usize,
    /// Largest ratio of longest to shortest semi-axis (ellipsoids) or of largest to
    /// smallest radius (ball intersections). Default `20`.
    pub max_cond: f64,
    /// Overall size `10^s` with `s` uniform in `[-scale_exp, scale_exp]`. Default `2`.
    pub scale_exp: f64,
}

impl Default for SetStrategyConfig {
    fn default() -> Self {
        Self { kinds: SetKind::ALL.to_vec(), max_dim: MAX_P, max_cond: 20.0, scale_exp: 2.0 }
    }
}

impl SetStrategyConfig {
    /// Only strongly convex kinds.
    pub fn strongly_convex() -> Self {
        Self { kinds: SetKind::STRONGLY_CONVEX.to_vec(), ..Self::default() }
    }
    /// A single kind.
    pub fn only(kind: SetKind) -> Self {
        Self { kinds: vec![kind], ..Self::default() }
    }
}

/// Parameters of a random set; [`SetParams::build`] makes the set.
#[derive(Debug, Clone)]
pub struct SetParams {
    pub kind: SetKind,
    /// Dimension (1 for intervals).
    pub p: usize,
    /// Overall size `10^scale_exp`.
    pub scale_exp: f64,
    /// In `[0, 1]`: semi-axes / radii are `scale * cond^shape_i`.
    pub shape: [f64; MAX_P],
    /// Entries of a matrix whose QR factor rotates ellipsoids (`0` entries: axis-aligned).
    pub rot: [f64; MAX_P * MAX_P],
    /// In `[-1, 1]^p`: centre offset (keeps the origin inside with a margin).
    pub centre: [f64; MAX_P],
    /// Ball centres (ball intersections) or half-space normals (polytopes), in `[-1, 1]^p`.
    pub extra: [[f64; MAX_P]; MAX_P],
    /// Number of balls (2..=4) or extra half-spaces (0..=4).
    pub count: usize,
    /// Conditioning bound used by `build`.
    pub max_cond: f64,
}

fn unit(v: &[f64]) -> Vec<f64> {
    let n = crate::linalg::norm(v);
    if n < 1e-9 {
        let mut e = vec![0.0; v.len()];
        e[0] = 1.0;
        e
    } else {
        v.iter().map(|x| x / n).collect()
    }
}

impl SetParams {
    pub fn scale(&self) -> f64 {
        10f64.powf(self.scale_exp)
    }

    /// Builds the set. Never fails for parameters drawn by [`set_params`].
    pub fn build(&self) -> Shape {
        let s = self.scale();
        let p = self.p;
        let cond = self.max_cond.max(1.0);
        match self.kind {
            SetKind::Interval => {
                // [-s c^a0, s c^a1 / cond]-ish: both ends away from 0
                let lo = -s * (0.05 + 0.95 * self.shape[0]);
                let hi = s * (0.05 + 0.95 * self.shape[1]);
                Shape::Interval(Interval::new(lo, hi).expect("lo < 0 < hi"))
            }
            SetKind::Ball => {
                let r = s;
                let c: Vec<f64> = (0..p).map(|i| 0.9 * r * self.centre[i] / (p as f64).sqrt()).collect();
                Shape::Ball(Ball::new(c, r).expect("finite radius"))
            }
            SetKind::Ellipsoid => {
                let axes: Vec<f64> = (0..p).map(|i| s * cond.powf(self.shape[i])).collect();
                let q = self.rotation();
                let d = DMatrix::from_diagonal(&nalgebra::DVector::from_iterator(p, axes.iter().map(|a| a * a)));
                let m = &q * d * q.transpose();
                let m = (&m + m.transpose()) * 0.5;
                // centre c = Q diag(a) w with |w| <= 0.9: 0 lies inside with margin
                let w: Vec<f64> = (0..p).map(|i| 0.9 * self.centre[i] / (p as f64).sqrt()).collect();
                let c: Vec<f64> = (0..p).map(|i| (0..p).map(|k| q[(i, k)] * axes[k] * w[k]).sum()).collect();
                Shape::Ellipsoid(Ellipsoid::new(c, &m).expect("SPD by construction"))
            }
            SetKind::BallIntersection => {
                let k = self.count.clamp(2, MAX_P);
                let radii: Vec<f64> = (0..k).map(|i| s * cond.powf(self.shape[i])).collect();
                // |c_i| <= 0.6 r_i: the origin is inside every ball with margin 0.4 r_i
                let centres: Vec<Vec<f64>> = (0..k)
                    .map(|i| (0..p).map(|j| 0.6 * radii[i] * self.extra[i][j] / (p as f64).sqrt()).collect())
                    .collect();
                Shape::BallIntersection(BallIntersection::new(centres, radii).expect("contains the origin"))
            }
            SetKind::Polytope => {
                // a box [-s_i, s_i] (bounded) cut by `count` half-spaces a^T x <= b, b > 0
                let mut normals = Vec::new();
                let mut offsets = Vec::new();
                for i in 0..p {
                    let si = s * cond.powf(self.shape[i]);
                    let mut e = vec![0.0; p];
                    e[i] = 1.0;
                    normals.push(e.clone());
                    offsets.push(si);
                    e[i] = -1.0;
                    normals.push(e);
                    offsets.push(si * (0.3 + 0.7 * (1.0 - self.shape[i])));
                }
                for j in 0..self.count.min(MAX_P) {
                    let a = unit(&self.extra[j][..p]);
                    normals.push(a);
                    offsets.push(s * (0.3 + 0.7 * (0.5 + 0.5 * self.centre[j % p])));
                }
                Shape::Polytope(Polytope::new(normals, offsets).expect("bounded, contains the origin"))
            }
        }
    }

    /// Orthogonal factor of the QR decomposition of `I + rot` (identity when `rot = 0`).
    fn rotation(&self) -> DMatrix<f64> {
        let p = self.p;
        let g = DMatrix::from_fn(p, p, |i, j| self.rot[i * MAX_P + j] * 2.0 + if i == j { 1.0 } else { 0.0 });
        let qr = g.qr();
        let q = qr.q();
        if q.iter().all(|x| x.is_finite()) {
            q
        } else {
            DMatrix::identity(p, p)
        }
    }
}

/// Strategy for [`SetParams`].
pub fn set_params(cfg: &SetStrategyConfig) -> BoxedStrategy<SetParams> {
    let kinds = cfg.kinds.clone();
    let max_dim = cfg.max_dim.clamp(1, MAX_P);
    let max_cond = cfg.max_cond;
    let se = cfg.scale_exp.abs();
    (
        proptest::sample::select(kinds),
        1..=max_dim,
        -se..=se,
        proptest::array::uniform4(0.0..=1.0f64),
        proptest::array::uniform16(-1.0..=1.0f64),
        proptest::array::uniform4(-1.0..=1.0f64),
        proptest::array::uniform4(proptest::array::uniform4(-1.0..=1.0f64)),
        0..=MAX_P,
    )
        .prop_map(move |(kind, p, scale_exp, shape, rot, centre, extra, count)| {
            let p = if kind == SetKind::Interval { 1 } else { p };
            SetParams { kind, p, scale_exp, shape, rot, centre, extra, count, max_cond }
        })
        .boxed()
}

/// A point of `S` with an inward normal `u in N_S(x)` (eq. (N)).
#[derive(Debug, Clone)]
pub struct PointParams {
    /// Direction `d` (first `p` entries used).
    pub dir: [f64; MAX_P],
    /// Interior point (normal 0) instead of a boundary point.
    pub interior: bool,
    /// Interior points: `x = depth * s(d)` with `s(d)` the support point; depth in `[0, 1)`.
    pub depth: f64,
    /// Normal magnitude `10^mag_exp`.
    pub mag_exp: f64,
}

/// Strategy for [`PointParams`]; 20% interior points.
pub fn point_params() -> BoxedStrategy<PointParams> {
    (proptest::array::uniform4(-1.0..=1.0f64), proptest::bool::weighted(0.2), 0.0..0.999f64, -2.0..=2.0f64)
        .prop_map(|(dir, interior, depth, mag_exp)| PointParams { dir, interior, depth, mag_exp })
        .boxed()
}

impl PointParams {
    /// `(x, u)`: a boundary point `x = s_S(d)` (the support point in direction `d`) with the
    /// inward normal `u = -t d/|d|` (valid for every convex set: `x` maximises `d^T s`), or an
    /// interior point `x = depth * s_S(d) + (1 - depth) * 0` with `u = 0`.
    pub fn build<S: ConvexSet + ?Sized>(&self, set: &S) -> (Vec<f64>, Vec<f64>) {
        let p = set.dim();
        let d = unit(&self.dir[..p]);
        let mut x = vec![0.0; p];
        set.support_point(&d, &mut x);
        if self.interior {
            x.iter_mut().for_each(|v| *v *= self.depth);
            (x, vec![0.0; p])
        } else {
            let t = 10f64.powf(self.mag_exp);
            (x, d.iter().map(|v| -t * v).collect())
        }
    }
}

/// A random set and two points with inward normals: the data of Lemma A1/A2.
#[derive(Debug, Clone)]
pub struct PairCase {
    pub set: SetParams,
    pub a: PointParams,
    pub b: PointParams,
}

/// Built form of [`PairCase`].
#[derive(Debug, Clone)]
pub struct Pair {
    pub set: Shape,
    pub x: Vec<f64>,
    pub u: Vec<f64>,
    pub y: Vec<f64>,
    pub v: Vec<f64>,
}

impl PairCase {
    pub fn build(&self) -> Pair {
        let set = self.set.build();
        let (x, u) = self.a.build(&set);
        let (y, v) = self.b.build(&set);
        Pair { set, x, u, y, v }
    }
}

/// Strategy for [`PairCase`].
pub fn pair_case(cfg: &SetStrategyConfig) -> BoxedStrategy<PairCase> {
    (set_params(cfg), point_params(), point_params()).prop_map(|(set, a, b)| PairCase { set, a, b }).boxed()
}

/// Arbitrary vectors of `R^p` at the scale of the set: `10^e * [-1, 1]^p`.
pub fn vector_params() -> BoxedStrategy<([f64; MAX_P], f64)> {
    (proptest::array::uniform4(-1.0..=1.0f64), -1.0..=1.0f64).boxed()
}
