//! Exact linear step maps over a step `h` for `x' = F x + B w(t) + u`:
//! `x(h) = Phi x + Psi (B w_0 + u) + Psi1 B (w_1 - w_0)` with `Phi = e^{hF}`,
//! `Psi = int_0^h e^{sF} ds` (= `h Psi(hF)` in the paper's notation, eq. (Psi)) and
//! `Psi1 = int_0^h e^{(h-s)F} (s/h) ds` (linear interpolation of `w` over the step).
//! All three come from one matrix exponential of the block matrix
//! `h [[F, I, 0], [0, 0, I/h], [0, 0, 0]]` (Van Loan).
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
}

fn row_major(m: &DMatrix<f64>) -> Vec<f64> {
    let mut v = Vec::with_capacity(m.len());
    for i in 0..m.nrows() {
        for j in 0..m.ncols() {
            v.push(m[(i, j)]);
        }
    }
    v
}

impl StepMaps {
    pub fn new(F: &DMatrix<f64>, B: &DMatrix<f64>, E: &DMatrix<f64>, h: f64) -> Self {
        let n = F.nrows();
        let mut M = DMatrix::zeros(3 * n, 3 * n);
        M.view_mut((0, 0), (n, n)).copy_from(&(F * h));
        for i in 0..n {
            M[(i, n + i)] = h;
            M[(n + i, 2 * n + i)] = 1.0;
        }
        let X = M.exp();
        let Phi = X.view((0, 0), (n, n)).into_owned();
        let Psi = X.view((0, n), (n, n)).into_owned();
        let Psi1 = X.view((0, 2 * n), (n, n)).into_owned();
        Self {
            h,
            n,
            Phi: row_major(&Phi),
            PsiB: row_major(&(&Psi * B)),
            Psi1B: row_major(&(&Psi1 * B)),
            PsiE: row_major(&(&Psi * E)),
            Psi: row_major(&Psi),
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
        assert!((s.Psi1B[0] - psi1).abs() < 1e-14);
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
