//! Speed floors of the backlash for balls and ellipsoids in R^2 and R^3 (beyond the paper;
//! proofs-notes/theta-engaged-balls.md): `theta_engaged` for `p >= 2`.
//!
//! Write `v = z - y` (in `Theta`). Almost everywhere where `v` is on the boundary, with `n` the
//! outward unit normal at the contact point `v` (the normal cone of a smooth set), the sweeping
//! process gives `z' = <y', n> n` with `<y', n> <= 0`, so `|z'| = -<y', n>`: only the normal
//! component of `y'` moves `z`. Along the orbit take the direction `e = eta_T' / |eta_T'|` and
//! write, asymptotically, `y' = s' e + q` with `s' >= s := |eta_T'| - D` and `|q| <= tau := D`
//! (`D` the radius of `C(F Xi_inf + E Theta)`, the band of (ydot)). With `c = -<n, e>`,
//!
//! ```text
//! |z'| = s' c - <q, n> >= s c - tau sqrt(1 - c^2)        (c >= 0).
//! ```
//!
//! How far the contact normal is from `-e` is measured by the gap
//! `G = <v, e> + sigma_Theta(-e) >= 0` (`0` exactly at the trailing point `x*(e)`, whose outward
//! normal is `-e`). With `Theta` inside a ball of radius `R` and containing one of radius `r`
//! at each boundary point (`R` the strong-convexity constant, `r` the smallest radius of
//! curvature: `R = r =` the radius for a ball, `a_max^2 / a_min` and `a_min^2 / a_max` for an
//! ellipsoid), `r (1 - c) <= G <= R (1 - c)` and `|v - x*(e)|^2 <= 2 R G`, and almost everywhere
//!
//! ```text
//! G' <= H(G) := max( -s + omega sqrt(2 R G),                                    (v inside)
//!                    -s (G / R) m(G) + tau min(1, sqrt(2 G / r)) + omega sqrt(2 R G) )  (v on the boundary)
//! ```
//!
//! with `omega >= |e'|` (at most `|eta_T''| / |eta_T'|`) and `m(G) = max(2 - G / r,
//! 1 - tau / sqrt(s^2 + tau^2)) <= 1 + c`. From `G <= width` at the start of a run of orbit
//! samples with `s > 0`, a bound `G_bar` is propagated step by step by a barrier argument (an
//! upper level where `H < 0` is never crossed upwards; where `H <= -kappa` on a band below the
//! level, `G` drops by `kappa dt` or to the band's bottom). Once `G_bar < r` and the floor
//! `s c_lo - tau sqrt(1 - c_lo^2)` (`c_lo = 1 - G_bar / r`) is positive, `v` cannot leave the
//! boundary (there `<y', n> < 0`); while it is inside, `G` falls at rate at least
//! `s - omega sqrt(2 R G_bar)`, so it touches the boundary within a computable time, and from
//! then on the floor holds: the cell is engaged.
//!
//! **Curvature.** On the boundary the Gauss map turns `v' = -(I - n n^T) y'` into
//! `n' = S v'`, `S` the shape operator (eigenvalues in `[1/R, 1/r]`), so with
//! `a = sqrt(1 - c^2)`, almost everywhere while `v` slides,
//!
//! ```text
//! c' >= a (s a / R - tau / sqrt(r R) - omega)      (where a >= tau sqrt(R / r) / (2 s)),
//! ```
//!
//! a sharper law than the gap's when `R / r` is large (elongated ellipsoids). Levels of `c`
//! where this is positive are barriers, and a bound `c_bar` is raised along it.
//!
//! **Catch.** For a threshold `c_hi` above `tau / sqrt(s^2 + tau^2)` (above which `v` cannot
//! leave the boundary) that is a barrier, the good set `{v on the boundary, c > c_hi}` is never
//! left, and outside it `G` falls at least at `min(s, a_hi (s a_hi - tau)) - omega sqrt(2 R G)`
//! (`a_hi = sqrt(1 - c_hi^2)`; on the boundary `|c| <= c_hi` there): as `G >= 0`, `v` is in the
//! good set after a computable time. Floors are the largest over the gap argument and the
//! thresholds `C_HI` (each a valid proof).
//!
//! Computed in the safe direction (rates and floors rounded down, `H` and `G_bar` up).
use crate::orbit::EtaOrbit;
use geometry::{ConvexSet, Shape};
use rounding::{pad_down, pad_up, sqrt_down, sqrt_up};

