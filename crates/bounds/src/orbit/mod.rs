//! The periodic orbit `eta_T = C xi_T` of the linearised system (eqs. (xiT), (etaT)) and the
//! quantities of Theorem 2 computed from it:
//! - [`eta_orbit`]: samples of `eta_T`, `eta_T'`; `osc = diam eta_T([0, T])` (eq. (mho)) from
//!   below and `||eta_T'||_inf` (eq. (zinf)) from above (closed form for sine inputs);
//! - [`piecewise`]: the same in closed form per piece for square waves and periodic CSV inputs;
//! - [`multisine`]: the same for a multisine input (a sum of the harmonics' phasor orbits);
//! - [`path_bounds`]: the path-length bounds (path), (path1) (dynamic programming over a time
//!   grid), (path2) (greedy packing) and (path1) with a step-length-dependent loss (beyond the
//!   paper).
pub mod eta_orbit;
pub mod multisine;
pub mod path_bounds;
pub mod piecewise;

pub use eta_orbit::{EtaOrbit, OrbitSettings};
pub use path_bounds::{packing_bound, partition_bound, partition_bound_local, path_bound, PackingBound};
