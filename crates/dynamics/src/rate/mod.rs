//! Measured convergence: the exponent of pairs of trajectories and the backlash motion.
//! - [`lyapunov_exponent`]: `(1/2) limsup (1/t) ln V(t)`, `V` of eq. (V_Gamma), by regression
//!   over periods with Benettin renormalisation.
//! - [`multipliers`]: the regime's dominant Floquet multiplier from the same pairs (a linear map
//!   fitted to the differences at the ends of the periods), free of `ln V`'s wobble when it is a
//!   complex pair.
//! - [`statistics`]: least-squares slope and the Student-t quantile of its interval.
//! - [`path_length`]: path length of `z` per period and the running maximum of `|z'|`.
pub mod lyapunov_exponent;
pub mod multipliers;
pub mod path_length;
pub mod statistics;
