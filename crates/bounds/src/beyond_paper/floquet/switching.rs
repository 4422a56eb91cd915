//! The phase conditions that make a zero of the shooting system ([`super::period_map`]) a
//! trajectory of the sweeping process with the assumed phase sequence, checked with intervals
//! over the verified box (every state `X_j` and duration `h_j` enclosed):
//!
//! - engaged on a face with sign `s` (`s = -1` on `hi`, `+1` on `lo`): `s y'(t) > 0` on the
//!   phase (so `z' = y'` is the projection of eq. (zdot): the play is pushed); at a release
//!   (`y' = 0` by the shooting equation) transversality `s y''(t) < 0` on a last piece
//!   `[h - eps, h]` (then `s y' > 0` before the release, and `y'` changes sign there);
//! - resting: `lo < q(t) < hi` inside the phase (so `z' = 0` is eq. (zdot)); after a release
//!   from `hi` (`q = hi`, `y' = 0`), `y'' > 0` and `q > lo` on a first piece `[0, eps]` (then `y'
//!   > 0`, `q` decreases from `hi`), mirrored after a release from `lo`; before a contact with
//!   the face `lo` (`q = lo`), `y' > 0` and `q < hi` on a last piece (then `q` decreases to
//!   `lo`: a transversal contact, `y'` pushing), mirrored for `hi`.
//!
//! Every condition is a strict inequality of a linear function `r . X(t)` with `X(t) =
//! e^{t G} X_j` enclosed over a piece of times ([`super::flow::expm_interval`]); pieces that
//! fail are bisected (up to [`MAX_DEPTH`] times). With these conditions the sweeping process's
//! solution from the section state is the piecewise flow (the solution of eq. (zdot) is
//! unique), so the zero is the periodic regime and the phase sequence is the one assumed.
//! Grazing (a switch with `y' = 0` at a contact, or `y'' = 0` at a release) cannot pass.
use super::flow::{dot, Face, Generators, PhaseKind};
use super::imat::IMat;
use super::period_map::Evaluation;
use rounding::Ival;

/// Most bisections of a piece.
pub const MAX_DEPTH: usize = 12;
/// Pieces per phase before bisection.
const PIECES: usize = 16;

/// Why a phase condition could not be proven.
#[derive(Debug, Clone, PartialEq)]
pub struct PhaseFailure {
    pub phase: usize,
    pub what: &'static str,
}

/// The range of a linear function `r . X(t)` over a piece of times, in the centred (mean
/// value) form `r . X(t_c) + [a - t_c, b - t_c] (r G) . X([a, b])`, intersected with the direct
/// enclosure `r . X([a, b])`: the crude enclosure of the whole piece enters only through the
/// derivative, so the range is tight to second order in the piece length.
pub struct Piece<'p> {
    G: &'p IMat,
    /// `X(t_c)`; `None`: the direct enclosure alone.
    Xc: Option<IMat>,
    Xr: IMat,
    dt: Ival,
}

impl Piece<'_> {
    pub fn range(&self, row: &[Ival]) -> Ival {
        let direct = dot(row, &self.Xr);
        let Some(Xc) = &self.Xc else { return direct };
        let d = row.len();
        let rG: Vec<Ival> =
            (0..d).map(|j| (0..d).fold(Ival::point(0.0), |s, i| s.add(row[i].mul(self.G.at(i, j))))).collect();
        let centred = dot(row, Xc).add(self.dt.mul(dot(&rG, &self.Xr)));
        centred.intersect(&direct).unwrap_or(centred)
    }
    fn valid(&self) -> bool {
        self.Xr.is_valid() && self.Xc.as_ref().is_none_or(|x| x.is_valid())
    }
}

/// A condition on the linear functions of `X(t)` over a piece.
type Cond<'c> = &'c dyn Fn(&Piece) -> bool;

/// `cond` on `X(t)` for all `t` in `[a, b]` (with bisection), from the state `X = X(tx)` at a
/// reference time `tx` (an end of the piece, so the flows are short): first on the direct
/// enclosure (one flow), then in the centred form; both halves of a bisection keep the
/// reference.
#[allow(clippy::too_many_arguments)]
fn holds(g: &Generators, kind: PhaseKind, X: &IMat, tx: f64, a: f64, b: f64, cond: Cond, depth: usize) -> bool {
    let tc = 0.5 * (a + b);
    let rel = |t: Ival| t.sub(Ival::point(tx));
    let mut piece = Piece {
        G: g.generator(kind),
        Xc: None,
        Xr: g.flow_apply(kind, rel(Ival::new(a, b)), X),
        dt: Ival::new(a, b).sub(Ival::point(tc)),
    };
    if piece.valid() && cond(&piece) {
        return true;
    }
    let Xc = g.flow_apply(kind, rel(Ival::point(tc)), X);
    piece.Xc = Some(Xc.clone());
    if piece.valid() && cond(&piece) {
        return true;
    }
    if depth >= MAX_DEPTH || !(b > a) || !Xc.is_valid() {
        return false;
    }
    // both halves from the same reference state (chaining the states would compound the
    // wrapping of the basis change at every level)
    holds(g, kind, X, tx, a, tc, cond, depth + 1) && holds(g, kind, X, tx, tc, b, cond, depth + 1)
}

