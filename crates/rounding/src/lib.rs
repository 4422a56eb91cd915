//! `rounding`: the soundness primitives of the workspace, in one audited place at the bottom of
//! the house (every crate that proves a bound in floating point, `geometry`, `lmi`, `dynamics`
//! and `bounds`, uses these and declares none of its own).
//!
//! Standing assumptions of every guarantee below: IEEE 754 binary64 arithmetic with
//! round-to-nearest-even (Rust's only mode), no FMA contraction (Rust never contracts `a * b + c`),
//! and no overflow; where underflow matters the primitive says so and guards against it.
//!
//! Module map (one concept per module, each declared once):
//! - [`roundoff`]: the unit roundoff [`UNIT_ROUNDOFF`] `u = 2^-53` and Higham's [`gamma`]`(k)`;
//! - [`two_sum`]: Knuth's error-free transformation [`two_sum()`] `a + b = s + e`;
//! - [`directed`]: directed rounding. Three families, kept apart because their call sites rely
//!   on their exact numbers:
//!   - one-ulp steps of an already computed value: [`ulp_up`], [`ulp_down_nonzero`];
//!   - operations rounded upward or downward, exact when the nearest result is (checked with
//!     TwoSum or an FMA residual): [`add_up`], [`mul_up`], [`div_up`], [`sqrt_up`], [`sqrt_down`];
//!   - relative margins with an absolute floor: [`pad_up`], [`pad_down`], [`scale_up`];
//! - [`enclosure`]: [`Enclosure`], a real number known to lie in `[lower, upper]`;
//! - [`interval`]: [`Ival`], interval arithmetic rounded outward (verified numerics).
//!
//! Every primitive has a test that checks its enclosure exactly (dyadic integer arithmetic on
//! many seeded random inputs, `exact` in the tests) and a negative control: the naive version
//! (the nearest result, a too-small margin, a wrong error term) is shown to violate the
//! enclosure on some input, so the check can fail.

// `!(x > 0.0)` is deliberate: it is also true for NaN, which must never pass a check.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::nonminimal_bool)]

pub mod directed;
pub mod enclosure;
pub mod interval;
pub mod roundoff;
pub mod two_sum;

#[cfg(test)]
pub(crate) mod exact;

pub use directed::{add_up, div_up, mul_up, pad_down, pad_up, scale_up, sqrt_down, sqrt_up, ulp_down_nonzero, ulp_up};
pub use enclosure::Enclosure;
pub use interval::Ival;
pub use roundoff::{gamma, UNIT_ROUNDOFF};
pub use two_sum::two_sum;
