//! `eta_T = C xi_T` (eq. (etaT)) of the `T`-periodic solution of the linearised system
//! (eqs. (xieta), (xiT)), its oscillation `osc = Omega_[0,T](eta_T)` (eqs. (osc), (mho)) and
//! `||eta_T'||_inf` (eq. (zinf)).
//!
//! **Sine input** `w = a sin(omega t + phase)`: `xi_T(t) = Im(g e^{i theta})`, `theta = omega t +
//! phase`, `g = (i omega I - F)^{-1} B a`, so `eta_T = P sin(theta) + Q cos(theta)` with
//! `P = C Re g`, `Q = C Im g`: an ellipse centred at 0. With `G = [[P.P, P.Q], [P.Q, Q.Q]]` and
//! `rho = sqrt(lambda_max(G))`: `osc = 2 rho` and `||eta_T'||_inf = omega rho` exactly; both are
//! returned with a relative rounding margin `16 n cond(i omega I - F) eps` in the safe direction
//! (verified up to that margin).
//!
//! **Piecewise-affine inputs** (a square wave; a periodic CSV input, linearly interpolated):
//! closed form per piece ([`super::piecewise`]); `osc` from below by the samples' diameter and
//! `||eta_T'||_inf` from above by the samples and the Lipschitz constant of `eta_T'` inside the
//! pieces, its jumps at the input's edges taken in (verified up to the rounding margin).
//!
//! **Multisine inputs** (a sum of harmonics of the sine): the sum of the harmonics' phasor
//! orbits ([`super::multisine`]); `osc` and `||eta_T'||_inf` from its samples as for the
//! piecewise inputs, with the Lipschitz constant `sum_j |c_j| (k_j omega)^2 |C g_j|` (verified
//! up to the rounding margin).
//!
//! **Other periodic inputs**: grid samples from `dynamics::periodic::linearised`; the sampled
//! diameter is a lower bound of `osc` only if the samples are exact, and the sampled maximum of
//! `|eta_T'|` is not an upper bound, so both are reported as estimates (`verified = false`).
use super::piecewise::Jump;
use crate::error::BoundsError;
use dynamics::periodic::linearised::{linearised_periodic, sine_phasor, LinearisedSettings};
use model::{Input, System};
use nalgebra::{Complex, DVector};
use std::f64::consts::TAU;

/// Settings of the orbit samples.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrbitSettings {
    /// Number of sample intervals over one period (`samples + 1` points, both ends). Default `2000`.
    pub samples: usize,
}

impl Default for OrbitSettings {
    fn default() -> Self {
        Self { samples: 2000 }
    }
}

/// Samples of `eta_T`, `eta_T'` and the two quantities of Theorem 2 computed from them.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[non_exhaustive]
pub struct EtaOrbit {
    pub period: f64,
    pub t: Vec<f64>,
    pub eta: Vec<Vec<f64>>,
    pub deta: Vec<Vec<f64>>,
    /// Lower bound (or estimate, see `verified`) of `osc`, eq. (mho).
    pub osc: f64,
    /// Upper bound (or estimate) of `||eta_T'||_inf`, eq. (zinf).
    pub eta_dot_inf: f64,
    /// Lipschitz constant of `eta_T'` (`omega ||eta_T'||_inf`, from above, for a sine; the
    /// largest sampled difference quotient otherwise, an estimate).
    pub deta_lipschitz: f64,
    /// Relative rounding margin of the closed-form samples (`0` for grid samples).
    pub rel_margin: f64,
    /// True when `osc` is a lower and `eta_dot_inf` an upper bound (closed form).
    pub verified: bool,
    /// Where `eta_T'` jumps between two samples (a piecewise-constant input's edges): its
    /// values on both sides, which every cell bound takes in.
    pub jumps: Vec<Jump>,
    /// How they were obtained.
    pub method: &'static str,
}

fn lambda_max_2x2(a: f64, b: f64, c: f64) -> f64 {
    0.5 * (a + c) + (0.25 * (a - c) * (a - c) + b * b).sqrt()
}

