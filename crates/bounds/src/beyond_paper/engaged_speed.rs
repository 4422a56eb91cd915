//! (zinf) for `p = 1` with the backlash's side pinned (beyond the paper;
//! proofs-notes/theta-star.md, "The speed bound").
//!
//! Eq. (zinf) bounds `|z'| <= ||eta_T'||_inf + D(C(F Xi_inf + E Theta),{0})`, taking the
//! backlash's offset `v = z - y` anywhere in `Theta`. For `p = 1`, `Theta = [lo, hi]`, the
//! sweeping process moves `z` only from a face: `z' > 0` forces `z = y + lo`, `z' < 0` forces
//! `z = y + hi` (the interval `y + Theta` pushes `z` from behind). With `x = xi_T + dev`,
//! `y' = eta_T' + C F dev + C E v` and `dev` in `Xi_inf` (asymptotically), so wherever `z` moves
//! (`z' = y'` there):
//!
//! ```text
//! z' > 0:   eta_T' - (s(-1) - CE lo) <= z' <= eta_T' + s(+1) + CE lo
//! z' < 0:   eta_T' - s(-1) - CE hi   <= z' <= eta_T' + (s(+1) + CE hi)
//! ```
//!
//! with `s(+-1) = sigma_{C F Xi_inf}(+-1)`. The ceilings are never above `D` (which takes the worst
//! `v` in `Theta` for either sign); they are lower by `CE (hi - lo)` when `CE > 0`. The floors
//! hold only while the backlash is engaged (`theta_engaged` decides where).
use crate::error::BoundsError;
use crate::tube::cf_rounding::{cf_support_error, PAD};
use crate::tube::{Horizon, SemigroupData, TubeKernel, TubeSettings};
use geometry::{ConvexSet, Shape};
use nalgebra::DMatrix;
use rounding::{pad_down, pad_up};

/// Offsets of the signed speed of `z` for `p = 1` (module docs), each an upper bound: the band of
/// [`EngagedHistory`] at `tau = 0` ([`EngagedHistory::pinned`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct EngagedSpeed {
    /// `z' <= eta_T' + ceil_up` wherever `z' > 0`.
    pub ceil_up: f64,
    /// `-z' <= -eta_T' + ceil_down` wherever `z' < 0`.
    pub ceil_down: f64,
    /// `z' >= eta_T' - floor_up` wherever `z' > 0`.
    pub floor_up: f64,
    /// `-z' >= -eta_T' - floor_down` wherever `z' < 0`.
    pub floor_down: f64,
}

impl EngagedSpeed {
    /// `limsup |z'| <= ||eta_T'||_inf + max(ceil_up, ceil_down)` (at least `0`), from above.
    pub fn zdot_bound(&self, eta_dot_inf: f64) -> f64 {
        pad_up((eta_dot_inf + self.ceil_up.max(self.ceil_down)).max(0.0), PAD)
    }
}

/// The engaged history of the backlash for `p = 1` (beyond the paper; proofs-notes/theta-engaged.md,
/// "Engaged history"). With `k(u) = C F e^{uF} E` and `dev(t) = int_0^inf e^{uF} E v(t - u) du`
/// (asymptotically), if the backlash has been engaged from one side for the last `tau`
/// (`v = w`, `w = lo` when rising, `hi` when falling), then
///
/// ```text
/// z' - eta_T' = C F dev + C E w = w (CE + I(tau)) + int_tau^inf k(u) v(t - u) du,
/// I(tau) = int_0^tau k,   int_tau^inf k v in [-S_-(tau), S_+(tau)],
/// S_+-(tau) = int_tau^inf sigma_Theta(+-k) = sigma_{C F Xi_inf}(+-1) - int_0^tau sigma_Theta(+-k)
/// ```
///
/// so the band of `z' - eta_T'` narrows from the width of `C F Xi_inf` at `tau = 0` to 0 as the
/// history lengthens. Tabulated at `tau_j = j dtau`; the integrals over `[0, tau_j]` come from
/// finite-horizon [`TubeKernel`]s (lower values: proven here because `sigma_Theta` of an
/// interval, or of the point `{1}` for `I`, is one multiplication, within the kernel's
/// allowance), those over `[0, inf)` from the caller's `sigma_{C F Xi_inf}` kernel (upper
/// values), each widened by the effect of `||C F_exact - fl(C F)||` ([`crate::tube::cf_rounding::cf_error`]).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct EngagedHistory {
    /// Grid step of `tau`.
    pub dtau: f64,
    /// Enclosure of `CE + I(tau_j)` (`= C e^{tau_j F} E`).
    pub known_lo: Vec<f64>,
    pub known_hi: Vec<f64>,
    /// Upper bounds of `S_+(tau_j)` and `S_-(tau_j)`.
    pub tail_up: Vec<f64>,
    pub tail_down: Vec<f64>,
}