/// Relative margin of the evaluations here (a few roundings each, far below it).
const REL: f64 = 1e-12;

/// What the floors need of `Theta`: proven bounds of its curvature radii and its width.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactGeometry {
    /// Lower bound of the smallest radius of curvature (a ball of this radius inside `Theta`
    /// touches every boundary point).
    pub r_inner: f64,
    /// Upper bound of the strong-convexity constant `R` (`Theta` inside a ball of radius `R`
    /// tangent at every boundary point).
    pub R: f64,
    /// Upper bound of the diameter (`G <= width` always).
    pub width: f64,
}

impl ContactGeometry {
    /// A ball (`r = R = ` radius) or an ellipsoid with a proven eigenvalue enclosure of its shape
    /// matrix (`r >= lambda_min / sqrt(lambda_max)`); `R` is the caller's proven upper bound of
    /// the strong-convexity constant (`R_upper >= r` is checked). `None` for other sets, a
    /// point, or an ellipsoid whose enclosure failed.
    pub fn of(theta: &Shape, R_upper: f64) -> Option<Self> {
        let r_inner = match theta {
            Shape::Ball(b) if b.radius > 0.0 => b.radius,
            Shape::Ellipsoid(e) => {
                let enc = e.eigen_enclosure()?;
                if !(enc.min_lower > 0.0) {
                    return None;
                }
                pad_down(enc.min_lower / sqrt_up(enc.max_upper), REL)
            }
            _ => return None,
        };
        let width = pad_up(theta.diameter().upper, REL);
        let ok = r_inner > 0.0 && R_upper.is_finite() && R_upper >= r_inner && width.is_finite();
        ok.then_some(Self { r_inner, R: R_upper, width })
    }
}

/// The constants of one orbit sample interval: lower bound `s` of `<y', e>`, bound `tau` of the
/// part of `y'` across `e`, bound `omega` of `|e'|`. `None`: no direction (`s <= 0`) or a jump of
/// `eta_T'` inside (a run of engagement is broken there).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Substep {
    pub s: f64,
    pub tau: f64,
    pub omega: f64,
    /// Upper bound of `<y', e>` (`|eta_T'| + sigma_band(e)`): with the contact normal within
    /// `c >= c_k` of `-e`, `|z'| <= s_max + tau sqrt(1 - c_k^2)` (the engaged ceiling).
    pub s_max: f64,
}

/// Floors and ceilings of `|z'|` per orbit sample interval and per cell (floor 0 and ceiling
/// infinite where not engaged).
#[derive(Debug, Clone, PartialEq)]
pub struct ContactFloors {
    /// Per sample interval of the orbit.
    pub sub_floor: Vec<f64>,
    pub sub_ceiling: Vec<f64>,
    /// Per cell: the smallest of its sample intervals' floors and the largest ceiling.
    pub floor: Vec<f64>,
    pub ceiling: Vec<f64>,
    /// Per sample interval: the bound `G_bar` of the gap over it.
    pub gap: Vec<f64>,
}

/// Upper bounds of the support function of the band `C(F Xi_inf + E Theta)` of (ydot) in a
/// direction: `sigma_{C F Xi_inf}(u) + sigma_Theta((C E)^T u)` with the tube kernel's proven
/// upper value, the error of `fl(C F)` ([`crate::tube::cf_rounding::cf_support_error`]) and the
/// rounding of `(C E)^T u`; never above `D`, its radius.
pub struct Band<'a> {
    tube_CF: &'a crate::tube::TubeKernel,
    theta: &'a Shape,
    CEt: nalgebra::DMatrix<f64>,
    err: f64,
    d: f64,
}

