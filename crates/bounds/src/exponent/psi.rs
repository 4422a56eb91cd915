//! `psi(gamma) = sqrt(beta + (alpha - lambda + gamma)^2 / 4) - (alpha + lambda + gamma)/2`,
//! eq. (phipsi): nonincreasing and convex in `gamma`, `psi(0)` of eq. (psilim), limit `-lambda`.
//! `psi` is nondecreasing in `beta` and nonincreasing in `alpha` and `lambda`, so it is evaluated
//! at `beta` from above and `alpha`, `lambda` from below.
//!
//! `theta = psi(0) - (gamma_1 / gamma_inf)(psi(0) - psi(gamma_inf))`, eq. (theta), is written as
//! the convex combination `(1 - kappa) psi(0) + kappa psi(gamma_inf)`, `kappa = gamma_1 /
//! gamma_inf in [0, 1]`, so upward-rounded `psi` values give an upward-rounded `theta`.

/// The function `psi` of eq. (phipsi) for fixed `(alpha, lambda, beta)`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Psi {
    pub alpha: f64,
    pub lambda: f64,
    pub beta: f64,
}

impl Psi {
    /// `psi(gamma)`, rounded upward by a few ulps of the terms. Cancellation-free for large
    /// `gamma`: `sqrt(beta + a^2) - a - lambda = beta / (sqrt(beta + a^2) + a) - lambda`, `a > 0`.
    pub fn eval(&self, gamma: f64) -> f64 {
        let a = 0.5 * (self.alpha - self.lambda + gamma);
        let s = (self.beta + a * a).sqrt();
        if a > 0.0 {
            let t = self.beta / (s + a);
            t - self.lambda + 8.0 * f64::EPSILON * (t.abs() + self.lambda.abs())
        } else {
            s - a - self.lambda + 8.0 * f64::EPSILON * (s + a.abs() + self.lambda.abs())
        }
    }

    /// `psi(0)`, eq. (psilim).
    pub fn at_zero(&self) -> f64 {
        self.eval(0.0)
    }

    /// `lim_{gamma -> inf} psi(gamma) = -lambda`, eq. (psilim).
    pub fn limit(&self) -> f64 {
        -self.lambda
    }

    /// The chord (psiup) over `[0, gamma_inf]` at `u`: `psi(0) - (u / gamma_inf)(psi(0) - psi(gamma_inf))`.
    pub fn chord(&self, gamma_inf: f64, u: f64) -> f64 {
        if gamma_inf <= 0.0 {
            return self.at_zero();
        }
        let k = (u / gamma_inf).clamp(0.0, 1.0);
        (1.0 - k) * self.at_zero() + k * self.eval(gamma_inf)
    }

    /// `theta` of eq. (theta): the chord at `gamma_1`.
    pub fn theta(&self, gamma_1: f64, gamma_inf: f64) -> f64 {
        self.chord(gamma_inf, gamma_1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_form_limits_and_monotonicity() {
        let p = Psi { alpha: 0.0, lambda: 0.15, beta: 0.02 };
        let naive = |g: f64| (p.beta + 0.25 * (p.alpha - p.lambda + g).powi(2)).sqrt() - 0.5 * (p.alpha + p.lambda + g);
        for g in [0.0, 0.1, 1.0, 10.0] {
            assert!((p.eval(g) - naive(g)).abs() < 1e-13, "{g}");
            assert!(p.eval(g) >= naive(g));
        }
        assert!((p.eval(1e9) - p.limit()).abs() < 1e-9);
        let mut prev = f64::INFINITY;
        for k in 0..100 {
            let v = p.eval(k as f64 * 0.05);
            assert!(v <= prev + 1e-15);
            prev = v;
        }
        // chord lies above psi on [0, gamma_inf] (convexity) and theta interpolates.
        let gi = 2.0;
        for k in 0..=20 {
            let u = gi * k as f64 / 20.0;
            assert!(p.chord(gi, u) >= p.eval(u) - 1e-14);
        }
        assert_eq!(p.theta(0.0, gi), p.at_zero());
        // Negative control: a point below the chord is detected as such.
        assert!(p.eval(1.0) < p.chord(gi, 1.0) - 1e-6);
    }
}
