//! Certified maximum over the unit sphere of a **sublinear** function `g` (positively
//! homogeneous and convex, e.g. any support function or a sum of them, eqs. (supp), (d),
//! (zinf)), much sharper than a Lipschitz bound.
//!
//! For `p = 2`: every unit `v` on the arc between unit vectors `v1`, `v2` (angle `delta < pi`)
//! is a conic combination `v = a v1 + b v2`, `a = sin(delta - phi)/sin(delta)`,
//! `b = sin(phi)/sin(delta)`, so `g(v) <= a g(v1) + b g(v2)`; the maximum over the arc of the
//! right-hand side is `sqrt(A^2 + B^2)` with `A = g1`, `B = (g2 - g1 cos delta)/sin delta` when
//! the maximiser `atan2(B, A)` lies in `[0, delta]`, else `max(g1, g2)`. The bound exceeds the
//! true arc maximum by `O(delta^2)`; arcs whose bound exceeds the best sampled value by more than
//! the tolerance are bisected. For `p = 1` the maximum is exact (`v = +-1`).
//!
//! For `p = 3`: spherical triangles with vertices `v1, v2, v3` (starting from the 8 octants);
//! on the cone they span `g(v) <= l^T v` with `l = V^{-T} (g1, g2, g3)`, whose maximum over the
//! unit vectors of the cone is `|l|` if `l` lies in the cone and otherwise the largest of the
//! three edge (arc) bounds. Triangles are split at the midpoint of their longest edge.
//!
//! For `4 <= p <= MAX_CONE_DIM` (= 8): the same idea on simplicial cones, [`cones_max`]. The
//! sphere is covered by the `2^p` orthant cones (vertices `+-e_i`); a cone `K` is spanned by
//! `p` unit vertices `v_1..v_p` (columns of `V`, Gram matrix `G = V^T V`). Every unit `v` in
//! `K` is `v = sum a_i v_i` with `a >= 0`, so by sublinearity `g(v) <= g^T a` with
//! `g = (g(v_1), ..., g(v_p))`. Two upper bounds of `g^T a` over the unit vectors of `K`:
//!
//! * (a) conic interpolation: for any `mu >= 0`, `g^T a <= (g + mu)^T a = (G y)^T a - r^T a
//!   = (V y).v - r^T a <= |V y| + |r|_inf sum a_i` for any `y`, with the residual
//!   `r = G y - (g + mu)`. With `y = a*`, the solution of the nonnegative least-squares problem
//!   `min_{a >= 0} a^T G a / 2 - g^T a` (an active-set solve, `p <= 8`), and
//!   `mu = max(G a* - g, 0)` (the KKT multiplier), `r` is rounding only and `|V a*| = |P_K l|`,
//!   `l = V^{-T} g`, is exactly the maximum of the conic interpolant `l.v` over the unit
//!   vectors of `K` (Moreau: `max_{v in K, |v| <= 1} l.v = |P_K l|`); it is `|l|` when `l`
//!   lies in `K`. Any `y` and any `mu >= 0` give a valid bound, so an inexact or
//!   unfinished solve (ill-conditioned `G`) only loosens it. It exceeds the true maximum over
//!   the cone by `O(h^2)`, `h` the cone's angular diameter.
//! * (b) `sum a_i = 1/|w|` where `w = v / sum a_i` lies in the flat simplex
//!   `conv(v_1..v_p)`, so `g^T a <= max_i g_i / dist(0, conv(v_i))` when `max_i g_i >= 0`
//!   (else `<= max_i g_i`, since `|w| <= 1`). Lower bounds of the distance, both valid for
//!   every `w = sum lambda_i v_i` in the simplex:
//!   `|w|^2 = sum lambda_i lambda_j G_ij >= min(m, m/p + c (1 - 1/p))` with
//!   `m = min_i G_ii`, `c = min_{i != j} G_ij` (it is linear in `s = sum lambda_i^2` in
//!   `[1/p, 1]`; exact for a regular simplex: `1 - E^2 (p-1)/(2p)` with unit vertices and
//!   chord `E`), and `|w| >= u.w/|u| >= min_i u.v_i / |u|` for the centroid direction
//!   `u = sum v_j` (`u.v_i` = row sums of `G`). (b) also bounds `sum a_i` in (a).
//!
//! The cone bound is the smaller of the two; cones sit in a max-heap by bound, the worst is split
//! at the normalised midpoint of its longest edge (largest angle; midpoints are cached per edge,
//! so neighbouring cones share evaluations), and the search stops when the gap to the best
//! sampled value is below the tolerance or the evaluation budget is spent (the bound is then
//! still valid, only wider). Rounding: the Gram entries, residual and `|V a*|` carry
//! `gamma_p`-type margins, every cone bound gets the blanket inflation
//! `ub + 1e-12 (|ub| + max_i |g_i|)` of the `p = 3` code, and because a floating midpoint lies
//! `delta = O(sqrt(p) p eps)` off the exact arc, the two children cover their parent only up to
//! a sliver of width `delta`; with `D` the largest depth reached every point of the sphere is
//! within `D delta` of a covered one and (for `U >= 0`) `max g <= U / (1 - D delta)`, which is
//! applied to the final upper bound `U`. Splits that reuse a cached midpoint cost no evaluation,
//! so they are capped as well (`max_evals * 4000 / p^3`, at most 2e6).
//!
//! Measured (release, `tol_abs 1e-9, tol_rel 1e-6, max_evals 20_000`, benches/sphere_max.rs):
//! isolated maxima (off-centre balls, ellipsoids, sums with linear terms) reach the tolerance in
//! 100 to 1000 evaluations; the centred ball, where every direction is a maximiser, spends the
//! budget and ends `upper/true - 1 = 5.8e-3` for `p = 4` (0.10 s; Lipschitz: 0.22) and `3.2e-2`
//! for `p = 5` (0.46 s; Lipschitz: 0.5); with the budget tripled for `p = 5`
//! ([`SphereMaxSettings::scaled_for_dimension`], what `bounds` uses) `1.83e-2` in 1.36 s. The
//! cone bounds run with the dimension as a compile-time constant and the heap holds
//! `(bound, arena slot)` pairs: 1.7 s -> 1.3 s for the same 60,000-evaluation search.
//!
//! For `p > MAX_CONE_DIM` the `2^p` initial cones each need about `2^(p-1)` splits before their
//! edges halve, so the refinement cannot progress within a useful budget (already at `p = 8`
//! the centred ball ends 0.84 loose, Lipschitz 1.32): the Lipschitz
//! branch and bound `crate::sphere_max` is used, its upper bound capped by the crude orthant
//! bound `g(v) <= sum |v_i| g(sign(v_i) e_i) <= |(max(g(e_i), g(-e_i), 0))_i|`
//! (`2 p` evaluations).
//!
//! The method needs sublinearity: for a function that is not convex on the cones (a narrow
//! bump) the "upper bound" can lie below a sampled value (see the negative-control tests).
//! Module map: [`arcs`] (`p = 2`), [`triangles`] (`p = 3`), [`cones`] (`4 <= p <= 8`, and any
//! `2 <= p <= 8` through [`cones_max`]) with its small non-negative least-squares solver
//! [`nnls`]; `p > 8` falls back to the Lipschitz branch and bound.
pub mod arcs;
#[cfg(test)]
mod cone_tests;
pub mod cones;
pub mod nnls;
#[cfg(test)]
mod tests;
pub mod triangles;

