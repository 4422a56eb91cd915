//! The small dense solvers of the cone bound: Cholesky solves on index subsets of a Gram matrix
//! and the non-negative least squares that chooses the conic interpolation `mu` (bound (a) of
//! the module docs of [`super`]). Fixed-size `MAX_CONE_DIM x MAX_CONE_DIM` scratch matrices.
use super::M;

/// Cholesky solve of `G[set, set] z[set] = g[set]`; false when a pivot is not safely positive.
fn solve_subset(G: &[f64; M * M], g: &[f64; M], set: &[usize], z: &mut [f64; M]) -> bool {
    let k = set.len();
    let mut L = [0.0; M * M];
    for r in 0..k {
        for c in 0..=r {
            let mut s = G[set[r] * M + set[c]];
            for t in 0..c {
                s -= L[r * M + t] * L[c * M + t];
            }
            if r == c {
                if s.is_nan() || s <= 1e-13 * G[set[r] * M + set[r]] {
                    return false;
                }
                L[r * M + r] = s.sqrt();
            } else {
                L[r * M + c] = s / L[c * M + c];
            }
        }
    }
    let mut y = [0.0; M];
    for r in 0..k {
        let mut s = g[set[r]];
        for t in 0..r {
            s -= L[r * M + t] * y[t];
        }
        y[r] = s / L[r * M + r];
    }
    for r in (0..k).rev() {
        let mut s = y[r];
        for t in r + 1..k {
            s -= L[t * M + r] * y[t];
        }
        y[r] = s / L[r * M + r];
    }
    for r in 0..k {
        z[set[r]] = y[r];
    }
    true
}

/// Cholesky solve of the whole `G z = g` for a dimension known at compile time (unrolled, no
/// index indirection: the hot path of [`nnls`]); false when a pivot is not safely positive.
#[inline]
fn solve_full<const P: usize>(G: &[f64; M * M], g: &[f64; M], z: &mut [f64; M]) -> bool {
    let mut L = [[0.0f64; P]; P];
    let mut inv = [0.0f64; P];
    for r in 0..P {
        for c in 0..=r {
            let mut s = G[r * M + c];
            for t in 0..c {
                s -= L[r][t] * L[c][t];
            }
            if r == c {
                if s.is_nan() || s <= 1e-13 * G[r * M + r] {
                    return false;
                }
                let d = s.sqrt();
                L[r][r] = d;
                inv[r] = 1.0 / d;
            } else {
                L[r][c] = s * inv[c];
            }
        }
    }
    let mut y = [0.0f64; P];
    for r in 0..P {
        let mut s = g[r];
        for t in 0..r {
            s -= L[r][t] * y[t];
        }
        y[r] = s * inv[r];
    }
    for r in (0..P).rev() {
        let mut s = y[r];
        for t in r + 1..P {
            s -= L[t][r] * y[t];
        }
        y[r] = s * inv[r];
    }
    z[..P].copy_from_slice(&y);
    true
}

/// Approximate `argmin_{a >= 0} a^T G a / 2 - g^T a` (Lawson-Hanson active set). The result is
/// always `>= 0`; it need not be optimal (any `a >= 0` gives a valid bound in [`cone_bound`]).
pub(super) fn nnls<const P: usize>(G: &[f64; M * M], g: &[f64; M], a: &mut [f64; M]) {
    let p = P;
    a.fill(0.0);
    let mut z = [0.0; M];
    // common case near a maximiser: the unconstrained solution (l = V^{-T} g inside the cone)
    if solve_full::<P>(G, g, &mut z) && z[..p].iter().all(|x| *x > 0.0) {
        a[..p].copy_from_slice(&z[..p]);
        return;
    }
    let scale = g[..p].iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let mut passive = [false; M];
    let mut set = [0usize; M];
    for _ in 0..3 * p {
        let mut best = None;
        let mut wmax = 1e-14 * scale;
        for j in (0..p).filter(|&j| !passive[j]) {
            let w = g[j] - (0..p).map(|k| G[j * M + k] * a[k]).sum::<f64>();
            if w > wmax {
                wmax = w;
                best = Some(j);
            }
        }
        let Some(j) = best else { return };
        passive[j] = true;
        for _ in 0..=p {
            let mut k = 0;
            for i in (0..p).filter(|&i| passive[i]) {
                set[k] = i;
                k += 1;
            }
            if !solve_subset(G, g, &set[..k], &mut z) {
                return;
            }
            if set[..k].iter().all(|&i| z[i] > 0.0) {
                for i in 0..p {
                    a[i] = if passive[i] { z[i] } else { 0.0 };
                }
                break;
            }
            // step towards z until the first passive coefficient hits 0, and drop it
            let (mut alpha, mut drop) = (f64::INFINITY, set[0]);
            for &i in set[..k].iter().filter(|&&i| z[i] <= 0.0) {
                let t = a[i] / (a[i] - z[i]);
                if t < alpha {
                    alpha = t;
                    drop = i;
                }
            }
            for &i in &set[..k] {
                a[i] += alpha * (z[i] - a[i]);
                if i == drop || a[i].is_nan() || a[i] <= 0.0 {
                    a[i] = 0.0;
                    passive[i] = false;
                }
            }
        }
    }
    for x in a[..p].iter_mut() {
        if x.is_nan() || *x < 0.0 {
            *x = 0.0;
        }
    }
}
