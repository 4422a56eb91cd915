//! Clarabel's scaled upper triangle of a symmetric matrix (`PSDTriangleConeT`).
//!
//! A symmetric `n x n` matrix `S` is stored as the vector `svec(S)` of length
//! `n (n + 1) / 2` holding its upper triangle **column by column**,
//! `(0,0), (0,1), (1,1), (0,2), (1,2), (2,2), ...`, with every off-diagonal entry
//! multiplied by `sqrt(2)`. With this scaling `<svec(S), svec(T)> = trace(S T)`, which is
//! what Clarabel's PSD cone assumes; getting the order or the scaling wrong does not
//! make the solver fail, it silently solves another problem, hence the round-trip and
//! end-to-end tests below.

use nalgebra::DMatrix;

/// `n (n + 1) / 2`, the length of `svec` of an `n x n` matrix.
pub fn triangular_number(n: usize) -> usize {
    n * (n + 1) / 2
}

/// Position of entry `(i, j)` (either order) in `svec`: column-major upper triangle.
pub fn triangle_index(i: usize, j: usize) -> usize {
    let (i, j) = if i <= j { (i, j) } else { (j, i) };
    triangular_number(j) + i
}

/// `svec(S(M))`, the scaled upper triangle of the symmetric part `S(M) = (M + M^T)/2`.
///
/// For a symmetric `M` this reads `M[(i, j)]` for `i <= j` (times `sqrt(2)` off the
/// diagonal). `M` must be square (checked by the callers; a non-square input uses its
/// leading square block).
pub fn svec(M: &DMatrix<f64>) -> Vec<f64> {
    let n = M.nrows().min(M.ncols());
    let mut v = Vec::with_capacity(triangular_number(n));
    for j in 0..n {
        for i in 0..=j {
            if i == j {
                v.push(M[(i, i)]);
            } else {
                v.push(std::f64::consts::SQRT_2 * 0.5 * (M[(i, j)] + M[(j, i)]));
            }
        }
    }
    v
}

/// Inverse of [`svec`]: the symmetric `n x n` matrix whose scaled triangle is `v`.
///
/// Returns `None` when `v.len() != n (n + 1) / 2`.
pub fn smat(v: &[f64], n: usize) -> Option<DMatrix<f64>> {
    if v.len() != triangular_number(n) {
        return None;
    }
    let mut M = DMatrix::zeros(n, n);
    for j in 0..n {
        for i in 0..=j {
            let x = v[triangle_index(i, j)];
            if i == j {
                M[(i, i)] = x;
            } else {
                let y = x / std::f64::consts::SQRT_2;
                M[(i, j)] = y;
                M[(j, i)] = y;
            }
        }
    }
    Some(M)
}

/// Basis of the symmetric `n x n` matrices in `svec` order: `E_ii` on the diagonal and
/// `E_ij + E_ji` off it, so that `Pi = sum_k x_k B_k` has `Pi[(i, j)] = x_k` with
/// `k = triangle_index(i, j)` (unscaled entries as decision variables).
pub fn symmetric_basis(n: usize) -> Vec<DMatrix<f64>> {
    let mut basis = Vec::with_capacity(triangular_number(n));
    for j in 0..n {
        for i in 0..=j {
            let mut B = DMatrix::zeros(n, n);
            B[(i, j)] = 1.0;
            B[(j, i)] = 1.0;
            basis.push(B);
        }
    }
    basis
}

/// The symmetric matrix with unscaled upper-triangle entries `x` (the inverse of the
/// parametrisation of [`symmetric_basis`]). `x.len()` must be `n (n + 1) / 2`.
pub(crate) fn sym_from_entries(x: &[f64], n: usize) -> DMatrix<f64> {
    let mut M = DMatrix::zeros(n, n);
    for j in 0..n {
        for i in 0..=j {
            let v = x[triangle_index(i, j)];
            M[(i, j)] = v;
            M[(j, i)] = v;
        }
    }
    M
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn order_and_scaling_match_clarabel_convention() {
        // 3 x 3 with distinct entries: the order must be (0,0),(0,1),(1,1),(0,2),(1,2),(2,2).
        let M = DMatrix::from_row_slice(3, 3, &[1.0, 2.0, 4.0, 2.0, 3.0, 5.0, 4.0, 5.0, 6.0]);
        let s = std::f64::consts::SQRT_2;
        let v = svec(&M);
        let expected = [1.0, 2.0 * s, 3.0, 4.0 * s, 5.0 * s, 6.0];
        assert_eq!(v.len(), 6);
        for (a, b) in v.iter().zip(expected) {
            assert_relative_eq!(*a, b, max_relative = 1e-15);
        }
        assert_eq!(triangle_index(0, 2), 3);
        assert_eq!(triangle_index(2, 1), 4);
    }

    #[test]
    fn round_trip_sizes_1_to_8() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for n in 1..=8 {
            let R = DMatrix::from_fn(n, n, |_, _| rng.random_range(-3.0..3.0));
            let S = (&R + R.transpose()) * 0.5;
            let v = svec(&S);
            assert_eq!(v.len(), triangular_number(n));
            let back = smat(&v, n).expect("length matches");
            assert_relative_eq!(back, S, epsilon = 1e-14, max_relative = 1e-15);
            // Inner product identity <svec S, svec T> = tr(S T).
            let R2 = DMatrix::from_fn(n, n, |_, _| rng.random_range(-3.0..3.0));
            let T = (&R2 + R2.transpose()) * 0.5;
            let ip: f64 = svec(&S).iter().zip(svec(&T)).map(|(a, b)| a * b).sum();
            assert_relative_eq!(ip, (&S * &T).trace(), epsilon = 1e-12);
            // Entry parametrisation is consistent with the basis.
            let x: Vec<f64> = (0..triangular_number(n)).map(|k| k as f64 + 1.0).collect();
            let mut sum = DMatrix::zeros(n, n);
            for (xk, B) in x.iter().zip(symmetric_basis(n)) {
                sum += B * *xk;
            }
            assert_eq!(sum, sym_from_entries(&x, n));
        }
        assert!(smat(&[1.0, 2.0], 2).is_none());
    }
}
