//! The simulation-error least-squares problem of one (composite) hypothesis.
//!
//! Unknowns: effect parameters `theta` in a box and the initial state `x0`. Residual on the
//! estimation segment `k < k_est`: `r_{k,i} = (yhat_{k,i}(theta, x0) - y_{k,i}) / sigma_i`
//! with `sigma_i` the standard deviation of output `i`, so outputs weigh alike. A held-out
//! block `exclude = [b0, b1)` (blocked cross-validation) is left out of the residual; the
//! simulation still runs through it (the input there is known, the output is not used).
use crate::hypothesis::{Hypothesis, Scales};
use crate::simulate::{ExtendedModel, InputHold, SimOutput, StepMaps};
use model::effects::Effect;
use model::System;

/// Data and structure shared by every evaluation.
pub struct Problem<'a> {
    pub sys: &'a System,
    /// Effects fixed at given values (none in the single-effect round).
    pub fixed: Vec<Effect>,
    pub parts: Vec<Hypothesis>,
    pub scales: &'a Scales,
    /// Input, flat `k * m + j`, whole record.
    pub w: &'a [f64],
    /// Output, flat `k * p + i`, whole record.
    pub y: &'a [f64],
    pub m: usize,
    pub p: usize,
    pub dt: f64,
    pub k_est: usize,
    pub weights: Vec<f64>,
    pub maps: StepMaps,
    pub substeps: usize,
    /// Input between samples.
    pub hold: InputHold,
    /// Backlash output at the start (`None`: at rest in the play, `z0 = C x0`).
    pub z0: Option<Vec<f64>>,
    /// Samples `[b0, b1)` left out of the residual (a held-out fold).
    pub exclude: Option<(usize, usize)>,
}

impl<'a> Problem<'a> {
    /// Number of effect parameters.
    pub fn k(&self) -> usize {
        self.parts.iter().map(|h| h.k()).sum()
    }
    /// Effects for parameter vector `theta` (physical units, parts concatenated).
    pub fn effects(&self, theta: &[f64]) -> Vec<Effect> {
        let mut out = self.fixed.clone();
        let mut off = 0;
        for h in &self.parts {
            out.push(h.effect(&theta[off..off + h.k()], self.scales));
            off += h.k();
        }
        out
    }
    pub fn lower(&self) -> Vec<f64> {
        self.parts.iter().flat_map(|h| h.lower.clone()).collect()
    }
    pub fn upper(&self) -> Vec<f64> {
        self.parts.iter().flat_map(|h| h.upper.clone()).collect()
    }
    /// The hypothesis and its local index for parameter `i` of the concatenated vector.
    fn part_of(&self, mut i: usize) -> (&Hypothesis, usize) {
        for h in &self.parts {
            if i < h.k() {
                return (h, i);
            }
            i -= h.k();
        }
        panic!("parameter index {i} beyond the problem's parameters")
    }
    /// Physical parameters from unit coordinates (see [`Hypothesis::param_at`]).
    pub fn params_at(&self, u: &[f64]) -> Vec<f64> {
        u.iter()
            .enumerate()
            .map(|(i, v)| {
                let (h, j) = self.part_of(i);
                h.param_at(j, *v)
            })
            .collect()
    }
    /// Unit coordinates of physical parameters.
    pub fn units_of(&self, theta: &[f64]) -> Vec<f64> {
        theta
            .iter()
            .enumerate()
            .map(|(i, v)| {
                let (h, j) = self.part_of(i);
                h.unit_of(j, *v)
            })
            .collect()
    }
    /// `d theta_i / d u_i` at `u`.
    pub fn slope(&self, u: &[f64]) -> Vec<f64> {
        u.iter()
            .enumerate()
            .map(|(i, v)| {
                let (h, j) = self.part_of(i);
                h.slope(j, *v)
            })
            .collect()
    }
    /// Simulates with `theta`, `x0` over the first `len` samples (`None`: the whole record).
    pub fn simulate(&self, theta: &[f64], x0: &[f64], len: Option<usize>) -> Option<SimOutput> {
        let ext = ExtendedModel::from_maps(self.sys, &self.effects(theta), self.maps.clone(), self.substeps)
            .ok()?
            .with_hold(self.hold);
        let len = len.unwrap_or(self.w.len() / self.m);
        let out = ext.simulate_from(&self.w[..len * self.m], self.dt, x0, self.z0.as_deref());
        out.finite.then_some(out)
    }
    /// Weighted residual on the estimation samples (None if the simulation blew up).
    pub fn residual(&self, theta: &[f64], x0: &[f64]) -> Option<Vec<f64>> {
        let out = self.simulate(theta, x0, Some(self.k_est))?;
        let p = self.p;
        let (b0, b1) = self.exclude.unwrap_or((0, 0));
        Some(
            (0..self.k_est * p)
                .filter(|idx| !(b0 * p..b1 * p).contains(idx))
                .map(|idx| (out.y[idx] - self.y[idx]) * self.weights[idx % p])
                .collect(),
        )
    }
}
