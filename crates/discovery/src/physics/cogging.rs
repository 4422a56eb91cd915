//! The cogging family: a position-periodic (cogging, detent) force on a velocity state whose
//! position state is known (a pair `x_pos' = a x_vel`).
//!
//! Fitted as `(a_sin, a_cos, period)`: the force `a_sin sin(2 pi x/P) + a_cos cos(2 pi x/P)`
//! is linear in the amplitudes (`+-` the site's force bound) and the period lies in a narrow
//! log box about the best period of a scan of the nominal residual ([`cogging_scan`],
//! [`COGGING_PERIODS`] over the recorded position range). Offered only with a nominal run
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

/// Scan for a cogging period: for periods `P` from `range / 40` to `range / 2.5` of the
/// position (log grid, step `P / (6 range)`, so the phase at the ends of the range is off
/// by at most `pi / 6` between neighbours), the linearised response of the output to the two
/// force regressors `sin(2 pi x_pos / P)`, `cos(2 pi x_pos / P)` on velocity state `vel`
/// (the contact dynamics `F = A + E C`, the regressor held over each sample) is fitted to
/// the nominal residual by least squares. Returns the period with the largest reduction of
/// the residual and its two amplitudes, or `None` without a nominal run.
pub fn cogging_scan(sys: &System, s: &Scales, pos: usize, vel: usize) -> Option<(f64, f64, f64)> {
    let run = s.nominal.as_ref()?;
    let (n, p) = (sys.n(), sys.p());
    let ke = run.k_est;
    if ke < 10 || s.dt <= 0.0 {
        return None;
    }
    let xp = position_signal(sys, run, pos);
    let range = xp.iter().copied().fold(f64::NEG_INFINITY, f64::max) - xp.iter().copied().fold(f64::INFINITY, f64::min);
    if !(range > 0.0 && range.is_finite()) {
        return None;
    }
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
    let mut best: Option<(f64, f64, f64, f64)> = None;
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
            let gain = a_s * gs + a_c * gc;
            if best.is_none_or(|b| gain > b.0) {
                best = Some((gain, per, a_s, a_c));
            }
        }
        per *= 1.0 + per / (6.0 * range);
    }
    best.map(|(_, per, a_s, a_c)| (per, a_s, a_c))
}

/// `cogging` on velocity state `vel` with position state `pos`: amplitudes of the sine and
/// cosine parts in `[-fs, fs]` (linear: the force is linear in them) and the period in a
/// log box of `+- 3` scan steps about the scan's best period ([`cogging_scan`]), started at
/// the scan's amplitudes, half and 1.5 times them. `None` without a scan.
fn cogging(sys: &System, s: &Scales, pos: usize, vel: usize, fs: f64) -> Option<Hypothesis> {
    let (per, a_s, a_c) = cogging_scan(sys, s, pos, vel)?;
    let run = s.nominal.as_ref()?;
    let xp = position_signal(sys, run, pos);
    let range = xp.iter().copied().fold(f64::NEG_INFINITY, f64::max) - xp.iter().copied().fold(f64::INFINITY, f64::min);
    let step = per / (6.0 * range);
    let h = Hypothesis {
        kind: Kind::Cogging { state: vel, position_state: pos },
        lower: vec![-fs, -fs, per * (1.0 - 3.0 * step)],
        upper: vec![fs, fs, per * (1.0 + 3.0 * step)],
        starts: vec![],
        names: vec!["amplitude_sin", "amplitude_cos", "period"],
        log_shift: vec![None, None, Some(0.0)],
    };
    let starts =
        [1.0, 0.5, 1.5].iter().map(|f| vec![h.unit_of(0, f * a_s), h.unit_of(1, f * a_c), h.unit_of(2, per)]).collect();
    Some(Hypothesis { starts, ..h })
}

impl Family for Cogging {
    fn hypotheses(&self, site: &Site, cx: &Context) -> Vec<Hypothesis> {
        match *site {
            Site::Velocity { state, force_bound, position_state: Some(pos), .. } => {
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
}
