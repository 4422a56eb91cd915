//! `theta_profile`: eq. (theta)'s chord argument made time-resolved (beyond the paper,
//! proofs-notes/theta-profile.md).
//!
//! Eq. (theta) uses two numbers about the backlash speed `u(t) = |z'(t)| / R` of each
//! trajectory: its mean over a period is at least `gamma_1` and it never exceeds `gamma_inf`.
//! Theorem 2's proof gives more, pointwise in time (asymptotically, up to terms that vanish):
//! - the speed bound (ydot): `y'(t) in eta_T'(t) + C(F Xi_inf + E Theta)`, so with (zy)
//!   `u(t) <= g(t) := (|eta_T'(t)| + D(C(F Xi_inf + E Theta), {0})) / R`;
//! - the path bound (diffs1) on every interval: `int_a^b u >= (|eta_T(b) - eta_T(a)| - d)_+ / R`.
//!
//! On a cell `c` of the period where `g <= g_c`, the convex nonincreasing `psi` lies below its
//! chord over `[0, g_c]`: `psi(u) <= psi(0) - s_c u`, `s_c = (psi(0) - psi(g_c)) / g_c`. The
//! chord is steeper where the speed bound is lower. For a partition of the period into intervals
//! `I_k` (unions of cells) with path bounds `M_k`, the mean of `psi(u)` over a period is at most
//!
//! `psi(0) - (1/T) sum_k L_k`,  `L_k = min { sum_{c in I_k} s_c U_c : sum U_c >= M_k, 0 <= U_c <= g_c h }`,
//!
//! and `L_k` is the greedy fill of the cells of `I_k` by increasing `s_c` (a fractional knapsack).
//! With the Jensen step (Jen) over the two trajectories this bounds the Lyapunov exponent like
//! eq. (theta). Any partition gives a valid bound; the one used is chosen by dynamic programming
//! over a grid of cell boundaries. With a single cell (`g_c = gamma_inf` everywhere) and the
//! partition of (path1) the bound is `theta*`; it is never larger than `theta*` for the same
//! partition, since every `s_c` is at least the global chord's slope.
//!
//! **Engaged cells (`theta_engaged`, p = 1, proofs-notes/theta-engaged.md).** With an interval
//! `Theta = [lo, hi]` the backlash output is pinned to the output once the output has moved
//! monotonically by the width `hi - lo`: if `sigma y` is nondecreasing on `[a, t]` (`sigma = +-1`)
//! and `sigma (y(t') - y(a)) >= hi - lo` for some `t' <= t`, then `z = y + lo` (or `y + hi`) and
//! `z' = y'` on `[t', t]`. With (ydot), `sigma y' >= sigma eta_T' - D`, so on a cell where this
//! holds from an earlier time `u >= l_c := (min_c sigma eta_T' - D) / R`. A cell then carries the
//! chord of `psi` over `[l_c, g_c]` instead of `[0, g_c]`, and the path bound of an interval only
//! has to be met by the speed above the floors. With every `l_c = 0` the bound is `theta_profile`.
use crate::beyond_paper::engaged_speed::{EngagedHistory, EngagedSpeed};
use crate::exponent::psi::Psi;
use geometry::linalg::dist;
use rounding::scale_up;

/// Relative margin of the enclosures here ([`scale_up`]): `1e-12`.
const MARGIN: f64 = 1e-12;

/// Time-resolved data of one period: cell speed bounds and the orbit at the cell boundaries.
#[derive(Debug, Clone, PartialEq)]
pub struct SpeedProfile {
    /// Cell length `h = T / cells`.
    pub h: f64,
    /// `g_c`: upper bound of `u = |z'| / R` on cell `c` (asymptotically).
    pub g: Vec<f64>,
    /// `eta_T` at the cell boundaries `c h`, `c = 0..=cells`.
    pub eta: Vec<Vec<f64>>,
    /// `d` of eq. (d) divided by `R` (upper bound / upper bound of R: see [`SpeedProfile::new`]).
    pub d: f64,
    /// `R` (upper bound) used to scale the path bounds.
    pub R: f64,
    /// `l_c`: a lower bound of `u` on cell `c` (asymptotically); all `0` unless set by
    /// [`SpeedProfile::with_floors`].
    pub floor: Vec<f64>,
    /// `(floor_up, floor_down)` of [`EngagedSpeed`] once set by [`SpeedProfile::with_signed_speed`]:
    /// the floors of engaged cells then use the pinned backlash side instead of `D`.
    pub engaged_offsets: Option<(f64, f64)>,
    /// For each cell with a floor: the sign `sigma` of the motion and the number of cells of the
    /// same run that were engaged before it (the backlash is engaged for at least that many
    /// cell lengths at the start of the cell). Set by [`SpeedProfile::with_floors`].
    pub engaged_age: Vec<Option<(f64, usize)>>,
}

