//! [`Ival`]: a closed real interval `[lo, hi]` whose arithmetic rounds outward, so that the
//! result of every operation contains the exact result for every choice of the operands in
//! their intervals (the inclusion property of interval arithmetic).
//!
//! Sums and products use the exact-checked directed operations of [`crate::directed`]
//! ([`add_up`], [`mul_up`], [`div_up`], [`sqrt_up`], [`sqrt_down`]; a downward result is the
//! negated upward result of the negated operands), so an operation on point intervals is at most
//! one ulp wide. Named `Ival` so that it does not collide with `geometry::Interval` (the set
//! `Theta = [lo, hi]`).
//!
//! Elementary functions ([`Ival::exp`], [`Ival::ln`]) rest on one extra assumption, stated where
//! they are defined: the platform's `f64::exp` / `f64::ln` are faithful (error below one ulp, as
//! glibc, musl and the Rust `libm` document), and the result is padded by a relative `8u`
//! (four half-ulps' worth) on each side.
use crate::directed::{add_up, div_up, mul_up, pad_down, pad_up, sqrt_down, sqrt_up};
use crate::roundoff::UNIT_ROUNDOFF;

/// A closed interval `[lo, hi]` with `lo <= hi` (or an empty/NaN interval, which every test below
/// treats as failing).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ival {
    pub lo: f64,
    pub hi: f64,
}

#[inline]
fn add_down(a: f64, b: f64) -> f64 {
    -add_up(-a, -b)
}
#[inline]
fn mul_down(a: f64, b: f64) -> f64 {
    -mul_up(-a, b)
}

