//! `p = 2`: branch and bound on arcs of the unit circle (module docs of [`super`]).
use crate::sphere_max::ordered_by_ub;
use crate::{Enclosure, SphereMaxSettings};
use std::collections::BinaryHeap;

/// Upper bound of a sublinear `g` over the arc from angle 0 to `delta` given its end values.
pub fn arc_bound(g1: f64, g2: f64, delta: f64) -> f64 {
    let (s, c) = delta.sin_cos();
    let A = g1;
    let B = (g2 - g1 * c) / s;
    let phi = B.atan2(A);
    let v = if phi >= 0.0 && phi <= delta { (A * A + B * B).sqrt() } else { g1.max(g2) };
    v * (1.0 + 4.0 * f64::EPSILON) + 4.0 * f64::EPSILON * (g1.abs() + g2.abs())
}

struct Arc {
    ub: f64,
    a0: f64,
    a1: f64,
    g0: f64,
    g1: f64,
}
ordered_by_ub!(Arc);

/// `max_{|v| = 1} g(v)` for sublinear `g` on the unit circle: the worst arc (largest
/// [`arc_bound`]) is split at its midpoint until the gap is within tolerance or the budget is
/// spent.
pub(super) fn arcs_max(mut g: impl FnMut(&[f64]) -> f64, s: &SphereMaxSettings) -> Enclosure {
    let mut ev = |a: f64| g(&[a.cos(), a.sin()]);
    let n0 = 64;
    let angles: Vec<f64> = (0..=n0).map(|i| std::f64::consts::TAU * i as f64 / n0 as f64).collect();
    let vals: Vec<f64> = angles[..n0].iter().map(|&a| ev(a)).collect();
    let mut evals = n0;
    let mut lower = vals.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let mut heap = BinaryHeap::new();
    for i in 0..n0 {
        let (g0, g1) = (vals[i], vals[(i + 1) % n0]);
        heap.push(Arc { ub: arc_bound(g0, g1, angles[i + 1] - angles[i]), a0: angles[i], a1: angles[i + 1], g0, g1 });
    }
    while let Some(top) = heap.peek() {
        if top.ub - lower <= s.tol_abs.max(s.tol_rel * lower.abs()) || evals >= s.max_evals {
            break;
        }
        let arc = heap.pop().expect("nonempty");
        let am = 0.5 * (arc.a0 + arc.a1);
        let gm = ev(am);
        evals += 1;
        lower = lower.max(gm);
        heap.push(Arc { ub: arc_bound(arc.g0, gm, am - arc.a0), a0: arc.a0, a1: am, g0: arc.g0, g1: gm });
        heap.push(Arc { ub: arc_bound(gm, arc.g1, arc.a1 - am), a0: am, a1: arc.a1, g0: gm, g1: arc.g1 });
    }
    let upper = heap.peek().map(|a| a.ub).unwrap_or(lower).max(lower);
    Enclosure::new(lower, upper)
}
