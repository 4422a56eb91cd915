//! `2 <= p <= MAX_CONE_DIM`: branch and bound on simplicial cones, the worst cone split at
//! its longest edge; the cone bound is the smaller of the conic-interpolation bound (a) and the
//! flat-simplex bound (b) (module docs of [`super`]).
use super::nnls::nnls;
use super::{EPS, M, MAX_CONE_DIM};
use crate::sphere_max::ordered_by_ub;
use crate::{Enclosure, SphereMaxSettings};
use std::collections::{BinaryHeap, HashMap};

/// A simplicial cone: `p` vertex ids (into the shared vertex list), its upper bound, the
/// positions in `idx` of its longest edge and its depth in the subdivision.
#[derive(Clone, Copy)]
struct Cone {
    ub: f64,
    idx: [u32; M],
    edge: (u8, u8),
    depth: u16,
}

/// Certified upper bound of a sublinear `g` over the unit vectors of the cone spanned by the
/// vertices `idx` (rows of `verts`, values `gval`), and the positions of its longest edge.
/// See the module docs, bounds (a) and (b).
#[cfg(test)]
pub(super) fn cone_bound(p: usize, verts: &[f64], gval: &[f64], idx: &[u32]) -> (f64, (u8, u8)) {
    match p {
        2 => cone_bound_p::<2>(verts, gval, idx),
        3 => cone_bound_p::<3>(verts, gval, idx),
        4 => cone_bound_p::<4>(verts, gval, idx),
        5 => cone_bound_p::<5>(verts, gval, idx),
        6 => cone_bound_p::<6>(verts, gval, idx),
        7 => cone_bound_p::<7>(verts, gval, idx),
        8 => cone_bound_p::<8>(verts, gval, idx),
        _ => panic!("cone_bound: dimension {p} outside 2..={MAX_CONE_DIM}"),
    }
}

/// [`cone_bound`] for a dimension known at compile time (the loops unroll).
#[inline]
fn cone_bound_p<const P: usize>(verts: &[f64], gval: &[f64], idx: &[u32]) -> (f64, (u8, u8)) {
    let p = P;
    let pf = p as f64;
    let v = |i: usize| &verts[idx[i] as usize * p..][..p];
    let mut gv = [0.0; M];
    for i in 0..p {
        gv[i] = gval[idx[i] as usize];
    }
    if gv[..p].iter().any(|x| x.is_nan()) {
        return (f64::NAN, (0, 1));
    }
    let gmax = gv[..p].iter().fold(f64::NEG_INFINITY, |m, x| m.max(*x));
    let gabs = gv[..p].iter().fold(0.0f64, |m, x| m.max(x.abs()));
    // Gram matrix; longest edge = smallest G_ij, ties broken by the global vertex ids so that
    // neighbouring cones choose (and share) the same midpoint.
    let mut G = [0.0; M * M];
    let mut edge = (0u8, 1u8);
    let mut key = (f64::INFINITY, u32::MAX, u32::MAX);
    for i in 0..p {
        for j in i..p {
            let d: f64 = v(i).iter().zip(v(j)).map(|(x, y)| x * y).sum();
            G[i * M + j] = d;
            G[j * M + i] = d;
            if j > i {
                let k = (d, idx[i].min(idx[j]), idx[i].max(idx[j]));
                if k.0 < key.0 || (k.0 == key.0 && (k.1, k.2) < (key.1, key.2)) {
                    key = k;
                    edge = (i as u8, j as u8);
                }
            }
        }
    }
    // |fl(G_ij) - v_i.v_j| <= gamma_p |v_i||v_j| <= eg (vertices are unit up to (p+4) eps)
    let eg = (pf + 2.0) * 1.02 * EPS;
    // (b): lower bounds of dist(0, conv(v_i))
    let mut m = f64::INFINITY;
    let mut c = f64::INFINITY;
    let mut rows = [0.0; M];
    for i in 0..p {
        m = m.min(G[i * M + i]);
        for j in 0..p {
            rows[i] += G[i * M + j];
            if j != i {
                c = c.min(G[i * M + j]);
            }
        }
    }
    let (m, c) = (m - eg, c - eg);
    let w2 = m.min(m / pf + c * (1.0 - 1.0 / pf));
    let d_gram = w2.max(0.0).sqrt() * (1.0 - 4.0 * EPS);
    let tot: f64 = rows[..p].iter().sum();
    let row_min = rows[..p].iter().fold(f64::INFINITY, |a, b| a.min(*b));
    // row sums: p Gram errors plus the summation, gamma_p each
    let er = 2.0 * pf * (pf + 2.0) * 1.02 * EPS;
    let num = row_min - er;
    let den = tot + pf * er;
    let d_u = if num > 0.0 && den > 0.0 { num / den.sqrt() * (1.0 - 4.0 * EPS) } else { 0.0 };
    let dlow = d_gram.max(d_u);
    // upper bound of sum a_i over the unit vectors of the cone
    let S = if dlow > 0.0 { 1.0 / dlow * (1.0 + 2.0 * EPS) } else { f64::INFINITY };
    let ub_b = if gmax >= 0.0 { gmax * S * (1.0 + 2.0 * EPS) } else { gmax * (1.0 - 8.0 * EPS) };
    // (a): conic interpolation with the NNLS point a* >= 0 and mu = max(G a* - g, 0)
    let mut a = [0.0; M];
    nnls::<P>(&G, &gv, &mut a);
    let a1: f64 = a[..p].iter().sum();
    let mut rmax = 0.0f64;
    for i in 0..p {
        let q: f64 = (0..p).map(|j| G[i * M + j] * a[j]).sum();
        // s_i = fl(g_i + mu_i) >= g_i since mu_i >= 0
        let s = gv[i] + (q - gv[i]).max(0.0);
        rmax = rmax.max((q - s).abs());
    }
    // |r_true - fl(r)|: Gram error and the matrix-vector product, each <= gamma_p |a|_1
    let rb = rmax * (1.0 + 2.0 * EPS) + 4.0 * (pf + 1.0) * EPS * a1;
    let mut z2 = 0.0;
    for k in 0..p {
        let zk: f64 = (0..p).map(|i| a[i] * v(i)[k]).sum();
        z2 += zk * zk;
    }
    let zn = z2.sqrt() * (1.0 + (pf + 2.0) * EPS) + 2.0 * (pf + 1.0) * EPS * a1;
    let ub_a = if rb > 0.0 { zn + rb * S } else { zn };
    let ub = if ub_a.is_finite() { ub_a.min(ub_b) } else { ub_b };
    (ub + 1e-12 * (ub.abs() + gabs), edge)
}