impl EtaOrbit {
    /// Computes the orbit of `sys` (the system's `Theta` is ignored: eq. (xieta)).
    pub fn new(sys: &System, settings: &OrbitSettings) -> Result<Self, BoundsError> {
        let T = sys.period().ok_or(BoundsError::NoPeriod { kind: sys.input.kind() })?;
        if settings.samples < 2 {
            return Err(BoundsError::BadSetting {
                name: "orbit.samples",
                value: settings.samples as f64,
                reason: "must be at least 2",
            });
        }
        if let Some(o) = super::piecewise::orbit(sys, T, settings.samples) {
            return Ok(o);
        }
        match &sys.input {
            Input::Sine { amplitudes, omega, phase } => {
                Ok(Self::sine(sys, amplitudes, *omega, *phase, T, settings.samples))
            }
            Input::Multisine { amplitudes, omega, phase, harmonics } => {
                Ok(super::multisine::orbit(sys, amplitudes, *omega, *phase, harmonics, T, settings.samples))
            }
            _ => {
                let lp =
                    linearised_periodic(sys, &LinearisedSettings { samples: settings.samples, ..Default::default() })?;
                let osc = lp.osc_lower();
                let eta_dot_inf = lp.deta_inf_sampled();
                let deta_lipschitz = lp
                    .deta
                    .windows(2)
                    .zip(lp.t.windows(2))
                    .map(|(d, t)| geometry::linalg::dist(&d[1], &d[0]) / (t[1] - t[0]))
                    .fold(0.0, f64::max);
                Ok(Self {
                    period: T,
                    t: lp.t,
                    eta: lp.eta,
                    deta: lp.deta,
                    osc,
                    eta_dot_inf,
                    deta_lipschitz,
                    rel_margin: 0.0,
                    verified: false,
                    jumps: vec![],
                    method: "grid samples (first-order-hold step map); sampled max of |eta_T'| is not an upper bound",
                })
            }
        }
    }

    fn sine(sys: &System, a: &[f64], omega: f64, phase: f64, T: f64, K: usize) -> Self {
        let n = sys.n();
        // g = (i omega I - F)^{-1} B a and the condition number for the rounding margin.
        let (g, cond) = match sine_phasor(&sys.F(), &sys.B, a, omega) {
            Some(ph) => (ph.g, ph.cond),
            None => (DVector::from_element(n, Complex::new(f64::NAN, f64::NAN)), f64::INFINITY),
        };
        let gr = g.map(|z| z.re);
        let gi = g.map(|z| z.im);
        let P = &sys.C * &gr;
        let Q = &sys.C * &gi;
        let rho = lambda_max_2x2(P.dot(&P), P.dot(&Q), Q.dot(&Q)).max(0.0).sqrt();
        let margin = 1e-12 + 16.0 * n as f64 * cond * f64::EPSILON;
        let ok = rho.is_finite() && margin < 1e-3;
        let dt = T / K as f64;
        let mut t = Vec::with_capacity(K + 1);
        let mut eta = Vec::with_capacity(K + 1);
        let mut deta = Vec::with_capacity(K + 1);
        for k in 0..=K {
            let tk = k as f64 * dt;
            let th = omega * tk + phase;
            let (s, c) = th.sin_cos();
            t.push(tk);
            eta.push(P.iter().zip(Q.iter()).map(|(p, q)| p * s + q * c).collect());
            deta.push(P.iter().zip(Q.iter()).map(|(p, q)| omega * (p * c - q * s)).collect());
        }
        Self {
            period: T,
            t,
            eta,
            deta,
            osc: 2.0 * rho * (1.0 - margin),
            eta_dot_inf: omega * rho * (1.0 + margin),
            // eta_T'' = -omega^2 eta_T, |eta_T| <= rho.
            deta_lipschitz: omega * omega * rho * (1.0 + margin),
            rel_margin: margin,
            verified: ok,
            jumps: vec![],
            method: "closed form (sine input: eta_T is an ellipse, osc = 2 rho, ||eta_T'|| = omega rho)",
        }
    }

    /// Samples with `osc`, `eta_dot_inf` left to [`EtaOrbit::certify_samples`].
    pub(super) fn from_samples(
        period: f64,
        t: Vec<f64>,
        eta: Vec<Vec<f64>>,
        deta: Vec<Vec<f64>>,
        deta_lipschitz: f64,
        jumps: Vec<Jump>,
    ) -> Self {
        Self {
            period,
            t,
            eta,
            deta,
            osc: f64::NAN,
            eta_dot_inf: f64::NAN,
            deta_lipschitz,
            rel_margin: 0.0,
            verified: false,
            jumps,
            method: "",
        }
    }

    /// `osc` from below (the samples' diameter less twice their error) and `eta_dot_inf` from
    /// above (the one-cell bound of [`EtaOrbit::eta_dot_cells`]) for samples within `margin`
    /// (relative to the largest sample) of the orbit; `rel_margin` is set so that
    /// `rel_margin osc` and `rel_margin eta_dot_inf` bound the samples' errors, as the sine's.
    pub(super) fn certify_samples(&mut self, margin: f64, verified: bool) {
        let (big_eta, big_deta) = self.largest_samples();
        let (e_eta, e_deta) = (margin * big_eta, margin * big_deta);
        let diam = self.osc_sampled();
        self.osc = (diam - 2.0 * e_eta) * (1.0 - 1e-12);
        (self.rel_margin, self.eta_dot_inf) = (0.0, 0.0);
        let cells = self.eta_dot_cells(1).map_or(f64::INFINITY, |(b, _)| b[0]);
        self.eta_dot_inf = (cells + 2.0 * e_deta) * (1.0 + 1e-12);
        self.rel_margin =
            (e_eta / self.osc.max(f64::MIN_POSITIVE)).max(e_deta / self.eta_dot_inf.max(f64::MIN_POSITIVE));
        self.verified = verified && self.osc > 0.0 && self.eta_dot_inf.is_finite();
        if !self.verified {
            self.rel_margin = 0.0;
        }
    }

