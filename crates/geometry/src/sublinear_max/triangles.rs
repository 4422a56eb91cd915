//! `p = 3`: branch and bound on spherical triangles, starting from the 8 octants (module docs
//! of [`super`]).
use super::arcs::arc_bound;
use crate::sphere_max::ordered_by_ub;
use crate::{Enclosure, SphereMaxSettings};
use std::collections::BinaryHeap;

struct Tri {
    ub: f64,
    v: [[f64; 3]; 3],
    g: [f64; 3],
}
ordered_by_ub!(Tri);

fn angle(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let c: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
    c.clamp(-1.0, 1.0).acos()
}

/// Upper bound of a sublinear `g` over the spherical triangle `v` with vertex values `g`.
fn tri_bound(v: &[[f64; 3]; 3], g: &[f64; 3]) -> f64 {
    let V = nalgebra::Matrix3::from_fn(|i, j| v[j][i]); // columns v_j
    let gmax = g.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let edges = || {
        let mut e = f64::NEG_INFINITY;
        for (i, j) in [(0, 1), (1, 2), (0, 2)] {
            e = e.max(arc_bound(g[i], g[j], angle(&v[i], &v[j])));
        }
        e
    };
    let Some(Vi) = V.try_inverse() else { return f64::INFINITY };
    let l = Vi.transpose() * nalgebra::Vector3::new(g[0], g[1], g[2]);
    let coef = Vi * l;
    let inside = coef.iter().all(|c| *c >= 0.0);
    let b = if inside { l.norm() } else { edges() };
    b * (1.0 + 1e-12) + 1e-12 * gmax
}

pub(super) fn triangles_max(mut g: impl FnMut(&[f64]) -> f64, s: &SphereMaxSettings) -> Enclosure {
    let mut evals = 0usize;
    let mut lower = f64::NEG_INFINITY;
    let mut ev = |v: &[f64; 3], evals: &mut usize, lower: &mut f64| {
        *evals += 1;
        let x = g(v);
        *lower = lower.max(x);
        x
    };
    let mut heap = BinaryHeap::new();
    let axes = |i: usize, sgn: f64| {
        let mut a = [0.0; 3];
        a[i] = sgn;
        a
    };
    let mut vals = std::collections::HashMap::new();
    for i in 0..3 {
        for sgn in [1.0, -1.0] {
            let a = axes(i, sgn);
            vals.insert((i, sgn as i8), ev(&a, &mut evals, &mut lower));
        }
    }
    for sx in [1.0, -1.0] {
        for sy in [1.0, -1.0] {
            for sz in [1.0, -1.0] {
                let v = [axes(0, sx), axes(1, sy), axes(2, sz)];
                let gv = [vals[&(0, sx as i8)], vals[&(1, sy as i8)], vals[&(2, sz as i8)]];
                heap.push(Tri { ub: tri_bound(&v, &gv), v, g: gv });
            }
        }
    }
    while let Some(top) = heap.peek() {
        if top.ub - lower <= s.tol_abs.max(s.tol_rel * lower.abs()) || evals >= s.max_evals {
            break;
        }
        let t = heap.pop().expect("nonempty");
        // longest edge (i, j), opposite vertex k
        let mut best = (0, 1, 2, -1.0);
        for (i, j, k) in [(0, 1, 2), (1, 2, 0), (0, 2, 1)] {
            let a = angle(&t.v[i], &t.v[j]);
            if a > best.3 {
                best = (i, j, k, a);
            }
        }
        let (i, j, k, _) = best;
        let mut m: [f64; 3] = std::array::from_fn(|d| t.v[i][d] + t.v[j][d]);
        let nm = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
        m.iter_mut().for_each(|x| *x /= nm);
        let gm = ev(&m, &mut evals, &mut lower);
        for (a, ga) in [(i, t.g[i]), (j, t.g[j])] {
            let v = [t.v[a], m, t.v[k]];
            let gv = [ga, gm, t.g[k]];
            heap.push(Tri { ub: tri_bound(&v, &gv), v, g: gv });
        }
    }
    let upper = heap.peek().map(|t| t.ub).unwrap_or(lower).max(lower);
    Enclosure::new(lower, upper)
}