impl SpeedProfile {
    /// `eta`: `cells + 1` samples of `eta_T` at `c h`; `eta_dot_cell[c]`: an upper bound of
    /// `|eta_T'|` on cell `c`; `d_ftheta`: `D(C(F Xi_inf + E Theta), {0})` from above; `d` from
    /// above; `R` from above (a set strongly convex with constant `R` is so with any larger one,
    /// so (QZdot) holds with `u = |z'| / R_upper` and every bound below is in those units).
    pub fn new(T: f64, eta: Vec<Vec<f64>>, eta_dot_cell: &[f64], d_ftheta: f64, d: f64, R: f64) -> Self {
        let cells = eta_dot_cell.len();
        assert_eq!(eta.len(), cells + 1, "one more boundary than cells");
        let g = eta_dot_cell.iter().map(|e| scale_up((e + d_ftheta) / R, MARGIN)).collect();
        Self {
            h: T / cells as f64,
            g,
            eta,
            d,
            R,
            floor: vec![0.0; cells],
            engaged_offsets: None,
            engaged_age: vec![None; cells],
        }
    }

    /// The profile with the signed speed bounds of [`EngagedSpeed`] (p = 1; proofs-notes/theta-star.md):
    /// on cell `c`, `z' <= max eta_T' + ceil_up` where `z' > 0` and `-z' <= -min eta_T' + ceil_down`
    /// where `z' < 0`, so `g_c` drops to `max(high_c + ceil_up, -low_c + ceil_down, 0) / R` where
    /// that is lower (`deta_low[c]`, `deta_high[c]` enclose `eta_T'` on the cell). Later floors
    /// use the engaged offsets.
    pub fn with_signed_speed(mut self, deta_low: &[f64], deta_high: &[f64], es: &EngagedSpeed) -> Self {
        assert!(deta_low.len() == self.cells() && deta_high.len() == self.cells(), "one enclosure per cell");
        for c in 0..self.cells() {
            let top = (deta_high[c] + es.ceil_up).max(-deta_low[c] + es.ceil_down).max(0.0);
            self.g[c] = self.g[c].min(scale_up(scale_up(top, MARGIN) / self.R, MARGIN));
        }
        self.engaged_offsets = Some((es.floor_up, es.floor_down));
        self
    }

    /// The profile with the speed floors of engaged cells (p = 1; module docs): `deta_low[c]`
    /// and `deta_high[c]` enclose `eta_T'` on cell `c`, `d_ftheta` is `D` from above and `width`
    /// is `hi - lo` of `Theta = [lo, hi]` from above. A cell gets the floor
    /// `(min_c sigma eta_T' - D) / R` (rounded down) when, for one sign `sigma`, every cell of a
    /// cyclic run ending with it has `min sigma eta_T' > D` and the run's cells before it carry
    /// at least `width` of guaranteed monotone motion of `sigma y`.
    pub fn with_floors(self, deta_low: &[f64], deta_high: &[f64], d_ftheta: f64, width: f64) -> Self {
        self.with_floors_tube(deta_low, deta_high, d_ftheta, width, f64::INFINITY)
    }

