//! The simulation-error least-squares problem of one (composite) hypothesis.
//!
//! Unknowns: effect parameters `theta` in a box and the initial state `x0`. Residual on the
//! estimation segment `k < k_est`: `r_{k,i} = (yhat_{k,i}(theta, x0) - y_{k,i}) / sigma_i`
//! with `sigma_i` the standard deviation of output `i`, so outputs weigh alike. A held-out
//! block `exclude = [b0, b1)` (blocked cross-validation) is left out of the residual; the
//! simulation still runs through it (the input there is known, the output is not used).
//!
//! Grey-box refit ([`Refit`]): freed nominal parameters are further unknowns, in their own
//! block of the solver (see [`crate::fit::nominal`]); without a refit the problem is as before.
use crate::fit::input_effects::{self, InputOp};
use crate::fit::nominal::Refit;
use crate::physics::{Hypothesis, Kind, Scales};
use dynamics::extended::{ExtendedModel, InputHold, SimOutput, StepMaps};
use model::effects::Effect;
use model::System;

/// Data and structure shared by every evaluation.
#[derive(Clone)]
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
    /// Freed nominal parameters (`None`: the nominal is fixed).
    pub refit: Option<Refit<'a>>,
}

impl<'a> Problem<'a> {
    /// Number of effect parameters.
    pub fn k(&self) -> usize {
        self.parts.iter().map(|h| h.k()).sum()
    }
    /// Effects for parameter vector `theta` (physical units, parts concatenated); per-input
    /// input effects are not among them (see [`Problem::input_ops`]).
    pub fn effects(&self, theta: &[f64]) -> Vec<Effect> {
        let mut out = self.fixed.clone();
        let mut off = 0;
        for h in &self.parts {
            if !matches!(h.kind, Kind::InputOn { .. }) {
                out.push(h.effect(&theta[off..off + h.k()], self.scales));
            }
            off += h.k();
        }
        out
    }
    /// Per-input input effects `(op, input, value)` for parameter vector `theta`.
    pub fn input_ops(&self, theta: &[f64]) -> Vec<(InputOp, usize, f64)> {
        let mut out = Vec::new();
        let mut off = 0;
        for h in &self.parts {
            if let Kind::InputOn { op, input } = h.kind {
                out.push((op, input, theta[off]));
            }
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
    /// Number of freed nominal parameters.
    pub fn k_nominal(&self) -> usize {
        self.refit.as_ref().map_or(0, |r| r.free.k())
    }
    /// Simulates with `theta`, `x0` over the first `len` samples (`None`: the whole record);
    /// freed nominal parameters at their values in [`Problem::refit`].
    pub fn simulate(&self, theta: &[f64], x0: &[f64], len: Option<usize>) -> Option<SimOutput> {
        let nom = self.refit.as_ref().map(|r| r.values.clone()).unwrap_or_default();
        self.simulate_with(theta, &nom, x0, len)
    }
    /// As [`Problem::simulate`] with freed nominal parameters at `nom`.
    /// The lag-one autocorrelation of the residual `y - yhat` at `(theta, nom, x0)` on the
    /// estimation segment (the largest over the outputs, [`crate::residual::ar1_rho`]); `None`
    /// where it cannot be simulated.
    pub fn estimation_residual_rho(&self, theta: &[f64], nom: &[f64], x0: &[f64]) -> Option<f64> {
        let sim = self.simulate_with(theta, nom, x0, None)?;
        let n = self.k_est * self.p;
        let e: Vec<f64> = self.y[..n].iter().zip(&sim.y[..n]).map(|(a, b)| a - b).collect();
        Some(crate::residual::ar1_rho(&e, self.k_est, self.p))
    }

    pub fn simulate_with(&self, theta: &[f64], nom: &[f64], x0: &[f64], len: Option<usize>) -> Option<SimOutput> {
        let len = len.unwrap_or(self.w.len() / self.m);
        let ops = self.input_ops(theta);
        if ops.is_empty() {
            let ext = self.model_at(theta, nom, self.substeps)?;
            let out = ext.simulate_from(&self.w[..len * self.m], self.dt, x0, self.z0.as_deref());
            return out.finite.then_some(out);
        }
        // Per-input effects: the transformed input on the sub-step grid, one linear step per
        // point (the same step maps), then back to the samples.
        let sub = self.substeps.max(1);
        let (m, p, n) = (self.m, self.p, x0.len());
        let wf = input_effects::transform(&self.w[..len * m], m, self.dt, sub, self.hold, &ops);
        let ext = self.model_at(theta, nom, 1)?;
        let fine = ext.simulate_from(&wf, self.dt / sub as f64, x0, self.z0.as_deref());
        if !fine.finite {
            return None;
        }
        let pick = |v: &[f64], c: usize| -> Vec<f64> {
            (0..len).flat_map(|k| v[k * sub * c..(k * sub + 1) * c].to_vec()).collect()
        };
        Some(SimOutput {
            y: pick(&fine.y, p),
            contact: (0..len).map(|k| fine.contact[k * sub]).collect(),
            z: pick(&fine.z, p),
            finite: true,
            x_rms: fine.x_rms.clone(),
            x: pick(&fine.x, n),
        })
    }
    /// The extended model at `(theta, nom)` (per-input effects left out: see
    /// [`Problem::input_ops`]), stepped `substeps` times per step of the problem's step maps.
    fn model_at(&self, theta: &[f64], nom: &[f64], substeps: usize) -> Option<ExtendedModel> {
        let effects = self.effects(theta);
        let refitted: Option<System> = match self.refit.as_ref() {
            Some(r) => Some(r.free.system_at(nom)?),
            None => None,
        };
        let sys = refitted.as_ref().unwrap_or(self.sys);
        let maps = match &refitted {
            None => self.maps.clone(),
            Some(s) => step_maps(s, self.dt, self.substeps)?,
        };
        Some(ExtendedModel::from_maps(sys, &effects, maps, substeps).ok()?.with_hold(self.hold))
    }

    /// [`Problem::residual_to`] at `x0` from a run beside the one from `x0_base`, whose
    /// residual is `r0` ([`ExtendedModel::simulate_merging`]): from the sample where the two
    /// runs' states are within `x_tol` of each other (per state; the outputs' tolerance
    /// follows from it), the rest of the residual is `r0`'s (the base run goes on only while
    /// the runs approach each other fast enough, see `dynamics::extended::merge`). Per-input
    /// effects and a digital loop are run whole. `None` where the simulation failed.
    #[allow(clippy::too_many_arguments)]
    pub fn residual_merged(
        &self,
        theta: &[f64],
        nom: &[f64],
        x0_base: &[f64],
        x0: &[f64],
        k_end: usize,
        r0: &[f64],
        x_tol: &[f64],
    ) -> Option<Vec<f64>> {
        if !self.input_ops(theta).is_empty() {
            return self.residual_to(theta, nom, x0, k_end);
        }
        let len = k_end.min(self.k_est);
        let ext = self.model_at(theta, nom, self.substeps)?;
        let (w, z0) = (&self.w[..len * self.m], self.z0.as_deref());
        let (out, merged_at) = match ext.simulate_merging(w, self.dt, x0_base, x0, z0, x_tol) {
            Some(run) => (run.out, run.merged_at),
            None => (ext.simulate_from(w, self.dt, x0, z0), None),
        };
        if !out.finite {
            return None;
        }
        self.weighted_residual(&out.y, len, merged_at.map(|k| (k, r0)))
    }

    /// The weighted residual `(yhat - y) w` of the simulated outputs `yhat` on the first `len`
    /// samples, the held-out block left out; with `base = (k, r0)`, from sample `k` on the
    /// entries of `r0` (the same layout) instead. `None` where `r0` is too short.
    fn weighted_residual(&self, yhat: &[f64], len: usize, base: Option<(usize, &[f64])>) -> Option<Vec<f64>> {
        let p = self.p;
        let (b0, b1) = self.exclude.unwrap_or((0, 0));
        let from = base.map_or(len, |b| b.0) * p;
        (0..len * p)
            .filter(|idx| !(b0 * p..b1 * p).contains(idx))
            .enumerate()
            .map(|(j, idx)| match base {
                Some((_, r0)) if idx >= from => r0.get(j).copied(),
                _ => Some((yhat[idx] - self.y[idx]) * self.weights[idx % p]),
            })
            .collect()
    }

    /// Weighted residual on the estimation samples (None if the simulation blew up).
    pub fn residual(&self, theta: &[f64], x0: &[f64]) -> Option<Vec<f64>> {
        let nom = self.refit.as_ref().map(|r| r.values.clone()).unwrap_or_default();
        self.residual_with(theta, &nom, x0)
    }
    /// As [`Problem::residual`] with freed nominal parameters at `nom`.
    pub fn residual_with(&self, theta: &[f64], nom: &[f64], x0: &[f64]) -> Option<Vec<f64>> {
        self.residual_to(theta, nom, x0, self.k_est)
    }

    /// The same problem stepped at `substeps` sub-steps per sample (its step maps recomputed):
    /// the solver's start phase at a coarser stepping ([`crate::fit::FitSettings::start_coarsening`]).
    /// `None` where the step maps are not finite.
    pub fn with_substeps(&self, substeps: usize) -> Option<Problem<'a>> {
        let sub = substeps.max(1);
        let maps = step_maps(self.sys, self.dt, sub)?;
        Some(Problem { maps, substeps: sub, ..self.clone() })
    }

    /// The residual on the first `k_end <= k_est` samples only (the solver's start phase on
    /// long records, see [`crate::fit::levenberg_marquardt`]).
    pub fn residual_to(&self, theta: &[f64], nom: &[f64], x0: &[f64], k_end: usize) -> Option<Vec<f64>> {
        let k_end = k_end.min(self.k_est);
        let out = self.simulate_with(theta, nom, x0, Some(k_end))?;
        self.weighted_residual(&out.y, k_end, None)
    }
}

/// The step maps of `sys` at `substeps` sub-steps per sample of `dt`; `None` where not finite.
fn step_maps(sys: &System, dt: f64, substeps: usize) -> Option<StepMaps> {
    let maps = StepMaps::new(&sys.F(), &sys.B, &sys.E, dt / substeps.max(1) as f64);
    maps.Phi.iter().chain(&maps.PsiB).chain(&maps.PsiE).all(|x| x.is_finite()).then_some(maps)
}
