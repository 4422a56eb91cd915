//! Knuth's TwoSum (D. E. Knuth, *TAOCP* vol. 2, Section 4.2.2, Theorem B; Higham Section 4.3).

/// `(s, e)` with `s = fl(a + b)` and `a + b = s + e` exactly.
///
/// Guarantee: exact for all finite `a`, `b` whose sum does not overflow (six operations, no
/// branch, no ordering of `|a|`, `|b|` needed; underflow cannot spoil it since sums of floats
/// are exact in the subnormal range). With `s` infinite, `e` is NaN.
#[inline]
pub fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exact::{Dyadic, Rng};

    /// Fast2Sum, which is exact only when `|a| >= |b|`: the negative control.
    fn fast_two_sum_unordered(a: f64, b: f64) -> (f64, f64) {
        let s = a + b;
        (s, b - (s - a))
    }

    #[test]
    fn two_sum_is_exact_and_fast_two_sum_without_ordering_is_not() {
        let mut rng = Rng::new(3);
        let mut control_fails = false;
        for _ in 0..50_000 {
            let (a, b) = (rng.float(-30, 30), rng.float(-30, 30));
            let exact = Dyadic::of(a).add(Dyadic::of(b));
            let (s, e) = two_sum(a, b);
            assert_eq!(s, a + b);
            assert!(Dyadic::of(s).add(Dyadic::of(e)).eq(exact), "{a} + {b}");
            let (s, e) = fast_two_sum_unordered(a, b);
            control_fails |= !Dyadic::of(s).add(Dyadic::of(e)).eq(exact);
        }
        assert!(control_fails, "negative control: unordered Fast2Sum was always exact");
    }
}