    /// [`SpeedProfile::with_floors`] where the guaranteed motion of `sigma y` over the cells of a
    /// run before cell `c` is also measured through the tube (proofs-notes/theta-engaged.md,
    /// "Rise through the tube"): `sigma (y(t') - y(a)) >= sum min sigma eta_T' h - dev_diam`
    /// with `dev_diam >= diam(C Xi_inf)` (`y - eta_T = C (x - xi_T)` lies in `C Xi_inf`
    /// asymptotically at both ends), the larger of this and `sum (min sigma eta_T' - D) h`.
    /// `dev_diam = inf` gives [`SpeedProfile::with_floors`].
    pub fn with_floors_tube(
        mut self,
        deta_low: &[f64],
        deta_high: &[f64],
        d_ftheta: f64,
        width: f64,
        dev_diam: f64,
    ) -> Self {
        let K = self.cells();
        assert!(deta_low.len() == K && deta_high.len() == K, "one enclosure per cell");
        let mut floor = vec![0.0f64; K];
        let mut age: Vec<Option<(f64, usize)>> = vec![None; K];
        for sigma in [1.0f64, -1.0] {
            // m - o rounded down: the guaranteed rate of sigma y (o = D) or of the engaged
            // backlash (o = its pinned offset, EngagedSpeed), m = min sigma eta_T' on the cell
            let m: Vec<f64> = (0..K).map(|c| if sigma > 0.0 { deta_low[c] } else { -deta_high[c] }).collect();
            let minus = |m: f64, o: f64| m - o - 4.0 * f64::EPSILON * (m.abs() + o.abs());
            let rate: Vec<f64> = m.iter().map(|&m| minus(m, d_ftheta)).collect();
            // z' = y' once engaged, so the engaged rate is never below the rate of y
            let offset = self.engaged_offsets.map(|(up, down)| if sigma > 0.0 { up } else { down });
            let engaged_rate: Vec<f64> = match offset {
                Some(o) => m.iter().zip(&rate).map(|(&m, &r)| r.max(minus(m, o))).collect(),
                None => rate.clone(),
            };
            // Start each run after a cell with no guaranteed motion; with none the speed bound
            // never leaves the band of D around 0 from one side, impossible for a periodic orbit
            // unless rate is positive everywhere, which would make the run a full cycle: skip.
            let Some(start) = (0..K).find(|&c| rate[c] <= 0.0) else { continue };
            let mut moved = 0.0f64;
            // sum of min sigma eta_T' h over the run, rounded down
            let mut rise = 0.0f64;
            let mut engaged_before = 0usize;
            for k in 1..=K {
                let c = (start + k) % K;
                if rate[c] <= 0.0 {
                    moved = 0.0;
                    rise = 0.0;
                    engaged_before = 0;
                    continue;
                }
                let through_tube = rise - dev_diam - 4.0 * f64::EPSILON * (rise.abs() + dev_diam.abs());
                if moved.max(through_tube) > width {
                    floor[c] = floor[c].max(engaged_rate[c] / self.R * (1.0 - 1e-12));
                    age[c] = Some((sigma, engaged_before));
                    engaged_before += 1;
                }
                moved += rate[c] * self.h * (1.0 - 1e-12);
                rise += m[c] * self.h * (1.0 - 1e-12);
            }
        }
        // a floor never exceeds the cell's speed bound (both are bounds of the same u)
        for (f, g) in floor.iter_mut().zip(&self.g) {
            *f = f.min(*g);
        }
        self.floor = floor;
        self.engaged_age = age;
        self
    }

    /// Continued engagement (p = 1; proofs-notes/theta-engaged.md, "Continued engagement"): the
    /// cell after an engaged cell (sign `sigma`, engaged for at least `age` cell lengths at its
    /// start) is engaged too when the band of an engagement of `age + 1` cell lengths
    /// (`hist.band`, or the pinned offsets without a history) proves `sigma z' > 0` on it: while
    /// the backlash is engaged, `sigma y' = sigma z'` stays positive, so it cannot leave the side
    /// it is pushed from. Such cells get the band's floor and ceiling and continue the run,
    /// also across cells where `min sigma eta_T' <= D` (which end a run of
    /// [`SpeedProfile::with_floors`]). Call after [`SpeedProfile::with_history`].
    pub fn with_continued_runs(
        mut self,
        deta_low: &[f64],
        deta_high: &[f64],
        hist: Option<&EngagedHistory>,
        lo: f64,
        hi: f64,
    ) -> Self {
        let K = self.cells();
        assert!(deta_low.len() == K && deta_high.len() == K, "one enclosure per cell");
        let Some((off_up, off_down)) = self.engaged_offsets else { return self };
        // two passes: a run that crosses the end of the period continues at its start
        for _ in 0..2 {
            for c in 0..K {
                let prev = (c + K - 1) % K;
                let (Some((sigma, age)), None) = (self.engaged_age[prev], self.engaged_age[c]) else { continue };
                if self.floor[prev] <= 0.0 {
                    continue;
                }
                let age = age + 1;
                // sigma z' in [sl, sh] while engaged for at least age h
                let (sl, sh) = match hist {
                    Some(h) => {
                        let (a, b) = h.band(age as f64 * self.h * (1.0 - 1e-12), if sigma > 0.0 { lo } else { hi });
                        let (zl, zh) = (deta_low[c] + a, deta_high[c] + b);
                        if sigma > 0.0 {
                            (zl, zh)
                        } else {
                            (-zh, -zl)
                        }
                    }
                    None if sigma > 0.0 => (deta_low[c] - off_up, f64::INFINITY),
                    None => (-deta_high[c] - off_down, f64::INFINITY),
                };
                let (sl, sh) = (sl - 4.0 * f64::EPSILON * sl.abs(), sh + 4.0 * f64::EPSILON * sh.abs());
                if sl <= 0.0 {
                    continue;
                }
                if sh.is_finite() {
                    self.g[c] = self.g[c].min(scale_up(sh.max(0.0) / self.R, MARGIN));
                }
                self.floor[c] = self.floor[c].max(sl / self.R * (1.0 - 1e-12)).min(self.g[c]);
                self.engaged_age[c] = Some((sigma, age));
            }
        }
        self
    }

