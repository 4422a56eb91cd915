//! The walk over the quadrature cells ([`TubeKernel::build`]): blocks of cells of equal width,
//! `e^{mF}` propagated from centre to centre with its error, the cell matrices
//! `K -+ r K'`, `K` and their error bounds, and the tiling of `[0, S]`
//! (proofs-notes/tube-quadrature.md, "the quadrature matrices" and "the cells").
use super::semigroup::SemigroupData;
use super::{frob, Accum, ThetaSupport, TubeKernel};
use geometry::Shape;
use nalgebra::DMatrix;
use rounding::{gamma, two_sum, UNIT_ROUNDOFF};

/// Cells per block (one exponential step across each block boundary).
const BLOCK: usize = 32;

impl TubeKernel {
    /// The cells of width `h(s) = h0 e^{grade s}` (capped at `h_cap`) in blocks of [`BLOCK`]
    /// tiling `[0, s_max]`; `None` when more than `max_cells` would be needed.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn build(
        sg: &SemigroupData,
        L: &DMatrix<f64>,
        LF: &DMatrix<f64>,
        LF2: &DMatrix<f64>,
        F: &DMatrix<f64>,
        E: &DMatrix<f64>,
        theta: &Shape,
        s_max: f64,
        h0: f64,
        grade: f64,
        h_cap: f64,
        d_theta: f64,
        nF: f64,
        nE: f64,
        msup: f64,
        r: usize,
        p: usize,
        max_cells: usize,
    ) -> Option<(Self, Accum)> {
        let mut walk = CellWalk::new(sg, L, LF, LF2, F, E, d_theta, nF, nE, msup, None);
        let mut sb = 0.0;
        let mut h_first = f64::NAN;
        while sb < s_max {
            let mut hb = (h0 * (grade * sb).exp()).min(h_cap).max(h0);
            let mut count = BLOCK;
            if sb + BLOCK as f64 * hb >= s_max {
                count = (((s_max - sb) / hb).ceil() as usize).max(1);
                hb = (s_max - sb) / count as f64;
            }
            if h_first.is_nan() {
                h_first = hb;
            }
            if walk.half.len() + count > max_cells {
                return None;
            }
            walk.block(hb, count);
            sb += count as f64 * hb;
            if count < BLOCK {
                break;
            }
        }
        Some(walk.finish(theta, s_max, h_first, r, p))
    }

    /// The number of cells [`Self::build`] would make (the same block arithmetic, no matrices),
    /// counted up to `limit + 1`.
    pub(super) fn graded_cells(s_max: f64, h0: f64, grade: f64, h_cap: f64, limit: usize) -> usize {
        let (mut sb, mut cells) = (0.0, 0usize);
        while sb < s_max && cells <= limit {
            let mut hb = (h0 * (grade * sb).exp()).min(h_cap).max(h0);
            let mut count = BLOCK;
            if sb + BLOCK as f64 * hb >= s_max {
                count = (((s_max - sb) / hb).ceil() as usize).max(1);
                hb = (s_max - sb) / count as f64;
            }
            cells += count;
            sb += count as f64 * hb;
            if count < BLOCK {
                break;
            }
        }
        cells
    }

    /// The cells of a stiff `F` (proofs-notes/tube-quadrature.md, "stiff plants"): block widths
    /// set by the local second-derivative bound, `h = 2^floor(log2(2 c / cbrt(D_Theta M2)))`
    /// (the width that equidistributes the remainder `D_Theta M2 r^3 / 3` against the number of
    /// cells), `M2` of the last cell of the previous block, at most doubling from block to block;
    /// `M2` is also bounded through the previous centre and `msup` (`alt_msup`, which must be
    /// `>= sup_{s >= 0} ||e^{sF}||_2`), so a cell may be wider than `1 / ||F||`. The widths only
    /// affect efficiency, not rigour. `None` when more than `max_cells` cells would be needed.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn build_adaptive(
        sg: &SemigroupData,
        L: &DMatrix<f64>,
        LF: &DMatrix<f64>,
        LF2: &DMatrix<f64>,
        F: &DMatrix<f64>,
        E: &DMatrix<f64>,
        theta: &Shape,
        s_max: f64,
        c: f64,
        d_theta: f64,
        nF: f64,
        nE: f64,
        msup: f64,
        alt_msup: f64,
        r: usize,
        p: usize,
        max_cells: usize,
    ) -> Option<(Self, Accum)> {
        let mut walk = CellWalk::new(sg, L, LF, LF2, F, E, d_theta, nF, nE, msup, Some(alt_msup));
        let mut sb = 0.0;
        let mut h_first = f64::NAN;
        let mut h_prev = f64::NAN;
        // the smallest width (widths far below the tiling's resolution are useless)
        let h_floor = (s_max * 1e-12).max(1e-300);
        while sb < s_max {
            let m2 = if walk.half.is_empty() { walk.prev_bracket * alt_msup * nE } else { walk.last_m2 };
            let target = 2.0 * c / (d_theta * m2).cbrt();
            let mut hb = if target.is_finite() && target > 0.0 {
                2f64.powi(target.log2().floor().clamp(-1000.0, 1000.0) as i32)
            } else {
                s_max
            };
            if !h_prev.is_nan() {
                hb = hb.min(2.0 * h_prev);
            }
            hb = hb.max(h_floor);
            let mut count = BLOCK;
            if sb + BLOCK as f64 * hb >= s_max {
                count = (((s_max - sb) / hb).ceil() as usize).max(1);
                hb = (s_max - sb) / count as f64;
            }
            if h_first.is_nan() {
                h_first = hb;
            }
            if walk.half.len() + count > max_cells {
                return None;
            }
            walk.block(hb, count);
            h_prev = hb;
            sb += count as f64 * hb;
            if count < BLOCK {
                break;
            }
        }
        Some(walk.finish(theta, s_max, h_first, r, p))
    }
}

