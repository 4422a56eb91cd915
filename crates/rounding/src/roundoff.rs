//! The unit roundoff and Higham's `gamma_k` (N. J. Higham, *Accuracy and Stability of Numerical
//! Algorithms*, 2nd ed., Sections 2.2 and 3.1).

/// Unit roundoff of `f64` with round-to-nearest, `u = 2^-53` (`f64::EPSILON / 2`).
///
/// Guarantee (Higham's standard model, eq. (2.4)): for `op` in `+ - * /` and `sqrt`, the computed
/// `fl(x op y) = (x op y)(1 + delta)` with `|delta| <= u`, provided the result neither overflows
/// nor falls in the subnormal range.
pub const UNIT_ROUNDOFF: f64 = f64::EPSILON / 2.0;

/// `gamma_k = k u / (1 - k u)` (Higham eq. (3.8)); `+inf` when `k u >= 1`.
///
/// Guarantee (Higham Lemma 3.1 and eq. (3.5)): a product of `k` factors `(1 + delta_i)^{+-1}`
/// with `|delta_i| <= u` is `1 + theta_k` with `|theta_k| <= gamma_k`; hence a sum or dot product
/// of `k` terms evaluated in any order is within `gamma_{k-1} sum |terms|` (a fortiori
/// `gamma_k sum |terms|`) of the exact value. Same assumptions as [`UNIT_ROUNDOFF`].
#[inline]
pub fn gamma(k: usize) -> f64 {
    let ku = k as f64 * UNIT_ROUNDOFF;
    if ku >= 1.0 {
        f64::INFINITY
    } else {
        ku / (1.0 - ku)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::exact::{Dyadic, Rng};

    /// `|fl(a op b) - (a op b)| <= u |a op b|` exactly, for `+` and `*` on random normal inputs;
    /// negative control: `u / 2` is too small on some input.
    #[test]
    fn unit_roundoff_bounds_one_rounding_and_half_of_it_does_not() {
        let mut rng = Rng::new(1);
        let (mut worst_ok, mut half_fails) = (true, false);
        for _ in 0..20_000 {
            let (a, b) = (rng.float(-20, 20), rng.float(-20, 20));
            for (computed, exact) in
                [(a + b, Dyadic::of(a).add(Dyadic::of(b))), (a * b, Dyadic::of(a).mul(Dyadic::of(b)))]
            {
                let err = Dyadic::of(computed).sub(exact).abs();
                // |err| <= u |exact|  <=>  |err| 2^53 <= |exact|
                worst_ok &= err.shl(53).le(exact.abs());
                half_fails |= !err.shl(54).le(exact.abs());
            }
        }
        assert!(worst_ok, "a rounding exceeded u");
        assert!(half_fails, "negative control: u/2 was never exceeded");
    }

    /// Recursive summation of `k` terms is within `gamma_{k-1} sum |x_i|` of the exact sum;
    /// negative control: `u sum |x_i|` is exceeded by `1 + u + ... + u` (each `u` lost).
    #[test]
    fn gamma_bounds_recursive_summation() {
        let mut rng = Rng::new(2);
        for k in 2..=16usize {
            for _ in 0..2_000 {
                let xs: Vec<f64> = (0..k).map(|_| rng.float(-3, 3)).collect();
                let computed = xs.iter().fold(0.0, |s, &x| s + x);
                let exact = xs.iter().fold(Dyadic::zero(), |s, &x| s.add(Dyadic::of(x)));
                let abs_sum = xs.iter().fold(Dyadic::zero(), |s, &x| s.add(Dyadic::of(x.abs())));
                let err = Dyadic::of(computed).sub(exact).abs();
                assert!(err.le(Dyadic::of(gamma(k - 1)).mul(abs_sum)), "k = {k}: {xs:?}");
            }
        }
        // negative control: a bound of one rounding (u) for a sum of k >= 3 terms fails
        let k = 8;
        let xs: Vec<f64> = std::iter::once(1.0).chain(std::iter::repeat_n(UNIT_ROUNDOFF, k - 1)).collect();
        let computed = xs.iter().fold(0.0, |s, &x| s + x);
        let exact = xs.iter().fold(Dyadic::zero(), |s, &x| s.add(Dyadic::of(x)));
        let abs_sum = exact;
        let err = Dyadic::of(computed).sub(exact).abs();
        assert!(!err.le(Dyadic::of(UNIT_ROUNDOFF).mul(abs_sum)));
        assert!(err.le(Dyadic::of(gamma(k - 1)).mul(abs_sum)));
    }

    #[test]
    fn gamma_values() {
        assert_eq!(gamma(0), 0.0);
        assert_eq!(gamma(1), UNIT_ROUNDOFF / (1.0 - UNIT_ROUNDOFF));
        assert_eq!(gamma(1usize << 53), f64::INFINITY);
        assert!(gamma(10) > 10.0 * UNIT_ROUNDOFF);
    }
}
