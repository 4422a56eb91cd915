//! The cogging family: a position-periodic (cogging, detent) force on a velocity state whose
//! position state is known (a pair `x_pos' = a x_vel`).
//!
//! Fitted as `(a_sin, a_cos, period)`: the force `a_sin sin(2 pi x/P) + a_cos cos(2 pi x/P)`
//! is linear in the amplitudes (`+-` the site's force bound) and the period lies in a log box
//! about the peaks of a scan of the nominal residual ([`cogging_scan`], [`COGGING_PERIODS`]
//! over the recorded position range, one peak per [`COGGING_SCAN_BANDS`] band), each peak a
//! start of the fit. Offered only with a nominal run
//! ([`super::Scales::nominal`]).
use super::scales::NominalRun;
use super::{Context, Family, Hypothesis, Kind, Scales, Site};
use model::effects::{names, Effect};
use model::System;

/// The cogging family (see the module documentation).
pub struct Cogging;

/// Fewest and most cogging periods over the recorded position range that the cogging
/// hypothesis considers (fewer than 2.5 look like a smooth position-dependent force, a
/// nonlinear spring that absorbs other mismatch; more than 40 need a finer position record
/// than the benchmark's).
pub const COGGING_PERIODS: (f64, f64) = (2.5, 40.0);

/// The position signal of state `pos` on the estimation segment: the measured output where a
/// row of `C` reads that state alone, else the nominal simulation's state.
fn position_signal(sys: &System, run: &NominalRun, pos: usize) -> Vec<f64> {
    let (n, p) = (sys.n(), sys.p());
    let direct = (0..p).find(|&r| (0..n).all(|c| (c == pos) == (sys.C[(r, c)] != 0.0)));
    match direct {
        Some(r) => (0..run.k_est).map(|k| run.y[k * p + r] / sys.C[(r, pos)]).collect(),
        None => (0..run.k_est).map(|k| run.x[k * n + pos]).collect(),
    }
}

/// Log-period bands of the scan whose best peak each becomes a start of the cogging fit
/// ([`cogging_scan`]). The scan's regressor is held over each sample, so a period shorter than
/// the position travelled in a sample or two aliases into a pseudo-random regressor that fits
/// the residual's noise better than the true period does (development seed 10211 `cogging`
/// #0: the scan's best peak 0.177 against a true 1.64, whose own gain was a third of it); the
/// fit, which steps the force between samples, decides among the bands' peaks.
pub const COGGING_SCAN_BANDS: usize = 3;

/// A peak of the cogging scan: the period and the least-squares amplitudes of its sine and
/// cosine regressors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScanPeak {
    pub period: f64,
    pub amplitude_sin: f64,
    pub amplitude_cos: f64,
}

/// Scan for a cogging period: for periods `P` from `range / 40` to `range / 2.5` of the
/// position (log grid, step `P / (6 range)`, so the phase at the ends of the range is off
/// by at most `pi / 6` between neighbours), the linearised response of the output to the two
/// force regressors `sin(2 pi x_pos / P)`, `cos(2 pi x_pos / P)` on velocity state `vel`
/// (the contact dynamics `F = A + E C`, the regressor held over each sample) is fitted to
/// the nominal residual by least squares. Returns the best local maximum of the residual's
/// reduction in each of [`COGGING_SCAN_BANDS`] equal log-period bands (the scan's ends count
/// as maxima), the largest reduction first; empty without a nominal run.
pub fn cogging_scan(sys: &System, s: &Scales, pos: usize, vel: usize) -> Vec<ScanPeak> {
    scan(sys, s, pos, vel).map_or(vec![], |(_, peaks)| peaks)
}

