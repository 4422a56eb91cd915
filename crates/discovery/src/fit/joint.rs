//! One model fitted jointly to several recordings of one machine (issue 28 item 3).
//!
//! Unknowns: the shared parameters (effect parameters `theta` in unit coordinates and the
//! freed nominal parameters over their scales, as in [`crate::fit::levenberg_marquardt`]) and
//! one initial state `x0_r` per recording (its nuisance). Residual: the recordings' weighted
//! residuals ([`Problem::residual_with`], each with its own output weights, hold, sub-steps
//! and sample time) concatenated, recording `r`'s scaled by `1 / sqrt(N_r)` (`N_r` its
//! residual count) so that every recording weighs alike whatever its length:
//! `cost = sum_r SSE_r / N_r`.
//!
//! With the shared parameters held ([`fit_joint`] with `free_shared = false`) the fit is
//! the initial states alone: a fitted model judged on a recording it was not fitted on.
use crate::fit::levenberg_marquardt::{correlation_block, jacobian, lm, sse, Objective};
use crate::fit::{FitSettings, FitStatus, Problem};

/// The shared parameters of a joint fit: where it starts, or where it is held.
#[derive(Debug, Clone)]
pub struct Shared {
    /// Effect parameters (physical units) of the problems' parts.
    pub theta: Vec<f64>,
    /// Freed nominal parameters (physical units; empty without a refit).
    pub nominal: Vec<f64>,
}

/// The result of a joint fit.
#[derive(Debug, Clone)]
pub struct JointFit {
    pub shared: Shared,
    /// 1-sigma (Gauss-Newton on the joint residual) of `shared.theta` and `shared.nominal`;
    /// `NaN` where not identifiable or not fitted.
    pub std: Vec<f64>,
    pub nominal_std: Vec<f64>,
    /// Statistical correlation of the nominal parameters (Gauss-Newton; empty where not
    /// computed).
    pub nominal_correlation: Vec<Vec<f64>>,
    /// Initial state per recording.
    pub x0: Vec<Vec<f64>>,
    /// Weighted SSE per recording (unscaled by its length) and its residual count.
    pub sse: Vec<f64>,
    pub n_res: Vec<usize>,
    pub status: FitStatus,
}

/// The joint objective (see the module documentation).
struct Joint<'p, 'a> {
    pbs: &'p [Problem<'a>],
    /// Effect parameters and freed nominal parameters in the variables (0 when held).
    k: usize,
    kn: usize,
    held: Shared,
    free_shared: bool,
    /// Nominal scales and scaled bounds.
    ns: Vec<f64>,
    nlo: Vec<f64>,
    nhi: Vec<f64>,
    /// Initial-state scales per recording.
    xs: Vec<Vec<f64>>,
    /// `1 / sqrt(N_r)`.
    norm: Vec<f64>,
}

impl Joint<'_, '_> {
    fn split(&self, v: &[f64]) -> (Shared, Vec<Vec<f64>>) {
        let pb = &self.pbs[0];
        let shared = if self.free_shared {
            Shared {
                theta: pb.params_at(&v[..self.k]),
                nominal: (0..self.kn).map(|i| v[self.k + i] * self.ns[i]).collect(),
            }
        } else {
            self.held.clone()
        };
        let mut off = if self.free_shared { self.k + self.kn } else { 0 };
        let x0 = self
            .xs
            .iter()
            .map(|xs| {
                let x: Vec<f64> = xs.iter().enumerate().map(|(i, s)| v[off + i] * s).collect();
                off += xs.len();
                x
            })
            .collect();
        (shared, x0)
    }
    fn residuals(&self, v: &[f64]) -> Option<Vec<Vec<f64>>> {
        let (sh, x0) = self.split(v);
        self.pbs.iter().zip(&x0).map(|(pb, x)| pb.residual_with(&sh.theta, &sh.nominal, x)).collect()
    }
}

