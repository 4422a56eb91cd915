//! Lower bounds of the asymptotic path length of the backlash output per period
//! (`liminf int_tau^{tau+T} |z'| dt`), Theorem 2 and the remarks after it:
//! - (path): `(osc - d)_+`;
//! - (path1): `sup over partitions 0 = t_0 < ... < t_N = T of sum (|eta_T(t_k) - eta_T(t_{k-1})| - d)_+`,
//!   computed exactly over partitions drawn from a time grid by dynamic programming
//!   (`best_j = max_{i < j} best_i + (|eta_j - eta_i| - d)_+`, `O(K^2)`); any partition gives a
//!   valid lower bound, so the grid maximum is one;
//! - (path2): `sup_{eps > d/2} (2 eps - d) N_eps` with `N_eps` replaced by the size of a greedy
//!   `eps`-packing of the sampled orbit (a packing, hence `<= N_eps`: still a lower bound).
//!   The packing points, taken in time order and closed cyclically, form a partition of a
//!   period whose `N` terms are each `>= 2 eps - d`, so (path2) never exceeds the cyclic (path1).
//!
//! All three are lower bounds when `d` is an upper bound and the samples lie on the orbit.
use geometry::linalg::dist;

/// (path): `(osc - d)_+`.
pub fn path_bound(osc: f64, d: f64) -> f64 {
    (osc - d).max(0.0)
}

/// (path1) by dynamic programming over the given samples `eta[0..=K]` (with `eta[K] = eta_T(T)`).
pub fn partition_bound(eta: &[&[f64]], d: f64) -> f64 {
    let K = eta.len();
    if K < 2 {
        return 0.0;
    }
    let mut best = vec![0.0f64; K];
    for j in 1..K {
        let mut b = 0.0f64;
        for i in 0..j {
            let v = best[i] + (dist(eta[j], eta[i]) - d).max(0.0);
            if v > b {
                b = v;
            }
        }
        best[j] = b;
    }
    best[K - 1]
}

/// (path1) with a loss that depends on the length of each step (beyond the paper,
/// proofs-notes/theta-star.md): over a step of length `dt = t_j - t_i`,
/// `z - eta_T = C dev + v` with `v = z - y` in `Theta` and `dev = x - xi_T` moving at speed
/// `|C dev'| <= D(C(F Xi_inf + E Theta),{0}) = speed` (zinf), so
/// `|z(t_j) - z(t_i)| >= |eta_j - eta_i| - min(d, diam(Theta) + dt speed)`.
/// Short steps lose about `diam(Theta)` instead of `d`, so finer partitions pay.
/// `t[k]` are the sample times of `eta[k]`; `d`, `diam_theta` and `speed` upper bounds.
pub fn partition_bound_local(eta: &[&[f64]], t: &[f64], d: f64, diam_theta: f64, speed: f64) -> f64 {
    let K = eta.len();
    if K < 2 || t.len() != K {
        return 0.0;
    }
    // The loss is rounded up: a relative 1e-12 covers the two roundings of `diam + dt speed`
    // and the rounding of `dt` (times on a grid of at most a few thousand points).
    let loss = |dt: f64| d.min((diam_theta + dt.abs() * speed) * (1.0 + 1e-12));
    let mut best = vec![0.0f64; K];
    for j in 1..K {
        let mut b = 0.0f64;
        for i in 0..j {
            let v = best[i] + (dist(eta[j], eta[i]) - loss(t[j] - t[i])).max(0.0);
            if v > b {
                b = v;
            }
        }
        best[j] = b;
    }
    best[K - 1]
}

/// Result of the (path2) search.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[non_exhaustive]
pub struct PackingBound {
    /// `max (2 eps - d) N`.
    pub value: f64,
    /// Maximising `eps`.
    pub eps: f64,
    /// Size of the greedy packing there.
    pub count: usize,
}

/// (path2): greedy `eps`-packings of the samples for `eps_count` values of `eps` in
/// `(d/2, osc/2]` (points pairwise at distance `>= 2 eps`).
pub fn packing_bound(eta: &[&[f64]], d: f64, osc: f64, eps_count: usize) -> PackingBound {
    let mut out = PackingBound { value: 0.0, eps: f64::NAN, count: 0 };
    if osc <= d || eta.is_empty() {
        return out;
    }
    let lo = 0.5 * d.max(0.0);
    let hi = 0.5 * osc;
    let m = eps_count.max(1);
    let mut centres: Vec<&[f64]> = Vec::new();
    for i in 1..=m {
        let eps = lo + (hi - lo) * i as f64 / m as f64;
        centres.clear();
        for &x in eta {
            if centres.iter().all(|c| dist(c, x) >= 2.0 * eps) {
                centres.push(x);
            }
        }
        let v = (2.0 * eps - d) * centres.len() as f64;
        if v > out.value {
            out = PackingBound { value: v, eps, count: centres.len() };
        }
    }
    out
}
