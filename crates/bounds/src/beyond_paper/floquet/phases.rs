//! The switching structure of the periodic regime, read from a simulation (a hypothesis, proven
//! or refuted later by [`super::period_map`] and [`super::switching`]).
//!
//! Method: the fixed point of the catching-up Poincare map ([`dynamics::periodic::poincare`])
//! is refined by the event-driven reference integrator over a few periods (exact piecewise
//! linear flow, [`dynamics::integrators::event_driven`]); on the last period every sample is
//! classified as engaged on a face (`q` on the face within `1e-9`, `y'` pushing) or resting; the
//! runs of one class are the phases, the changes the switches. The section of the period map is
//! the input phase `theta_0 = omega t_0 + phase` in `{0, pi/2, pi, 3 pi / 2}` farthest from any
//! switch: there the exosystem state `(sin, cos)` is exact (`(0, 1)`, `(1, 0)`, ...).
use super::flow::{Face, PhaseKind};
use super::FloquetError;
use dynamics::integrators::event_driven::{event_driven, EventDrivenSettings};
use dynamics::periodic::poincare::{periodic_regime, FixedPointStatus, PoincareSettings};
use dynamics::trajectory::Trajectory;
use model::System;
use nalgebra::DVector;

/// A phase sequence over one period from a section, with a starting guess.
#[derive(Debug, Clone, PartialEq)]
pub struct PhaseStructure {
    /// The section `theta_0 = quarter pi / 2` (`quarter` in `0..4`).
    pub quarter: usize,
    /// Phases from the section in order; the last continues the first (same kind), so there
    /// are `kinds.len() - 1` switches.
    pub kinds: Vec<PhaseKind>,
    /// Guesses of the durations of every phase but the last.
    pub durations: Vec<f64>,
    /// Guess of the state at the section.
    pub x0: Vec<f64>,
    pub z0: f64,
}

impl PhaseStructure {
    /// `(sin theta_0, cos theta_0)`, exact.
    pub fn section_sc(&self) -> (f64, f64) {
        [(0.0, 1.0), (1.0, 0.0), (0.0, -1.0), (-1.0, 0.0)][self.quarter % 4]
    }
    /// Number of switches per period.
    pub fn switches(&self) -> usize {
        self.kinds.len() - 1
    }
}

/// Samples per period of the event-driven run.
const SAMPLES: usize = 4096;

/// Reads the structure of the regime of `sys` (p = 1, `Theta = [lo, hi]`, sine input).
pub fn simulate_structure(
    sys: &System,
    lo: f64,
    hi: f64,
    omega: f64,
    phase: f64,
    max_periods: usize,
) -> Result<PhaseStructure, FloquetError> {
    let T = 2.0 * std::f64::consts::PI / omega;
    let s2 = near_regime(sys, T, max_periods)?;
    let periods = 3usize;
    let dt = T / SAMPLES as f64;
    let st = EventDrivenSettings { dt_out: dt, max_step: dt, t_end: periods as f64 * T, ..Default::default() };
    let (tr, _) = event_driven(&s2, &st).map_err(|e| FloquetError::Simulation { what: e.to_string() })?;
    let first = (periods - 1) * SAMPLES;
    let classes = classify(sys, &tr, first, lo, hi);
    let sw = switch_samples(&classes);
    if sw.is_empty() {
        return Err(FloquetError::NoContact);
    }
    let k = sw.len();
    let kind_after = |j: usize| classes[sw[j]];
    let t_sw: Vec<f64> = sw.iter().map(|&i| (i as f64 - 0.5) * dt).collect();
    let (quarter, t0) = section(&t_sw, T, omega, phase);
    // first switch after t0
    let j0 = (0..k).min_by(|&a, &b| (t_sw[a] - t0).rem_euclid(T).total_cmp(&(t_sw[b] - t0).rem_euclid(T))).unwrap_or(0);
    let mut kinds = vec![kind_after((j0 + k - 1) % k)];
    let mut durations = Vec::new();
    let mut t_prev = t0;
    for i in 0..k {
        let j = (j0 + i) % k;
        let d = (t_sw[j] - t_prev).rem_euclid(T);
        durations.push(d);
        t_prev = t_sw[j];
        kinds.push(kind_after(j));
    }
    let i0 = first + ((t0 / dt).round() as usize % SAMPLES);
    Ok(PhaseStructure { quarter, kinds, durations, x0: tr.x_at(i0)[..sys.n()].to_vec(), z0: tr.z_at(i0)[0] })
}

