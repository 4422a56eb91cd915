//! Matrix exponential `e^{hA}` and the integrals `t Psi(tA) = int_0^t e^{sA} ds` (eq. (Psi))
//! and `int_0^t e^{(t-s)A} s ds`, all from one augmented matrix exponential (Van Loan):
//!
//! ```text
//! expm(t [[A, I, 0], [0, 0, I], [0, 0, 0]]) = [[e^{tA}, Gamma1(t), Gamma2(t)], [0, I, tI], [0, 0, I]]
//! Gamma1(t) = int_0^t e^{sA} ds = t Psi(tA),   Gamma2(t) = int_0^t e^{(t-s)A} s ds.
//! ```
//! Everything takes and returns `DMatrix<f64>` so that other crates (discovery) can reuse it.
use nalgebra::DMatrix;
use rounding::{gamma, UNIT_ROUNDOFF};

/// Largest 1-norm handed to nalgebra's `exp` directly: it bounds `||M^k||` for k up to 27 to
/// choose its scaling, and a norm above about 2.6e11 overflows those powers to infinity, which
/// made the number of squarings `u64::MAX` (a plant entry of 1e60 hung `theta` and `simulate`).
const EXP_MAX_NORM: f64 = 1e8;

/// `e^{M}` (scaling and squaring with Pade approximants, nalgebra's `exp`). A matrix of 1-norm
/// above [`EXP_MAX_NORM`] is first scaled by an exact power of two to that norm and the result
/// squared back (at most about 1000 squarings for any finite matrix); below, nalgebra's own
/// choice stands unchanged.
pub fn expm(M: &DMatrix<f64>) -> DMatrix<f64> {
    let norm = (0..M.ncols()).map(|j| M.column(j).iter().map(|x| x.abs()).sum::<f64>()).fold(0.0, f64::max);
    if !norm.is_finite() {
        return DMatrix::from_element(M.nrows(), M.ncols(), f64::NAN);
    }
    if norm <= EXP_MAX_NORM {
        return M.clone().exp();
    }
    let squarings = (norm / EXP_MAX_NORM).log2().ceil() as i32;
    let mut X = (M * 0.5f64.powi(squarings)).exp();
    for _ in 0..squarings {
        X = &X * &X;
    }
    X
}

/// Frobenius norm rounded upward: the computed `sqrt(sum x^2)` has relative error below
/// `gamma_{len + 2}` (sum of squares `gamma_len`, square root and its rounding).
pub fn frobenius_up(M: &DMatrix<f64>) -> f64 {
    let s: f64 = M.iter().map(|x| x * x).sum();
    s.sqrt() * (1.0 + 2.0 * gamma(M.len() + 2))
}

