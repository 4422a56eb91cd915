//! Proven upper bounds of support functions evaluated in floating point (issue 15, item 3):
//! `sigma_S(u) <= support_upper(u)` for the exact `u` handed in, the rounding of the evaluation
//! included (Higham's `gamma_k` bounds, doubled, and one upward ulp at the end). Used by the tube
//! quadrature (`bounds::tube::xi_support`), whose upper sums must be upper bounds.
//!
//! For intersections of balls and polytopes the bound is a *dual certificate*, valid whatever
//! the accuracy of the computed maximiser: for an intersection `cap_i B_i`,
//! `sigma(u) <= sum_i sigma_{B_i}(u_i)` for every split `u = sum_i u_i` (the support function of
//! an intersection is the infimal convolution of the parts'); for a polytope
//! `{x : A x <= b}`, `sigma(u) <= b^T y + D(S,{0}) |u - A^T y|` for every `y >= 0` (Lagrangian
//! duality). The maximiser only chooses a split (or `y`) that makes the bound tight.
use crate::linalg::solve_small;
use rounding::{gamma, sqrt_up, ulp_up, UNIT_ROUNDOFF};

/// Upper bound of `sigma_{B_r(c)}(u) = c^T u + r |u|`.
#[inline]
pub fn ball_support_upper(c: &[f64], r: f64, u: &[f64]) -> f64 {
    let p = u.len();
    let (mut d, mut ad, mut ss) = (0.0, 0.0, 0.0);
    for i in 0..p {
        let t = c[i] * u[i];
        d += t;
        ad += t.abs();
        ss += u[i] * u[i];
    }
    let rn = r * sqrt_up(ss * (1.0 + 2.0 * gamma(p + 1)));
    ulp_up(d + rn + 2.0 * gamma(p + 4) * (ad + rn) + 1e-300)
}

/// Upper bound of `sigma(u) = c^T u + sqrt(u^T M u)` (ellipsoid, `M` row-major `p x p`).
#[inline]
pub fn ellipsoid_support_upper(c: &[f64], m: &[f64], u: &[f64]) -> f64 {
    let p = u.len();
    let (mut q, mut aq) = (0.0, 0.0);
    for i in 0..p {
        for j in 0..p {
            let t = u[i] * m[i * p + j] * u[j];
            q += t;
            aq += t.abs();
        }
    }
    let s = sqrt_up((q + 2.0 * gamma(p * p + 2) * aq).max(0.0) * (1.0 + 2.0 * UNIT_ROUNDOFF));
    let (mut d, mut ad) = (0.0, 0.0);
    for i in 0..p {
        let t = c[i] * u[i];
        d += t;
        ad += t.abs();
    }
    ulp_up(d + s + 2.0 * gamma(p + 4) * ad + 4.0 * UNIT_ROUNDOFF * s + 1e-300)
}

/// Split certificate for `cap_{i in J} B_{r_i}(c_i)` at a (computed) maximiser `s`: the
/// least-squares coefficients `a` of `u ~ sum_{i in J} a_i (s - c_i)` give the split
/// `u_i = a_i (s - c_i)` (all but the last), `u_last = u - sum u_i`; the rounding `e` of the last
/// subtraction is paid with the Lipschitz constant `|c_last| + r_last` of the last ball's support
/// function. `None` when `J` has fewer than two balls or the Gram system is singular.
pub fn split_support_upper(centres: &[&[f64]], radii: &[f64], s: &[f64], u: &[f64]) -> Option<f64> {
    let k = centres.len().min(s.len());
    if k < 2 {
        return None;
    }
    let p = u.len();
    let normals: Vec<Vec<f64>> = (0..k).map(|i| (0..p).map(|d| s[d] - centres[i][d]).collect()).collect();
    let mut gram = vec![0.0; k * k];
    let mut rhs: Vec<f64> = (0..k).map(|a| normals[a].iter().zip(u).map(|(x, y)| x * y).sum()).collect();
    for a in 0..k {
        for b in 0..k {
            gram[a * k + b] = normals[a].iter().zip(&normals[b]).map(|(x, y)| x * y).sum();
        }
    }
    if !solve_small(&mut gram, &mut rhs, k, 1e-12) || rhs.iter().any(|x| !x.is_finite()) {
        return None;
    }
    let mut last = u.to_vec();
    let mut abs_sum = vec![0.0; p];
    let mut total = 0.0;
    let mut total_abs = 0.0;
    for i in 0..k - 1 {
        let ui: Vec<f64> = normals[i].iter().map(|x| rhs[i] * x).collect();
        for d in 0..p {
            last[d] -= ui[d];
            abs_sum[d] += ui[d].abs();
        }
        let b = ball_support_upper(centres[i], radii[i], &ui);
        total += b;
        total_abs += b.abs();
    }
    // |fl(u - sum u_i) - (u - sum u_i)| <= gamma_k (|u| + sum |u_i|) componentwise.
    let g = 2.0 * gamma(k + 1);
    let e: f64 = (0..p).map(|d| (g * (u[d].abs() + abs_sum[d])).powi(2)).sum::<f64>().sqrt() * 1.01;
    let cl: f64 = centres[k - 1].iter().map(|x| x * x).sum::<f64>().sqrt() * 1.01;
    let b = ball_support_upper(centres[k - 1], radii[k - 1], &last);
    total += b;
    total_abs += b.abs();
    let v = total + (cl + radii[k - 1] * 1.01) * e + 2.0 * gamma(k + 2) * total_abs;
    v.is_finite().then(|| ulp_up(v))
}