/// [`cogging_scan`] with the recorded position range it scanned over; `None` without a
/// nominal run or a position range.
fn scan(sys: &System, s: &Scales, pos: usize, vel: usize) -> Option<(f64, Vec<ScanPeak>)> {
    let run = s.nominal.as_ref()?;
    if run.k_est < 10 || s.dt <= 0.0 {
        return None;
    }
    let xp = position_signal(sys, run, pos);
    let range = xp.iter().copied().fold(f64::NEG_INFINITY, f64::max) - xp.iter().copied().fold(f64::INFINITY, f64::min);
    if !(range > 0.0 && range.is_finite()) {
        return None;
    }
    let gains = scan_gains(sys, s, run, &xp, range, vel);
    Some((range, band_peaks(&gains, range / COGGING_PERIODS.1, range / COGGING_PERIODS.0)))
}

/// The scan itself: `(gain, peak)` at every period of the grid, the force on velocity state
/// `vel` (see [`cogging_scan`]).
fn scan_gains(sys: &System, s: &Scales, run: &NominalRun, xp: &[f64], range: f64, vel: usize) -> Vec<(f64, ScanPeak)> {
    let (n, p) = (sys.n(), sys.p());
    let ke = run.k_est;
    // Weighted residual (outputs weigh alike).
    let wts: Vec<f64> = (0..p)
        .map(|i| {
            let m = (0..ke).map(|k| run.y[k * p + i]).sum::<f64>() / ke as f64;
            let v = (0..ke).map(|k| (run.y[k * p + i] - m).powi(2)).sum::<f64>() / ke as f64;
            1.0 / v.sqrt().max(1e-300)
        })
        .collect();
    let e: Vec<f64> = (0..ke * p).map(|i| (run.y[i] - run.y_nominal[i]) * wts[i % p]).collect();
    let maps = dynamics::extended::StepMaps::new(&sys.F(), &sys.B, &sys.E, s.dt);
    let col: Vec<f64> = (0..n).map(|i| maps.Psi[i * n + vel]).collect();
    let response = |u: &[f64], out: &mut Vec<f64>| {
        out.clear();
        let mut x = vec![0.0; n];
        let mut xn = vec![0.0; n];
        for k in 0..ke {
            for (r, wr) in wts.iter().enumerate() {
                out.push(wr * (0..n).map(|c| sys.C[(r, c)] * x[c]).sum::<f64>());
            }
            let uk = if k + 1 < ke { 0.5 * (u[k] + u[k + 1]) } else { u[k] };
            for i in 0..n {
                xn[i] = (0..n).map(|c| maps.Phi[i * n + c] * x[c]).sum::<f64>() + col[i] * uk;
            }
            std::mem::swap(&mut x, &mut xn);
        }
    };
    let (pmin, pmax) = (range / COGGING_PERIODS.1, range / COGGING_PERIODS.0);
    let mut gains = vec![];
    let (mut rs, mut rc) = (Vec::with_capacity(ke * p), Vec::with_capacity(ke * p));
    let mut per = pmin;
    while per <= pmax {
        let kw = std::f64::consts::TAU / per;
        let us: Vec<f64> = xp.iter().map(|x| (kw * x).sin()).collect();
        let uc: Vec<f64> = xp.iter().map(|x| (kw * x).cos()).collect();
        response(&us, &mut rs);
        response(&uc, &mut rc);
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(u, v)| u * v).sum::<f64>();
        let (hss, hsc, hcc) = (dot(&rs, &rs), dot(&rs, &rc), dot(&rc, &rc));
        let (gs, gc) = (dot(&rs, &e), dot(&rc, &e));
        let det = hss * hcc - hsc * hsc;
        if det > 1e-12 * (hss * hcc).max(1e-300) {
            let (a_s, a_c) = ((hcc * gs - hsc * gc) / det, (hss * gc - hsc * gs) / det);
            gains.push((a_s * gs + a_c * gc, ScanPeak { period: per, amplitude_sin: a_s, amplitude_cos: a_c }));
        }
        per *= 1.0 + per / (6.0 * range);
    }
    gains
}

