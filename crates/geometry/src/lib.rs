//! Convex compact sets in R^p as they enter the paper
//! "Convergence to periodic regimes in nonlinear feedback systems with a strongly convex
//! backlash" (`../shared/paper/strongly-convex-backlash.tex`).
//!
//! Every set implements [`ConvexSet`]: support function (eq. (supp)), a support point,
//! metric projection `P_S` (eq. (P)), membership, the distance from an interior point to the
//! boundary (Lemma A1's `r`, eq. (r)), the projection onto the cone of *inward* normals
//! `N_S(q)` (eqs. (N), (zdot)), the diameter, the deviation `D(S,{0})` (eq. (DTheta0)) and the
//! strong-convexity constant `R` (eq. (R)).
//!
//! Module map (one module per mathematical object):
//! - [`shapes`]: [`Interval`], [`Ball`], [`Ellipsoid`], [`BallIntersection`], [`Polytope`],
//!   [`SupportSet`] (a set known only through its support function), and the closed enum
//!   [`Shape`] used by model files.
//! - [`ops`]: linear images `M S` ([`LinearImage`]) and Minkowski sums `S1 + S2`
//!   ([`MinkowskiSum`]) through support functions.
//! - [`normal_cone`]: projection onto finitely generated cones (non-smooth boundary points).
//! - [`sphere_max`]: certified maximisation of a Lipschitz function over the unit sphere.
//! - [`sublinear_max`]: sharper certified maxima over the unit sphere of sublinear functions
//!   (sums of support functions, eqs. (d), (zinf)) by conic combination on arcs and triangles.
//! - [`curvature`]: numerical `R` of planar sets from the support function.
//! - `strategies` (feature `proptest-support`): seeded proptest strategies for random sets
//!   containing 0 and points with inward normals, shared by the tests of every crate.
//!
//! All points are plain `&[f64]` slices so that hot loops (the catching-up integrator)
//! neither allocate nor convert.
#![allow(non_snake_case)]

pub mod convex_set;
pub mod curvature;
pub mod error;
pub mod linalg;
pub mod normal_cone;
pub mod ops;
pub mod shapes;
pub mod sphere_max;
#[cfg(feature = "proptest-support")]
pub mod strategies;
pub mod strong_convexity;
pub mod sublinear_max;

pub use convex_set::ConvexSet;
pub use error::GeometryError;
pub use ops::{LinearImage, MinkowskiSum};
/// The two-sided enclosure of a real quantity (declared in the `rounding` crate).
pub use rounding::Enclosure;
pub use shapes::{Ball, BallIntersection, Ellipsoid, Interval, Polytope, Shape, SupportSet};
pub use sphere_max::{sphere_max, SphereMaxSettings};
pub use strong_convexity::StrongConvexity;
pub use sublinear_max::sublinear_sphere_max;