    /// The profile with given ceilings of `|z'|` per cell where lower (`p >= 2`: the engaged
    /// ceilings of balls and ellipsoids, [`crate::beyond_paper::contact_floors`]): `g_c =
    /// min(g_c, ceiling_c / R)` rounded up. Call before [`SpeedProfile::with_speed_floors`].
    pub fn with_speed_ceilings(mut self, zdot_ceiling: &[f64]) -> Self {
        assert_eq!(zdot_ceiling.len(), self.cells(), "one ceiling per cell");
        for (g, &u) in self.g.iter_mut().zip(zdot_ceiling) {
            if u.is_finite() && u >= 0.0 {
                *g = g.min(scale_up(scale_up(u, MARGIN) / self.R, MARGIN));
            }
        }
        self
    }

    /// The profile with given floors of `|z'|` per cell (`p >= 2`: the contact floors of balls
    /// and ellipsoids, [`crate::beyond_paper::contact_floors`]; proofs-notes/theta-engaged-balls.md):
    /// `l_c = floor_c / R` rounded down, never above the cell's ceiling. No engaged history.
    pub fn with_speed_floors(mut self, zdot_floor: &[f64]) -> Self {
        assert_eq!(zdot_floor.len(), self.cells(), "one floor per cell");
        for (c, &f) in zdot_floor.iter().enumerate() {
            let l = if f > 0.0 { f / self.R * (1.0 - 1e-12) } else { 0.0 };
            self.floor[c] = l.min(self.g[c]).max(0.0);
            self.engaged_age[c] = None;
        }
        self
    }

    /// The engaged cells' bounds from the backlash's engaged history ([`EngagedHistory`], p = 1;
    /// proofs-notes/theta-engaged.md, "Engaged history"): on a cell engaged (sign `sigma`) for at
    /// least `age h`, `z' - eta_T'` lies in `hist.band(age h, w)` with `w = lo` (rising) or `hi`
    /// (falling), so `sigma z'` lies in `[m_lo + a, m_hi + b]` mirrored for `sigma = -1`. Raises
    /// floors and lowers ceilings where that is sharper; the floors stay below the ceilings.
    /// Call after [`SpeedProfile::with_floors`].
    pub fn with_history(
        mut self,
        deta_low: &[f64],
        deta_high: &[f64],
        hist: &EngagedHistory,
        lo: f64,
        hi: f64,
    ) -> Self {
        let K = self.cells();
        assert!(deta_low.len() == K && deta_high.len() == K, "one enclosure per cell");
        for c in 0..K {
            let Some((sigma, age)) = self.engaged_age[c] else { continue };
            let tau = age as f64 * self.h * (1.0 - 1e-12);
            let (a, b) = hist.band(tau, if sigma > 0.0 { lo } else { hi });
            // z' in [deta_low + a, deta_high + b]; |z'| = sigma z' (> 0 on an engaged cell)
            let (zl, zh) = (deta_low[c] + a, deta_high[c] + b);
            let (sl, sh) = if sigma > 0.0 { (zl, zh) } else { (-zh, -zl) };
            let (sl, sh) = (sl - 4.0 * f64::EPSILON * sl.abs(), sh + 4.0 * f64::EPSILON * sh.abs());
            self.g[c] = self.g[c].min(scale_up(sh.max(0.0) / self.R, MARGIN));
            self.floor[c] = self.floor[c].max(sl / self.R * (1.0 - 1e-12)).min(self.g[c]);
        }
        self
    }

