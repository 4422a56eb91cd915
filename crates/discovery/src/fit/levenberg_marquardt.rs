//! Bounded Levenberg-Marquardt on the simulation error with several starts.
//!
//! Variables: effect parameters in unit coordinates `u in [0, 1]` (linear
//! `(theta - lower) / (upper - lower)`, or logarithmic for scale-like parameters, see
//! [`crate::hypothesis::Hypothesis::param_at`]) kept in the box by projection, and `x0 / x_scale`. Jacobian by forward differences (step `tol_fd`
//! in normalised units: large enough to see through the kinks of plays and stick-slip).
//! Step: `(J^T J + lambda diag(J^T J)) d = -J^T r`; accepted when the cost decreases.
//!
//! Uncertainty: Gauss-Newton covariance `s^2 (J^T J)^{-1}` with `s^2 = SSE / (N - k)`, mapped
//! back to physical units. It assumes white residuals and is optimistic when they are not.
use crate::fit::Problem;
use nalgebra::{DMatrix, DVector};
use serde::Serialize;

/// Settings of the solver.
#[derive(Debug, Clone)]
pub struct FitSettings {
    /// Iterations from each start before the best start is refined. Default 6.
    pub max_iter_start: usize,
    /// Iterations of the refinement. Default 40.
    pub max_iter: usize,
    /// Forward-difference step in normalised units. Default 1e-3.
    pub tol_fd: f64,
    /// Relative cost decrease below which iteration stops. Default 1e-7.
    pub tol_cost: f64,
}

impl Default for FitSettings {
    fn default() -> Self {
        Self { max_iter_start: 6, max_iter: 40, tol_fd: 1e-3, tol_cost: 1e-7 }
    }
}

/// How the solver ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FitStatus {
    Converged,
    MaxIterations,
    /// Every start produced a diverging simulation.
    Failed,
}

/// Result of a fit.
#[derive(Debug, Clone, Serialize)]
pub struct FitResult {
    /// Effect parameters (physical units).
    pub theta: Vec<f64>,
    /// Their standard deviations (Gauss-Newton); `NaN` where not identifiable.
    pub std: Vec<f64>,
    pub x0: Vec<f64>,
    /// Weighted sum of squared residuals on the estimation segment.
    pub sse: f64,
    /// Number of residuals.
    pub n_res: usize,
    pub status: FitStatus,
    pub evaluations: usize,
}

struct Vars<'p, 'a> {
    pb: &'p Problem<'a>,
    xs: Vec<f64>,
    k: usize,
}

impl Vars<'_, '_> {
    fn split(&self, v: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let theta = self.pb.params_at(&v[..self.k]);
        let x0 = (0..self.xs.len()).map(|i| v[self.k + i] * self.xs[i]).collect();
        (theta, x0)
    }
    fn res(&self, v: &[f64], evals: &mut usize) -> Option<Vec<f64>> {
        *evals += 1;
        let (t, x) = self.split(v);
        self.pb.residual(&t, &x)
    }
    fn clamp(&self, v: &mut [f64]) {
        for x in v.iter_mut().take(self.k) {
            *x = x.clamp(0.0, 1.0);
        }
    }
}

fn sse(r: &[f64]) -> f64 {
    r.iter().map(|x| x * x).sum()
}

fn jacobian(vars: &Vars, v: &[f64], r0: &[f64], h: f64, evals: &mut usize) -> DMatrix<f64> {
    let nv = v.len();
    let mut J = DMatrix::zeros(r0.len(), nv);
    for c in 0..nv {
        let mut vp = v.to_vec();
        // Step towards the interior for bounded variables.
        let step = if c < vars.k && v[c] + h > 1.0 { -h } else { h };
        vp[c] += step;
        if let Some(rp) = vars.res(&vp, evals) {
            for i in 0..r0.len() {
                J[(i, c)] = (rp[i] - r0[i]) / step;
            }
        }
    }
    J
}