impl<'a> Band<'a> {
    /// `tube_CF` the kernel of `C F Xi_inf` built with `tube` (the semigroup `sg` of `F`), `d`
    /// the proven `D`.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        tube_CF: &'a crate::tube::TubeKernel,
        C: &nalgebra::DMatrix<f64>,
        F: &nalgebra::DMatrix<f64>,
        E: &nalgebra::DMatrix<f64>,
        theta: &'a Shape,
        sg: &crate::tube::SemigroupData,
        tube: &crate::tube::TubeSettings,
        d: f64,
    ) -> Self {
        let d_theta = theta.deviation_from_origin().upper;
        let CE = C * E;
        // fl(C E) and fl((C E)^T u): within gamma_{n + p + 2} (|C| |E|) |u| of the exact values
        let abs_ce: f64 = (C.abs() * E.abs()).iter().map(|x| x * x).sum::<f64>().sqrt();
        let err_w = rounding::gamma(C.ncols() + C.nrows() + 2) * abs_ce * 2.0;
        let err = crate::tube::cf_rounding::cf_support_error(C, F, E, tube.f_radius, sg, d_theta) + d_theta * err_w;
        Self { tube_CF, theta, CEt: CE.transpose(), err, d }
    }

    /// Upper bound of `sigma_band(u)` for `|u| <= 1 + 1e-9` (at most `D`).
    pub fn support_upper(&self, u: &[f64]) -> f64 {
        let w = &self.CEt * nalgebra::DVector::from_column_slice(u);
        let v = self.tube_CF.support_upper(u) + self.theta.support_upper(w.as_slice()) + self.err;
        let v = pad_up(v, 4.0 * REL);
        if v.is_finite() {
            v.min(self.d)
        } else {
            self.d
        }
    }
}

/// Laps of the period: the state is started from `G <= width` at `t = 0` of some late period
/// and carried over; the last lap's floors hold in every later period.
const LAPS: usize = 3;