/// The state of the walk: the stored cell matrices and sums, `P ~ e^{tau F}` at the current
/// cell centre `tau` (the exact sum of the float steps, kept as a double-double
/// `(t_hi, t_lo)`), and the summed local errors `cum_loc`.
struct CellWalk<'a> {
    sg: &'a SemigroupData,
    F: &'a DMatrix<f64>,
    L: &'a DMatrix<f64>,
    LF: &'a DMatrix<f64>,
    LF2: &'a DMatrix<f64>,
    E: &'a DMatrix<f64>,
    d_theta: f64,
    nF: f64,
    nE: f64,
    msup: f64,
    /// `gamma_n` and the norms of `L`, `fl(L F)`, `fl(fl(L F) F)`.
    gn: f64,
    nL: f64,
    nLF: f64,
    nLF2: f64,
    /// Errors of `fl(L F)` and `fl(fl(L F) F)` against `L F` and `L F^2`.
    e_LF: f64,
    e_LF2: f64,
    minus: Vec<f64>,
    mid: Vec<f64>,
    plus: Vec<f64>,
    half: Vec<f64>,
    remainder: f64,
    k_l1: f64,
    acc: Accum,
    P: Option<DMatrix<f64>>,
    cum_loc: f64,
    prev_rr: f64,
    t_hi: f64,
    t_lo: f64,
    t_lo_abs: f64,
    defects: f64,
    /// `Some(msup)` (`>= sup_{s >= 0} ||e^{sF}||_2`): `M2` is also bounded through the previous
    /// centre (stiff plants); `None`: the centre and `e^{r ||F||}` alone.
    alt: Option<f64>,
    /// Upper bound of `||L F^2 e^{m' F}||_F` at the previous centre `m'` (at `0` before the first
    /// cell), and the last cell's `M2`.
    prev_bracket: f64,
    /// Anchors `(a, b)`: a centre `a` (0 first, then the first centre of each block) and
    /// `b >= ||L F e^{aF}||_F`; for the current block, `anchor_b` (the anchor's `b`) and
    /// `g_alt >= sup_{u >= u_lo} ||F e^{uF}||_2`, `u_lo` at most the distance from the anchor
    /// to the block's start.
    anchors: Vec<(f64, f64)>,
    anchor_b: f64,
    g_alt: f64,
    last_m2: f64,
    /// Stiff plants: the row blocks `W e^{mF}`, `W = [L; fl(L F); fl(fl(L F) F)]`, propagated
    /// instead of `e^{mF}` (their errors scale with `||L F^k e^{mF}||`, not `||L F^k|| ||e^{mF}||`).
    rows: Option<Rows>,
}

/// `Q ~ W e^{mF}` (`3 r x n`) and, per row block `k`, the summed local errors `cum[k]`
/// (Frobenius) and the error of the block of `W` itself (`init[k]`, against `L F^k`).
struct Rows {
    Q: DMatrix<f64>,
    r: usize,
    cum: [f64; 3],
    init: [f64; 3],
}