/// Runs LM from `v`, at most `iters` iterations. Returns (v, r, cost, converged).
fn lm(
    vars: &Vars,
    mut v: Vec<f64>,
    iters: usize,
    s: &FitSettings,
    evals: &mut usize,
) -> Option<(Vec<f64>, Vec<f64>, f64, bool)> {
    let mut r = vars.res(&v, evals)?;
    let mut cost = sse(&r);
    let mut lambda = 1e-2;
    let mut converged = false;
    for _ in 0..iters {
        let J = jacobian(vars, &v, &r, s.tol_fd, evals);
        let JtJ = J.transpose() * &J;
        let g = J.transpose() * DVector::from_column_slice(&r);
        let mut improved = false;
        for _ in 0..8 {
            let mut M = JtJ.clone();
            for i in 0..M.nrows() {
                M[(i, i)] += lambda * JtJ[(i, i)].max(1e-12);
            }
            let Some(d) = M.lu().solve(&(-&g)) else {
                lambda *= 10.0;
                continue;
            };
            let mut vn: Vec<f64> = v.iter().zip(d.iter()).map(|(a, b)| a + b).collect();
            vars.clamp(&mut vn);
            if let Some(rn) = vars.res(&vn, evals) {
                let cn = sse(&rn);
                if cn < cost {
                    let rel = (cost - cn) / cost.max(1e-300);
                    v = vn;
                    r = rn;
                    cost = cn;
                    lambda = (lambda / 3.0).max(1e-9);
                    improved = true;
                    if rel < s.tol_cost {
                        converged = true;
                    }
                    break;
                }
            }
            lambda *= 4.0;
        }
        if !improved || converged {
            converged = true;
            break;
        }
    }
    Some((v, r, cost, converged))
}

/// Fits `pb` from the starts of its parts (the cartesian product is avoided: start `i` of
/// every part together) and initial state `x0_init`; `x_scale` scales the initial state.
pub fn fit(pb: &Problem, x0_init: &[f64], x_scale: &[f64], warm: Option<&[f64]>, s: &FitSettings) -> FitResult {
    let lo = pb.lower();
    let k = lo.len();
    let xs: Vec<f64> = x_scale.iter().map(|v| v.max(1e-9)).collect();
    let vars = Vars { pb, xs: xs.clone(), k };
    let mut evals = 0;
    let x0v: Vec<f64> = x0_init.iter().zip(&xs).map(|(a, b)| a / b).collect();
    let nstart = pb.parts.iter().map(|h| h.starts.len()).max().unwrap_or(1).max(1);
    let mut starts: Vec<Vec<f64>> = Vec::new();
    if let Some(w) = warm {
        // Warm start: the given leading parameters, then the new part's starts.
        let nw = w.len();
        for i in 0..nstart {
            let mut v: Vec<f64> = pb.units_of(w);
            let mut off = 0;
            for h in &pb.parts {
                if off >= nw {
                    v.extend(h.starts[i % h.starts.len()].iter());
                }
                off += h.k();
            }
            v.extend(x0v.iter());
            starts.push(v);
        }
    } else {
        for i in 0..nstart {
            let mut v: Vec<f64> = pb.parts.iter().flat_map(|h| h.starts[i % h.starts.len()].clone()).collect();
            v.extend(x0v.iter());
            starts.push(v);
        }
    }
    let mut best: Option<(Vec<f64>, Vec<f64>, f64, bool)> = None;
    for v in starts {
        if let Some(res) = lm(&vars, v, s.max_iter_start, s, &mut evals) {
            if best.as_ref().is_none_or(|b| res.2 < b.2) {
                best = Some(res);
            }
        }
    }
    let Some(b) = best else {
        return FitResult {
            theta: lo,
            std: vec![f64::NAN; k],
            x0: x0_init.to_vec(),
            sse: f64::INFINITY,
            n_res: 0,
            status: FitStatus::Failed,
            evaluations: evals,
        };
    };
    let (v, r, cost, conv) = lm(&vars, b.0.clone(), s.max_iter, s, &mut evals).unwrap_or(b);
    // Gauss-Newton covariance of the effect parameters.
    let J = jacobian(&vars, &v, &r, s.tol_fd, &mut evals);
    let nres = r.len();
    let dof = (nres as f64 - v.len() as f64).max(1.0);
    let s2 = cost / dof;
    let JtJ = J.transpose() * &J;
    let slope = pb.slope(&v[..k]);
    let std: Vec<f64> = match JtJ.clone().try_inverse() {
        Some(inv) => (0..k).map(|i| (s2 * inv[(i, i)]).max(0.0).sqrt() * slope[i].abs()).collect(),
        None => vec![f64::NAN; k],
    };
    let (theta, x0) = vars.split(&v);
    FitResult {
        theta,
        std,
        x0,
        sse: cost,
        n_res: nres,
        status: if conv { FitStatus::Converged } else { FitStatus::MaxIterations },
        evaluations: evals,
    }
}