/// The sample intervals' constants of `orbit` (closed-form samples; `None` when the orbit is not
/// verified, `p < 2`, or `D` is not finite): `|eta_T'|` from below by the samples less the
/// Lipschitz constant times half the spacing and the samples' margin, `omega = Lip / |eta_T'|`.
///
/// `band(u)` bounds the support function of the band of (ydot) in the unit direction `u`
/// ([`Band::support_upper`]; `|_| D` is always valid): `<y', e> >= |eta_T'| - band(-e)`, with
/// `band` taken at both ends of the interval plus `D` times the turn of `e` over half of it and
/// the samples' direction error.
pub fn substeps(orbit: &EtaOrbit, d_ftheta: f64, band: &dyn Fn(&[f64]) -> f64) -> Option<Vec<Option<Substep>>> {
    if !orbit.verified || orbit.deta.first().map_or(0, Vec::len) < 2 || !d_ftheta.is_finite() {
        return None;
    }
    let K = orbit.t.len() - 1;
    let dt = orbit.period / K as f64;
    let lip = orbit.deta_lipschitz;
    let slack = pad_up(0.5 * dt * lip + 2.0 * orbit.rel_margin * orbit.eta_dot_inf, REL);
    let sample_err = 2.0 * orbit.rel_margin * orbit.eta_dot_inf;
    let norm = |d: &[f64]| d.iter().map(|x| x * x).sum::<f64>().sqrt();
    let unit = |d: &[f64], sign: f64| -> Vec<f64> {
        let n = norm(d);
        d.iter().map(|x| sign * x / n).collect()
    };
    let jumps: std::collections::BTreeSet<usize> = orbit.jumps.iter().map(|j| j.interval).collect();
    // |eta_T'| from below and above on each interval, and |e'| from above
    let (m, top): (Vec<f64>, Vec<f64>) = (0..K)
        .map(|k| {
            let (a, b) = (norm(&orbit.deta[k]), norm(&orbit.deta[k + 1]));
            (pad_down(a.min(b) * (1.0 - REL) - slack, REL), pad_up(a.max(b) * (1.0 + REL) + slack, REL))
        })
        .unzip();
    // The band in the direction of motion, evaluated at every BAND_STRIDE-th sample (the tube
    // kernel's support is the costly part): on a block of intervals e stays within
    // omega_max (block length) / 2 of a direction at the block's ends (plus the samples'
    // direction error 2 sample_err / m), and the band's support is D-Lipschitz.
    let blocks = K.div_ceil(BAND_STRIDE);
    // the band against and along the motion at a block boundary, evaluated once for the two
    // blocks that share it
    let mut at_boundary: Vec<Option<(f64, f64)>> = vec![None; blocks + 1];
    let mut band_at = |i: usize| -> (f64, f64) {
        let slot = &mut at_boundary[i.div_ceil(BAND_STRIDE)];
        *slot.get_or_insert_with(|| {
            let d = &orbit.deta[i];
            (band(&unit(d, -1.0)), band(&unit(d, 1.0)))
        })
    };
    let block_band: Vec<(f64, f64)> = (0..blocks)
        .map(|bk| {
            let (i0, i1) = (bk * BAND_STRIDE, ((bk + 1) * BAND_STRIDE).min(K));
            let m_min = m[i0..i1].iter().copied().fold(f64::INFINITY, f64::min);
            if !(m_min > 0.0 && lip.is_finite()) || (i0..i1).any(|k| jumps.contains(&k)) {
                return (d_ftheta, d_ftheta);
            }
            let omega = pad_up(lip / m_min, REL);
            let span = (i1 - i0) as f64 * dt;
            let turn = pad_up(d_ftheta * (omega * 0.5 * span + 2.0 * sample_err / m_min + 1e-9), REL);
            let ((back_a, fwd_a), (back_b, fwd_b)) = (band_at(i0), band_at(i1));
            let back = pad_up(back_a.max(back_b) + turn, REL).min(d_ftheta);
            let fwd = pad_up(fwd_a.max(fwd_b) + turn, REL).min(d_ftheta);
            (back, fwd)
        })
        .collect();
    Some(
        (0..K)
            .map(|k| {
                if jumps.contains(&k) || !(m[k] > 0.0 && lip.is_finite()) {
                    return None;
                }
                let omega = pad_up(lip / m[k], REL);
                let (back, fwd) = block_band[k / BAND_STRIDE];
                let s = pad_down(m[k] - back, REL);
                (s > 0.0).then(|| Substep { s, tau: d_ftheta, omega, s_max: pad_up(top[k] + fwd, REL) })
            })
            .collect(),
    )
}

/// Orbit sample intervals per evaluation of the band's support ([`substeps`]).
const BAND_STRIDE: usize = 10;

/// Upper bound of `H(G)` for `G in [g1, g2]` (module docs).
fn h_upper(g1: f64, g2: f64, st: &Substep, geo: &ContactGeometry) -> f64 {
    let (s, tau, omega) = (st.s, st.tau, st.omega);
    let (r, R) = (geo.r_inner, geo.R);
    let g1 = g1.max(0.0);
    let drift = pad_up(omega * sqrt_up(2.0 * R * g2), REL);
    let inside = -s + drift;
    // m(G) from below on [g1, g2] (non-increasing in G)
    let m_width = 2.0 - pad_up(g2 / r, REL);
    let m_slide = 1.0 - pad_up(tau / sqrt_down(s * s + tau * tau), REL);
    let m = m_width.max(m_slide).max(0.0);
    let pull = pad_down(s * (g1 / R) * m, 4.0 * REL);
    let across = pad_up(tau * sqrt_up(pad_up(2.0 * g2 / r, REL)).min(1.0), REL);
    let boundary = -pull + across + drift;
    let v = inside.max(boundary);
    v + REL * (s + pull + across + drift) + f64::MIN_POSITIVE
}