/// Lagrangian certificate for `{x : A x <= b}` (rows `normals`, `offsets`) at a (computed)
/// maximising vertex `v`: `y >= 0` on (at most `p`) nearly active rows from least squares, then
/// `sigma(u) <= b^T y + dev |u - A^T y|` (`dev >= D(S,{0})`), every sum bounded with
/// `gamma_k`. With no usable `y` the bound is `dev |u|`. No allocation for `p <= 16`.
/// `row_norms[i] = |a_i|` (only used to select the nearly active rows).
pub fn polytope_support_upper(
    normals: &[Vec<f64>],
    row_norms: &[f64],
    offsets: &[f64],
    v: &[f64],
    dev: f64,
    u: &[f64],
) -> f64 {
    const MAXP: usize = 16;
    let p = u.len();
    let nu = sqrt_up(u.iter().map(|x| x * x).sum::<f64>() * (1.0 + 2.0 * gamma(p + 1)));
    let fallback = ulp_up(dev * nu * (1.0 + 4.0 * UNIT_ROUNDOFF));
    if p > MAXP {
        return fallback;
    }
    let vn: f64 = v.iter().map(|x| x * x).sum::<f64>().sqrt();
    // The (at most p) nearly active rows with the smallest relative slack, by insertion.
    let mut act = [(f64::INFINITY, usize::MAX); MAXP];
    let mut k = 0usize;
    for (i, a) in normals.iter().enumerate() {
        let an = row_norms[i];
        let slack = offsets[i] - a.iter().zip(v).map(|(x, y)| x * y).sum::<f64>();
        let rel = slack.abs() / (offsets[i].abs() + an * vn).max(1e-300);
        if !(rel <= 1e-9) {
            continue;
        }
        if k < p {
            act[k] = (rel, i);
            k += 1;
        } else if rel < act[k - 1].0 {
            act[k - 1] = (rel, i);
        } else {
            continue;
        }
        let mut j = k - 1;
        while j > 0 && act[j].0 < act[j - 1].0 {
            act.swap(j, j - 1);
            j -= 1;
        }
    }
    if k == 0 {
        return fallback;
    }
    let mut gram = [0.0; MAXP * MAXP];
    let mut y = [0.0; MAXP];
    for a in 0..k {
        let ra = &normals[act[a].1];
        y[a] = ra.iter().zip(u).map(|(x, z)| x * z).sum();
        for b in 0..k {
            gram[a * k + b] = ra.iter().zip(&normals[act[b].1]).map(|(x, z)| x * z).sum();
        }
    }
    if !solve_small(&mut gram[..k * k], &mut y[..k], k, 1e-12) {
        return fallback;
    }
    let (mut by, mut aby) = (0.0, 0.0);
    for a in 0..k {
        y[a] = y[a].max(0.0);
        let t = offsets[act[a].1] * y[a];
        by += t;
        aby += t.abs();
    }
    let g = 2.0 * gamma(k + 2);
    let mut res2 = 0.0;
    for d in 0..p {
        let (mut r, mut ar) = (u[d], u[d].abs());
        for a in 0..k {
            let t = normals[act[a].1][d] * y[a];
            r -= t;
            ar += t.abs();
        }
        res2 += (r.abs() + g * ar).powi(2);
    }
    let res = sqrt_up(res2 * (1.0 + 2.0 * gamma(p + 1)));
    let val = by + g * aby + dev * res * (1.0 + 4.0 * UNIT_ROUNDOFF);
    if val.is_finite() {
        ulp_up(val).min(fallback)
    } else {
        fallback
    }
}

