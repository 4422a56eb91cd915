//! Spectral abscissa `mu = max Re eig(F)` of the linearised system, eq. (stab),
//! and validation of the data `(F, E, C)` of eqs. (F), (G_H).

use crate::error::{LmiError, Result};
use nalgebra::DMatrix;

/// Reject NaN / infinite entries, naming the matrix and the position.
pub(crate) fn check_finite(what: &'static str, M: &DMatrix<f64>) -> Result<()> {
    for j in 0..M.ncols() {
        for i in 0..M.nrows() {
            let v = M[(i, j)];
            if !v.is_finite() {
                return Err(LmiError::NonFinite { what, row: i, col: j, value: v });
            }
        }
    }
    Ok(())
}

pub(crate) fn check_shape(what: &'static str, M: &DMatrix<f64>, expected: (usize, usize)) -> Result<()> {
    if M.shape() != expected {
        return Err(LmiError::DimensionMismatch { what, expected, found: M.shape() });
    }
    Ok(())
}

pub(crate) fn check_scalar(what: &'static str, v: f64) -> Result<()> {
    if !v.is_finite() {
        return Err(LmiError::NonFinite { what, row: 0, col: 0, value: v });
    }
    Ok(())
}

/// Validate `F` (square, nonempty, finite). Returns `n`.
pub(crate) fn check_F(F: &DMatrix<f64>) -> Result<usize> {
    let n = F.nrows();
    if n == 0 {
        return Err(LmiError::Empty { what: "F", shape: F.shape() });
    }
    check_shape("F", F, (n, n))?;
    check_finite("F", F).map(|_| n)
}

/// Validate `(F, E, C)`: `F` is `n x n`, `E` is `n x p`, `C` is `p x n`, all finite,
/// `n, p >= 1`. Returns `(n, p)`.
pub(crate) fn check_system(F: &DMatrix<f64>, E: &DMatrix<f64>, C: &DMatrix<f64>) -> Result<(usize, usize)> {
    let n = check_F(F)?;
    let p = E.ncols();
    if p == 0 {
        return Err(LmiError::Empty { what: "E", shape: E.shape() });
    }
    check_shape("E", E, (n, p))?;
    check_shape("C", C, (p, n))?;
    check_finite("E", E)?;
    check_finite("C", C)?;
    Ok((n, p))
}

/// Spectral abscissa `mu = max Re eig(F)`, eq. (stab).
///
/// Computed from a real Schur form (nalgebra), so it is a floating-point estimate,
/// accurate to about `eps * ||F||` for normal `F` and less for defective `F`; the
/// certificates of this crate never rely on it beyond choosing the interval
/// `(0, |mu|)` of eq. (lammu).
///
/// Errors: [`LmiError::Empty`], [`LmiError::DimensionMismatch`], [`LmiError::NonFinite`],
/// [`LmiError::EigenNotConverged`].
pub fn spectral_abscissa(F: &DMatrix<f64>) -> Result<f64> {
    let n = check_F(F)?;
    let schur = nalgebra::linalg::Schur::try_new(F.clone(), f64::EPSILON, 10_000 * n)
        .ok_or(LmiError::EigenNotConverged { n })?;
    let eig = schur.complex_eigenvalues();
    Ok(eig.iter().map(|z| z.re).fold(f64::NEG_INFINITY, f64::max))
}

/// `mu` of eq. (stab) with the Hurwitz check of eq. (F): errors with
/// [`LmiError::NotHurwitz`] when `mu >= 0`.
pub fn hurwitz_mu(F: &DMatrix<f64>) -> Result<f64> {
    let mu = spectral_abscissa(F)?;
    if mu >= 0.0 {
        return Err(LmiError::NotHurwitz { mu });
    }
    Ok(mu)
}

/// Check `0 < lambda < |mu|`, eq. (lammu).
pub(crate) fn check_lambda(lambda: f64, mu: f64) -> Result<()> {
    check_scalar("lambda", lambda)?;
    if !(lambda > 0.0 && lambda < -mu) {
        return Err(LmiError::LambdaOutOfRange { lambda, mu });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn paper_example_mu() {
        // NOTES.md worked example: F = [[0,1],[-1,-0.6]], eigenvalues -0.3 +- i sqrt(0.91).
        let F = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -1.0, -0.6]);
        assert_relative_eq!(spectral_abscissa(&F).unwrap(), -0.3, epsilon = 1e-12);
        assert_relative_eq!(hurwitz_mu(&F).unwrap(), -0.3, epsilon = 1e-12);
    }

    #[test]
    fn bad_inputs_are_errors() {
        let F = DMatrix::from_row_slice(2, 2, &[0.1, 1.0, -1.0, 0.0]);
        assert!(matches!(hurwitz_mu(&F), Err(LmiError::NotHurwitz { mu }) if mu > 0.0));
        let Fnan = DMatrix::from_row_slice(2, 2, &[0.0, f64::NAN, -1.0, 0.0]);
        assert!(matches!(spectral_abscissa(&Fnan), Err(LmiError::NonFinite { what: "F", row: 0, col: 1, .. })));
        let Frect = DMatrix::zeros(2, 3);
        assert!(matches!(
            spectral_abscissa(&Frect),
            Err(LmiError::DimensionMismatch { what: "F", expected: (2, 2), found: (2, 3) })
        ));
        let E = DMatrix::zeros(3, 1);
        let C = DMatrix::zeros(1, 2);
        let Fok = DMatrix::from_row_slice(2, 2, &[-1.0, 0.0, 0.0, -2.0]);
        assert!(matches!(
            check_system(&Fok, &E, &C),
            Err(LmiError::DimensionMismatch { what: "E", expected: (2, 1), found: (3, 1) })
        ));
        assert!(matches!(check_lambda(0.0, -1.0), Err(LmiError::LambdaOutOfRange { .. })));
        assert!(
            matches!(check_lambda(1.0, -1.0), Err(LmiError::LambdaOutOfRange { lambda, mu }) if lambda == 1.0 && mu == -1.0)
        );
        assert!(check_lambda(0.5, -1.0).is_ok());
    }
}
