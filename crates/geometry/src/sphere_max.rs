//! Certified maximisation of a Lipschitz function over the unit sphere `S_{p-1}`.
//!
//! Used wherever the paper needs `max_{|u| = 1}` of a support-function expression and a
//! sampled maximum would not be a valid upper bound (NOTES.md: "a sampled maximum of a support
//! function over the sphere is NOT a valid upper bound without a Lipschitz correction").
//!
//! Method: the sphere is covered by the `2p` faces of the cube `[-1, 1]^p`, each a
//! `(p-1)`-dimensional box. The radial map `u -> u/|u|` restricted to `|u| >= 1` is the metric
//! projection onto the unit ball, hence 1-Lipschitz, so on a box of half-diagonal `h` with
//! centre `c`: `f <= f(c/|c|) + L h`. Boxes are split (branch and bound) until the gap between
//! the best value found and the largest upper bound is below the tolerance. For `p = 1` the
//! sphere is `{-1, 1}` and the maximum is exact.
use crate::Enclosure;

/// Orders the items of a branch-and-bound max-heap by their upper bound `ub` (total order on
/// `f64`, so a NaN bound sorts first and is seen at once).
macro_rules! ordered_by_ub {
    ($($t:ty),+) => {$(
        impl PartialEq for $t {
            fn eq(&self, o: &Self) -> bool {
                self.ub == o.ub
            }
        }
        impl Eq for $t {}
        impl PartialOrd for $t {
            fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
                Some(self.cmp(o))
            }
        }
        impl Ord for $t {
            fn cmp(&self, o: &Self) -> std::cmp::Ordering {
                self.ub.total_cmp(&o.ub)
            }
        }
    )+};
}
pub(crate) use ordered_by_ub;
use std::collections::BinaryHeap;

/// Settings of [`sphere_max`].
#[derive(Debug, Clone)]
pub struct SphereMaxSettings {
    /// Absolute gap `upper - lower` at which the search stops. Default `1e-9`.
    pub tol_abs: f64,
    /// Relative gap (to `|lower|`) at which the search stops. Default `1e-7`.
    pub tol_rel: f64,
    /// Maximum number of function evaluations. Default `200_000`.
    pub max_evals: usize,
}

impl Default for SphereMaxSettings {
    fn default() -> Self {
        Self { tol_abs: 1e-9, tol_rel: 1e-7, max_evals: 200_000 }
    }
}

impl SphereMaxSettings {
    /// The same settings with the evaluation budget scaled for the dimension `p` of the
    /// sphere: `3 max_evals` for `p = 5`, unchanged otherwise. The simplicial-cone bound of
    /// [`crate::sublinear_sphere_max`] on the worst case (a centred ball, every direction
    /// maximal) loosens like `evals^(-2/(p-1))`; with the production budget of `20_000` it ends
    /// 0.58 % loose for `p = 4` and 3.2 % for `p = 5`, with `60_000` 1.83 % for `p = 5` (about
    /// 1.3 s on the 2-core machine, benches/sphere_max.rs). For `p >= 6` the split cap, not the
    /// evaluations, ends the search, so a larger budget buys little.
    pub fn scaled_for_dimension(&self, p: usize) -> Self {
        let factor = if p == 5 { 3 } else { 1 };
        Self { max_evals: self.max_evals.saturating_mul(factor), ..self.clone() }
    }
}

struct Cell {
    ub: f64,
    face: usize,
    sign: f64,
    centre: Vec<f64>,
    half: f64,
}
ordered_by_ub!(Cell);