impl Rows {
    /// `||Q_k||_F` rounded up as `frobenius_up` does.
    fn norm(&self, k: usize) -> f64 {
        let b = self.Q.rows(k * self.r, self.r);
        let s: f64 = b.iter().map(|x| x * x).sum();
        s.sqrt() * (1.0 + 2.0 * gamma(b.len() + 2))
    }
    /// `Q <- fl(Q S)` with `e_S >= ||S - e^{hF}||_2`: block `k` gains the local error
    /// `||Q_k||_F (e_S + gamma_n ||S||_F)` (then carried by the exact semigroup).
    fn step(&mut self, S: &DMatrix<f64>, eS: f64, gn: f64) {
        let nS = frob(S);
        for k in 0..3 {
            self.cum[k] += self.norm(k) * (eS + gn * nS);
        }
        self.Q = &self.Q * S;
    }
}

impl<'a> CellWalk<'a> {
    #[allow(clippy::too_many_arguments)]
    fn new(
        sg: &'a SemigroupData,
        L: &'a DMatrix<f64>,
        LF: &'a DMatrix<f64>,
        LF2: &'a DMatrix<f64>,
        F: &'a DMatrix<f64>,
        E: &'a DMatrix<f64>,
        d_theta: f64,
        nF: f64,
        nE: f64,
        msup: f64,
        alt: Option<f64>,
    ) -> Self {
        let n = F.nrows();
        let gn = gamma(n);
        let nL = frob(L);
        let nLF = frob(LF);
        let nLF2 = frob(LF2);
        // fl(L F) and fl(fl(L F) F) against L F and L F^2.
        let e_LF = gn * nL * nF;
        let e_LF2 = e_LF * nF + gn * nLF * nF;
        // ||L F^2 e^{0 F}|| = ||L F^2||: fl(L F F) (exact identity) and its error.
        let nI = (n as f64).sqrt() * (1.0 + 4.0 * UNIT_ROUNDOFF);
        let prev_bracket = nLF2 + gn * nLF2 * nI + e_LF2 * nI;
        let bracket1_at_0 = nLF + gn * nLF * nI + e_LF * nI;
        Self {
            sg,
            F,
            L,
            LF,
            LF2,
            E,
            d_theta,
            nF,
            nE,
            msup,
            gn,
            nL,
            nLF,
            nLF2,
            e_LF,
            e_LF2,
            minus: Vec::new(),
            mid: Vec::new(),
            plus: Vec::new(),
            half: Vec::new(),
            remainder: 0.0,
            k_l1: 0.0,
            acc: Accum::default(),
            P: None,
            cum_loc: 0.0,
            prev_rr: 0.0,
            t_hi: 0.0,
            t_lo: 0.0,
            t_lo_abs: 0.0,
            defects: 0.0,
            alt,
            prev_bracket,
            rows: alt.map(|_| {
                let r = L.nrows();
                let mut Q = DMatrix::<f64>::zeros(3 * r, n);
                Q.rows_mut(0, r).copy_from(L);
                Q.rows_mut(r, r).copy_from(LF);
                Q.rows_mut(2 * r, r).copy_from(LF2);
                Rows { Q, r, cum: [0.0; 3], init: [0.0, e_LF, e_LF2] }
            }),
            anchors: vec![(0.0, bracket1_at_0)],
            anchor_b: f64::INFINITY,
            g_alt: f64::INFINITY,
            last_m2: f64::NAN,
        }
    }

    /// The exact centre moves by `x`: `(t_hi, t_lo) += x` (TwoSum).
    fn advance(&mut self, x: f64) {
        let (s, e) = two_sum(self.t_hi, x);
        self.t_hi = s;
        self.t_lo += e;
        self.t_lo_abs += e.abs();
    }

    /// One block of `count` cells of width `hb`.
    fn block(&mut self, hb: f64, count: usize) {
        let rr = 0.5 * hb;
        let grow = (rr * self.nF).exp();
        let (step, e_step) = self.sg.exp_step(hb);
        let n_step = frob(&step);
        if let Some(ms) = self.alt {
            // The block starts at sb; the last anchor a <= sb / 2 and u_lo = 2^floor(log2(sb - a))
            // (shrunk by 1e-9 against the rounding of the positions): for every cell of the
            // block, ||L F^2 e^{sF}|| <= b ||F e^{u_lo F}|| ms.
            let sb = if self.half.is_empty() { 0.0 } else { self.t_hi + self.prev_rr };
            let &(a, b) = self.anchors.iter().rev().find(|(a, _)| *a <= 0.5 * sb).unwrap_or(&self.anchors[0]);
            let gap = (sb - a) * (1.0 - 1e-9);
            if gap > 0.0 {
                let u_lo = 2f64.powi(gap.log2().floor() as i32);
                let (X, eX) = self.sg.exp_step(u_lo);
                let nX = frob(&X);
                let nF = self.nF;
                self.g_alt = (frob(&(self.F * &X)) + self.gn * nF * nX + nF * eX) * ms * (1.0 + 1e-12);
                self.anchor_b = b;
            } else {
                self.g_alt = f64::INFINITY;
            }
        }
        if self.rows.is_some() {
            self.first_centre_rows(rr);
            for j in 0..count {
                self.cell_rows(j, hb, rr, grow, &step, e_step);
            }
        } else {
            self.first_centre(rr);
            for j in 0..count {
                self.cell(j, hb, rr, grow, &step, e_step, n_step);
            }
        }
        self.prev_rr = rr;
    }

