//! Exact step maps of the linear ODE `x' = A x + u(t)` over one step `h`:
//!
//! - `u` held constant: `x(h) = e^{hA} x(0) + h Psi(hA) u0` (eq. (Psi));
//! - `u` linearly interpolated, `u(s) = u0 + (s/h)(u1 - u0)`:
//!   `x(h) = e^{hA} x(0) + Gamma1 u0 + Gamma2 (u1 - u0) / h`, `Gamma2 = int_0^h e^{(h-s)A} s ds`.
//!
//! With `u = B w + E z` this is the linear part of eq. (xy) with `z` held over the step (the
//! catching-up scheme) and `w` held or linearly interpolated. Public and `DMatrix`-based so that
//! other crates (discovery) can simulate extended models with the same maps.
use super::expm::exp_integrals;
pub use super::hold::InputHold;
use crate::error::{check_dt, DynamicsError};
use nalgebra::{DMatrix, DVector};

/// Exact step map of `x' = A x + u` for a step `h`.
#[derive(Debug, Clone, PartialEq)]
pub struct StepMap {
    pub h: f64,
    /// `e^{hA}`.
    pub phi: DMatrix<f64>,
    /// `h Psi(hA) = int_0^h e^{sA} ds`.
    pub gamma1: DMatrix<f64>,
    /// `int_0^h e^{(h-s)A} s ds`.
    pub gamma2: DMatrix<f64>,
}

impl StepMap {
    pub fn new(A: &DMatrix<f64>, h: f64) -> Result<Self, DynamicsError> {
        check_dt(h)?;
        if A.nrows() != A.ncols() {
            return Err(DynamicsError::Dimension { what: "A (square)", expected: A.nrows(), got: A.ncols() });
        }
        let I = exp_integrals(A, h);
        Ok(Self { h, phi: I.phi, gamma1: I.gamma1, gamma2: I.gamma2 })
    }
    /// `x(h) = e^{hA} x + h Psi(hA) u0` (`u` held).
    pub fn apply_held(&self, x: &DVector<f64>, u0: &DVector<f64>) -> DVector<f64> {
        &self.phi * x + &self.gamma1 * u0
    }
    /// `x(h)` for `u` linear from `u0` to `u1` over the step.
    pub fn apply_linear(&self, x: &DVector<f64>, u0: &DVector<f64>, u1: &DVector<f64>) -> DVector<f64> {
        &self.phi * x + &self.gamma1 * u0 + &self.gamma2 * ((u1 - u0) / self.h)
    }
}

/// The step map of eq. (xy) for a system `(A, B, E)`: `x_{k+1} = Phi x_k + G1E z_k + G1B w_k
/// + G2B (w_{k+1} - w_k)` with `G2B = Gamma2 B / h` (zero for [`InputHold::Zoh`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SystemStepMap {
    pub h: f64,
    pub hold: InputHold,
    pub phi: DMatrix<f64>,
    pub g1E: DMatrix<f64>,
    pub g1B: DMatrix<f64>,
    pub g2B: DMatrix<f64>,
}

impl SystemStepMap {
    pub fn new(
        A: &DMatrix<f64>,
        B: &DMatrix<f64>,
        E: &DMatrix<f64>,
        h: f64,
        hold: InputHold,
    ) -> Result<Self, DynamicsError> {
        let s = StepMap::new(A, h)?;
        let g2B = match hold {
            InputHold::Zoh => DMatrix::zeros(A.nrows(), B.ncols()),
            InputHold::Foh => &s.gamma2 * B / h,
        };
        Ok(Self { h, hold, g1E: &s.gamma1 * E, g1B: &s.gamma1 * B, g2B, phi: s.phi })
    }
    pub fn for_system(sys: &model::System, h: f64, hold: InputHold) -> Result<Self, DynamicsError> {
        Self::new(&sys.A, &sys.B, &sys.E, h, hold)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// Affine input `u(s) = u0 + s v`: the linear-hold map is exact; compare with a fine RK4.
    #[test]
    fn linear_hold_is_exact_for_affine_inputs_and_held_is_not() {
        let A = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -2.0, -0.6]);
        let h = 0.5;
        let sm = StepMap::new(&A, h).unwrap();
        let x0 = DVector::from_vec(vec![0.3, -0.2]);
        let u0 = DVector::from_vec(vec![0.1, 1.0]);
        let u1 = DVector::from_vec(vec![-0.4, 2.0]);
        let f = |s: f64, x: &DVector<f64>| &A * x + &u0 + (&u1 - &u0) * (s / h);
        let k = 4000;
        let dt = h / k as f64;
        let mut x = x0.clone();
        for i in 0..k {
            let s = i as f64 * dt;
            let k1 = f(s, &x);
            let k2 = f(s + dt / 2.0, &(&x + &k1 * (dt / 2.0)));
            let k3 = f(s + dt / 2.0, &(&x + &k2 * (dt / 2.0)));
            let k4 = f(s + dt, &(&x + &k3 * dt));
            x += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (dt / 6.0);
        }
        assert_relative_eq!(sm.apply_linear(&x0, &u0, &u1), x, epsilon = 1e-12);
        assert!((sm.apply_held(&x0, &u0) - &x).norm() > 1e-3, "negative control: holding u is not exact");
        assert!(StepMap::new(&A, 0.0).is_err() && StepMap::new(&A, f64::NAN).is_err());
    }
}
