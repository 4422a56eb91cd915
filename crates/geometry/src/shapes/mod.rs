//! The concrete sets of the paper, one module per shape.
pub mod ball;
pub mod ball_intersection;
pub mod ellipsoid;
pub mod interval;
pub mod polytope;
pub mod shape;
pub mod support_set;
pub mod upper;

pub use ball::Ball;
pub use ball_intersection::BallIntersection;
pub use ellipsoid::Ellipsoid;
pub use interval::Interval;
pub use polytope::Polytope;
pub use shape::Shape;
pub use support_set::SupportSet;

use crate::GeometryError;

pub(crate) fn check_finite(what: &'static str, xs: &[f64]) -> Result<(), GeometryError> {
    match xs.iter().find(|x| !x.is_finite()) {
        Some(&value) => Err(GeometryError::NotFinite { what, value }),
        None => Ok(()),
    }
}

pub(crate) fn fmt_vec(v: &[f64]) -> String {
    let parts: Vec<String> = v.iter().map(|x| format!("{x}")).collect();
    format!("[{}]", parts.join(", "))
}
