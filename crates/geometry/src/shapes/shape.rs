//! The closed set of parametric shapes a model file can name (`[theta] shape = "..."`).
use crate::{Ball, BallIntersection, ConvexSet, Ellipsoid, Enclosure, Interval, Polytope, StrongConvexity};

/// One of the parametric shapes; dispatches statically to the concrete set.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    Interval(Interval),
    Ball(Ball),
    Ellipsoid(Ellipsoid),
    BallIntersection(BallIntersection),
    Polytope(Polytope),
}

impl Shape {
    /// The shape's name as written in model files.
    pub fn kind(&self) -> &'static str {
        match self {
            Shape::Interval(_) => "interval",
            Shape::Ball(b) if b.radius == 0.0 => "point",
            Shape::Ball(_) => "ball",
            Shape::Ellipsoid(_) => "ellipsoid",
            Shape::BallIntersection(_) => "ball_intersection",
            Shape::Polytope(_) => "polytope",
        }
    }
    /// The singleton `{0}` in R^p (the linearised system, eq. (xieta)).
    pub fn origin(p: usize) -> Self {
        Shape::Ball(Ball { centre: vec![0.0; p], radius: 0.0 })
    }
    /// A proven upper bound of `sigma(u)` for the exact `u` handed in, the rounding of the
    /// evaluation included ([`super::upper`]): closed forms with `gamma_k` bounds for intervals,
    /// balls and ellipsoids, dual certificates for intersections of balls and polytopes.
    pub fn support_upper(&self, u: &[f64]) -> f64 {
        match self {
            Shape::Interval(i) => rounding::mul_up(u[0], if u[0] >= 0.0 { i.hi } else { i.lo }),
            Shape::Ball(b) => super::upper::ball_support_upper(&b.centre, b.radius, u),
            Shape::Ellipsoid(e) => super::upper::ellipsoid_support_upper(e.centre(), e.matrix(), u),
            Shape::BallIntersection(bi) => bi.support_upper(u),
            Shape::Polytope(pt) => pt.support_upper(u),
        }
    }
}

macro_rules! dispatch {
    ($self:ident, $s:ident => $e:expr) => {
        match $self {
            Shape::Interval($s) => $e,
            Shape::Ball($s) => $e,
            Shape::Ellipsoid($s) => $e,
            Shape::BallIntersection($s) => $e,
            Shape::Polytope($s) => $e,
        }
    };
}

impl ConvexSet for Shape {
    fn dim(&self) -> usize {
        dispatch!(self, s => s.dim())
    }
    fn support(&self, u: &[f64]) -> f64 {
        dispatch!(self, s => s.support(u))
    }
    fn support_point(&self, u: &[f64], out: &mut [f64]) {
        dispatch!(self, s => s.support_point(u, out))
    }
    #[inline]
    fn project(&self, x: &[f64], out: &mut [f64]) {
        dispatch!(self, s => s.project(x, out))
    }
    fn contains(&self, x: &[f64], tol: f64) -> bool {
        dispatch!(self, s => s.contains(x, tol))
    }
    fn dist_to_boundary(&self, x: &[f64]) -> f64 {
        dispatch!(self, s => s.dist_to_boundary(x))
    }
    fn project_normal_cone(&self, q: &[f64], v: &[f64], tol: f64, out: &mut [f64]) {
        dispatch!(self, s => s.project_normal_cone(q, v, tol, out))
    }
    fn diameter(&self) -> Enclosure {
        dispatch!(self, s => s.diameter())
    }
    fn deviation_from_origin(&self) -> Enclosure {
        dispatch!(self, s => s.deviation_from_origin())
    }
    fn strong_convexity(&self) -> StrongConvexity {
        dispatch!(self, s => s.strong_convexity())
    }
    fn describe(&self) -> String {
        dispatch!(self, s => s.describe())
    }
}