impl EngagedHistory {
    /// Tabulates `tau_j = j dtau`, `j = 0..=steps` (`steps = 0`: the pinned band only, no
    /// kernels). `tube_CF` is the kernel of `sigma_{C F Xi_inf}` built with `tube` (whose
    /// `f_radius` covers `F`), `sg` the semigroup data of `F`, `Theta = [lo, hi]` (any set in R^1
    /// is that interval) with `lo <= 0 <= hi`. `None` when `p != 1`, `0` is not in Theta or a
    /// bound is not finite.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        tube_CF: &TubeKernel,
        C: &DMatrix<f64>,
        F: &DMatrix<f64>,
        E: &DMatrix<f64>,
        (lo, hi): (f64, f64),
        sg: &SemigroupData,
        tube: &TubeSettings,
        dtau: f64,
        steps: usize,
    ) -> Result<Option<Self>, BoundsError> {
        Self::new_reusing(None, tube_CF, C, F, E, (lo, hi), sg, tube, dtau, steps)
    }

    /// [`Self::new`], with the entries `tau_j` it shares with `known` taken from there instead of
    /// computed again. `known` must come from `new` (or this function) with the same arguments
    /// but `steps`: entry `j` depends on `j dtau` and those arguments only, so the result is the
    /// one `new` gives, bit for bit ([`HistoryMemo`] keeps that promise).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn new_reusing(
        known: Option<&Self>,
        tube_CF: &TubeKernel,
        C: &DMatrix<f64>,
        F: &DMatrix<f64>,
        E: &DMatrix<f64>,
        (lo, hi): (f64, f64),
        sg: &SemigroupData,
        tube: &TubeSettings,
        dtau: f64,
        steps: usize,
    ) -> Result<Option<Self>, BoundsError> {
        let shape_ok = C.nrows() == 1 && E.ncols() == 1 && C.ncols() == E.nrows() && lo <= 0.0 && 0.0 <= hi;
        if !shape_ok || (steps > 0 && !(dtau > 0.0 && dtau.is_finite())) || sg.exp_norm().is_none() {
            return Ok(None);
        }
        let n = C.ncols();
        // CE = sum C_i E_i with its rounding error (at most n u sum |C_i E_i| / (1 - n u))
        let ce = (0..n).map(|i| C[(0, i)] * E[(i, 0)]).sum::<f64>();
        let ce_err = 2.0 * (n as f64 + 1.0) * f64::EPSILON * (0..n).map(|i| (C[(0, i)] * E[(i, 0)]).abs()).sum::<f64>();
        // the kernels use L = fl(C F): its error times int ||e^{s F_exact}|| ||E|| (times
        // D(Theta, {0}) for the support integrals, 1 for I)
        let l_err = cf_support_error(C, F, E, tube.f_radius, sg, 1.0);
        let theta = Shape::Interval(geometry::Interval { lo, hi });
        let d_theta = theta.deviation_from_origin().upper;
        let CF = C * F;
        let unit = Shape::Interval(geometry::Interval { lo: 1.0, hi: 1.0 });
        let (s_up, s_down) = (tube_CF.support_upper(&[1.0]), tube_CF.support_upper(&[-1.0]));
        let mut out = Self {
            dtau,
            known_lo: vec![pad_down(ce - ce_err, PAD)],
            known_hi: vec![pad_up(ce + ce_err, PAD)],
            tail_up: vec![pad_up(s_up + d_theta * l_err, PAD)],
            tail_down: vec![pad_up(s_down + d_theta * l_err, PAD)],
        };
        let reused = known.map_or(0, |k| (k.tail_up.len() - 1).min(steps));
        if let Some(k) = known.filter(|_| reused > 0) {
            out.known_lo = k.known_lo[..=reused].to_vec();
            out.known_hi = k.known_hi[..=reused].to_vec();
            out.tail_up = k.tail_up[..=reused].to_vec();
            out.tail_down = k.tail_down[..=reused].to_vec();
        }
        for j in reused + 1..=steps {
            let tau = j as f64 * dtau;
            let h = Horizon::Finite(tau);
            let kt = TubeKernel::with_shared(&CF, F, E, &theta, d_theta, sg, h, tube)?;
            let ki = TubeKernel::with_shared(&CF, F, E, &unit, 1.0, sg, h, tube)?;
            let (a_up, a_down) = (kt.support_bounds(&[1.0]).lower, kt.support_bounds(&[-1.0]).lower);
            let int = ki.support_bounds(&[1.0]);
            out.tail_up.push(pad_up(s_up - a_up + 2.0 * d_theta * l_err, PAD).max(0.0));
            out.tail_down.push(pad_up(s_down - a_down + 2.0 * d_theta * l_err, PAD).max(0.0));
            out.known_lo.push(pad_down(ce - ce_err + int.lower - l_err, PAD));
            out.known_hi.push(pad_up(ce + ce_err + int.upper + l_err, PAD));
        }
        let finite = [&out.known_lo, &out.known_hi, &out.tail_up, &out.tail_down]
            .iter()
            .all(|v| v.iter().all(|x| x.is_finite()));
        Ok(finite.then_some(out))
    }

    /// The pinned offsets: the band at `tau = 0` for either side (`z' > 0` only with `v = lo`,
    /// `z' < 0` only with `v = hi`; module docs of this file).
    pub fn pinned(&self, lo: f64, hi: f64) -> EngagedSpeed {
        let (a_up, b_up) = self.band(0.0, lo);
        let (a_down, b_down) = self.band(0.0, hi);
        EngagedSpeed { ceil_up: b_up, floor_up: -a_up, ceil_down: -a_down, floor_down: b_down }
    }

    /// Enclosure `[a, b]` of `z' - eta_T'` at a time when the backlash has been engaged from the
    /// side `w` (`lo` while rising, `hi` while falling) for at least `tau` (module docs).
    pub fn band(&self, tau: f64, w: f64) -> (f64, f64) {
        let last = self.tail_up.len() - 1;
        // the largest tau_j <= tau (a shorter history is still a valid one)
        let j = ((tau / self.dtau) * (1.0 - 1e-9)).floor().clamp(0.0, last as f64) as usize;
        let (k_lo, k_hi) = if w >= 0.0 {
            (w * self.known_lo[j], w * self.known_hi[j])
        } else {
            (w * self.known_hi[j], w * self.known_lo[j])
        };
        (pad_down(k_lo - self.tail_down[j], PAD), pad_up(k_hi + self.tail_up[j], PAD))
    }
}