/// One sample interval of length `dt` from `G <= g0`: `(sup of G over it, bound at its end)`.
fn gap_step(g0: f64, dt: f64, st: &Substep, geo: &ContactGeometry) -> (f64, f64) {
    let W = geo.width;
    // G <= width always
    let g0 = g0.min(W);
    let eps = 1e-9 * W;
    // a band [g0 - delta, g0] where H <= -kappa < 0: G stays <= g0 and ends <= g0 - min(delta, kappa dt)
    let mut drop = None::<f64>;
    let mut delta = g0;
    for _ in 0..40 {
        let h = h_upper(g0 - delta, g0 + eps, st, geo);
        if h < 0.0 {
            let d = delta.min(-h * dt * (1.0 - REL));
            drop = Some(drop.map_or(d, |b: f64| b.max(d)));
        }
        delta *= 0.5;
    }
    if let Some(d) = drop {
        return (g0, pad_up((g0 - d).max(0.0), REL));
    }
    // otherwise the lowest level above g0 that G cannot cross upwards
    for i in 1..=64 {
        let U = g0 + (W - g0) * i as f64 / 64.0;
        if h_upper(U - 1e-6 * W, U + eps, st, geo) < 0.0 {
            let U = pad_up(U, REL);
            return (U, U);
        }
    }
    (W, W)
}

/// `s c - tau sqrt(1 - c^2)` from below, for `c >= 0` (`0` otherwise): `|z'|` on the boundary
/// with `-<n, e> >= c`.
fn floor_at_c(c: f64, st: &Substep) -> f64 {
    if !(c >= 0.0) {
        return 0.0;
    }
    let c = c.min(1.0);
    let across = pad_up(st.tau * sqrt_up(pad_up((1.0 - c) * (1.0 + c), REL)), REL);
    pad_down(pad_down(st.s * c, REL) - across, REL).max(0.0)
}

/// `s_max + tau sqrt(1 - c^2)` from above: `|z'| = <y', e> c' - <q, n>` on the boundary with
/// `-<n, e> = c' >= c >= 0`.
fn ceiling_at_c(c: f64, st: &Substep) -> f64 {
    let c = c.clamp(0.0, 1.0);
    pad_up(st.s_max + st.tau * sqrt_up(pad_up((1.0 - c) * (1.0 + c), REL)), REL)
}

/// `c = 1 - G / r` from below: the cosine bound that the gap bound `g` gives on the boundary.
fn c_of_gap(g: f64, geo: &ContactGeometry) -> f64 {
    1.0 - pad_up(g / geo.r_inner, REL)
}

/// `tau / sqrt(s^2 + tau^2)` from above: for `c` above it `<y', n> < 0`, so `v` cannot leave
/// the boundary; on the boundary `c >=` minus it (`mu >= 0`).
fn c_leave(st: &Substep) -> f64 {
    pad_up(st.tau / sqrt_down(st.s * st.s + st.tau * st.tau), REL)
}

/// Lower bound of `c'` on the boundary for `c in [c1, c2]` (module docs, "Curvature"):
/// `a (s a / R - tau / sqrt(r R) - omega)` with `a = sqrt(1 - c^2)`, valid where
/// `a >= tau sqrt(R / r) / (2 s)`; `-inf` where that is not proven.
fn c_rate_lower(c1: f64, c2: f64, st: &Substep, geo: &ContactGeometry) -> f64 {
    let (r, R) = (geo.r_inner, geo.R);
    let a_of = |c: f64| sqrt_down(((1.0 - c.abs()) * (1.0 + c.abs())).max(0.0) * (1.0 - REL));
    let a_lo = a_of(c1).min(a_of(c2));
    let a_hi = if c1 <= 0.0 && c2 >= 0.0 { 1.0 } else { pad_up(a_of(c1).max(a_of(c2)), REL).min(1.0) };
    let need = pad_up(st.tau * sqrt_up(R / r) / (2.0 * st.s), REL);
    if a_lo < need {
        return f64::NEG_INFINITY;
    }
    let kappa = pad_up(st.tau / sqrt_down(r * R) + st.omega, REL);
    // f(a) = a (s a / R - kappa): convex, its minimum over [a_lo, a_hi] at an end or the vertex
    let f = |a: f64| a * (st.s * a / R - kappa);
    let vertex = kappa * R / (2.0 * st.s);
    let mut m = f(a_lo).min(f(a_hi));
    if vertex > a_lo && vertex < a_hi {
        m = m.min(f(vertex));
    }
    m - REL * (st.s / R + kappa) - f64::MIN_POSITIVE
}