    /// `max_c g_c`: an upper bound of `limsup |z'| / R` (every time lies in some cell).
    pub fn max_speed(&self) -> f64 {
        self.g.iter().copied().fold(0.0, f64::max)
    }

    /// Number of cells with a positive floor.
    pub fn engaged_cells(&self) -> usize {
        self.floor.iter().filter(|&&f| f > 0.0).count()
    }

    pub fn cells(&self) -> usize {
        self.g.len()
    }

    /// `M` of the interval between boundaries `i < j`: `(|eta(j) - eta(i)| - d)_+ / R`, rounded
    /// down.
    pub fn path_lower(&self, i: usize, j: usize) -> f64 {
        let m = (dist(&self.eta[j], &self.eta[i]) - self.d).max(0.0) / self.R;
        (m * (1.0 - 1e-12)).max(0.0)
    }

    /// Chord slopes `s_c` of `psi` over `[l_c, g_c]`, rounded down (`psi` values are rounded
    /// up, and a smaller slope gives a larger, still valid, upper chord).
    pub fn slopes(&self, psi: &Psi) -> Vec<f64> {
        self.g
            .iter()
            .zip(&self.floor)
            .map(|(&g, &l)| if g > l { ((psi.eval(l) - psi.eval(g)) / (g - l) * (1.0 - 1e-12)).max(0.0) } else { 0.0 })
            .collect()
    }

    /// `L` of the cells `i..j` (boundaries `i < j`) with path bound `m`: the floors carry
    /// `sum l_c h`, the rest is a greedy fill by increasing slope up to `(g_c - l_c) h`.
    /// `scratch` is reused between calls.
    fn interval_loss(&self, s: &[f64], i: usize, j: usize, m: f64, scratch: &mut Vec<usize>) -> f64 {
        let m = m - self.floor[i..j].iter().map(|l| l * self.h).sum::<f64>() * (1.0 + 1e-12);
        if m <= 0.0 {
            return 0.0;
        }
        scratch.clear();
        scratch.extend(i..j);
        scratch.sort_unstable_by(|&a, &b| s[a].total_cmp(&s[b]));
        let mut left = m;
        let mut loss = 0.0;
        for &c in scratch.iter() {
            let cap = (self.g[c] - self.floor[c]).max(0.0) * self.h;
            let take = cap.min(left);
            loss += s[c] * take;
            left -= take;
            if left <= 0.0 {
                break;
            }
        }
        // Cells cannot carry the path bound only through the rounding of the enclosures; the
        // loss of the full capacity is then used (smaller than the true minimum: still valid).
        loss * (1.0 - 1e-12)
    }

    /// The bound `(1/T) sum_c h psi(l_c) - (1/T) sum_k L_k` (`psi(0) - (1/T) sum_k L_k` without
    /// floors) for the partition given by boundary indices `nodes` (increasing, from `0` to
    /// `cells`), rounded up.
    pub fn bound(&self, psi: &Psi, nodes: &[usize]) -> f64 {
        let s = self.slopes(psi);
        let mut scratch = Vec::new();
        let total: f64 = nodes
            .windows(2)
            .map(|w| self.interval_loss(&s, w[0], w[1], self.path_lower(w[0], w[1]), &mut scratch))
            .sum();
        let T = self.h * self.cells() as f64;
        let p0 = psi.at_zero();
        // mean of psi at the floors (psi(0) where there is none), each value rounded up
        let (base, scale) = self.floor.iter().fold((0.0f64, 0.0f64), |(b, a), &l| {
            let v = if l > 0.0 { psi.eval(l) } else { p0 };
            (b + v, a + v.abs())
        });
        let K = self.cells() as f64;
        let base = base / K + 2.0 * K * f64::EPSILON * scale / K;
        let v = base - total / T;
        v + 4.0 * f64::EPSILON * (base.abs() + (total / T).abs())
    }