/// The longest [`EngagedHistory`] computed for one problem, for the next report on the same
/// plant, Theta, period and tube settings (another amplitude, a sweep point): its entries are a
/// prefix of any longer table ([`EngagedHistory::new_reusing`]). Asked about another problem, it
/// forgets what it had.
#[derive(Debug, Default)]
pub struct HistoryMemo {
    key: Option<HistoryKey>,
    longest: Option<EngagedHistory>,
}

#[derive(Debug, PartialEq)]
struct HistoryKey {
    C: DMatrix<f64>,
    F: DMatrix<f64>,
    E: DMatrix<f64>,
    /// `lo`, `hi`, `dtau` and `sigma_{C F Xi_inf}(+-1)` from above, as bits.
    bits: [u64; 5],
    tube: TubeSettings,
}

impl HistoryMemo {
    /// [`EngagedHistory::new`] through the memo (the same arguments, the same result).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn history(
        &mut self,
        tube_CF: &TubeKernel,
        C: &DMatrix<f64>,
        F: &DMatrix<f64>,
        E: &DMatrix<f64>,
        (lo, hi): (f64, f64),
        sg: &SemigroupData,
        tube: &TubeSettings,
        dtau: f64,
        steps: usize,
    ) -> Result<Option<EngagedHistory>, BoundsError> {
        let (s_up, s_down) = (tube_CF.support_upper(&[1.0]), tube_CF.support_upper(&[-1.0]));
        let key = HistoryKey {
            C: C.clone(),
            F: F.clone(),
            E: E.clone(),
            bits: [lo.to_bits(), hi.to_bits(), dtau.to_bits(), s_up.to_bits(), s_down.to_bits()],
            tube: *tube,
        };
        if self.key.as_ref() != Some(&key) {
            self.key = Some(key);
            self.longest = None;
        }
        let h = EngagedHistory::new_reusing(self.longest.as_ref(), tube_CF, C, F, E, (lo, hi), sg, tube, dtau, steps)?;
        if let Some(h) = &h {
            if self.longest.as_ref().is_none_or(|l| l.tail_up.len() < h.tail_up.len()) {
                self.longest = Some(h.clone());
            }
        }
        Ok(h)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tube::{Horizon, SemigroupData, TubeSettings};
    use geometry::{ConvexSet, Interval, Shape};
    use nalgebra::DMatrix;

    fn kernel(C: &DMatrix<f64>, F: &DMatrix<f64>, E: &DMatrix<f64>, theta: &Shape) -> TubeKernel {
        TubeKernel::new(&(C * F), F, E, theta, Horizon::Infinite, &TubeSettings::default()).unwrap()
    }

    /// The pinned offsets (the history's band at tau = 0, no kernels).
    fn pinned(
        k: &TubeKernel,
        C: &DMatrix<f64>,
        F: &DMatrix<f64>,
        E: &DMatrix<f64>,
        lo: f64,
        hi: f64,
    ) -> Option<EngagedSpeed> {
        let st = TubeSettings::default();
        EngagedHistory::new(k, C, F, E, (lo, hi), &SemigroupData::new(F), &st, 1.0, 0)
            .unwrap()
            .map(|h| h.pinned(lo, hi))
    }

    /// The memo gives what `new` gives, bit for bit, for a shorter table (a prefix of the one it
    /// holds) and a longer one (extended from it); negative control: another Theta at the same
    /// plant is computed afresh, not taken from the memo (its tails differ).
    #[test]
    fn history_memo_equals_new_bit_for_bit() {
        let F = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -1.0, -0.6]);
        let C = DMatrix::from_row_slice(1, 2, &[1.0, 0.3]);
        let E = DMatrix::from_row_slice(2, 1, &[0.2, 1.0]);
        let st = TubeSettings::default();
        let sg = SemigroupData::new(&F);
        let (lo, hi) = (-0.1, 0.2);
        let k = kernel(&C, &F, &E, &Shape::Interval(Interval::new(lo, hi).unwrap()));
        let fresh = |steps| EngagedHistory::new(&k, &C, &F, &E, (lo, hi), &sg, &st, 0.5, steps).unwrap().unwrap();
        let mut memo = HistoryMemo::default();
        let mut via = |steps| memo.history(&k, &C, &F, &E, (lo, hi), &sg, &st, 0.5, steps).unwrap().unwrap();
        for steps in [4, 2, 8, 6, 8] {
            assert_eq!(via(steps), fresh(steps), "{steps} steps");
        }
        let (lo2, hi2) = (-0.2, 0.2);
        let k2 = kernel(&C, &F, &E, &Shape::Interval(Interval::new(lo2, hi2).unwrap()));
        let other = memo.history(&k2, &C, &F, &E, (lo2, hi2), &sg, &st, 0.5, 4).unwrap().unwrap();
        let other_fresh = EngagedHistory::new(&k2, &C, &F, &E, (lo2, hi2), &sg, &st, 0.5, 4).unwrap().unwrap();
        assert_eq!(other, other_fresh);
        assert_ne!(other.tail_up, fresh(4).tail_up);
    }

    /// The ceilings never exceed D (which allows any v in Theta); with CE > 0 they are lower
    /// by CE (hi - lo), with CE = 0 (worked example) equal to D's terms.
    #[test]
    fn ceilings_against_d() {
        let F = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -1.0, -0.6]);
        let theta = Shape::Interval(Interval::new(-0.1, 0.2).unwrap());
        for (C, E, ce) in [
            (DMatrix::from_row_slice(1, 2, &[1.0, 0.0]), DMatrix::from_row_slice(2, 1, &[0.0, 1.0]), 0.0),
            (DMatrix::from_row_slice(1, 2, &[1.0, 0.5]), DMatrix::from_row_slice(2, 1, &[0.0, 1.0]), 0.5),
            (DMatrix::from_row_slice(1, 2, &[1.0, -0.5]), DMatrix::from_row_slice(2, 1, &[0.0, 1.0]), -0.5),
        ] {
            let k = kernel(&C, &F, &E, &theta);
            let s = pinned(&k, &C, &F, &E, -0.1, 0.2).unwrap();
            let (su, sd) = (k.support_upper(&[1.0]), k.support_upper(&[-1.0]));
            // D's two terms: s(u) + sigma_Theta(CE u)
            let d = (su + theta.support(&[ce])).max(sd + theta.support(&[-ce]));
            let ceil = s.ceil_up.max(s.ceil_down);
            assert!(ceil <= d * (1.0 + 1e-12) + 1e-15, "ce {ce}: ceiling {ceil} above D {d}");
            if ce > 0.0 {
                assert!(s.ceil_up <= su + ce * 0.2 - ce * 0.3 + 1e-12, "ce {ce}: {}", s.ceil_up);
            } else {
                assert!((ceil - d).abs() <= 1e-12 * d.abs().max(1.0), "ce {ce}: {ceil} vs {d}");
            }
            // negative control: the floors are not ceilings (floor_up allows z' below eta' - s(-1))
            assert!(s.floor_up >= sd - ce * (-0.1) - 1e-12);
        }
    }

    /// The band of `z' - eta_T'` after an engaged history of length `tau`, against direct
    /// quadrature of `C F dev + C E lo` for random histories `v(t - u)` in Theta that equal `lo`
    /// on `u < tau`: every value inside; the band narrows with tau. Negative control: the band
    /// without its tail terms (history older than tau ignored) misses some history.
    #[test]
    fn history_band_contains_random_histories() {
        let F = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -1.0, -0.6]);
        let C = DMatrix::from_row_slice(1, 2, &[1.0, 0.3]);
        let E = DMatrix::from_row_slice(2, 1, &[0.2, 1.0]);
        let (lo, hi) = (-0.1, 0.2);
        let theta = Shape::Interval(Interval::new(lo, hi).unwrap());
        let st = TubeSettings::default();
        let k = kernel(&C, &F, &E, &theta);
        let sg = SemigroupData::new(&F);
        let hist = EngagedHistory::new(&k, &C, &F, &E, (lo, hi), &sg, &st, 0.5, 8).unwrap().unwrap();
        // tails shrink with the history's length
        for j in 1..hist.tail_up.len() {
            assert!(hist.tail_up[j] + hist.tail_down[j] <= hist.tail_up[j - 1] + hist.tail_down[j - 1] + 1e-9);
        }
        // direct quadrature of int_0^U k(u) v(u) du + CE lo, k(u) = C F e^{uF} E (U = 60, |e^{60F}| ~ 1e-8)
        let du = 1e-3;
        let steps = 60_000usize;
        let step = (F.clone() * du).exp();
        let CF = &C * &F;
        let mut P = DMatrix::<f64>::identity(2, 2);
        let mut kv = Vec::with_capacity(steps);
        for _ in 0..steps {
            kv.push((&CF * &P * &E)[(0, 0)]);
            P = &P * &step;
        }
        let ce = (&C * &E)[(0, 0)];
        let mut rng = 12345u64;
        let mut next = || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            (rng >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut missed_without_tail = 0;
        for &tau in &[0.0, 1.0, 2.0, 3.7] {
            let (a, b) = hist.band(tau, lo);
            let j = ((tau / hist.dtau) * (1.0 - 1e-9)).floor() as usize;
            let (ka, kb) = (lo * hist.known_hi[j.min(8)], lo * hist.known_lo[j.min(8)]);
            for trial in 0..200 {
                // v = lo on [0, tau); before: blocks of random length at random levels or at the ends
                let mut v = vec![lo; steps];
                let mut u = (tau / du).ceil() as usize;
                while u < steps {
                    let len = 1 + (next() * 3000.0) as usize;
                    let level = match trial % 3 {
                        0 => lo + (hi - lo) * next(),
                        _ => {
                            if next() < 0.5 {
                                lo
                            } else {
                                hi
                            }
                        }
                    };
                    for x in v.iter_mut().skip(u).take(len) {
                        *x = level;
                    }
                    u += len;
                }
                let val: f64 = kv.iter().zip(&v).map(|(k, v)| k * v).sum::<f64>() * du + ce * lo;
                assert!(val >= a - 1e-3 && val <= b + 1e-3, "tau {tau}: {val} outside [{a}, {b}]");
                if val < ka - 1e-3 || val > kb + 1e-3 {
                    missed_without_tail += 1;
                }
            }
        }
        assert!(missed_without_tail > 0, "negative control: the band without tails was never violated");
        // tau = 0 is the pinned bound (module docs): [CE lo - s(-1), CE lo + s(+1)]
        let (su, sd) = (k.support_upper(&[1.0]), k.support_upper(&[-1.0]));
        let (a0, b0) = hist.band(0.0, lo);
        assert!((b0 - (su + ce * lo)).abs() < 1e-9 && (a0 - (ce * lo - sd)).abs() < 1e-9, "{a0} {b0} {su} {sd}");
    }

    #[test]
    fn rejects_p_2_and_zero_outside() {
        let F = DMatrix::from_row_slice(2, 2, &[-1.0, 0.0, 0.0, -2.0]);
        let C = DMatrix::identity(2, 2);
        let E = DMatrix::identity(2, 2);
        let theta = Shape::Interval(Interval::new(-0.1, 0.2).unwrap());
        let C1 = DMatrix::from_row_slice(1, 2, &[1.0, 0.0]);
        let E1 = DMatrix::from_row_slice(2, 1, &[1.0, 0.0]);
        let k = kernel(&C1, &F, &E1, &theta);
        assert!(pinned(&k, &C, &F, &E, -0.1, 0.2).is_none());
        assert!(pinned(&k, &C1, &F, &E1, 0.1, 0.2).is_none(), "0 not in Theta");
        assert!(pinned(&k, &C1, &F, &E1, -0.1, 0.2).is_some());
    }
}