    /// The largest `|eta_T|` and `|eta_T'|` among the samples: what the margin of
    /// [`EtaOrbit::certify_samples`] is relative to.
    pub(super) fn largest_samples(&self) -> (f64, f64) {
        let big = |v: &[Vec<f64>]| v.iter().map(|x| geometry::linalg::norm(x)).fold(0.0, f64::max);
        (big(&self.eta), big(&self.deta))
    }

    /// The jumps of `eta_T'` inside sample intervals `lo..hi`: their one-sided values.
    fn jump_values(&self, lo: usize, hi: usize) -> impl Iterator<Item = &Vec<f64>> {
        self.jumps.iter().filter(move |j| (lo..hi).contains(&j.interval)).flat_map(|j| [&j.before, &j.after])
    }

    /// Largest distance between two samples: a lower bound of `osc` when the samples are exact
    /// (a cross-check of the closed form).
    pub fn osc_sampled(&self) -> f64 {
        let mut best = 0.0f64;
        for i in 0..self.eta.len() {
            for j in i + 1..self.eta.len() {
                best = best.max(geometry::linalg::dist(&self.eta[i], &self.eta[j]));
            }
        }
        best
    }

    /// Sampled maximum of `|eta_T'|` (a lower estimate of `||eta_T'||_inf`).
    pub fn eta_dot_sampled(&self) -> f64 {
        self.deta.iter().map(|d| geometry::linalg::norm(d)).fold(0.0, f64::max)
    }

    /// Upper bounds of `|eta_T'|` on `cells` equal cells of the period (`cells` must divide the
    /// number of sample intervals): the largest sampled `|eta_T'|` in the cell plus the
    /// Lipschitz constant times half the sample spacing plus the samples' rounding margin (a
    /// bound when `verified`), and the
    /// samples of `eta_T` at the cell boundaries. `None` if `cells` does not divide it.
    pub fn eta_dot_cells(&self, cells: usize) -> Option<(Vec<f64>, Vec<Vec<f64>>)> {
        let K = self.t.len() - 1;
        if cells == 0 || !K.is_multiple_of(cells) {
            return None;
        }
        let per = K / cells;
        let dt = self.period / K as f64;
        let slack = 0.5 * dt * self.deta_lipschitz * (1.0 + 1e-12);
        let bounds = (0..cells)
            .map(|c| {
                let m = (c * per..=(c + 1) * per)
                    .map(|k| &self.deta[k])
                    .chain(self.jump_values(c * per, (c + 1) * per))
                    .map(|d| geometry::linalg::norm(d))
                    .fold(0.0, f64::max);
                (m + slack + 2.0 * self.rel_margin * self.eta_dot_inf) * (1.0 + 1e-12)
            })
            .collect();
        let nodes = (0..=cells).map(|c| self.eta[c * per].clone()).collect();
        Some((bounds, nodes))
    }

    /// Enclosures `[low_c, high_c]` of the scalar `eta_T'` (p = 1) on `cells` equal cells (as
    /// [`EtaOrbit::eta_dot_cells`]: sampled extremes widened by the Lipschitz constant times half
    /// the sample spacing and the samples' rounding margin; enclosures when `verified`). `None`
    /// unless the output is scalar and `cells` divides the number of sample intervals.
    pub fn deta_cells_scalar(&self, cells: usize) -> Option<(Vec<f64>, Vec<f64>)> {
        let K = self.t.len() - 1;
        if cells == 0 || !K.is_multiple_of(cells) || self.deta.first().map(Vec::len) != Some(1) {
            return None;
        }
        let per = K / cells;
        let dt = self.period / K as f64;
        let slack = (0.5 * dt * self.deta_lipschitz + 2.0 * self.rel_margin * self.eta_dot_inf) * (1.0 + 1e-12);
        let (mut low, mut high) = (Vec::with_capacity(cells), Vec::with_capacity(cells));
        for c in 0..cells {
            let (lo, hi) = (c * per..=(c + 1) * per)
                .map(|k| &self.deta[k])
                .chain(self.jump_values(c * per, (c + 1) * per))
                .map(|d| d[0])
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
            low.push(lo - slack - 4.0 * f64::EPSILON * lo.abs());
            high.push(hi + slack + 4.0 * f64::EPSILON * hi.abs());
        }
        Some((low, high))
    }

    /// Every `stride`-th sample index, always including the last (`t = T`).
    pub fn subsample(&self, points: usize) -> Vec<usize> {
        let K = self.t.len() - 1;
        let m = points.clamp(1, K);
        let mut idx: Vec<usize> = (0..=m).map(|i| (i * K) / m).collect();
        idx.dedup();
        idx
    }
}

/// `2 pi / omega` helper for tests.
pub fn sine_period(omega: f64) -> f64 {
    TAU / omega
}