// Named methods rather than operator traits: every call site reads as the rounded operation it is.
#[allow(clippy::should_implement_trait)]
impl Ival {
    /// `[lo, hi]` as given (the caller guarantees `lo <= hi`).
    #[inline]
    pub const fn new(lo: f64, hi: f64) -> Self {
        Self { lo, hi }
    }
    /// The point interval `[x, x]`.
    #[inline]
    pub const fn point(x: f64) -> Self {
        Self { lo: x, hi: x }
    }
    /// `[m - r, m + r]` rounded outward (`r >= 0`).
    pub fn mid_rad(m: f64, r: f64) -> Self {
        Self { lo: add_down(m, -r), hi: add_up(m, r) }
    }
    /// `[-r, r]` (`r >= 0`).
    pub fn sym(r: f64) -> Self {
        Self { lo: -r, hi: r }
    }
    /// Midpoint (rounded to nearest; a point inside the interval).
    pub fn mid(&self) -> f64 {
        let m = 0.5 * self.lo + 0.5 * self.hi;
        m.clamp(self.lo, self.hi)
    }
    /// Width `hi - lo` rounded upward.
    pub fn width(&self) -> f64 {
        add_up(self.hi, -self.lo)
    }
    /// An upper bound of `max(|lo|, |hi|)` (the magnitude; exact).
    pub fn mag(&self) -> f64 {
        self.lo.abs().max(self.hi.abs())
    }
    /// `min |x|` over the interval (the mignitude; exact): `0` when it contains `0`.
    pub fn mig(&self) -> f64 {
        if self.lo > 0.0 {
            self.lo
        } else if self.hi < 0.0 {
            -self.hi
        } else {
            0.0
        }
    }
    /// Whether both ends are finite and `lo <= hi` (false for NaN).
    pub fn is_valid(&self) -> bool {
        self.lo.is_finite() && self.hi.is_finite() && self.lo <= self.hi
    }
    pub fn contains(&self, x: f64) -> bool {
        self.lo <= x && x <= self.hi
    }
    /// `self` lies in the interior of `other` (strictly inside both ends).
    pub fn interior_of(&self, other: &Ival) -> bool {
        other.lo < self.lo && self.hi < other.hi
    }
    /// The intersection, `None` when empty.
    pub fn intersect(&self, o: &Ival) -> Option<Ival> {
        let (lo, hi) = (self.lo.max(o.lo), self.hi.min(o.hi));
        (lo <= hi).then_some(Ival { lo, hi })
    }
    /// The smallest interval containing both.
    pub fn hull(&self, o: &Ival) -> Ival {
        Ival { lo: self.lo.min(o.lo), hi: self.hi.max(o.hi) }
    }
    /// `x > 0` for every `x` in the interval.
    pub fn is_positive(&self) -> bool {
        self.lo > 0.0
    }
    /// `x < 0` for every `x` in the interval.
    pub fn is_negative(&self) -> bool {
        self.hi < 0.0
    }
    pub fn add(self, o: Ival) -> Ival {
        Ival { lo: add_down(self.lo, o.lo), hi: add_up(self.hi, o.hi) }
    }
    pub fn sub(self, o: Ival) -> Ival {
        Ival { lo: add_down(self.lo, -o.hi), hi: add_up(self.hi, -o.lo) }
    }
    pub fn neg(self) -> Ival {
        Ival { lo: -self.hi, hi: -self.lo }
    }
    pub fn mul(self, o: Ival) -> Ival {
        let (a, b, c, d) = (self.lo, self.hi, o.lo, o.hi);
        let lo = mul_down(a, c).min(mul_down(a, d)).min(mul_down(b, c)).min(mul_down(b, d));
        let hi = mul_up(a, c).max(mul_up(a, d)).max(mul_up(b, c)).max(mul_up(b, d));
        Ival { lo, hi }
    }
    /// `self * x` for a float `x`.
    pub fn scale(self, x: f64) -> Ival {
        self.mul(Ival::point(x))
    }
    /// `self / o`; the whole line (`[-inf, inf]`) when `o` contains `0`.
    pub fn div(self, o: Ival) -> Ival {
        if !(o.lo > 0.0 || o.hi < 0.0) {
            return Ival { lo: f64::NEG_INFINITY, hi: f64::INFINITY };
        }
        // a / b with b of one sign: divide by |b| (> 0) with div_up, flip signs as needed.
        let q_up = |a: f64, b: f64| if b > 0.0 { div_up(a, b) } else { div_up(-a, -b) };
        let q_down = |a: f64, b: f64| -q_up(-a, b);
        let (a, b, c, d) = (self.lo, self.hi, o.lo, o.hi);
        let lo = q_down(a, c).min(q_down(a, d)).min(q_down(b, c)).min(q_down(b, d));
        let hi = q_up(a, c).max(q_up(a, d)).max(q_up(b, c)).max(q_up(b, d));
        Ival { lo, hi }
    }
    /// `x^2` (tighter than `self.mul(self)` when the interval contains `0`).
    pub fn sqr(self) -> Ival {
        let (m, mm) = (self.mig(), self.mag());
        Ival { lo: mul_down(m, m).max(0.0), hi: mul_up(mm, mm) }
    }
    /// `sqrt(x)` of the non-negative part (`lo < 0` is clamped to `0`).
    pub fn sqrt(self) -> Ival {
        Ival { lo: sqrt_down(self.lo.max(0.0)), hi: sqrt_up(self.hi.max(0.0)) }
    }
    /// `e^x`. Assumes a faithful `f64::exp` (error below one ulp); each end is padded by a
    /// relative `8u`, which covers two ulps.
    pub fn exp(self) -> Ival {
        let rel = 8.0 * UNIT_ROUNDOFF;
        Ival { lo: pad_down(self.lo.exp(), rel).max(0.0), hi: pad_up(self.hi.exp(), rel) }
    }
    /// `ln x` for `x > 0` (`lo <= 0` gives `-inf` as the lower end). Assumes a faithful
    /// `f64::ln`; each end is padded by a relative `8u` plus one ulp of `1` (the absolute
    /// floor where `ln x` is near `0`).
    pub fn ln(self) -> Ival {
        let rel = 8.0 * UNIT_ROUNDOFF;
        let lo = if self.lo > 0.0 { pad_down(self.lo.ln(), rel) - f64::EPSILON } else { f64::NEG_INFINITY };
        let hi = if self.hi > 0.0 { pad_up(self.hi.ln(), rel) + f64::EPSILON } else { f64::NEG_INFINITY };
        Ival { lo, hi }
    }
    /// Relative width `(hi - lo) / min |x|` (rounded up; `inf` when the interval contains `0`).
    pub fn relative_width(&self) -> f64 {
        let m = self.mig();
        if m > 0.0 {
            div_up(self.width(), m)
        } else {
            f64::INFINITY
        }
    }
}

