//! `Phi(t) = I_p - t C Psi(tA) E`, eq. (Phi), with `t Psi(tA) = int_0^t e^{sA} ds` (eq. (Psi))
//! from one augmented matrix exponential (`dynamics::linear::expm::t_psi`).
//!
//! Theorem 1 asks `Phi(t)` to be nonsingular on `[0, T]`; [`scan_phi`] finds the first sign
//! change of `det Phi` (refined by bisection) or the first grid point where its smallest
//! singular value falls below `tol_sigma`. (The feasibility problem of [`super::rest_set`] uses
//! the equivalent form (zin), `Phi(t) z in C x_*(t) + Theta`, which needs no inverse.)
use dynamics::linear::expm::t_psi;
use nalgebra::DMatrix;

/// `Phi(t)` of eq. (Phi) (`p x p`).
pub fn phi(A: &DMatrix<f64>, C: &DMatrix<f64>, E: &DMatrix<f64>, t: f64) -> DMatrix<f64> {
    let p = C.nrows();
    DMatrix::identity(p, p) - C * t_psi(A, t) * E
}

/// Result of [`scan_phi`].
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PhiScan {
    /// First `t` in `[0, T]` where `Phi(t)` is singular (grid + bisection), if any.
    pub first_singular: Option<f64>,
    /// Smallest singular value of `Phi` over the grid.
    pub min_sigma: f64,
    /// Where it occurs.
    pub t_min_sigma: f64,
}

fn det_sigma(M: &DMatrix<f64>) -> (f64, f64) {
    let d = M.determinant();
    let s = M.clone().singular_values().min();
    (d, s)
}

/// Scans `Phi` on `grid + 1` points of `[0, T]`.
pub fn scan_phi(A: &DMatrix<f64>, C: &DMatrix<f64>, E: &DMatrix<f64>, T: f64, grid: usize, tol_sigma: f64) -> PhiScan {
    let K = grid.max(1);
    let mut out = PhiScan { first_singular: None, min_sigma: f64::INFINITY, t_min_sigma: 0.0 };
    let (mut d_prev, _) = det_sigma(&phi(A, C, E, 0.0));
    let mut t_prev = 0.0;
    for k in 1..=K {
        let t = T * k as f64 / K as f64;
        let (d, s) = det_sigma(&phi(A, C, E, t));
        if s < out.min_sigma {
            out.min_sigma = s;
            out.t_min_sigma = t;
        }
        if out.first_singular.is_none() {
            if s <= tol_sigma {
                out.first_singular = Some(t);
            } else if d.signum() != d_prev.signum() {
                // bisection on the sign change of det Phi
                let (mut a, mut b, da) = (t_prev, t, d_prev);
                for _ in 0..60 {
                    let c = 0.5 * (a + b);
                    let (dc, _) = det_sigma(&phi(A, C, E, c));
                    if dc.signum() == da.signum() {
                        a = c;
                    } else {
                        b = c;
                    }
                }
                out.first_singular = Some(0.5 * (a + b));
            }
        }
        d_prev = d;
        t_prev = t;
    }
    out
}