    /// The partition (boundary indices from `0` to `cells`) maximising the total loss, by
    /// dynamic programming over every `stride`-th boundary (`O((cells/stride)^2)` intervals).
    pub fn best_partition(&self, psi: &Psi, stride: usize) -> Vec<usize> {
        let K = self.cells();
        let stride = stride.clamp(1, K.max(1));
        let mut grid: Vec<usize> = (0..K).step_by(stride).collect();
        grid.push(K);
        let s = self.slopes(psi);
        let mut scratch = Vec::new();
        let n = grid.len();
        let mut best = vec![0.0f64; n];
        let mut prev = vec![0usize; n];
        for b in 1..n {
            let (mut v, mut arg) = (f64::NEG_INFINITY, 0);
            for a in 0..b {
                let (i, j) = (grid[a], grid[b]);
                let l = best[a] + self.interval_loss(&s, i, j, self.path_lower(i, j), &mut scratch);
                if l > v {
                    v = l;
                    arg = a;
                }
            }
            best[b] = v;
            prev[b] = arg;
        }
        let mut nodes = vec![K];
        let mut b = n - 1;
        while b > 0 {
            b = prev[b];
            nodes.push(grid[b]);
        }
        nodes.reverse();
        nodes
    }
}

/// The profile a report's `theta_engaged` (or, with no engaged cell, `theta_profile`) was
/// computed from, with its partition and the certified `(lambda, b_hat)` points it was minimised
/// over: the evidence of the bound, for diagnostics (which input of the profile loses most:
/// `theta_benchmark`'s near-threshold mode puts measured speeds or tube widths in its place).
#[derive(Debug, Clone, PartialEq)]
pub struct ProfileEvidence {
    pub profile: SpeedProfile,
    /// Partition (cell boundary indices from `0` to `cells`).
    pub nodes: Vec<usize>,
    /// `alpha` from below and the certified `(lambda, b_hat)` points.
    pub alpha: f64,
    pub points: Vec<(f64, f64)>,
}