/// `pi` enclosed: `std::f64::consts::PI` is the nearest float below `pi`.
pub const PI: Ival = Ival { lo: std::f64::consts::PI, hi: 3.1415926535897936 };

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exact::{Dyadic, Rng};

    fn encl(iv: Ival, exact: Dyadic) -> bool {
        Dyadic::of(iv.lo).le(exact) && exact.le(Dyadic::of(iv.hi))
    }

    /// Sums, differences and products of random intervals contain the exact results at their
    /// ends (the extreme points of a sum or product of intervals are attained at ends); the
    /// nearest rounding of the same formulas (negative control) misses the exact value on some
    /// input.
    #[test]
    fn arithmetic_contains_the_exact_results() {
        let mut rng = Rng::new(21);
        let mut naive_fails = false;
        for _ in 0..20_000 {
            let (a, b, c, d) = (rng.float(-4, 4), rng.float(-4, 4), rng.float(-4, 4), rng.float(-4, 4));
            let x = Ival::new(a.min(b), a.max(b));
            let y = Ival::new(c.min(d), c.max(d));
            let (s, df, p) = (x.add(y), x.sub(y), x.mul(y));
            for u in [x.lo, x.hi] {
                for v in [y.lo, y.hi] {
                    let (ue, ve) = (Dyadic::of(u), Dyadic::of(v));
                    assert!(encl(s, ue.add(ve)), "{x:?} + {y:?}");
                    assert!(encl(df, ue.sub(ve)), "{x:?} - {y:?}");
                    assert!(encl(p, ue.mul(ve)), "{x:?} * {y:?}");
                    naive_fails |= !encl(Ival::point(u * v), ue.mul(ve));
                }
            }
        }
        assert!(naive_fails, "negative control: the nearest product always exact");
    }

    /// `x / y` contains `u / v` at the ends: `lo * v <= u <= hi * v` exactly for `v > 0`.
    #[test]
    fn division_contains_the_exact_quotients() {
        let mut rng = Rng::new(22);
        for _ in 0..20_000 {
            let (a, b) = (rng.float(-4, 4), rng.float(-4, 4));
            let (c, d) = (rng.float(-4, 4).abs(), rng.float(-4, 4).abs());
            let sign = if rng.float(-2, 2) > 0.0 { 1.0 } else { -1.0 };
            let x = Ival::new(a.min(b), a.max(b));
            let y = Ival::new(sign * c.min(d), sign * c.max(d));
            let y = if sign > 0.0 { y } else { Ival::new(y.hi, y.lo) };
            let q = x.div(y);
            for u in [x.lo, x.hi] {
                for v in [y.lo, y.hi] {
                    // u / v in [lo, hi]  <=>  lo v <= u <= hi v (v > 0), reversed for v < 0
                    let (l, h) = (Dyadic::of(q.lo).mul(Dyadic::of(v)), Dyadic::of(q.hi).mul(Dyadic::of(v)));
                    let ue = Dyadic::of(u);
                    if v > 0.0 {
                        assert!(l.le(ue) && ue.le(h), "{x:?} / {y:?}");
                    } else {
                        assert!(h.le(ue) && ue.le(l), "{x:?} / {y:?}");
                    }
                }
            }
        }
        assert!(!Ival::new(1.0, 2.0).div(Ival::new(-1.0, 1.0)).is_valid());
    }

    #[test]
    fn elementary_functions_and_predicates() {
        let e = Ival::point(1.0).exp();
        assert!(e.lo < std::f64::consts::E && std::f64::consts::E < e.hi && e.width() < 1e-14);
        let l = Ival::new(2.0, 2.0).ln();
        assert!(l.contains(std::f64::consts::LN_2) && l.width() < 1e-14);
        assert!(Ival::point(1.0).ln().contains(0.0));
        assert_eq!(PI.hi, PI.lo.next_up());
        let s = Ival::new(-2.0, 3.0).sqr();
        assert_eq!((s.lo, s.hi), (0.0, 9.0));
        assert!(Ival::new(1.0, 2.0).interior_of(&Ival::new(0.5, 2.5)));
        assert!(!Ival::new(1.0, 2.0).interior_of(&Ival::new(1.0, 2.5)));
        assert!(Ival::new(0.0, 1.0).intersect(&Ival::new(2.0, 3.0)).is_none());
        assert_eq!(Ival::new(-3.0, 1.0).mig(), 0.0);
        assert_eq!(Ival::new(-3.0, -1.0).mig(), 1.0);
        assert!(!Ival::new(f64::NAN, 1.0).is_valid());
        assert!(Ival::new(1.0, 1.0 + 1e-10).relative_width() < 2e-10);
    }
}