/// `e^M` together with a rigorous bound `err >= ||X - e^M||_F` on the error of the returned
/// `X = expm(M)` (the exact exponential of the floating-point matrix `M`).
///
/// The bound compares `X` with an independent evaluation `Y` whose error is bounded a priori:
/// `B = M / 2^s` (exact scaling by a power of two, `||B||_F <= 1/2`), the Taylor polynomial
/// `T_K(B)`, `K = 18`, by Horner's rule, then `s` squarings. Truncation:
/// `||e^B - T_K(B)|| <= ||B||^{K+1} / (K+1)! / (1 - ||B|| / (K+2))`. Rounding, in Frobenius norms
/// of the computed matrices (`|fl(PQ) - PQ| <= gamma_n |P||Q|`, so
/// `||fl(PQ) - PQ||_F <= gamma_n ||P||_F ||Q||_F`):
/// - Horner step `Z <- I + (B Z) / k`: `e <- (||B|| e + gamma_n ||B|| ||Z||) / k + 2u (||V|| + ||Z'||)`;
/// - squaring `Y <- Y^2`: `e <- gamma_n ||Y||^2 + e (2 ||Y|| + e)`.
///
/// Then `err = ||X - Y||_F + e`, all terms rounded up (a relative `1e-6` on the bound covers the
/// rounding of its own evaluation). Non-finite input, or an `M` whose scaling would underflow,
/// gives `err = +inf` (never a wrong bound). The bound is sharp (a few ulps of `||e^M||`) for
/// `||M|| <~ 1` and loosens by about `(2 ||Y_i||)` per squaring for larger `||M||`.
pub fn expm_enclosure(M: &DMatrix<f64>) -> (DMatrix<f64>, f64) {
    let X = expm(M);
    let n = M.nrows();
    let nm = frobenius_up(M);
    if !(nm.is_finite() && X.iter().all(|x| x.is_finite())) {
        return (X, f64::INFINITY);
    }
    if n == 0 {
        return (X, 0.0);
    }
    let mut s = 0i32;
    while nm * 0.5f64.powi(s) > 0.5 {
        s += 1;
    }
    let scale = 0.5f64.powi(s);
    // Scaling by 2^-s is exact unless it reaches the subnormal range.
    if M.iter().any(|&x| x != 0.0 && (x * scale).abs() < 1e-290) {
        return (X, f64::INFINITY);
    }
    let B = M * scale;
    let nb = frobenius_up(&B);
    let gn = gamma(n);
    const K: usize = 18;
    let I = DMatrix::<f64>::identity(n, n);
    let mut Z = I.clone();
    let mut e = 0.0f64;
    for k in (1..=K).rev() {
        let nz = frobenius_up(&Z);
        let W = &B * &Z;
        let V = W / k as f64;
        let Zn = &I + &V;
        e = (nb * e + gn * nb * nz) / k as f64 + 2.0 * UNIT_ROUNDOFF * (frobenius_up(&V) + frobenius_up(&Zn));
        Z = Zn;
    }
    // Truncation of the Taylor series.
    let mut fact = 1.0f64;
    for k in 1..=K + 1 {
        fact *= k as f64;
    }
    e += nb.powi(K as i32 + 1) / fact / (1.0 - nb / (K as f64 + 2.0));
    let mut Y = Z;
    for _ in 0..s {
        let ny = frobenius_up(&Y);
        e = gn * ny * ny + e * (2.0 * ny + e);
        Y = &Y * &Y;
    }
    let diff = frobenius_up(&(&X - &Y)) * (1.0 + 2.0 * UNIT_ROUNDOFF);
    let err = (diff + e) * (1.0 + 1e-6) + 1e-300;
    (X, if err.is_finite() { err } else { f64::INFINITY })
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

    #[test]
    fn huge_matrices_end_with_an_answer() {
        // nalgebra's exp alone does not return for this matrix (its scaling count saturates)
        let M = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -2e60, -0.6]);
        let X = expm(&M);
        assert_eq!(X.shape(), (2, 2));
        let stiff = DMatrix::from_row_slice(2, 2, &[-1e60, 0.0, 0.0, -1.0]);
        let X = expm(&stiff);
        assert_eq!(X[(0, 0)], 0.0);
        // (the slow mode is lost to rounding at this stiffness: the CLI refuses such plants
        // by default, see moreau's budget `MAX_PLANT_ENTRY`)
        assert!((0.0..=1.0).contains(&X[(1, 1)]), "{X}");
        // below the threshold the result is nalgebra's, bit for bit
        let small = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -2.0, -0.6]);
        assert_eq!(expm(&small), small.clone().exp());
        assert!(expm(&DMatrix::from_element(1, 1, f64::INFINITY))[(0, 0)].is_nan());
    }
    use approx::assert_relative_eq;

    #[test]
    fn expm_enclosure_is_tight_and_contains_the_exact_exponential() {
        // Nilpotent: e^M = I + M exactly.
        let M = DMatrix::from_row_slice(2, 2, &[0.0, 0.75, 0.0, 0.0]);
        let (X, err) = expm_enclosure(&M);
        let exact = DMatrix::from_row_slice(2, 2, &[1.0, 0.75, 0.0, 1.0]);
        assert!(frobenius_up(&(&X - &exact)) <= err, "{err}");
        assert!(err < 1e-14, "{err}");
        // Rotation generator: e^{t J} = [[cos t, sin t], [-sin t, cos t]].
        for t in [0.1, 1.0, 3.0, 10.0] {
            let M = DMatrix::from_row_slice(2, 2, &[0.0, t, -t, 0.0]);
            let (X, err) = expm_enclosure(&M);
            let exact = DMatrix::from_row_slice(2, 2, &[t.cos(), t.sin(), -t.sin(), t.cos()]);
            assert!(frobenius_up(&(&X - &exact)) <= err + 4e-16, "t {t}: err {err}");
            assert!(err < 1e-12, "t {t}: err {err}");
        }
        // Stable non-normal 3x3: the bound stays small at ||M|| ~ 1 (measured 1.1e-14).
        let M = DMatrix::from_row_slice(3, 3, &[-0.3, 0.8, 0.0, 0.0, -0.5, 0.4, 0.1, 0.0, -0.2]);
        let e3 = expm_enclosure(&M).1;
        assert!(e3 < 5e-14, "{e3}");
        assert!(expm_enclosure(&DMatrix::from_element(1, 1, f64::NAN)).1.is_infinite());
    }

    /// Negative control: a wrong "exponential" (one entry off by 1e-10) is outside the
    /// enclosure, i.e. the bound is not vacuous.
    #[test]
    fn negative_control_perturbed_exponential_is_outside_the_bound() {
        let M = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -1.0, -0.6]);
        let (X, err) = expm_enclosure(&M);
        let mut Xw = X.clone();
        Xw[(0, 1)] += 1e-10;
        // ||Xw - e^M|| >= 1e-10 - err > err.
        assert!(1e-10 - err > err, "{err}");
    }

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