/// The largest level `L <= c` (down to `c_floor`) that `c` cannot cross downwards over the
/// substep (`c' > 0` on a band just below `L`), `None` if there is none above `c_floor`.
fn c_barrier(c: f64, c_floor: f64, st: &Substep, geo: &ContactGeometry) -> Option<f64> {
    (0..=16).map(|i| c - (c - c_floor) * i as f64 / 16.0).find(|&L| {
        let band = 1e-6 * (1.0 + L.abs());
        L > c_floor && c_rate_lower(L - band, L, st, geo) > 0.0
    })
}

/// The bound `L` raised over a substep of length `dt`: by `min(delta, kappa dt)` where
/// `c' >= kappa > 0` on `[L, L + delta]`.
fn c_gain(L: f64, dt: f64, st: &Substep, geo: &ContactGeometry) -> f64 {
    let mut best = 0.0f64;
    let mut delta = 1.0 - L;
    for _ in 0..30 {
        let k = c_rate_lower(L, (L + delta).min(1.0), st, geo);
        if k > 0.0 {
            best = best.max(delta.min(k * dt * (1.0 - REL)));
        }
        delta *= 0.5;
    }
    L + best * (1.0 - REL)
}

/// Thresholds `c_hi` of the "catch" argument (module docs): each gives a valid proof; the
/// floors are the largest over them.
const C_HI: [f64; 6] = [0.2, 0.4, 0.6, 0.75, 0.85, 0.92];

/// Rate at which `G` falls while `v` is inside or on the boundary with `-c_hi <= c <= c_hi`,
/// from below (`<= 0`: none proven). `drift` bounds `omega sqrt(2 R G)`.
fn catch_rate(c_hi: f64, st: &Substep, drift: f64) -> f64 {
    let a = sqrt_down(((1.0 - c_hi) * (1.0 + c_hi)) * (1.0 - REL));
    if a < st.tau / (2.0 * st.s) * (1.0 + REL) {
        return 0.0;
    }
    let boundary = pad_down(a * pad_down(st.s * a - st.tau, REL), REL);
    pad_down(boundary.min(st.s) - drift, REL)
}

