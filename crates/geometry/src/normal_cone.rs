//! Projection onto a finitely generated cone `cone{g_1, ..., g_k}`: the inward normal cone at
//! a non-smooth boundary point of a polytope or of an intersection of balls (eq. (zdot)).
use crate::linalg::{dot, for_each_subset, solve_small};

/// Writes into `out` the projection of `v` onto `{sum_j alpha_j g_j : alpha >= 0}`.
///
/// Exact active-set enumeration (the cones here have a handful of generators): by
/// Caratheodory's theorem some optimal support has at most `p` generators; a candidate
/// support `I` is optimal iff its least-squares coefficients are non-negative and the residual
/// has non-positive inner product with every generator (KKT conditions).
pub fn project_onto_cone(generators: &[Vec<f64>], v: &[f64], out: &mut [f64]) {
    let p = v.len();
    let k = generators.len();
    out.iter_mut().for_each(|o| *o = 0.0);
    let scale = crate::linalg::norm(v).max(f64::MIN_POSITIVE);
    let tol = 1e-12 * scale;
    if generators.iter().all(|g| dot(g, v) <= tol) {
        return;
    }
    let mut found = false;
    for size in 1..=k.min(p) {
        for_each_subset(k, size, |idx| {
            let mut gram = vec![0.0; size * size];
            let mut rhs = vec![0.0; size];
            for (a, &i) in idx.iter().enumerate() {
                rhs[a] = dot(&generators[i], v);
                for (b, &j) in idx.iter().enumerate() {
                    gram[a * size + b] = dot(&generators[i], &generators[j]);
                }
            }
            if !solve_small(&mut gram, &mut rhs, size, 1e-12) || rhs.iter().any(|&a| a < -tol) {
                return true;
            }
            let mut cand = vec![0.0; p];
            for (a, &i) in idx.iter().enumerate() {
                for d in 0..p {
                    cand[d] += rhs[a].max(0.0) * generators[i][d];
                }
            }
            let resid: Vec<f64> = (0..p).map(|d| v[d] - cand[d]).collect();
            if generators.iter().all(|g| dot(g, &resid) <= tol) {
                out.copy_from_slice(&cand);
                found = true;
                return false;
            }
            true
        });
        if found {
            return;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadrant_cone_clips_negative_parts() {
        let g = vec![vec![1.0, 0.0], vec![0.0, 1.0]];
        let mut out = [0.0; 2];
        project_onto_cone(&g, &[2.0, -3.0], &mut out);
        assert_eq!(out, [2.0, 0.0]);
        project_onto_cone(&g, &[-2.0, -3.0], &mut out);
        assert_eq!(out, [0.0, 0.0]);
        project_onto_cone(&g, &[1.5, 0.5], &mut out);
        assert_eq!(out, [1.5, 0.5]);
    }

    #[test]
    fn narrow_cone_projection_satisfies_moreau_decomposition() {
        let g = vec![vec![1.0, 0.2], vec![1.0, -0.2]];
        let v = [0.3, 1.0];
        let mut out = [0.0; 2];
        project_onto_cone(&g, &v, &mut out);
        let r = [v[0] - out[0], v[1] - out[1]];
        // residual orthogonal to the projection and in the polar cone
        assert!(dot(&r, &out).abs() < 1e-12);
        assert!(g.iter().all(|gi| dot(gi, &r) <= 1e-12));
    }
}