/// Encloses `max_{|u|=1} f(u)` for an `L`-Lipschitz `f` (with respect to the Euclidean
/// distance on the sphere). Returns `Enclosure { lower, upper }` where `lower` is attained at a
/// sampled point and `upper` is certified by the Lipschitz constant (up to rounding in `f`).
/// If the evaluation budget runs out the bounds are still valid, only wider.
pub fn sphere_max(p: usize, mut f: impl FnMut(&[f64]) -> f64, lipschitz: f64, s: &SphereMaxSettings) -> Enclosure {
    assert!(p >= 1, "sphere_max: dimension must be >= 1");
    if p == 1 {
        let a = f(&[1.0]);
        let b = f(&[-1.0]);
        return Enclosure::exact(a.max(b));
    }
    let lip = lipschitz.max(0.0);
    let d = p - 1;
    let mut u = vec![0.0; p];
    let mut evals = 0usize;
    let mut lower = f64::NEG_INFINITY;
    let mut heap = BinaryHeap::new();
    let mut eval_cell = |face: usize, sign: f64, centre: &[f64], u: &mut Vec<f64>, evals: &mut usize| -> f64 {
        let mut k = 0;
        for i in 0..p {
            u[i] = if i == face {
                sign
            } else {
                k += 1;
                centre[k - 1]
            };
        }
        let n = crate::linalg::norm(u);
        u.iter_mut().for_each(|x| *x /= n);
        *evals += 1;
        f(u)
    };
    // Initial subdivision: each face split into 4^(d) cells of half-width 1/4 (d <= 2), else 2^d.
    let splits: usize = if d <= 2 { 4 } else { 2 };
    let half0 = 1.0 / splits as f64;
    for face in 0..p {
        for sign in [1.0, -1.0] {
            let mut idx = vec![0usize; d];
            loop {
                let centre: Vec<f64> = idx.iter().map(|&i| -1.0 + half0 * (2 * i + 1) as f64).collect();
                let v = eval_cell(face, sign, &centre, &mut u, &mut evals);
                lower = lower.max(v);
                let h = half0 * (d as f64).sqrt();
                heap.push(Cell { ub: v + lip * h, face, sign, centre, half: half0 });
                // next multi-index
                let mut j = 0;
                while j < d {
                    idx[j] += 1;
                    if idx[j] < splits {
                        break;
                    }
                    idx[j] = 0;
                    j += 1;
                }
                if j == d {
                    break;
                }
            }
        }
    }
    while let Some(top) = heap.peek() {
        let gap = top.ub - lower;
        if gap <= s.tol_abs.max(s.tol_rel * lower.abs()) || evals >= s.max_evals {
            break;
        }
        let cell = heap.pop().unwrap();
        let half = cell.half / 2.0;
        let h = half * (d as f64).sqrt();
        for m in 0..(1usize << d) {
            let centre: Vec<f64> =
                cell.centre.iter().enumerate().map(|(j, c)| c + if m >> j & 1 == 1 { half } else { -half }).collect();
            let v = eval_cell(cell.face, cell.sign, &centre, &mut u, &mut evals);
            lower = lower.max(v);
            heap.push(Cell { ub: v + lip * h, face: cell.face, sign: cell.sign, centre, half });
        }
    }
    let upper = heap.peek().map(|c| c.ub).unwrap_or(lower).max(lower);
    Enclosure::new(lower, upper)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn max_of_linear_function_is_its_norm() {
        let g = [3.0, -4.0];
        let b = sphere_max(2, |u| g[0] * u[0] + g[1] * u[1], 5.0, &SphereMaxSettings::default());
        assert!(b.lower <= 5.0 + 1e-12 && b.upper >= 5.0 - 1e-12, "{b:?}");
        assert!(b.width() < 1e-6, "{b:?}");
        // p = 3: the Lipschitz bound is first order while the function is flat to second order at
        // its maximum, so the default budget of 200,000 evaluations ends with a gap ~ 5e-4.
        let g3 = [1.0, 2.0, 2.0];
        let lin3 = |u: &[f64]| g3.iter().zip(u).map(|(a, b)| a * b).sum::<f64>();
        let b3 = sphere_max(3, lin3, 3.0, &SphereMaxSettings::default());
        assert!(b3.lower <= 3.0 + 1e-12 && b3.upper >= 3.0 - 1e-12, "{b3:?}");
        assert!(b3.width() < 1e-3, "{b3:?}");
        // a smaller budget gives wider, still enclosing bounds
        let small = sphere_max(3, lin3, 3.0, &SphereMaxSettings { max_evals: 2_000, ..Default::default() });
        assert!(small.lower <= 3.0 + 1e-12 && small.upper >= 3.0 - 1e-12, "{small:?}");
        assert!(small.width() >= b3.width(), "{small:?} vs {b3:?}");
    }

    #[test]
    fn a_too_small_lipschitz_constant_breaks_the_certificate() {
        // Negative control: a peak of height 1 and radius 1e-3 at angle 0.3, zero elsewhere.
        // Its Lipschitz constant is 2e3; with it the upper bound is valid. With L = 1e-3 and a
        // budget of 2,000 evaluations the search stops on the flank of the peak and the "upper
        // bound" is below the true maximum 1: a wrong bound, as it must be.
        let peak = |u: &[f64]| (1.0 - 1e6 * ((u[0] - 0.3f64.cos()).powi(2) + (u[1] - 0.3f64.sin()).powi(2))).max(0.0);
        let budget = SphereMaxSettings { max_evals: 2_000, ..Default::default() };
        let honest = sphere_max(2, peak, 2e3, &budget);
        assert!(honest.upper >= 1.0 - 1e-9, "{honest:?}");
        let dishonest = sphere_max(2, peak, 1e-3, &budget);
        assert!(dishonest.upper < 1.0 - 1e-3, "a wrong Lipschitz constant should give a wrong bound: {dishonest:?}");
    }
}