/// Floors of `|z'|` per sample interval (module docs) from the intervals' constants, each of
/// length `dt`; `start_gap` the bound of `G` at the start of a run (`geo.width`: any state).
/// Returns the floors, the engaged ceilings (infinite where not engaged) and the gap bounds per
/// interval.
pub fn floors_from_substeps(
    subs: &[Option<Substep>],
    dt: f64,
    geo: &ContactGeometry,
    start_gap: f64,
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let K = subs.len();
    let mut floor = vec![0.0; K];
    let mut ceiling = vec![f64::INFINITY; K];
    let mut gaps = vec![geo.width; K];
    let mut g = start_gap;
    // Some(c_bar): v is on the boundary with -<n, e> >= c_bar at the start of the interval
    let mut engaged: Option<f64> = None;
    // open windows while not engaged: the gap argument ("touch budget") and one catch argument
    // per threshold of C_HI, each the bound of G had v stayed in its bad set since it opened
    let mut touch: Option<f64> = None;
    let mut catch: [Option<f64>; C_HI.len()] = [None; C_HI.len()];
    for lap in 0..LAPS {
        let last = lap + 1 == LAPS;
        for (k, sub) in subs.iter().enumerate() {
            let Some(st) = sub else {
                (g, engaged, touch, catch) = (start_gap, None, None, [None; C_HI.len()]);
                if last {
                    (floor[k], ceiling[k], gaps[k]) = (0.0, f64::INFINITY, geo.width);
                }
                continue;
            };
            let (sup, next) = gap_step(g, dt, st, geo);
            let leave = c_leave(st);
            let c_gap = c_of_gap(sup, geo);
            let drift = pad_up(st.omega * sqrt_up(2.0 * geo.R * sup), REL);
            let (mut fk, mut ck) = (0.0, f64::INFINITY);
            if let Some(cb) = engaged {
                // the cosine bound kept over the interval: a barrier level below cb, or the gap's
                let barrier = c_barrier(cb, leave, st, geo);
                let c_eff = barrier.unwrap_or(f64::NEG_INFINITY).max(c_gap);
                if c_eff > leave {
                    fk = floor_at_c(c_eff, st);
                    ck = ceiling_at_c(c_eff, st);
                    let raised = barrier.map_or(f64::NEG_INFINITY, |L| c_gain(L, dt, st, geo));
                    engaged = Some(raised.max(c_of_gap(next, geo)));
                } else {
                    engaged = None;
                }
            } else {
                let mut caught = f64::NEG_INFINITY;
                // the gap argument: v cannot leave the boundary once c_gap > leave; inside, G
                // falls at rate s - drift, so it touches within the budget
                if c_gap > leave {
                    let p = touch.unwrap_or(g) - pad_down(st.s - drift, REL).max(0.0) * dt * (1.0 - REL);
                    touch = Some(p);
                    if p < -REL * geo.width {
                        caught = caught.max(c_of_gap(next, geo));
                    }
                } else {
                    touch = None;
                }
                // the catch arguments: outside the good set {boundary, c > c_hi} (absorbing when
                // c_hi > leave and c_hi is a barrier) G falls at the catch rate
                for (w, &c_hi) in catch.iter_mut().zip(&C_HI) {
                    let rate = catch_rate(c_hi, st, drift);
                    let good = c_hi > leave && rate > 0.0 && c_rate_lower(c_hi - 1e-6, c_hi, st, geo) > 0.0;
                    if !good {
                        *w = None;
                        continue;
                    }
                    let p = w.unwrap_or(g) - rate * dt * (1.0 - REL);
                    *w = Some(p);
                    if p < -REL * geo.width {
                        caught = caught.max(c_hi);
                    }
                }
                if caught > leave {
                    (engaged, touch, catch) = (Some(caught), None, [None; C_HI.len()]);
                }
            }
            if last {
                (floor[k], ceiling[k], gaps[k]) = (fk, ck, sup);
            }
            g = next;
        }
    }
    (floor, ceiling, gaps)
}

/// The floors for `orbit` split into `cells` equal cells (`cells` divides the samples), `None`
/// when [`substeps`] gives none or no cell is engaged.
pub fn contact_floors(
    orbit: &EtaOrbit,
    cells: usize,
    d_ftheta: f64,
    band: &dyn Fn(&[f64]) -> f64,
    geo: &ContactGeometry,
) -> Option<ContactFloors> {
    let subs = substeps(orbit, d_ftheta, band)?;
    let K = subs.len();
    if cells == 0 || !K.is_multiple_of(cells) {
        return None;
    }
    let dt = orbit.period / K as f64;
    let (sub_floor, sub_ceiling, gap) = floors_from_substeps(&subs, dt, geo, geo.width);
    let per = K / cells;
    let floor: Vec<f64> =
        (0..cells).map(|c| sub_floor[c * per..(c + 1) * per].iter().copied().fold(f64::INFINITY, f64::min)).collect();
    let ceiling: Vec<f64> =
        (0..cells).map(|c| sub_ceiling[c * per..(c + 1) * per].iter().copied().fold(0.0, f64::max)).collect();
    floor.iter().any(|&f| f > 0.0).then_some(ContactFloors { sub_floor, sub_ceiling, floor, ceiling, gap })
}