    /// `P` moves to the first centre of a block of half-width `rr` (from `0`, or across the
    /// block boundary by `r_prev + rr`, whose TwoSum error is a tiling defect).
    fn first_centre(&mut self, rr: f64) {
        self.P = Some(match self.P.take() {
            None => {
                let (P0, e0) = self.sg.exp_step(rr);
                self.cum_loc += e0;
                self.advance(rr);
                P0
            }
            Some(Pp) => {
                let (g, e) = two_sum(self.prev_rr, rr);
                self.defects += e.abs();
                let (G, eG) = self.sg.exp_step(g);
                self.cum_loc += frob(&Pp) * (eG + self.gn * frob(&G));
                self.advance(g);
                &Pp * &G
            }
        });
    }

    /// [`Self::first_centre`] for the row blocks: `Q` moves to the first centre of the block.
    fn first_centre_rows(&mut self, rr: f64) {
        let g = if self.half.is_empty() && self.t_hi == 0.0 {
            rr
        } else {
            let (g, e) = two_sum(self.prev_rr, rr);
            self.defects += e.abs();
            g
        };
        let (G, eG) = self.sg.exp_step(g);
        let gn = self.gn;
        if let Some(rows) = self.rows.as_mut() {
            rows.step(&G, eG, gn);
        }
        self.advance(g);
    }

    /// [`Self::cell`] for the row blocks (stiff plants, proofs-notes/tube-quadrature.md): `K`,
    /// `K'` and the bracket of `M2` from `Q_k ~ L F^k e^{mF}` with the errors
    /// `d_k = (init_k + cum_k) msup` (Frobenius).
    fn cell_rows(&mut self, j: usize, hb: f64, rr: f64, grow: f64, step: &DMatrix<f64>, e_step: f64) {
        let (gn, nE, msup) = (self.gn, self.nE, self.msup);
        if j > 0 {
            if let Some(rows) = self.rows.as_mut() {
                rows.step(step, e_step, gn);
            }
            self.advance(hb);
        }
        let rows = self.rows.as_ref().expect("row mode");
        let d = |k: usize| (rows.init[k] + rows.cum[k]) * msup * (1.0 + 1e-10);
        let (n0, n1, n2) = (rows.norm(0), rows.norm(1), rows.norm(2));
        let (d0, d1, d2) = (d(0), d(1), d(2));
        let K = rows.Q.rows(0, rows.r) * self.E;
        let nK = frob(&K);
        let e_K = d0 * nE + gn * n0 * nE;
        let K1 = rows.Q.rows(rows.r, rows.r) * self.E;
        let nK1 = frob(&K1);
        let e_K1 = d1 * nE + gn * n1 * nE;
        let bracket = n2 + d2;
        let mut M2 = bracket * grow * nE * (1.0 + 1e-12);
        let ms = self.alt.unwrap_or(f64::INFINITY);
        let via_prev = self.prev_bracket * ms * nE * (1.0 + 1e-12);
        let via_prev1 = self.anchor_b * self.g_alt * nE * (1.0 + 1e-12);
        for v in [via_prev, via_prev1] {
            if v < M2 || M2.is_nan() {
                M2 = v;
            }
        }
        self.prev_bracket = bracket;
        if j == 0 {
            self.anchors.push((self.t_hi, n1 + d1));
        }
        self.last_m2 = M2;
        self.push_cell(rr, &K, nK, e_K, &K1, nK1, e_K1, M2);
    }

