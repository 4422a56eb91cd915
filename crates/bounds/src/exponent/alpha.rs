//! `alpha = lambda_min(S(C E))`, eq. (alpha), `S(M) = (M + M^T)/2`, with a rigorous lower bound:
//! the floating-point product `C E` is within `gamma_n |C| |E|` (entrywise) of the exact one, and
//! Rump's test ([`lmi::verify::proves_lambda_min_at_least`]) proves `lambda_min >= alpha_lower`
//! for every symmetric matrix within that distance.
use nalgebra::DMatrix;

/// `alpha` of eq. (alpha): floating-point estimate and proven lower bound.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Alpha {
    pub estimate: f64,
    pub lower: f64,
    pub verified: bool,
}

/// Computes `alpha` for `C` (`p x n`) and `E` (`n x p`).
pub fn alpha(C: &DMatrix<f64>, E: &DMatrix<f64>) -> Alpha {
    let CE = C * E;
    let S = (&CE + CE.transpose()) * 0.5;
    let p = S.nrows();
    let eig = S.clone().symmetric_eigen();
    let est = eig.eigenvalues.iter().copied().fold(f64::INFINITY, f64::min);
    // (n + 2) eps / (1 - (n + 2) eps) = gamma_{2(n+2)}
    let gam = rounding::gamma(2 * (C.ncols() + 2));
    let absprod = C.abs() * E.abs();
    let rounding = gam * absprod.iter().map(|x| x * x).sum::<f64>().sqrt();
    let scale = S.iter().map(|x| x * x).sum::<f64>().sqrt();
    if scale == 0.0 && rounding == 0.0 {
        // every product term c_ik e_kj is exactly zero (|C| |E| = 0), so C E = 0 exactly: alpha = 0
        return Alpha { estimate: 0.0, lower: 0.0, verified: true };
    }
    let mut lower = est - rounding - 4.0 * (p as f64 + 1.0) * f64::EPSILON * scale - f64::MIN_POSITIVE;
    let mut verified = false;
    let mut step = 1e-15 * (est.abs() + scale + rounding) + 1e-290;
    for _ in 0..12 {
        if lmi::verify::proves_lambda_min_at_least(&S, rounding, lower) {
            verified = true;
            break;
        }
        lower -= step;
        step *= 10.0;
    }
    Alpha { estimate: est, lower, verified }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn worked_example_has_alpha_zero_and_negative_control() {
        let C = DMatrix::from_row_slice(1, 2, &[1.0, 0.0]);
        let E = DMatrix::from_row_slice(2, 1, &[0.0, 1.0]);
        let a = alpha(&C, &E);
        assert!(a.verified && a.lower == 0.0, "C E = 0 exactly: {a:?}");
        // 2 x 2 case with known eigenvalues: S(CE) = [[1, 1], [1, 1]] -> 0 and 2.
        let C2 = DMatrix::identity(2, 2);
        let E2 = DMatrix::from_row_slice(2, 2, &[1.0, 2.0, 0.0, 1.0]);
        let a2 = alpha(&C2, &E2);
        assert!(a2.verified && a2.lower <= 0.0 && a2.lower > -1e-12, "{a2:?}");
        // Negative control: Rump's test must refuse a claimed lower bound above lambda_min.
        let S = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 1.0, 1.0]);
        assert!(!lmi::verify::proves_lambda_min_at_least(&S, 0.0, 1e-6));
    }
}
