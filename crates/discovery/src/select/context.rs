//! The data every candidate is fitted and scored on: the recording (flattened, time-major),
//! the output weights, the scales of the hypotheses' bounds and starts, and the simulation
//! setup of one pass of the diagnosis (input hold, sub-steps and their step maps, initial state).
use crate::fit::{FreeNominal, Problem, Refit};
use crate::hypothesis::{Hypothesis, Scales};
use dynamics::extended::{InputHold, StepMaps};
use model::effects::Effect;
use model::System;

/// The recording and model as every fit of one pass sees them (one input hold, one sub-step
/// count): builds the [`Problem`] of a hypothesis and scores simulations.
pub struct FitContext<'a> {
    pub sys: &'a System,
    pub scales: Scales,
    /// Inputs and outputs, time-major (`n` samples of `m` resp. `p`).
    pub w: Vec<f64>,
    pub y: Vec<f64>,
    pub m: usize,
    pub p: usize,
    pub dt: f64,
    /// Samples of the record and of its estimation segment.
    pub n: usize,
    pub k_est: usize,
    /// Output weights (inverse standard deviations).
    pub weights: Vec<f64>,
    pub maps: StepMaps,
    pub substeps: usize,
    /// Scales of the free initial state; empty when it is fixed (model file).
    pub x_scale: Vec<f64>,
    pub x0_init: Vec<f64>,
    pub hold: InputHold,
    pub z0: Option<Vec<f64>>,
    /// Freed nominal parameters (`[fit] free`), if any.
    pub free: Option<&'a FreeNominal>,
}

impl<'a> FitContext<'a> {
    /// The problem of `fixed` effects and the hypotheses `parts` on the estimation segment.
    pub fn problem(&'a self, fixed: Vec<Effect>, parts: Vec<Hypothesis>) -> Problem<'a> {
        self.problem_on(fixed, parts, self.k_est, None)
    }
    /// The problem of `parts` with the freed nominal parameters refitted from `nominal` (or
    /// held at the model file's values: `None`).
    pub fn problem_r(&'a self, parts: Vec<Hypothesis>, nominal: Option<&[f64]>) -> Problem<'a> {
        self.with_refit(self.problem(vec![], parts), nominal)
    }
    /// `pb` with the freed nominal parameters refitted from `nominal` (`None`: held).
    pub fn with_refit(&'a self, mut pb: Problem<'a>, nominal: Option<&[f64]>) -> Problem<'a> {
        if let (Some(free), Some(v)) = (self.free, nominal) {
            pb.refit = Some(Refit { free, values: v.to_vec() });
        }
        pb
    }
    /// The problem with residuals on `[0, k_end)` minus `exclude`.
    pub fn problem_on(
        &'a self,
        fixed: Vec<Effect>,
        parts: Vec<Hypothesis>,
        k_end: usize,
        exclude: Option<(usize, usize)>,
    ) -> Problem<'a> {
        Problem {
            sys: self.sys,
            fixed,
            parts,
            scales: &self.scales,
            w: &self.w,
            y: &self.y,
            m: self.m,
            p: self.p,
            dt: self.dt,
            k_est: k_end,
            weights: self.weights.clone(),
            maps: self.maps.clone(),
            substeps: self.substeps,
            hold: self.hold,
            z0: self.z0.clone(),
            exclude,
            refit: None,
        }
    }
    /// Weighted SSE of a simulated output against the recording over samples `[k0, k1)`.
    pub fn weighted_sse(&self, yhat: &[f64], k0: usize, k1: usize) -> f64 {
        self.weighted_sse_between(yhat, &self.y, k0, k1)
    }
    /// Weighted SSE between two outputs over samples `[k0, k1)`.
    pub fn weighted_sse_between(&self, a: &[f64], b: &[f64], k0: usize, k1: usize) -> f64 {
        let p = self.p;
        (k0 * p..k1 * p).map(|i| ((a[i] - b[i]) * self.weights[i % p]).powi(2)).sum()
    }
}