impl ProfileEvidence {
    /// The smallest bound of `prof` over the certified points, with the partition chosen for it
    /// at the point where the evidence's own profile is smallest (`prof` = the evidence's profile:
    /// the reported bound, up to the partition's lambda).
    pub fn bound_of(&self, prof: &SpeedProfile) -> f64 {
        let psi = |&(lambda, beta): &(f64, f64)| Psi { alpha: self.alpha, lambda, beta };
        let Some(best) = self.points.iter().min_by(|a, b| {
            self.profile.bound(&psi(a), &self.nodes).total_cmp(&self.profile.bound(&psi(b), &self.nodes))
        }) else {
            return f64::INFINITY;
        };
        let nodes = prof.best_partition(&psi(best), 4);
        self.points.iter().map(|p| prof.bound(&psi(p), &nodes)).fold(f64::INFINITY, f64::min)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circle_profile(cells: usize, amp: f64, D: f64, d: f64, R: f64) -> SpeedProfile {
        let T = std::f64::consts::TAU;
        let h = T / cells as f64;
        let eta: Vec<Vec<f64>> = (0..=cells).map(|c| vec![amp * (c as f64 * h).sin()]).collect();
        // |eta'| = amp |cos t| <= max at the cell ends + amp h (Lipschitz constant amp).
        let edot: Vec<f64> = (0..cells)
            .map(|c| {
                let (a, b) = ((c as f64 * h).cos().abs(), ((c + 1) as f64 * h).cos().abs());
                amp * (a.max(b) + h)
            })
            .collect();
        SpeedProfile::new(T, eta, &edot, D, d, R)
    }

    #[test]
    fn never_above_the_global_chord_and_constant_speed_recovers_it() {
        let psi = Psi { alpha: 0.0, lambda: 0.3, beta: 0.024 };
        let prof = circle_profile(400, 1.667, 0.214, 0.637, 0.1);
        let nodes = prof.best_partition(&psi, 4);
        let b = prof.bound(&psi, &nodes);
        // Global chord with the same partition's total path.
        let total: f64 = nodes.windows(2).map(|w| prof.path_lower(w[0], w[1])).sum();
        let gmax = prof.g.iter().copied().fold(0.0, f64::max);
        let T = prof.h * prof.cells() as f64;
        let global = psi.theta(total / T, gmax);
        assert!(b <= global + 1e-12, "{b} > {global}");
        assert!(b < global - 0.01, "the profile must help on a sine: {b} vs {global}");
        // With a flat profile every slope equals the global one: the two coincide.
        let mut flat = prof.clone();
        flat.g.iter_mut().for_each(|g| *g = gmax);
        let bf = flat.bound(&psi, &nodes);
        assert!((bf - global).abs() < 1e-9, "{bf} vs {global}");
    }

    #[test]
    fn negative_control_a_speed_bound_too_low_makes_the_cells_infeasible() {
        // Halving the speed bounds below what the path needs: the greedy fill runs out of
        // capacity, and the loss of a feasible problem is not reachable - the bound moves up
        // relative to the honest one only through the steeper slopes, which is the effect an
        // unsound speed bound would have: detected by comparing with the measured motion in
        // crates/theorems/tests/theta_vs_measured.rs. Here: the bound decreases when g is
        // (wrongly) lowered, so a wrong g gives a wrong, too optimistic, bound.
        let psi = Psi { alpha: 0.0, lambda: 0.3, beta: 0.024 };
        let prof = circle_profile(400, 1.667, 0.214, 0.637, 0.1);
        let nodes = prof.best_partition(&psi, 4);
        let honest = prof.bound(&psi, &nodes);
        let mut wrong = prof.clone();
        wrong.g.iter_mut().for_each(|g| *g *= 0.7);
        assert!(wrong.bound(&psi, &nodes) < honest - 1e-3);
    }

    /// Scalar play `z in y + [lo, hi]` driven by `y = amp sin t` (no feedback: `eta_T = y`,
    /// `D = 0`), its profile with floors, and the true speeds `|z'|` per cell (finest sampling).
    fn play_case(width_used: f64) -> (SpeedProfile, Vec<f64>) {
        let (amp, lo, hi, cells, sub) = (1.0, -0.1, 0.1, 400usize, 50usize);
        let T = std::f64::consts::TAU;
        let h = T / cells as f64;
        let mut prof = circle_profile(cells, amp, 0.0, hi - lo, hi);
        // enclosures of y' = amp cos t per cell (Lipschitz amp, half the cell)
        let (low, high): (Vec<f64>, Vec<f64>) = (0..cells)
            .map(|c| {
                let (a, b) = ((c as f64 * h).cos(), ((c + 1) as f64 * h).cos());
                (amp * a.min(b) - amp * h, amp * a.max(b) + amp * h)
            })
            .unzip();
        prof = prof.with_floors(&low, &high, 0.0, width_used);
        // the play over two periods from z = 0; speeds of the second period, min per cell
        let dt = h / sub as f64;
        let mut z = 0.0f64;
        let mut min_speed = vec![f64::INFINITY; cells];
        for k in 0..2 * cells * sub {
            let t1 = (k + 1) as f64 * dt;
            let y1 = amp * t1.sin();
            let z1 = z.clamp(y1 + lo, y1 + hi);
            if k >= cells * sub {
                let c = (k - cells * sub) / sub;
                min_speed[c] = min_speed[c].min((z1 - z).abs() / dt / hi);
            }
            z = z1;
        }
        (prof, min_speed)
    }

    #[test]
    fn floors_lie_below_the_true_speed_of_a_play_and_sharpen_the_bound() {
        let psi = Psi { alpha: 0.0, lambda: 0.3, beta: 0.024 };
        let (prof, speed) = play_case(0.2);
        assert!(prof.engaged_cells() > prof.cells() / 2, "{} engaged", prof.engaged_cells());
        for (c, (floor, sp)) in prof.floor.iter().zip(&speed).enumerate() {
            // one sample step of slack for the discrete derivative near the catching point
            assert!(*floor <= sp + 0.05, "cell {c}: floor {floor} above speed {sp}");
        }
        let nodes = prof.best_partition(&psi, 4);
        let mut none = prof.clone();
        none.floor.iter_mut().for_each(|l| *l = 0.0);
        let (with, without) = (prof.bound(&psi, &nodes), none.bound(&psi, &nodes));
        assert!(with < without - 0.05, "floors must help: {with} vs {without}");
    }

    /// The play of [`play_case`] with a claimed band `D = 0.3` of `y' - eta_T'` (conservative:
    /// the play has none) and enclosures of `y'` per cell.
    fn play_with_band(dev_diam: f64) -> (SpeedProfile, Vec<f64>, Vec<f64>, Vec<f64>) {
        let (prof, speed) = play_case(0.2);
        let (cells, h) = (prof.cells(), prof.h);
        let (low, high): (Vec<f64>, Vec<f64>) = (0..cells)
            .map(|c| {
                let (a, b) = ((c as f64 * h).cos(), ((c + 1) as f64 * h).cos());
                (a.min(b) - h, a.max(b) + h)
            })
            .unzip();
        let mut p = prof;
        p.floor.iter_mut().for_each(|f| *f = 0.0);
        p.engaged_age.iter_mut().for_each(|a| *a = None);
        (p.with_floors_tube(&low, &high, 0.3, 0.2, dev_diam), speed, low, high)
    }

    #[test]
    fn rise_through_the_tube_and_continued_runs_engage_more_cells_below_the_true_speed() {
        let (plain, speed, low, high) = play_with_band(f64::INFINITY);
        let (tube, ..) = play_with_band(0.05);
        assert!(
            tube.engaged_cells() > plain.engaged_cells() + 5,
            "{} vs {}",
            tube.engaged_cells(),
            plain.engaged_cells()
        );
        // the play's y' is eta_T' exactly: engaged offsets 0 are its pinned band
        let mut cont = tube.clone();
        cont.engaged_offsets = Some((0.0, 0.0));
        let cont = cont.with_continued_runs(&low, &high, None, -0.1, 0.1);
        assert!(
            cont.engaged_cells() > tube.engaged_cells() + 5,
            "{} vs {}",
            cont.engaged_cells(),
            tube.engaged_cells()
        );
        for p in [&plain, &tube, &cont] {
            for (c, (floor, sp)) in p.floor.iter().zip(&speed).enumerate() {
                assert!(*floor <= sp + 0.05, "cell {c}: floor {floor} above speed {sp}");
            }
        }
        // with dev_diam = inf the tube variant is with_floors itself
        let (prof, ..) = play_case(0.2);
        let mut again = prof.clone();
        again.floor.iter_mut().for_each(|f| *f = 0.0);
        let again = again.with_floors_tube(&low, &high, 0.3, 0.2, f64::INFINITY);
        assert_eq!(again.floor, plain.floor);
    }

    #[test]
    fn negative_control_continued_runs_without_the_band_claim_a_stopped_backlash_moves() {
        // offsets far below the truth (y' taken 0.5 above eta_T' while engaged): the runs continue
        // past the turning point of the play, where z rests, and the play refutes those floors
        let (tube, speed, low, high) = play_with_band(0.05);
        let mut wrong = tube.clone();
        wrong.engaged_offsets = Some((-0.5, -0.5));
        let wrong = wrong.with_continued_runs(&low, &high, None, -0.1, 0.1);
        let bad = (0..wrong.cells()).filter(|&c| wrong.floor[c] > speed[c] + 0.05).count();
        assert!(bad > 5, "the unsound continuation must be caught: {bad} cells");
        // and the tube rise with no room for the deviation at all engages where z still rests
        let (no_room, ..) = play_with_band(-0.19);
        let bad = (0..no_room.cells()).filter(|&c| no_room.floor[c] > speed[c] + 0.05).count();
        assert!(bad > 5, "the unsound tube rise must be caught: {bad} cells");
    }

    #[test]
    fn negative_control_floors_without_the_catching_width_claim_a_resting_backlash_moves() {
        // width 0 ignores that z rests while y crosses the gap after each reversal: cells where
        // the true speed is 0 get a floor, which the simulated play refutes.
        let (prof, speed) = play_case(0.0);
        let wrong = (0..prof.cells()).filter(|&c| prof.floor[c] > speed[c] + 0.05).count();
        assert!(wrong > 10, "the unsound floors must be caught: {wrong} cells");
        // and with no guaranteed motion at all (D larger than every |y'|) no cell is engaged
        let (mut p2, _) = play_case(0.2);
        p2 = p2.with_floors(&vec![-1.0; 400], &vec![1.0; 400], 2.0, 0.2);
        assert_eq!(p2.engaged_cells(), 0);
    }
}