/// The split certificate of [`split_support_upper`] for two discs in the plane meeting at the
/// (computed) vertex `s`, without allocation: `u = a n_i + b n_j` by Cramer's rule
/// (`n = s - c`), `u_i = a n_i`, `u_j = fl(u - u_i)` with its rounding paid by the Lipschitz
/// constant of `sigma_{B_j}`. `None` when the normals are (nearly) parallel.
pub fn split_support_upper_2d(ci: &[f64], ri: f64, cj: &[f64], rj: f64, s: &[f64], u: &[f64]) -> Option<f64> {
    let ni = [s[0] - ci[0], s[1] - ci[1]];
    let nj = [s[0] - cj[0], s[1] - cj[1]];
    let det = ni[0] * nj[1] - ni[1] * nj[0];
    let scale = (ni[0] * ni[0] + ni[1] * ni[1]) * (nj[0] * nj[0] + nj[1] * nj[1]);
    if !(det * det > 1e-20 * scale) {
        return None;
    }
    let a = (u[0] * nj[1] - u[1] * nj[0]) / det;
    let ui = [a * ni[0], a * ni[1]];
    let uj = [u[0] - ui[0], u[1] - ui[1]];
    let g = 2.0 * UNIT_ROUNDOFF * 1.01;
    let e = ((g * (u[0].abs() + ui[0].abs())).powi(2) + (g * (u[1].abs() + ui[1].abs())).powi(2)).sqrt();
    let lip = (cj[0] * cj[0] + cj[1] * cj[1]).sqrt() * 1.01 + rj * 1.01;
    let (b1, b2) = (ball_support_upper(ci, ri, &ui), ball_support_upper(cj, rj, &uj));
    let v = b1 + b2 + lip * e * 1.01 + 2.0 * gamma(3) * (b1.abs() + b2.abs());
    v.is_finite().then(|| ulp_up(v))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ball_and_ellipsoid_bounds_are_above_and_tight() {
        let c = [0.3, -0.2];
        for k in 0..64 {
            let a = k as f64 * 0.1;
            let u = [a.cos() * 3.0, a.sin() * 3.0];
            let exact = c[0] * u[0] + c[1] * u[1] + 0.5 * (u[0] * u[0] + u[1] * u[1]).sqrt();
            let b = ball_support_upper(&c, 0.5, &u);
            assert!(b >= exact && b <= exact + 1e-14, "{b} {exact}");
            let m = [0.04, 0.01, 0.01, 0.0025 + 0.0025];
            let q = u[0] * u[0] * m[0] + 2.0 * u[0] * u[1] * m[1] + u[1] * u[1] * m[3];
            let ex = c[0] * u[0] + c[1] * u[1] + q.sqrt();
            let e = ellipsoid_support_upper(&c, &m, &u);
            assert!(e >= ex && e <= ex + 1e-14, "{e} {ex}");
        }
    }

    /// The split certificate is valid for every split: with a deliberately wrong maximiser it
    /// still bounds the true support value (here, a single disc's), only less tightly.
    #[test]
    fn split_is_valid_for_any_maximiser_and_tight_at_the_vertex() {
        let (c1, c2) = ([-0.15, 0.0], [0.15, 0.0]);
        let h = (0.04f64 - 0.0225).sqrt();
        let vertex = [0.0, h];
        let cs: [&[f64]; 2] = [&c1, &c2];
        // u = (0, 1): the maximiser is the vertex; sigma = h.
        let b = split_support_upper(&cs, &[0.2, 0.2], &vertex, &[0.0, 1.0]).unwrap();
        assert!(b >= h && b <= h * (1.0 + 1e-13), "{b} vs {h}");
        // A wrong "maximiser" gives a valid (larger) bound.
        let w = split_support_upper(&cs, &[0.2, 0.2], &[0.05, 0.1], &[0.0, 1.0]).unwrap();
        assert!(w >= h, "{w}");
    }

    #[test]
    fn polytope_certificate_bounds_the_square() {
        // [-1, 1]^2 as A x <= b.
        let normals = vec![vec![1.0, 0.0], vec![-1.0, 0.0], vec![0.0, 1.0], vec![0.0, -1.0]];
        let offsets = vec![1.0; 4];
        let dev = 2f64.sqrt() * (1.0 + 1e-12);
        let u = [0.3, 0.7];
        let rn = vec![1.0; 4];
        let b = polytope_support_upper(&normals, &rn, &offsets, &[1.0, 1.0], dev, &u);
        assert!((1.0..=1.0 + 1e-14).contains(&b), "{b}");
        // A vertex that is not the maximiser: still an upper bound.
        let w = polytope_support_upper(&normals, &rn, &offsets, &[1.0, -1.0], dev, &u);
        assert!(w >= 1.0, "{w}");
    }
}