use crate::{sphere_max, Enclosure, SphereMaxSettings};
pub use arcs::arc_bound;
use arcs::arcs_max;
#[cfg(test)]
use cones::cone_bound;
pub use cones::cones_max;
use triangles::triangles_max;

/// Largest dimension handled by the simplicial-cone branch and bound [`cones_max`]; above it
/// `sublinear_sphere_max` falls back to the Lipschitz branch and bound.
pub const MAX_CONE_DIM: usize = 8;
const EPS: f64 = f64::EPSILON;
/// Stride of the fixed-size `MAX_CONE_DIM x MAX_CONE_DIM` scratch matrices.
const M: usize = MAX_CONE_DIM;

/// `max_{|v| = 1} g(v)` for sublinear `g`; `lipschitz` is used only for `p > MAX_CONE_DIM`
/// (the Lipschitz fallback).
pub fn sublinear_sphere_max(
    p: usize,
    mut g: impl FnMut(&[f64]) -> f64,
    lipschitz: f64,
    s: &SphereMaxSettings,
) -> Enclosure {
    match p {
        0 => Enclosure::exact(f64::NAN),
        1 => Enclosure::exact(g(&[1.0]).max(g(&[-1.0]))),
        2 => arcs_max(g, s),
        3 => triangles_max(g, s),
        4..=MAX_CONE_DIM => cones_max(p, g, s),
        _ => lipschitz_fallback(p, g, lipschitz, s),
    }
}

/// `p > MAX_CONE_DIM`: the Lipschitz branch and bound ([`sphere_max`]), its upper value capped
/// by the crude orthant bound `|(max(g(e_i), g(-e_i)))_i|` of the `2p` axis values.
fn lipschitz_fallback(p: usize, mut g: impl FnMut(&[f64]) -> f64, lipschitz: f64, s: &SphereMaxSettings) -> Enclosure {
    // crude orthant bound from the 2p axis values, then the Lipschitz branch and bound
    let mut m2 = 0.0;
    let mut e = vec![0.0; p];
    for i in 0..p {
        let mut m = 0.0f64;
        for sgn in [1.0, -1.0] {
            e[i] = sgn;
            let x = g(&e);
            // a NaN value must not be skipped by `max`: it voids the crude bound
            m = if x.is_nan() { f64::INFINITY } else { m.max(x) };
        }
        e[i] = 0.0;
        m2 += m * m;
    }
    let crude = m2.sqrt() * (1.0 + (p as f64 + 2.0) * EPS);
    let b = sphere_max(p, g, lipschitz, s);
    Enclosure::new(b.lower, b.upper.min(crude).max(b.lower))
}