/// The best local maximum of `gains` (periods increasing; the ends count as maxima) in each of
/// [`COGGING_SCAN_BANDS`] equal log-period bands of `[pmin, pmax]`, the largest gain first.
fn band_peaks(gains: &[(f64, ScanPeak)], pmin: f64, pmax: f64) -> Vec<ScanPeak> {
    let g = |i: usize| gains[i].0;
    let is_peak = |i: usize| (i == 0 || g(i) > g(i - 1)) && (i + 1 == gains.len() || g(i) >= g(i + 1));
    let band = |per: f64| {
        let b = ((per / pmin).ln() / (pmax / pmin).ln() * COGGING_SCAN_BANDS as f64).floor();
        (b.max(0.0) as usize).min(COGGING_SCAN_BANDS - 1)
    };
    let mut best: Vec<Option<(f64, ScanPeak)>> = vec![None; COGGING_SCAN_BANDS];
    for i in (0..gains.len()).filter(|&i| is_peak(i)) {
        let slot = &mut best[band(gains[i].1.period)];
        if slot.is_none_or(|(b, _)| g(i) > b) {
            *slot = Some(gains[i]);
        }
    }
    let mut peaks: Vec<(f64, ScanPeak)> = best.into_iter().flatten().collect();
    peaks.sort_by(|a, b| b.0.total_cmp(&a.0));
    peaks.into_iter().map(|(_, peak)| peak).collect()
}

/// `cogging` on velocity state `vel` with position state `pos`: amplitudes of the sine and
/// cosine parts in `[-fs, fs]` (linear: the force is linear in them) and the period in a log
/// box from `3` scan steps below the lowest of the scan's band peaks ([`cogging_scan`]) to `3`
/// above the highest. Started at the best peak's amplitudes, half and 1.5 times them, and at
/// each other peak's amplitudes. `None` without a scan.
fn cogging(sys: &System, s: &Scales, pos: usize, vel: usize, fs: f64) -> Option<Hypothesis> {
    let (range, peaks) = scan(sys, s, pos, vel)?;
    let best = *peaks.first()?;
    let step = |per: f64| per / (6.0 * range);
    let lo = peaks.iter().map(|q| q.period).fold(f64::INFINITY, f64::min);
    let hi = peaks.iter().map(|q| q.period).fold(0.0, f64::max);
    let h = Hypothesis {
        kind: Kind::Cogging { state: vel, position_state: pos },
        lower: vec![-fs, -fs, lo * (1.0 - 3.0 * step(lo))],
        upper: vec![fs, fs, hi * (1.0 + 3.0 * step(hi))],
        starts: vec![],
        names: vec!["amplitude_sin", "amplitude_cos", "period"],
        log_shift: vec![None, None, Some(0.0)],
    };
    let start = |f: f64, q: &ScanPeak| {
        vec![h.unit_of(0, f * q.amplitude_sin), h.unit_of(1, f * q.amplitude_cos), h.unit_of(2, q.period)]
    };
    let starts =
        [1.0, 0.5, 1.5].iter().map(|&f| start(f, &best)).chain(peaks[1..].iter().map(|q| start(1.0, q))).collect();
    Some(Hypothesis { starts, ..h })
}

impl Family for Cogging {
    fn hypotheses(&self, site: &Site, cx: &Context) -> Vec<Hypothesis> {
        match *site {
            // The scan runs over the record: only where the library asks for cogging.
            Site::Velocity { state, force_bound, position_state: Some(pos), .. }
                if cx.allows(Kind::Cogging { state, position_state: pos }) =>
            {
                cogging(cx.sys, cx.scales, pos, state, force_bound).into_iter().collect()
            }
            _ => vec![],
        }
    }