/// `max_{|v| = 1} g(v)` for sublinear `g` and `2 <= p <= MAX_CONE_DIM` by branch and bound on
/// simplicial cones (module docs; `sublinear_sphere_max` uses it for `p >= 4`). `lower` is the
/// best sampled value, `upper` a certified bound, valid (only wider) when the budget runs out.
pub fn cones_max(p: usize, g: impl FnMut(&[f64]) -> f64, s: &SphereMaxSettings) -> Enclosure {
    assert!((2..=MAX_CONE_DIM).contains(&p), "cones_max: dimension must be in 2..={MAX_CONE_DIM}");
    match p {
        2 => cones_max_p::<2>(g, s),
        3 => cones_max_p::<3>(g, s),
        4 => cones_max_p::<4>(g, s),
        5 => cones_max_p::<5>(g, s),
        6 => cones_max_p::<6>(g, s),
        7 => cones_max_p::<7>(g, s),
        _ => cones_max_p::<8>(g, s),
    }
}

/// A heap entry: a cone's upper bound and its slot in the cone arena (16 bytes, so that the
/// heap of up to millions of cones moves little memory).
#[derive(Clone, Copy)]
struct Entry {
    ub: f64,
    slot: u32,
}
ordered_by_ub!(Entry);

/// [`cones_max`] for a dimension known at compile time: the `2^p` cones of the coordinate
/// axes, then the open cone of largest bound split at its longest edge until the gap, the
/// evaluations or the splits run out.
fn cones_max_p<const P: usize>(g: impl FnMut(&[f64]) -> f64, s: &SphereMaxSettings) -> Enclosure {
    let p = P;
    let mut found = Vertices::axes(p, g);
    let mut open = Open::with_capacity(1 << p);
    for mask in 0..1u32 << p {
        let mut idx = [0u32; M];
        for (i, x) in idx[..p].iter_mut().enumerate() {
            *x = 2 * i as u32 + (mask >> i & 1);
        }
        let (ub, edge) = cone_bound_p::<P>(&found.verts, &found.gval, &idx[..p]);
        open.push(Cone { ub, idx, edge, depth: 0 });
    }
    // Splits may reuse cached midpoints without an evaluation (many do for larger p): cap them
    // too, scaled with the O(p^3) cost of a cone bound, and at 2e6 (about 100 MB of cones).
    let max_splits = (s.max_evals.max(64) * 4000 / p.pow(3)).min(2_000_000);
    let mut splits = 0usize;
    let mut max_depth = 0u16;
    while let Some(top) = open.heap.peek() {
        if top.ub.is_nan()
            || top.ub - found.lower <= s.tol_abs.max(s.tol_rel * found.lower.abs())
            || found.evals >= s.max_evals
            || splits >= max_splits
        {
            break;
        }
        let cone = open.pop();
        let (i, j) = (cone.edge.0 as usize, cone.edge.1 as usize);
        let mid = found.midpoint((cone.idx[i].min(cone.idx[j]), cone.idx[i].max(cone.idx[j])));
        let depth = cone.depth.saturating_add(1);
        max_depth = max_depth.max(depth);
        for replace in [i, j] {
            let mut idx = cone.idx;
            idx[replace] = mid;
            let (ub, edge) = cone_bound_p::<P>(&found.verts, &found.gval, &idx[..p]);
            open.push(Cone { ub, idx, edge, depth });
        }
        splits += 1;
    }
    let U = open.heap.peek().map(|c| c.ub).unwrap_or(found.lower);
    covered(p, found.lower, U, max_depth)
}

