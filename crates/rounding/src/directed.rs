//! Directed rounding in round-to-nearest arithmetic. Three families, each primitive declared
//! once; they differ on purpose (their callers' numbers depend on which one they use):
//!
//! - **One-ulp steps** of a value already computed to nearest: [`ulp_up`] (always one ulp up)
//!   and [`ulp_down_nonzero`] (one ulp down, `0` kept). The last rounding of a formula whose
//!   exact value is already on the safe side.
//! - **Operations rounded in one direction**, exact whenever the nearest result is (an
//!   error-free TwoSum or FMA residual decides whether to step): [`add_up`], [`mul_up`],
//!   [`div_up`], [`sqrt_up`], [`sqrt_down`]. The tightest directed results available without
//!   changing the rounding mode.
//! - **Relative margins with an absolute floor**: [`pad_up`], [`pad_down`] (`x +- rel |x| +-
//!   MIN_POSITIVE`) and [`scale_up`] (`x (1 + rel) + MIN_POSITIVE`). Enclosures of a value known
//!   only up to a relative error (a short sum of a few roundings), cheaper and wider than the
//!   exact-checked operations.
//!
//! Assumptions: round-to-nearest (Rust's only mode), no overflow of the results (an infinite or
//! NaN input is passed through unchanged unless stated otherwise).
use crate::two_sum::two_sum;

/// `x` moved up one ulp (`x` itself when not finite).
///
/// Guarantee: if `x = fl(y)` is the nearest float to a real `y` (one rounding, `|x - y| <=
/// ulp(x) / 2`), then `ulp_up(x) >= y`; more generally `ulp_up(x) > x` for finite `x`.
#[inline]
pub fn ulp_up(x: f64) -> f64 {
    if x.is_finite() {
        x.next_up()
    } else {
        x
    }
}

/// `x` moved down one ulp, except that `0` (and a non-finite `x`) is returned unchanged.
///
/// Guarantee: if `x = fl(y) != 0` is the nearest float to a real `y`, then `ulp_down_nonzero(x)
/// <= y`. Zero is kept for lower bounds of quantities known to be `>= 0` whose computed value
/// is a clamp `max(0, .)` (then `0 <= y` already); do not use it where `fl(y) = 0` can hide a
/// negative `y` (underflow).
#[inline]
pub fn ulp_down_nonzero(x: f64) -> f64 {
    if x.is_finite() && x != 0.0 {
        x.next_down()
    } else {
        x
    }
}

/// `true` when `x` is zero or a normal number far from under- and overflow, so that the exactness
/// tests below (which read the sign of an `fma` residual) cannot be fooled by underflow.
#[inline]
fn tame(x: f64) -> bool {
    x == 0.0 || (x.is_finite() && x.abs() >= 1e-140 && x.abs() <= 1e140)
}

/// `a + b` rounded upward: the nearest sum, moved up one ulp when [`two_sum`] shows that the
/// exact sum is larger.
///
/// Guarantee: `add_up(a, b) >= a + b` exactly, and it is the nearest sum or the next float above
/// it (finite inputs, no overflow).
pub fn add_up(a: f64, b: f64) -> f64 {
    let (s, err) = two_sum(a, b);
    if !s.is_finite() {
        return s;
    }
    if err > 0.0 {
        s.next_up()
    } else {
        s
    }
}

/// `a b` rounded upward (exactness of the nearest product checked with `fma`; a product below
/// `1e-290` in modulus, where the residual may underflow, gets an absolute `1e-290` instead).
///
/// Guarantee: `mul_up(a, b) >= a b` exactly (finite inputs, no overflow).
#[inline]
pub fn mul_up(a: f64, b: f64) -> f64 {
    let p = a * b;
    if !p.is_finite() {
        return p;
    }
    if p.abs() < 1e-290 {
        return p + 1e-290;
    }
    if a.mul_add(b, -p) > 0.0 {
        p.next_up()
    } else {
        p
    }
}

/// `a / b` rounded upward (`b > 0`): the quotient `q` is kept when `q b >= a` exactly (sign of
/// the fused residual `fma(q, b, -a)`), otherwise moved up one ulp. Outside the tame range
/// (`1e-140 <= |.| <= 1e140`) or for `b <= 0`: two ulps up, unchecked.
///
/// Guarantee: `div_up(a, b) >= a / b` exactly for `b > 0` and a finite quotient.
pub fn div_up(a: f64, b: f64) -> f64 {
    let q = a / b;
    if !(tame(a) && tame(b) && tame(q)) || !(b > 0.0) {
        return if q.is_finite() { q.next_up().next_up() } else { q };
    }
    if q.mul_add(b, -a) >= 0.0 {
        q
    } else {
        q.next_up()
    }
}

