//! Matrix exponential `e^{hA}` and the integrals `t Psi(tA) = int_0^t e^{sA} ds` (eq. (Psi))
//! and `int_0^t e^{(t-s)A} s ds`, all from one augmented matrix exponential (Van Loan):
//!
//! ```text
//! expm(t [[A, I, 0], [0, 0, I], [0, 0, 0]]) = [[e^{tA}, Gamma1(t), Gamma2(t)], [0, I, tI], [0, 0, I]]
//! Gamma1(t) = int_0^t e^{sA} ds = t Psi(tA),   Gamma2(t) = int_0^t e^{(t-s)A} s ds.
//! ```
//! Everything takes and returns `DMatrix<f64>` so that other crates (discovery) can reuse it.
use nalgebra::DMatrix;

/// `e^{M}` (scaling and squaring with Pade approximants, nalgebra's `exp`).
pub fn expm(M: &DMatrix<f64>) -> DMatrix<f64> {
    M.clone().exp()
}

/// The three blocks of the augmented exponential for the step `t`.
#[derive(Debug, Clone, PartialEq)]
pub struct ExpIntegrals {
    /// `e^{tA}`.
    pub phi: DMatrix<f64>,
    /// `Gamma1 = int_0^t e^{sA} ds = t Psi(tA)`, eq. (Psi).
    pub gamma1: DMatrix<f64>,
    /// `Gamma2 = int_0^t e^{(t-s)A} s ds` (response to a unit ramp input).
    pub gamma2: DMatrix<f64>,
}

/// `e^{tA}`, `t Psi(tA)` and `int_0^t e^{(t-s)A} s ds` from one `3n x 3n` exponential.
pub fn exp_integrals(A: &DMatrix<f64>, t: f64) -> ExpIntegrals {
    let n = A.nrows();
    let mut M = DMatrix::<f64>::zeros(3 * n, 3 * n);
    M.view_mut((0, 0), (n, n)).copy_from(&(A * t));
    // exp(t [[A, I, 0],[0, 0, I],[0,0,0]]) = exp([[tA, tI, 0],[0, 0, tI],[0,0,0]]).
    for i in 0..n {
        M[(i, n + i)] = t;
        M[(n + i, 2 * n + i)] = t;
    }
    let X = expm(&M);
    ExpIntegrals {
        phi: X.view((0, 0), (n, n)).into_owned(),
        gamma1: X.view((0, n), (n, n)).into_owned(),
        gamma2: X.view((0, 2 * n), (n, n)).into_owned(),
    }
}

/// `t Psi(tA) = int_0^t e^{sA} ds`, eq. (Psi): top-right block of `expm(t [[A, I], [0, 0]])`.
pub fn t_psi(A: &DMatrix<f64>, t: f64) -> DMatrix<f64> {
    let n = A.nrows();
    let mut M = DMatrix::<f64>::zeros(2 * n, 2 * n);
    M.view_mut((0, 0), (n, n)).copy_from(&(A * t));
    for i in 0..n {
        M[(i, n + i)] = t;
    }
    expm(&M).view((0, n), (n, n)).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn scalar_case_matches_the_closed_forms() {
        let a = -0.7;
        let t = 1.3;
        let A = DMatrix::from_element(1, 1, a);
        let I = exp_integrals(&A, t);
        assert_relative_eq!(I.phi[(0, 0)], (a * t).exp(), max_relative = 1e-14);
        assert_relative_eq!(I.gamma1[(0, 0)], ((a * t).exp() - 1.0) / a, max_relative = 1e-14);
        // int_0^t e^{a(t-s)} s ds = (e^{at} - 1 - a t) / a^2
        assert_relative_eq!(I.gamma2[(0, 0)], ((a * t).exp() - 1.0 - a * t) / (a * a), max_relative = 1e-13);
        assert_relative_eq!(t_psi(&A, t)[(0, 0)], I.gamma1[(0, 0)], max_relative = 1e-14);
    }

    #[test]
    fn singular_matrix_gives_t_psi_equal_t_times_identity_and_quadrature_agrees() {
        // A nilpotent: e^{sA} = I + sA, int_0^t = tI + t^2/2 A.
        let A = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 0.0, 0.0]);
        let G = t_psi(&A, 2.0);
        assert_relative_eq!(G, DMatrix::from_row_slice(2, 2, &[2.0, 2.0, 0.0, 2.0]), epsilon = 1e-14);
        // general A: compare Gamma2 with a fine Simpson quadrature
        let A = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -2.0, -0.6]);
        let t = 0.8;
        let I = exp_integrals(&A, t);
        let k = 2000;
        let mut q = DMatrix::zeros(2, 2);
        for i in 0..=k {
            let s = t * i as f64 / k as f64;
            let wgt = if i == 0 || i == k {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            q += expm(&(&A * (t - s))) * (s * wgt * t / (3.0 * k as f64));
        }
        assert_relative_eq!(I.gamma2, q, epsilon = 1e-12);
    }
}