/// An end piece `[0, eps]` (forward from `X`, or backward with `sign = -1`) on which `cond`
/// holds, trying `eps / 2^m`; the length found.
fn end_piece(g: &Generators, kind: PhaseKind, X: &IMat, eps: f64, sign: f64, cond: Cond) -> Option<f64> {
    let mut e = eps;
    for _ in 0..=MAX_DEPTH {
        let ok = if sign > 0.0 {
            holds(g, kind, X, 0.0, 0.0, e, cond, MAX_DEPTH)
        } else {
            holds(g, kind, X, 0.0, -e, 0.0, cond, MAX_DEPTH)
        };
        if ok {
            return Some(e);
        }
        e *= 0.5;
    }
    None
}

/// Checks every phase of `ev` (an evaluation of the shooting system over the verified box).
pub fn check_phases(g: &Generators, kinds: &[PhaseKind], ev: &Evaluation) -> Result<(), PhaseFailure> {
    let k = kinds.len() - 1;
    let (lo, hi) = (g.lo, g.hi);
    let qr = g.q_row();
    for j in 0..=k {
        let kind = kinds[j];
        let h = ev.durations[j];
        if !(h.lo > 0.0) {
            return Err(PhaseFailure { phase: j, what: "duration not provably positive" });
        }
        let (Xs, Xe) = (&ev.states[j], &ev.states[j + 1]);
        let eps = h.lo / PIECES as f64;
        let r1 = g.ydot_row(kind);
        let r2 = g.yddot_row(kind);
        let (mut t_a, mut t_b) = (0.0, h.hi);
        match kind {
            PhaseKind::Engaged(face) => {
                let s = if face == Face::Hi { -1.0 } else { 1.0 };
                if j < k {
                    // release at the end: s y'' < 0 on a last piece
                    let c = |P: &Piece| P.range(&r2).scale(s).is_negative();
                    let e = end_piece(g, kind, Xe, eps, -1.0, &c)
                        .ok_or(PhaseFailure { phase: j, what: "release not transversal (y'' sign)" })?;
                    t_b = h.hi - e;
                }
                let c = |P: &Piece| P.range(&r1).scale(s).is_positive();
                if !piecewise(g, kind, Xs, t_a, t_b, &c) {
                    return Err(PhaseFailure { phase: j, what: "engaged phase: y' does not keep pushing" });
                }
            }
            PhaseKind::Resting => {
                let inside = |P: &Piece| {
                    let q = P.range(&qr);
                    q.lo > lo.hi && q.hi < hi.lo
                };
                if j > 0 {
                    let PhaseKind::Engaged(from) = kinds[j - 1] else {
                        return Err(PhaseFailure { phase: j, what: "two resting phases in a row" });
                    };
                    let s = if from == Face::Hi { 1.0 } else { -1.0 };
                    let c = |P: &Piece| {
                        let q = P.range(&qr);
                        P.range(&r2).scale(s).is_positive()
                            && if from == Face::Hi { q.lo > lo.hi } else { q.hi < hi.lo }
                    };
                    t_a = end_piece(g, kind, Xs, eps, 1.0, &c).ok_or(PhaseFailure {
                        phase: j,
                        what: "leaving the face after release not proven (y'' sign)",
                    })?;
                }
                if j < k {
                    let PhaseKind::Engaged(to) = kinds[j + 1] else {
                        return Err(PhaseFailure { phase: j, what: "two resting phases in a row" });
                    };
                    let s = if to == Face::Lo { 1.0 } else { -1.0 };
                    let c = |P: &Piece| {
                        let q = P.range(&qr);
                        P.range(&r1).scale(s).is_positive() && if to == Face::Lo { q.hi < hi.lo } else { q.lo > lo.hi }
                    };
                    let e = end_piece(g, kind, Xe, eps, -1.0, &c)
                        .ok_or(PhaseFailure { phase: j, what: "contact not transversal (y' sign)" })?;
                    t_b = h.hi - e;
                }
                if !piecewise(g, kind, Xs, t_a, t_b, &inside) {
                    return Err(PhaseFailure { phase: j, what: "resting phase: q does not stay inside Theta" });
                }
            }
        }
    }
    Ok(())
}

/// `cond` on `[a, b]` split into [`PIECES`] pieces, each bisected as needed.
fn piecewise(g: &Generators, kind: PhaseKind, X: &IMat, a: f64, b: f64, cond: Cond) -> bool {
    if !(b >= a) {
        return false;
    }
    let step = (b - a) / PIECES as f64;
    (0..PIECES).all(|i| {
        let (s, e) = (a + i as f64 * step, if i + 1 == PIECES { b } else { a + (i + 1) as f64 * step });
        let Xs = g.flow_apply(kind, Ival::point(s), X);
        Xs.is_valid() && holds(g, kind, &Xs, s, s, e, cond, 0)
    })
}