    /// Stores a cell's matrices `K -+ rr K'`, `K` and adds its norms, errors, remainder and
    /// `int ||K||` contribution (shared by [`Self::cell`] and [`Self::cell_rows`]).
    #[allow(clippy::too_many_arguments)]
    fn push_cell(
        &mut self,
        rr: f64,
        K: &DMatrix<f64>,
        nK: f64,
        e_K: f64,
        K1: &DMatrix<f64>,
        nK1: f64,
        e_K1: f64,
        M2: f64,
    ) {
        let Km = K - K1 * rr;
        let Kp = K + K1 * rr;
        let e_pm = e_K + rr * e_K1 + 2.01 * UNIT_ROUNDOFF * (nK + rr * nK1);
        let acc = &mut self.acc;
        acc.norm_pm += rr * (frob(&Km) + frob(&Kp));
        acc.norm_mid += 2.0 * rr * nK;
        acc.err_pm += 2.0 * rr * e_pm;
        acc.err_mid += 2.0 * rr * e_K;
        // M is r x p; store M^T (p x r) row-major, i.e. M column-major.
        self.minus.extend(Km.iter().copied());
        self.mid.extend(K.iter().copied());
        self.plus.extend(Kp.iter().copied());
        self.half.push(rr);
        self.remainder += self.d_theta * M2 * rr * rr * rr / 3.0;
        self.k_l1 += 2.0 * rr * (nK + e_K + rr * (nK1 + e_K1) + 0.5 * rr * rr * M2);
    }

    /// Cell `j` of a block (after one step of `hb` unless it is the first): its matrices
    /// `K -+ rr K'`, `K`, their error bounds, the Taylor remainder and the norm sums.
    #[allow(clippy::too_many_arguments)]
    fn cell(&mut self, j: usize, hb: f64, rr: f64, grow: f64, step: &DMatrix<f64>, e_step: f64, n_step: f64) {
        let (gn, nL, nLF, nLF2, e_LF, e_LF2) = (self.gn, self.nL, self.nLF, self.nLF2, self.e_LF, self.e_LF2);
        let (nE, msup) = (self.nE, self.msup);
        let mut Pc = self.P.take().unwrap();
        if j > 0 {
            self.cum_loc += frob(&Pc) * (e_step + gn * n_step);
            Pc = &Pc * step;
            self.advance(hb);
        }
        let nP = frob(&Pc);
        let dP = msup * self.cum_loc * (1.0 + 1e-10);
        let PE = &Pc * self.E;
        let nPE = frob(&PE);
        let e_PE = dP * nE + gn * nP * nE;
        let K = self.L * &PE;
        let nK = frob(&K);
        let e_K = nL * e_PE + gn * nL * nPE;
        let K1 = self.LF * &PE;
        let nK1 = frob(&K1);
        let e_K1 = nLF * e_PE + e_LF * (nPE + e_PE) + gn * nLF * nPE;
        // M2 >= ||L F^2 e^{sF} E|| on the cell (1e-12: libm's exp within 1 ulp).
        let M2 = (frob(&(self.LF2 * &Pc)) + gn * nLF2 * nP + nLF2 * dP + e_LF2 * (nP + dP)) * grow * nE * (1.0 + 1e-12);
        self.push_cell(rr, &K, nK, e_K, &K1, nK1, e_K1, M2);
        self.P = Some(Pc);
    }

    /// The kernel: tiling defects and the distance of the last cell's end from `S`, and the
    /// rounding of the sums of positive terms (relative `gamma_{cells+4}`).
    fn finish(self, theta: &Shape, s_max: f64, h_first: f64, r: usize, p: usize) -> (TubeKernel, Accum) {
        let mut acc = self.acc;
        // Tiling: junction defects and the distance of the last cell's end from S.
        let end_gap = if self.half.is_empty() {
            s_max.abs()
        } else {
            let d0 = self.t_hi - s_max;
            (d0 + self.t_lo + self.prev_rr).abs()
                + 4.0 * UNIT_ROUNDOFF * (d0.abs() + self.t_lo.abs() + self.prev_rr + self.t_lo_abs)
                + 4.0 * UNIT_ROUNDOFF * UNIT_ROUNDOFF * self.t_hi
        };
        acc.tiling = (self.defects + end_gap) * self.nL * self.msup * self.nE * (1.0 + 1e-10);
        // The sums of positive terms above: relative gamma_{cells+4}.
        let gs = 1.0 + 2.0 * gamma(self.half.len() + 4);
        acc.norm_pm *= gs;
        acc.norm_mid *= gs;
        acc.err_pm *= gs;
        acc.err_mid *= gs;
        let h = if h_first.is_nan() { 0.0 } else { h_first };
        let kernel = TubeKernel {
            r,
            p,
            theta: ThetaSupport::new(theta),
            minus: self.minus,
            mid: self.mid,
            plus: self.plus,
            half: self.half,
            remainder: self.remainder * gs * (1.0 + 1e-10),
            tail: 0.0,
            rounding_up: 0.0,
            rounding_lo: 0.0,
            k_l1: self.k_l1 * gs,
            d_theta: self.d_theta,
            zero_in_theta: true,
            s_max,
            h,
        };
        (kernel, acc)
    }
}
