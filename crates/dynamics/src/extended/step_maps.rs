//! Exact linear step maps over a step `h` for `x' = F x + B w(t) + u`:
//! `x(h) = Phi x + Psi (B w_0 + u) + Psi1 B (w_1 - w_0)` with `Phi = e^{hF}`,
//! `Psi = int_0^h e^{sF} ds` (= `h Psi(hF)` in the paper's notation, eq. (Psi)) and
//! `Psi1 = int_0^h e^{(h-s)F} (s/h) ds` (linear interpolation of `w`, or of a coasting play's
//! `q`, over the step).
//! All three come from the one matrix exponential of [`crate::linear::expm::exp_integrals`]
//! (Van Loan), shared with the catching-up scheme; here they are stored row-major for the
//! extended model's inner loop.
use crate::linear::expm::exp_integrals;
use nalgebra::DMatrix;

/// Row-major step matrices for step `h`.
#[derive(Debug, Clone)]
pub struct StepMaps {
    pub h: f64,
    pub n: usize,
    /// `e^{hF}` (n x n).
    pub Phi: Vec<f64>,
    /// `int_0^h e^{sF} ds` (n x n).
    pub Psi: Vec<f64>,
    /// `Psi B` (n x m).
    pub PsiB: Vec<f64>,
    /// `Psi1 B` (n x m).
    pub Psi1B: Vec<f64>,
    /// `Psi E` (n x p).
    pub PsiE: Vec<f64>,
    /// `Psi1 E` (n x p): a play deviation `q` that changes linearly over the step.
    pub Psi1E: Vec<f64>,
}

pub(super) fn row_major(m: &DMatrix<f64>) -> Vec<f64> {
    let mut v = Vec::with_capacity(m.len());
    for i in 0..m.nrows() {
        for j in 0..m.ncols() {
            v.push(m[(i, j)]);
        }
    }
    v
}

impl StepMaps {
    /// The maps for step `h` from [`crate::linear::expm::exp_integrals`] (the same exact
    /// integrals as the catching-up scheme's [`crate::linear::step_map::SystemStepMap`]):
    /// `Psi = Gamma1`, `Psi1 = Gamma2 / h`.
    pub fn new(F: &DMatrix<f64>, B: &DMatrix<f64>, E: &DMatrix<f64>, h: f64) -> Self {
        let I = exp_integrals(F, h);
        let psi1 = &I.gamma2 / h;
        Self {
            h,
            n: F.nrows(),
            PsiB: row_major(&(&I.gamma1 * B)),
            Psi1B: row_major(&(&psi1 * B)),
            PsiE: row_major(&(&I.gamma1 * E)),
            Psi1E: row_major(&(&psi1 * E)),
            Phi: row_major(&I.phi),
            Psi: row_major(&I.gamma1),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scalar_maps_match_closed_form() {
        // x' = -a x + w with w linear in time: closed forms of Phi, Psi, Psi1.
        let a = 2.0;
        let h = 0.3;
        let s = StepMaps::new(
            &DMatrix::from_element(1, 1, -a),
            &DMatrix::from_element(1, 1, 1.0),
            &DMatrix::from_element(1, 1, 0.0),
            h,
        );
        let phi = (-a * h).exp();
        let psi = (1.0 - phi) / a;
        // int_0^h e^{-a(h-s)} s/h ds = (a h - 1 + e^{-a h}) / (a^2 h)
        let psi1 = (a * h - 1.0 + phi) / (a * a * h);
        assert!((s.Phi[0] - phi).abs() < 1e-14);
        assert!((s.Psi[0] - psi).abs() < 1e-14);
        assert!((s.Psi1B[0] - psi1).abs() < 1e-13);
        // Negative control: a different step must not match.
        let t = StepMaps::new(
            &DMatrix::from_element(1, 1, -a),
            &DMatrix::from_element(1, 1, 1.0),
            &DMatrix::from_element(1, 1, 0.0),
            0.31,
        );
        assert!((t.Psi1B[0] - psi1).abs() > 1e-4);
    }
}