/// The enclosure from the best value `lower` and the largest open bound `U` after splits as
/// deep as `max_depth`: a NaN value of g voids the bound (and `f64::max` would hide it); the
/// covering slivers of the floating midpoints (module docs) widen it, `max g <= U / (1 - D delta)`.
fn covered(p: usize, lower: f64, U: f64, max_depth: u16) -> Enclosure {
    if U.is_nan() {
        return Enclosure::new(lower, f64::NAN);
    }
    let delta = 4.0 * (p as f64).sqrt() * (p as f64 + 4.0) * EPS;
    let cover = f64::from(max_depth) * delta;
    let upper = if U > 0.0 { U / (1.0 - cover) * (1.0 + 2.0 * EPS) } else { U };
    Enclosure::new(lower, upper.max(lower))
}

/// The unit vectors met so far (rows of `verts`), g at each (`gval`), the number of
/// evaluations and the best value; the midpoints of edges already split, by vertex ids.
struct Vertices<G> {
    p: usize,
    g: G,
    verts: Vec<f64>,
    gval: Vec<f64>,
    evals: usize,
    lower: f64,
    mids: HashMap<(u32, u32), u32>,
}

impl<G: FnMut(&[f64]) -> f64> Vertices<G> {
    /// The `2p` signed coordinate axes: vertex `2i` is `+e_i`, `2i + 1` is `-e_i`.
    fn axes(p: usize, g: G) -> Self {
        let mut found = Vertices {
            p,
            g,
            verts: Vec::with_capacity(p * 4096),
            gval: Vec::with_capacity(4096),
            evals: 0,
            lower: f64::NEG_INFINITY,
            mids: HashMap::new(),
        };
        let mut e = vec![0.0; p];
        for i in 0..p {
            for sgn in [1.0, -1.0] {
                e.iter_mut().for_each(|x| *x = 0.0);
                e[i] = sgn;
                found.add(&e);
            }
        }
        found
    }

    /// Evaluates g at the unit vector `v` and keeps both; the new vertex's id.
    fn add(&mut self, v: &[f64]) -> u32 {
        let x = (self.g)(v);
        self.evals += 1;
        self.lower = self.lower.max(x);
        let id = self.gval.len() as u32;
        self.verts.extend_from_slice(v);
        self.gval.push(x);
        id
    }

    /// The normalised midpoint of the edge between vertices `key` (ids, smaller first), made
    /// and evaluated once: neighbouring cones share it.
    fn midpoint(&mut self, key: (u32, u32)) -> u32 {
        if let Some(&id) = self.mids.get(&key) {
            return id;
        }
        let p = self.p;
        let (a, b) = (key.0 as usize * p, key.1 as usize * p);
        let mut m: Vec<f64> = (0..p).map(|k| self.verts[a + k] + self.verts[b + k]).collect();
        let n = crate::linalg::norm(&m);
        m.iter_mut().for_each(|x| *x /= n);
        let id = self.add(&m);
        self.mids.insert(key, id);
        id
    }
}

/// The open cones: an arena whose slots of split cones are reused, and a heap of (bound, slot).
struct Open {
    arena: Vec<Cone>,
    free: Vec<u32>,
    heap: BinaryHeap<Entry>,
}

impl Open {
    fn with_capacity(n: usize) -> Self {
        Open { arena: Vec::with_capacity(n), free: Vec::new(), heap: BinaryHeap::with_capacity(n) }
    }

    fn push(&mut self, cone: Cone) {
        let slot = match self.free.pop() {
            Some(k) => {
                self.arena[k as usize] = cone;
                k
            }
            None => {
                self.arena.push(cone);
                (self.arena.len() - 1) as u32
            }
        };
        self.heap.push(Entry { ub: cone.ub, slot });
    }

    /// The open cone of largest bound, taken out (its slot freed).
    fn pop(&mut self) -> Cone {
        let slot = self.heap.pop().expect("nonempty").slot;
        self.free.push(slot);
        self.arena[slot as usize]
    }
}
