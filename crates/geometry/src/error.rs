//! Errors raised when a set is built from bad data.
use thiserror::Error;

/// Why a convex set could not be built. Every variant carries the offending values.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum GeometryError {
    #[error("dimension mismatch in {what}: expected {expected}, got {got}")]
    DimensionMismatch { what: &'static str, expected: usize, got: usize },
    #[error("{what} must be finite, got {value}")]
    NotFinite { what: &'static str, value: f64 },
    #[error("{what} must be non-negative, got {value}")]
    Negative { what: &'static str, value: f64 },
    #[error("interval lower end {lo} exceeds upper end {hi}")]
    EmptyInterval { lo: f64, hi: f64 },
    #[error("ellipsoid matrix is not symmetric positive definite (smallest eigenvalue {min_eig:e})")]
    NotPositiveDefinite { min_eig: f64 },
    #[error("ellipsoid matrix is not symmetric (|M - M^T| = {asymmetry:e})")]
    NotSymmetric { asymmetry: f64 },
    #[error("dimension must be between 1 and {max}, got {got}")]
    UnsupportedDimension { max: usize, got: usize },
    #[error("the intersection of the given balls is empty")]
    EmptyIntersection,
    #[error("a set needs at least one {what}")]
    NoParts { what: &'static str },
    #[error("polytope is unbounded (recession direction {direction:?})")]
    UnboundedPolytope { direction: Vec<f64> },
    #[error("polytope is empty")]
    EmptyPolytope,
    #[error("polytope normal {index} is zero")]
    ZeroNormal { index: usize },
    #[error("polytope has an empty interior (zero volume): its width across half-space {index} is {width:e}, against a diameter {diameter:e}; Theta must be a full-dimensional set (use shape = \"point\" for {{0}})")]
    DegeneratePolytope { index: usize, width: f64, diameter: f64 },
}