/// `sqrt(x)` rounded upward (`x >= 0`).
///
/// Guarantee: `sqrt_up(x)^2 >= x` exactly, i.e. `sqrt_up(x) >= sqrt(x)` (finite `x >= 0`).
#[inline]
pub fn sqrt_up(x: f64) -> f64 {
    let s = x.sqrt();
    if !(tame(x) && tame(s)) {
        return if s.is_finite() && s > 0.0 { s.next_up() } else { s };
    }
    if s.mul_add(s, -x) >= 0.0 {
        s
    } else {
        s.next_up()
    }
}

/// `sqrt(x)` rounded downward (`x >= 0`).
///
/// Guarantee: `0 <= sqrt_down(x) <= sqrt(x)` (finite `x >= 0`).
pub fn sqrt_down(x: f64) -> f64 {
    let s = x.sqrt();
    if !(tame(x) && tame(s)) {
        return if s.is_finite() && s > 0.0 { s.next_down().max(0.0) } else { s };
    }
    if s.mul_add(s, -x) <= 0.0 {
        s
    } else {
        s.next_down()
    }
}

/// `x + rel |x| + MIN_POSITIVE` (`x` itself when not finite): a value known up to a relative
/// error, moved up.
///
/// Guarantee (round-to-nearest, `6u <= rel <= 1/2`, `|x|` normal or zero): `pad_up(x, rel) >= y`
/// for every real `y` with `|y - x| <= (rel / 2) |x|`, and `pad_up(0, rel) > 0`. (The three
/// roundings lose at most `3u |x|` of the margin `rel |x|`.)
#[inline]
pub fn pad_up(x: f64, rel: f64) -> f64 {
    if x.is_finite() {
        x + rel * x.abs() + f64::MIN_POSITIVE
    } else {
        x
    }
}

/// `x - rel |x| - MIN_POSITIVE` (`x` itself when not finite): the mirror of [`pad_up`].
///
/// Guarantee (same assumptions): `pad_down(x, rel) <= y` for every real `y` with `|y - x| <=
/// (rel / 2) |x|`, and `pad_down(0, rel) < 0`.
#[inline]
pub fn pad_down(x: f64, rel: f64) -> f64 {
    if x.is_finite() {
        x - rel * x.abs() - f64::MIN_POSITIVE
    } else {
        x
    }
}