/// `sys` started at the fixed point of the catching-up Poincare map (period `T`). The fixed
/// point only seeds the structure: an iteration stalled by the catching-up's own jitter near
/// the regime is good enough (Newton and Krawczyk decide); far from it is not.
fn near_regime(sys: &System, T: f64, max_periods: usize) -> Result<System, FloquetError> {
    let ps = PoincareSettings { dt: T / 2000.0, tol_residual: 1e-9, max_periods, ..Default::default() };
    let reg = periodic_regime(sys, &ps).map_err(|e| FloquetError::Simulation { what: e.to_string() })?;
    let scale = 1.0 + reg.x0.iter().chain(&reg.z0).fold(0.0f64, |a, v| a.max(v.abs()));
    if reg.status != FixedPointStatus::Converged && !(reg.residual <= 1e-4 * scale) {
        return Err(FloquetError::NoRegime { periods: reg.iterations });
    }
    let mut s2 = sys.clone();
    s2.x0 = DVector::from_column_slice(&reg.x0);
    s2.z0 = DVector::from_column_slice(&reg.z0);
    Ok(s2)
}

/// The class of each of the [`SAMPLES`] samples from `first` on: engaged on a face (`q` on the
/// face within `1e-9`, `y'` pushing) or resting.
fn classify(sys: &System, tr: &Trajectory, first: usize, lo: f64, hi: f64) -> Vec<PhaseKind> {
    let tol = 1e-9 * (1.0 + hi.abs().max(lo.abs()));
    (first..first + SAMPLES)
        .map(|i| {
            let x = DVector::from_column_slice(tr.x_at(i));
            let z = tr.z_at(i)[0];
            let w = DVector::from_column_slice(tr.w_at(i));
            let y = (&sys.C * &x)[0];
            let yd = (&sys.C * (&sys.A * &x + &sys.B * &w + &sys.E * z))[0];
            let q = z - y;
            if (q - hi).abs() <= tol && yd < 0.0 {
                PhaseKind::Engaged(Face::Hi)
            } else if (q - lo).abs() <= tol && yd > 0.0 {
                PhaseKind::Engaged(Face::Lo)
            } else {
                PhaseKind::Resting
            }
        })
        .collect()
}

/// The cyclic runs of `classes`: switch `j` at sample `sw[j]` (the class changes between
/// `sw - 1` and `sw`), one-sample runs dropped (classification noise at a release, where
/// `y' = 0`).
fn switch_samples(classes: &[PhaseKind]) -> Vec<usize> {
    let mut sw: Vec<usize> = (0..SAMPLES).filter(|&i| classes[i] != classes[(i + SAMPLES - 1) % SAMPLES]).collect();
    loop {
        let k = sw.len();
        if k < 2 {
            break;
        }
        let short = (0..k).find(|&j| (sw[(j + 1) % k] + SAMPLES - sw[j]) % SAMPLES <= 1);
        match short {
            Some(j) => {
                let j2 = (j + 1) % k;
                let (a, b) = (j.min(j2), j.max(j2));
                sw.remove(b);
                sw.remove(a);
            }
            None => break,
        }
    }
    sw
}

/// The section: the quarter of the input phase farthest from a switch (at times `t_sw`), and
/// its time in `[0, T)`.
fn section(t_sw: &[f64], T: f64, omega: f64, phase: f64) -> (usize, f64) {
    let dist = |t0: f64| {
        t_sw.iter()
            .map(|&ts| {
                let d = (ts - t0).rem_euclid(T);
                d.min(T - d)
            })
            .fold(f64::INFINITY, f64::min)
    };
    let t_of = |q: usize| ((q as f64 * std::f64::consts::FRAC_PI_2 - phase) / omega).rem_euclid(T);
    let quarter = (0..4).max_by(|&a, &b| dist(t_of(a)).total_cmp(&dist(t_of(b)))).unwrap_or(0);
    (quarter, t_of(quarter))
}