impl Objective for Joint<'_, '_> {
    fn res(&self, v: &[f64], evals: &mut usize) -> Option<Vec<f64>> {
        *evals += 1;
        let parts = self.residuals(v)?;
        Some(parts.iter().zip(&self.norm).flat_map(|(r, c)| r.iter().map(move |x| x * c)).collect())
    }
    fn clamp(&self, v: &mut [f64]) {
        if !self.free_shared {
            return;
        }
        for x in v.iter_mut().take(self.k) {
            *x = x.clamp(0.0, 1.0);
        }
        for i in 0..self.kn {
            v[self.k + i] = v[self.k + i].clamp(self.nlo[i], self.nhi[i]);
        }
    }
    fn step_back(&self, v: &[f64], c: usize, h: f64) -> bool {
        self.free_shared
            && ((c < self.k && v[c] + h > 1.0)
                || (c >= self.k && c < self.k + self.kn && v[c] + h > self.nhi[c - self.k]))
    }
}

/// Fits the problems `pbs` (one per recording, the same parts and refit; residuals on their
/// estimation samples) jointly from `start` and the initial states `x0_init` scaled by
/// `x_scale` (per recording); `free_shared = false` holds the shared parameters at `start`
/// and fits the initial states alone.
pub fn fit_joint(
    pbs: &[Problem],
    start: &Shared,
    x0_init: &[Vec<f64>],
    x_scale: &[Vec<f64>],
    free_shared: bool,
    s: &FitSettings,
) -> JointFit {
    let pb = &pbs[0];
    let (k, kn) = if free_shared { (pb.k(), pb.k_nominal()) } else { (0, 0) };
    let (ns, nlo, nhi) = match (&pb.refit, free_shared) {
        (Some(r), true) => {
            let (a, b) = r.free.bounds_scaled();
            (r.free.scale.clone(), a, b)
        }
        _ => (vec![], vec![], vec![]),
    };
    let xs: Vec<Vec<f64>> = x_scale.iter().map(|v| v.iter().map(|x| x.max(1e-9)).collect()).collect();
    let norm: Vec<f64> = pbs.iter().map(|p| 1.0 / ((p.k_est * p.p).max(1) as f64).sqrt()).collect();
    let joint = Joint { pbs, k, kn, held: start.clone(), free_shared, ns, nlo, nhi, xs, norm };
    let mut v: Vec<f64> = Vec::new();
    if free_shared {
        v.extend(pb.units_of(&start.theta));
        v.extend((0..kn).map(|i| (start.nominal[i] / joint.ns[i]).clamp(joint.nlo[i], joint.nhi[i])));
    }
    for (x, s) in x0_init.iter().zip(&joint.xs) {
        v.extend(x.iter().zip(s).map(|(a, b)| a / b));
    }
    let mut evals = 0;
    let failed = || JointFit {
        shared: start.clone(),
        std: vec![f64::NAN; k],
        nominal_std: vec![f64::NAN; kn],
        nominal_correlation: vec![],
        x0: x0_init.to_vec(),
        sse: vec![f64::INFINITY; pbs.len()],
        n_res: vec![0; pbs.len()],
        status: FitStatus::Failed,
    };
    let Some((v, r, cost, converged)) = lm(&joint, v, s.max_iter, s, &mut evals) else { return failed() };
    let Some(parts) = joint.residuals(&v) else { return failed() };
    // Gauss-Newton sigma of the shared parameters, in physical units.
    let (mut std, mut nominal_std) = (vec![f64::NAN; k], vec![f64::NAN; kn]);
    let mut nominal_correlation = vec![];
    if k + kn > 0 {
        let J = jacobian(&joint, &v, &r, s.tol_fd, s.parallel, &mut evals);
        let dof = (r.len() as f64 - v.len() as f64).max(1.0);
        // s^2 of the scaled residual: exact where the recordings have equal residual counts,
        // their mean where not (white residuals; no sandwich here).
        let s2 = cost / dof;
        if let Some(inv) = (J.transpose() * &J).try_inverse() {
            let slope = pb.slope(&v[..k]);
            for i in 0..k {
                std[i] = (s2 * inv[(i, i)]).max(0.0).sqrt() * slope[i].abs();
            }
            for i in 0..kn {
                nominal_std[i] = (s2 * inv[(k + i, k + i)]).max(0.0).sqrt() * joint.ns[i];
            }
            nominal_correlation = correlation_block(&inv, k, kn);
        }
    }
    let (shared, x0) = joint.split(&v);
    JointFit {
        shared,
        std,
        nominal_std,
        nominal_correlation,
        x0,
        sse: parts.iter().map(|r| sse(r)).collect(),
        n_res: parts.iter().map(|r| r.len()).collect(),
        status: if converged { FitStatus::Converged } else { FitStatus::MaxIterations },
    }
}