/// `x (1 + rel) + MIN_POSITIVE` (`x` itself when not finite): a non-negative value moved up by a
/// relative `rel`.
///
/// Guarantee (round-to-nearest, `x >= 0` finite, `8u <= rel <= 1`): `scale_up(x, rel) >= x (1 +
/// rel / 2)`, and `scale_up(0, rel) > 0`. Not an upward rounding for `x < 0`.
#[inline]
pub fn scale_up(x: f64, rel: f64) -> f64 {
    if x.is_finite() {
        x * (1.0 + rel) + f64::MIN_POSITIVE
    } else {
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exact::{Dyadic, Rng};
    use crate::UNIT_ROUNDOFF;

    const N: usize = 50_000;

    /// `ulp_up` / `ulp_down_nonzero` of one rounded sum or product enclose the exact value; the
    /// nearest value alone (the negative control) does not.
    #[test]
    fn ulp_steps_enclose_one_rounding() {
        let mut rng = Rng::new(10);
        let (mut up_fails, mut down_fails) = (false, false);
        for _ in 0..N {
            let (a, b) = (rng.float(-30, 30), rng.float(-30, 30));
            for (nearest, exact) in
                [(a + b, Dyadic::of(a).add(Dyadic::of(b))), (a * b, Dyadic::of(a).mul(Dyadic::of(b)))]
            {
                assert!(exact.le(Dyadic::of(ulp_up(nearest))), "{a} {b}");
                if nearest != 0.0 {
                    assert!(Dyadic::of(ulp_down_nonzero(nearest)).le(exact), "{a} {b}");
                }
                up_fails |= !exact.le(Dyadic::of(nearest));
                down_fails |= !Dyadic::of(nearest).le(exact);
            }
        }
        assert!(up_fails && down_fails, "negative control: the nearest value always enclosed");
        assert_eq!(ulp_up(f64::INFINITY), f64::INFINITY);
        assert_eq!(ulp_up(f64::NEG_INFINITY), f64::NEG_INFINITY);
        assert_eq!(ulp_down_nonzero(0.0), 0.0);
        assert!(ulp_up(0.0) > 0.0);
    }

    /// `add_up`, `mul_up` are upper bounds of the exact sum/product and at most one ulp above the
    /// nearest; the nearest value is below the exact one on some input.
    #[test]
    fn add_up_and_mul_up_enclose() {
        let mut rng = Rng::new(11);
        let (mut add_fails, mut mul_fails) = (false, false);
        for _ in 0..N {
            let (a, b) = (rng.float(-30, 30), rng.float(-30, 30));
            let sum = Dyadic::of(a).add(Dyadic::of(b));
            let r = add_up(a, b);
            assert!(sum.le(Dyadic::of(r)) && r <= (a + b).next_up(), "{a} + {b}");
            add_fails |= !sum.le(Dyadic::of(a + b));
            let prod = Dyadic::of(a).mul(Dyadic::of(b));
            let r = mul_up(a, b);
            assert!(prod.le(Dyadic::of(r)) && r <= (a * b).next_up(), "{a} * {b}");
            mul_fails |= !prod.le(Dyadic::of(a * b));
        }
        assert!(add_fails && mul_fails, "negative control: the nearest value always enclosed");
        // exact cases stay exact
        assert_eq!(add_up(0.5, 0.25), 0.75);
        assert_eq!(mul_up(3.0, 0.5), 1.5);
        // tiny products: the absolute floor
        assert!(mul_up(1e-200, -1e-200) > 0.0);
    }

    /// `div_up(a, b) b >= a` and `sqrt_up(x)^2 >= x >= sqrt_down(x)^2` exactly; the nearest
    /// quotient / root fails on some input.
    #[test]
    fn div_and_sqrt_enclose() {
        let mut rng = Rng::new(12);
        let (mut div_fails, mut up_fails, mut down_fails) = (false, false, false);
        for _ in 0..N {
            let (a, b) = (rng.float(-30, 30), rng.float(-30, 30).abs());
            let a_ex = Dyadic::of(a);
            assert!(a_ex.le(Dyadic::of(div_up(a, b)).mul(Dyadic::of(b))), "{a} / {b}");
            assert!(div_up(a, b) <= (a / b).next_up());
            div_fails |= !a_ex.le(Dyadic::of(a / b).mul(Dyadic::of(b)));
            let x = b;
            let x_ex = Dyadic::of(x);
            let (u, d) = (Dyadic::of(sqrt_up(x)), Dyadic::of(sqrt_down(x)));
            assert!(x_ex.le(u.mul(u)) && d.mul(d).le(x_ex), "sqrt {x}");
            let s = Dyadic::of(x.sqrt());
            up_fails |= !x_ex.le(s.mul(s));
            down_fails |= !s.mul(s).le(x_ex);
        }
        assert!(div_fails && up_fails && down_fails, "negative control: the nearest value always enclosed");
        assert_eq!((div_up(4.0, 2.0), sqrt_up(4.0), sqrt_down(4.0)), (2.0, 2.0, 2.0));
        // outside the tame range: two ulps up, still an upper bound
        assert!(div_up(1e-300, 3.0) > 1e-300 / 3.0);
        assert!(sqrt_down(1e-300) <= 1e-150 && sqrt_up(1e-300) >= 1e-150);
    }

    /// `pad_up(x, 8u) >= x + 4u |x|`, `pad_down(x, 8u) <= x - 4u |x|` exactly (the documented
    /// `rel / 2`); negative control: with `rel = u` the margin is lost on some input.
    #[test]
    fn pads_cover_half_their_margin() {
        let mut rng = Rng::new(13);
        let rel = 8.0 * UNIT_ROUNDOFF;
        let mut control_fails = false;
        for _ in 0..N {
            let x = rng.float(-60, 60);
            let (xe, half) = (Dyadic::of(x), Dyadic::of(x.abs()).shl(-51)); // 4u |x|
            assert!(xe.add(half).le(Dyadic::of(pad_up(x, rel))), "{x}");
            assert!(Dyadic::of(pad_down(x, rel)).le(xe.sub(half)), "{x}");
            control_fails |= !xe.add(half).le(Dyadic::of(pad_up(x, UNIT_ROUNDOFF)));
        }
        assert!(control_fails, "negative control: rel = u always covered 4u");
        assert!(pad_up(0.0, rel) > 0.0 && pad_down(0.0, rel) < 0.0);
        assert_eq!(pad_up(f64::INFINITY, rel), f64::INFINITY);
    }

    /// `scale_up(x, 1e-12) >= x (1 + 5e-13)` exactly for `x >= 0`; negative control: `rel = 0`.
    #[test]
    fn scale_up_covers_half_its_margin() {
        let mut rng = Rng::new(14);
        let rel = 1e-12;
        let half = Dyadic::of(0.5 * rel);
        let mut control_fails = false;
        for _ in 0..N {
            let x = rng.float_bits(30, -60, 60).abs();
            let target = Dyadic::of(x).add(Dyadic::of(x).mul(half));
            assert!(target.le(Dyadic::of(scale_up(x, rel))), "{x}");
            control_fails |= !target.le(Dyadic::of(scale_up(x, 0.0)));
        }
        assert!(control_fails, "negative control: rel = 0 always covered");
        assert!(scale_up(0.0, rel) > 0.0);
    }
}