/// The floors of `sys` as [`crate::assemble`] computes them (its stage 2's tube kernel of
/// `C F Xi_inf`, `D`, `R` and orbit, rebuilt here with the same settings), for tests and
/// benchmarks that compare them with simulations: `(floors, D)`, `None` where the assembly
/// computes none.
pub fn for_system(
    sys: &model::System,
    cells: usize,
    settings: &crate::ThetaSettings,
) -> Result<Option<(ContactFloors, f64)>, crate::BoundsError> {
    use crate::tube::{tube_diameters_with, SemigroupData, TubeSettings};
    let F = sys.F();
    let (C, E) = (&sys.C, &sys.E);
    let tube =
        TubeSettings { f_radius: lmi::verify::f_enclosure_radius(&F, E, C).norm() * (1.0 + 1e-10), ..settings.tube };
    let sg = SemigroupData::new(&F);
    let d_theta = sys.theta.deviation_from_origin().upper;
    let diam = tube_diameters_with(C, &F, E, &sys.theta, d_theta, &sg, &tube, &settings.sphere)?;
    let d_ftheta = diam.d_ftheta.upper;
    let orbit = EtaOrbit::new(sys, &settings.orbit)?;
    let Some(geo) = ContactGeometry::of(&sys.theta, sys.theta.strong_convexity().upper()) else { return Ok(None) };
    let band = Band::new(&diam.tube_CF, C, &F, E, &sys.theta, &sg, &tube, d_ftheta);
    let K = orbit.t.len() - 1;
    let cells = (1..=cells.min(K).max(1)).rev().find(|&d| K.is_multiple_of(d)).unwrap_or(1);
    Ok(contact_floors(&orbit, cells, d_ftheta, &|u| band.support_upper(u), &geo).map(|f| (f, d_ftheta)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ball(r: f64) -> ContactGeometry {
        ContactGeometry { r_inner: r, R: r, width: 2.0 * r }
    }

    /// A circle orbit of speed 1 and turning rate 1 (`eta = (sin t, -cos t)`) against a ball of
    /// radius 0.2 with no band: the steady lag of the normal is `asin(omega r / s) = asin(0.2)`,
    /// so the floor tends to `cos(asin 0.2) = 0.98`; the bound must get close and stay below.
    #[test]
    fn circle_without_band_approaches_the_exact_steady_speed() {
        let geo = ball(0.2);
        let st = Substep { s: 1.0, tau: 0.0, omega: 1.0, s_max: 1.0 };
        let subs = vec![Some(st); 2000];
        let (floor, _, _) = floors_from_substeps(&subs, std::f64::consts::TAU / 2000.0, &geo, geo.width);
        let exact = (1.0f64 - 0.04).sqrt();
        let best = floor.iter().copied().fold(0.0, f64::max);
        assert!(best <= exact + 1e-12, "floor {best} above the exact normal speed {exact}");
        assert!(best > 0.9, "floor {best} too far below {exact}");
    }

    /// A break (no direction) resets the run: the sample intervals right after it are not
    /// engaged (the backlash may rest while `y` crosses the gap).
    #[test]
    fn a_break_resets_engagement() {
        let geo = ball(0.2);
        let st = Substep { s: 1.0, tau: 0.05, omega: 0.5, s_max: 1.1 };
        let mut subs = vec![Some(st); 400];
        subs[100] = None;
        let (floor, _, _) = floors_from_substeps(&subs, 0.01, &geo, geo.width);
        assert_eq!(floor[100], 0.0);
        assert_eq!(floor[101], 0.0, "just after a break nothing is engaged");
        assert!(floor[399] > 0.5, "{}", floor[399]);
    }
}