    fn name(&self, kind: Kind) -> Option<&'static str> {
        matches!(kind, Kind::Cogging { .. }).then_some(names::COGGING)
    }

    fn label(&self, kind: Kind) -> Option<String> {
        match kind {
            Kind::Cogging { state, .. } => Some(format!("{}(x{})", names::COGGING, state + 1)),
            _ => None,
        }
    }

    fn description(&self, kind: Kind) -> Option<String> {
        match kind {
            Kind::Cogging { state, position_state } => Some(format!("A position-periodic (cogging, detent) force on velocity state x{} that repeats every period of position x{}, as from motor magnets passing stator teeth or a ball screw's pitch.", state + 1, position_state + 1)),
            _ => None,
        }
    }

    /// `a_s sin + a_c cos = R sin(. + phase)` with `R = hypot(a_s, a_c)`, `phase = atan2(a_c, a_s)`.
    fn effect(&self, kind: Kind, theta: &[f64]) -> Option<Effect> {
        match kind {
            Kind::Cogging { state, position_state } => Some(Effect::Cogging {
                state,
                position_state,
                amplitude: theta[0].hypot(theta[1]),
                period: theta[2].max(1e-300),
                phase: theta[1].atan2(theta[0]),
            }),
            _ => None,
        }
    }

    fn main_parameter(&self, effect: &Effect) -> Option<(f64, Option<&'static str>)> {
        match effect {
            Effect::Cogging { amplitude, .. } => Some((*amplitude, None)),
            _ => None,
        }
    }

    fn every_parameter(&self, effect: &Effect) -> Option<Vec<(&'static str, f64)>> {
        match effect {
            Effect::Cogging { amplitude, period, .. } => Some(vec![("amplitude", *amplitude), ("period", *period)]),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cogging_parameters_map_to_amplitude_and_phase() {
        // Cogging: a_s sin + a_c cos = R sin(. + phase).
        let cog = Hypothesis {
            kind: Kind::Cogging { state: 1, position_state: 0 },
            lower: vec![-1.0, -1.0, 0.1],
            upper: vec![1.0, 1.0, 1.0],
            starts: vec![],
            names: vec!["amplitude_sin", "amplitude_cos", "period"],
            log_shift: vec![None, None, Some(0.0)],
        };
        let Effect::Cogging { amplitude, period, phase, position_state, .. } =
            cog.effect(&[0.3, -0.4, 0.25], &Scales::default())
        else {
            panic!("not cogging")
        };
        assert_eq!((position_state, period), (0, 0.25));
        for t in [0.0, 0.7, 2.9] {
            let a = 0.3 * f64::sin(t) - 0.4 * f64::cos(t);
            assert!((amplitude * (t + phase).sin() - a).abs() < 1e-12);
        }
    }

    #[test]
    fn each_band_offers_its_best_peak_best_first() {
        // Gains over periods 0.1-1.6 (3 bands of a factor 16^(1/3) = 2.52 each: 0.1-0.252,
        // 0.252-0.635, 0.635-1.6): a tall
        // aliased peak at 0.15, a smaller one at 0.18 in the same band, nothing but a slope in
        // the middle band, and a scan that still rises at its upper end (1.6).
        let pers: Vec<f64> = (0..=40).map(|i| 0.1 * 16f64.powf(i as f64 / 40.0)).collect();
        let gain =
            |p: f64| 18.0 * (-((p - 0.15) / 0.01).powi(2)).exp() + 9.0 * (-((p - 0.18) / 0.01).powi(2)).exp() + 4.0 * p;
        let gains: Vec<(f64, ScanPeak)> =
            pers.iter().map(|&p| (gain(p), ScanPeak { period: p, amplitude_sin: p, amplitude_cos: -p })).collect();
        let peaks = band_peaks(&gains, 0.1, 1.6);
        let got: Vec<f64> = peaks.iter().map(|q| q.period).collect();
        // The alias first (the largest gain), then the scan's upper end; the second peak of the
        // first band and the slope of the middle band offer nothing.
        assert_eq!(got.len(), 2, "{got:?}");
        assert!((got[0] - 0.15).abs() < 0.01, "{got:?}");
        assert_eq!(got[1], *pers.last().unwrap());
        assert_eq!((peaks[1].amplitude_sin, peaks[1].amplitude_cos), (got[1], -got[1]));
        // Empty scan, no peaks.
        assert!(band_peaks(&[], 0.1, 1.6).is_empty());
    }
}
