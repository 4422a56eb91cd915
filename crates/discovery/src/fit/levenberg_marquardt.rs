//! Bounded Levenberg-Marquardt on the simulation error with several starts.
//!
//! Variables: effect parameters in unit coordinates `u in [0, 1]` (linear
//! `(theta - lower) / (upper - lower)`, or logarithmic for scale-like parameters, see
//! [`crate::hypothesis::Hypothesis::param_at`]) kept in the box by projection, freed nominal
//! parameters over their scales (grey-box refit, [`crate::fit::nominal`]; user bounds kept by
//! projection) and `x0 / x_scale`. Jacobian by forward differences (step `tol_fd`
//! in normalised units: large enough to see through the kinks of plays and stick-slip).
//! Step: `(J^T J + lambda diag(J^T J)) d = -J^T r`; accepted when the cost decreases.
//!
//! Uncertainty: the larger of the Gauss-Newton variance `s^2 (J^T J)^{-1}`, `s^2 = SSE / (N - k)`
//! (white residuals), and the sandwich `(J^T J)^{-1} S (J^T J)^{-1}` with a batch-means estimate
//! `S` of the long-run covariance of the score (coloured residuals), mapped back to physical
//! units. Model error that biases the estimate is not covered by either.
use crate::fit::Problem;
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
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
    /// Estimation segments of at least this many samples run the multi-start phase on a
    /// leading part (see [`LONG_RECORD`]); `usize::MAX` never. Default [`LONG_RECORD`].
    pub long_record: usize,
    /// The multi-start phase (screening and the start iterations) steps the simulation this
    /// many times more coarsely where that leaves at least [`MIN_START_SUBSTEPS`] sub-steps per
    /// sample; the refinement of the best start runs at the problem's own stepping (see
    /// [`START_COARSENING`]). 1: never. Default [`START_COARSENING`].
    pub start_coarsening: usize,
    /// Evaluate the columns of the finite-difference Jacobian and the starts in parallel
    /// (rayon; the result is the same either way). Default true.
    pub parallel: bool,
}

impl Default for FitSettings {
    fn default() -> Self {
        Self {
            max_iter_start: 6,
            max_iter: 40,
            tol_fd: 1e-3,
            tol_cost: 1e-7,
            long_record: LONG_RECORD,
            start_coarsening: START_COARSENING,
            parallel: true,
        }
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
    /// An effect parameter has no influence on the residual at the solution (e.g. friction
    /// that holds the mass stuck for the whole record, a saturation limit above every input):
    /// the fit is stuck, not evidence against the effect.
    ZeroGradient,
    /// An effect parameter ended on its upper bound (clipped): the optimum may lie beyond.
    AtBound,
}

/// The effect parameters' statistical covariance, both estimates (see
/// [`FitResult::effect_covariance`]).
#[derive(Debug, Clone)]
pub struct EffectCovariance {
    pub gauss_newton: DMatrix<f64>,
    pub sandwich: DMatrix<f64>,
}

impl EffectCovariance {
    /// The statistical 1-sigma of a function of the parameters `[off, off + g.len())` with
    /// gradient `g` there: `sqrt(max(g' C_gn g, g' C_sw g))` (linearised, as the parameters'
    /// own sigmas); `NaN` where `g` or the block is not finite or out of range.
    pub fn std_of(&self, off: usize, g: &[f64]) -> f64 {
        let k = g.len();
        if off + k > self.gauss_newton.nrows() || g.iter().any(|v| !v.is_finite()) {
            return f64::NAN;
        }
        let form = |c: &DMatrix<f64>| {
            (0..k).map(|i| (0..k).map(|j| g[i] * c[(off + i, off + j)] * g[j]).sum::<f64>()).sum::<f64>()
        };
        let v = form(&self.gauss_newton).max(form(&self.sandwich));
        if v.is_finite() {
            v.max(0.0).sqrt()
        } else {
            f64::NAN
        }
    }
}

impl FitStatus {
    /// Whether the fit can count as evidence against its effect (it converged inside its
    /// box with a non-zero gradient).
    pub fn conclusive(&self) -> bool {
        matches!(self, FitStatus::Converged | FitStatus::MaxIterations)
    }
}

/// Result of a fit.
#[derive(Debug, Clone, Serialize)]
pub struct FitResult {
    /// Effect parameters (physical units).
    pub theta: Vec<f64>,
    /// Their standard deviations (Gauss-Newton); `NaN` where not identifiable.
    pub std: Vec<f64>,
    /// Freed nominal parameters (grey-box refit; empty without one), physical units.
    pub nominal: Vec<f64>,
    /// Their standard deviations, as `std`.
    pub nominal_std: Vec<f64>,
    /// Their statistical correlation matrix (Gauss-Newton; `NaN` where not identifiable; empty
    /// without a refit or where the normal matrix is singular).
    pub nominal_correlation: Vec<Vec<f64>>,
    /// The effect parameters' covariance matrices, Gauss-Newton and batch-means sandwich
    /// (physical units; `None` where not computed or the normal matrix is singular): `std` is
    /// the larger of their diagonals, and a function `g` of the parameters has the 1-sigma
    /// `sqrt(max(g' C_gn g, g' C_sw g))` ([`EffectCovariance::std_of`]).
    #[serde(skip)]
    pub effect_covariance: Option<EffectCovariance>,
    pub x0: Vec<f64>,
    /// Weighted sum of squared residuals on the estimation segment.
    pub sse: f64,
    /// Number of residuals.
    pub n_res: usize,
    pub status: FitStatus,
    pub evaluations: usize,
}

#[derive(Clone)]
struct Vars<'p, 'a> {
    /// The problem (in the start phase of a finely stepped fit, its coarser-stepped copy).
    pb: &'p Problem<'a>,
    /// Scales of the free initial state (empty: the initial state is fixed at `x0_fixed`).
    xs: Vec<f64>,
    x0_fixed: Vec<f64>,
    k: usize,
    /// Freed nominal parameters: count, scales and scaled bounds.
    kn: usize,
    ns: Vec<f64>,
    nlo: Vec<f64>,
    nhi: Vec<f64>,
    /// Residuals on samples `[0, k_end)` of the estimation segment (`k_end = k_est` but in
    /// the start phase of a long record).
    k_end: usize,
}

impl Vars<'_, '_> {
    fn split(&self, v: &[f64]) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let theta = self.pb.params_at(&v[..self.k]);
        let nom: Vec<f64> = (0..self.kn).map(|i| v[self.k + i] * self.ns[i]).collect();
        let off = self.k + self.kn;
        let x0 = if self.xs.is_empty() {
            self.x0_fixed.clone()
        } else {
            (0..self.xs.len()).map(|i| v[off + i] * self.xs[i]).collect()
        };
        (theta, nom, x0)
    }
    /// Whether variable `c` is a freed nominal parameter on one of its bounds.
    fn nominal_at_bound(&self, v: &[f64], c: usize) -> bool {
        c >= self.k && c < self.k + self.kn && {
            let i = c - self.k;
            let tol = 1e-9 * (1.0 + v[c].abs());
            v[c] <= self.nlo[i] + tol || v[c] >= self.nhi[i] - tol
        }
    }
}

/// A bounded least-squares objective of the solver ([`lm`]): the residual at a point, the
/// projection on its box, and the side of a finite-difference step. [`fit`] solves one
/// recording's [`Problem`]; [`crate::fit::joint`] several recordings with shared parameters.
pub(crate) trait Objective: Sync {
    /// The residual at `v` (`None` where the simulation blew up); counts the evaluation.
    fn res(&self, v: &[f64], evals: &mut usize) -> Option<Vec<f64>>;
    /// Projects `v` on the box.
    fn clamp(&self, v: &mut [f64]);
    /// Whether a forward step `h` on variable `c` would leave the box (then it is taken
    /// backwards).
    fn step_back(&self, v: &[f64], c: usize, h: f64) -> bool;
    /// The residual at `vp`, which differs from `v` (residual `r0`) in variable `c` alone (a
    /// Jacobian column); [`Objective::res`] at `vp` unless the objective knows a cheaper way.
    fn res_beside(&self, v: &[f64], vp: &[f64], c: usize, r0: &[f64], evals: &mut usize) -> Option<Vec<f64>> {
        let _ = (v, c, r0);
        self.res(vp, evals)
    }
}

/// An initial-state column of the Jacobian takes the base run's residual from the sample
/// where the perturbed run's state is within this share of the step of the base run's, in
/// every state (in the fit's state scales; [`Problem::residual_merged`]): the perturbation
/// has decayed to `1e-8` of its size, and the column's entries after that would be below
/// `1e-8` of those of the start, under the forward difference's own truncation error.
pub const MERGE_DECAY: f64 = 1e-8;

impl Objective for Vars<'_, '_> {
    fn res(&self, v: &[f64], evals: &mut usize) -> Option<Vec<f64>> {
        *evals += 1;
        let (t, n, x) = self.split(v);
        self.pb.residual_to(&t, &n, &x, self.k_end)
    }
    /// An initial-state variable: the run from `vp` beside the run from `v` until they
    /// merge ([`Problem::residual_merged`], [`MERGE_DECAY`]).
    fn res_beside(&self, v: &[f64], vp: &[f64], c: usize, r0: &[f64], evals: &mut usize) -> Option<Vec<f64>> {
        if c < self.k + self.kn || self.xs.is_empty() {
            return self.res(vp, evals);
        }
        *evals += 1;
        let (t, n, x) = self.split(vp);
        let x_base = self.split(v).2;
        let step = (vp[c] - v[c]).abs();
        let x_tol: Vec<f64> = self.xs.iter().map(|s| MERGE_DECAY * step * s.abs()).collect();
        self.pb.residual_merged(&t, &n, &x_base, &x, self.k_end, r0, &x_tol)
    }
    fn clamp(&self, v: &mut [f64]) {
        for x in v.iter_mut().take(self.k) {
            *x = x.clamp(0.0, 1.0);
        }
        for i in 0..self.kn {
            v[self.k + i] = v[self.k + i].clamp(self.nlo[i], self.nhi[i]);
        }
    }
    fn step_back(&self, v: &[f64], c: usize, h: f64) -> bool {
        (c < self.k && v[c] + h > 1.0) || (c >= self.k && c < self.k + self.kn && v[c] + h > self.nhi[c - self.k])
    }
}

pub(crate) fn sse(r: &[f64]) -> f64 {
    r.iter().map(|x| x * x).sum()
}

/// Forward-difference Jacobian of the residual at `v` (residual `r0` there), step `h` towards
/// the interior of the box. The columns are independent simulations: with `parallel` they are
/// evaluated on the rayon pool (the same numbers either way).
pub(crate) fn jacobian<O: Objective>(
    vars: &O,
    v: &[f64],
    r0: &[f64],
    h: f64,
    parallel: bool,
    evals: &mut usize,
) -> DMatrix<f64> {
    let nv = v.len();
    let mut J = DMatrix::zeros(r0.len(), nv);
    let column = |c: usize| -> (f64, Option<Vec<f64>>, usize) {
        let mut vp = v.to_vec();
        // Step towards the interior for bounded variables.
        let step = if vars.step_back(v, c, h) { -h } else { h };
        vp[c] += step;
        let mut e = 0;
        let rp = vars.res_beside(v, &vp, c, r0, &mut e);
        (step, rp, e)
    };
    let cols: Vec<(f64, Option<Vec<f64>>, usize)> =
        if parallel && nv > 1 { (0..nv).into_par_iter().map(column).collect() } else { (0..nv).map(column).collect() };
    for (c, (step, rp, e)) in cols.into_iter().enumerate() {
        *evals += e;
        if let Some(rp) = rp {
            for i in 0..r0.len() {
                J[(i, c)] = (rp[i] - r0[i]) / step;
            }
        }
    }
    J
}

/// Long-run covariance of the score `J^T r` when the residuals are serially correlated
/// (batch means): the per-sample scores `g_t = sum_j J_(t p + j)^T r_(t p + j)` (residuals are
/// time-major with `p` outputs) are summed over consecutive blocks of `L` samples and
/// `S = sum_b G_b G_b^T`. `L` is ten times the lag at which the residual autocorrelation first
/// falls below `1/e` (block sums of an AR(1) with `rho = 0.9` then carry 90 % of the long-run
/// variance), at least 1, at most a tenth of the record so that there are >= 10 blocks. For
/// white residuals `S ~ s^2 J^T J`, the Gauss-Newton value.
fn long_run_score_covariance(J: &DMatrix<f64>, r: &[f64], p: usize) -> DMatrix<f64> {
    let nv = J.ncols();
    let p = p.max(1);
    let t_len = r.len() / p;
    let mut S = DMatrix::zeros(nv, nv);
    if t_len == 0 {
        return S;
    }
    let max_block = (t_len / 10).max(1);
    // Lags beyond a tenth of the largest block cannot change it: the search stops there.
    let block = (10 * residual_correlation_length(r, p, max_block.div_ceil(10))).clamp(1, max_block);
    let mut g = DVector::zeros(nv);
    let mut filled = 0;
    for t in 0..t_len {
        for j in 0..p {
            let idx = t * p + j;
            for c in 0..nv {
                g[c] += J[(idx, c)] * r[idx];
            }
        }
        filled += 1;
        if filled == block || t + 1 == t_len {
            S += &g * g.transpose();
            g.fill(0.0);
            filled = 0;
        }
    }
    S
}

/// First time lag (in samples, at most `max_lag`) at which the autocorrelation of the
/// residuals, pooled over the `p` outputs, falls below `1/e`: doubling lags bracket the
/// crossing, bisection locates it (about `2 log2(max_lag)` autocorrelations, not `max_lag`:
/// a long record with coloured residuals stays cheap).
fn residual_correlation_length(r: &[f64], p: usize, max_lag: usize) -> usize {
    let t_len = r.len() / p;
    let max_lag = max_lag.min(t_len.saturating_sub(1)).max(1);
    let c0: f64 = r.iter().map(|x| x * x).sum();
    if c0 <= 0.0 || !c0.is_finite() || t_len < 2 {
        return 1;
    }
    let below = |lag: usize| {
        let c: f64 = (lag * p..t_len * p).map(|i| r[i] * r[i - lag * p]).sum();
        c / c0 < (-1.0f64).exp()
    };
    let (mut lo, mut hi) = (0, 1);
    while !below(hi) {
        if hi >= max_lag {
            return max_lag;
        }
        lo = hi;
        hi = (2 * hi).min(max_lag);
    }
    // Not below at `lo` (or `lo = 0`), below at `hi`.
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if below(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

/// Runs LM from `v`, at most `iters` iterations. Returns (v, r, cost, converged).
pub(crate) fn lm<O: Objective>(
    vars: &O,
    v: Vec<f64>,
    iters: usize,
    s: &FitSettings,
    evals: &mut usize,
) -> Option<(Vec<f64>, Vec<f64>, f64, bool)> {
    let r = vars.res(&v, evals)?;
    Some(lm_from(vars, v, r, iters, s, evals))
}

/// [`lm`] from `v` whose residual `r` is known (the same iterations, one simulation fewer).
pub(crate) fn lm_from<O: Objective>(
    vars: &O,
    mut v: Vec<f64>,
    mut r: Vec<f64>,
    iters: usize,
    s: &FitSettings,
    evals: &mut usize,
) -> (Vec<f64>, Vec<f64>, f64, bool) {
    let mut cost = sse(&r);
    let mut lambda = 1e-2;
    let mut converged = false;
    for _ in 0..iters {
        let J = jacobian(vars, &v, &r, s.tol_fd, s.parallel, evals);
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
    (v, r, cost, converged)
}

/// Fits `pb` from the starts of its parts (the cartesian product is avoided: start `i` of
/// every part together) and initial state `x0_init`; `x_scale` scales the initial state, and
/// an empty `x_scale` holds the initial state fixed at `x0_init` (known from the model file).
///
/// With more than [`SCREENED_STARTS`] starts (decades of a level-like parameter), every start
/// is first evaluated once and only the best [`SCREENED_STARTS`] are iterated.
///
/// Steps: `starts` -> `best_start` (screening and a few iterations from each) -> refinement
/// of the best on the whole estimation segment -> `conclude` (covariance and status).
pub fn fit(pb: &Problem, x0_init: &[f64], x_scale: &[f64], warm: Option<&[f64]>, s: &FitSettings) -> FitResult {
    fit_with(pb, x0_init, x_scale, Starts::Warm(warm), s, true)
}

/// One group of starts of [`fit_groups`]: for each part of the problem (in order), its
/// parameters in physical units, or `None` for the part's own start grid.
pub type PartStarts = Vec<Option<Vec<f64>>>;

/// [`fit`] from several groups of starts, pooled: every start of every group is evaluated once,
/// the best [`POOLED_KEPT_STARTS`] by that first cost are iterated
/// ([`FitSettings::max_iter_start`] iterations each) and the best end point is refined, once.
/// The cost of one multi-start fit, where one fit per group costs a start phase, a refinement
/// and a covariance per group.
pub fn fit_groups(pb: &Problem, x0_init: &[f64], x_scale: &[f64], groups: &[PartStarts], s: &FitSettings) -> FitResult {
    fit_with(pb, x0_init, x_scale, Starts::Groups(groups), s, true)
}

/// Where [`fit_with`] starts from.
#[derive(Clone, Copy)]
enum Starts<'w> {
    /// The parts' start grids, the leading parameters given where warm ([`starts`]).
    Warm(Option<&'w [f64]>),
    /// Groups of starts ([`fit_groups`]).
    Groups(&'w [PartStarts]),
}

/// [`fit`]'s estimate alone: the same parameters, initial state and SSE, without the
/// covariance and the stuck-fit checks of its end point (one Jacobian fewer): `std` and
/// `nominal_std` are `NaN`, `nominal_correlation` is empty and the status is `Converged`,
/// `MaxIterations` or `Failed`. For refits whose spread, not their own sigma, is wanted (the
/// folds of the cross-validation and of the jackknife).
pub fn fit_estimate(
    pb: &Problem,
    x0_init: &[f64],
    x_scale: &[f64],
    warm: Option<&[f64]>,
    s: &FitSettings,
) -> FitResult {
    fit_with(pb, x0_init, x_scale, Starts::Warm(warm), s, false)
}

/// [`fit`] (`covariance`) or [`fit_estimate`].
fn fit_with(
    pb: &Problem,
    x0_init: &[f64],
    x_scale: &[f64],
    from: Starts,
    s: &FitSettings,
    covariance: bool,
) -> FitResult {
    let lo = pb.lower();
    let k = lo.len();
    let xs: Vec<f64> = x_scale.iter().map(|v| v.max(1e-9)).collect();
    let (kn, ns, nlo, nhi, nom0) = match &pb.refit {
        Some(r) => {
            let (a, b) = r.free.bounds_scaled();
            (r.free.k(), r.free.scale.clone(), a, b, r.values.clone())
        }
        None => (0, vec![], vec![], vec![], vec![]),
    };
    // Start of the freed nominal parameters (scaled, inside their bounds).
    let nomv: Vec<f64> = (0..kn).map(|i| (nom0[i] / ns[i]).clamp(nlo[i], nhi[i])).collect();
    let vars =
        Vars { pb, xs: xs.clone(), x0_fixed: x0_init.to_vec(), k, kn, ns: ns.clone(), nlo, nhi, k_end: pb.k_est };
    let mut evals = 0;
    if k == 0 && kn == 0 && xs.is_empty() {
        return nothing_to_fit(&vars, x0_init, &mut evals);
    }
    let x0v: Vec<f64> = if xs.is_empty() { vec![] } else { x0_init.iter().zip(&xs).map(|(a, b)| a / b).collect() };
    let groups: Vec<Vec<Vec<f64>>> = match from {
        Starts::Warm(warm) => vec![starts(pb, k, warm, &nomv, &x0v)],
        Starts::Groups(g) => g.iter().map(|g| group_starts(pb, g, &nomv, &x0v)).collect(),
    };
    // Several starts only (a single warm start goes straight to the refinement): screening and
    // the start iterations see a leading part of a long estimation segment (at least
    // LONG_RECORD / 2 samples and a third of it) and a finely stepped problem at a coarser
    // stepping; the refinement below sees the whole segment at the problem's stepping, from
    // the best start.
    let several = groups.iter().map(Vec::len).sum::<usize>() > 1;
    let coarse = several.then(|| start_phase_problem(pb, s)).flatten();
    let k_end = if several && pb.k_est >= s.long_record { (s.long_record / 2).max(pb.k_est / 3) } else { pb.k_est };
    let start_vars = Vars { pb: coarse.as_ref().unwrap_or(pb), k_end, ..vars.clone() };
    let keep = if groups.len() > 1 { POOLED_KEPT_STARTS } else { SCREENED_STARTS };
    let best = best_start(&start_vars, groups.concat(), keep, s, &mut evals);
    let failed = |evals: usize| FitResult {
        theta: lo.clone(),
        std: vec![f64::NAN; k],
        nominal: nom0.clone(),
        nominal_std: vec![f64::NAN; kn],
        nominal_correlation: vec![],
        effect_covariance: None,
        x0: x0_init.to_vec(),
        sse: f64::INFINITY,
        n_res: 0,
        status: FitStatus::Failed,
        evaluations: evals,
    };
    let Some(b) = best else { return failed(evals) };
    let refined = match start_vars.k_end == vars.k_end && coarse.is_none() {
        // the best start's residual is that of the whole segment already
        true => Some(lm_from(&vars, b.0, b.1, s.max_iter, s, &mut evals)),
        false => match lm(&vars, b.0.clone(), s.max_iter, s, &mut evals) {
            Some(done) => Some(done),
            // the best start's residual is of the leading part or the coarser stepping of the
            // start phase: the fallback is evaluated on the whole segment at the problem's
            // own stepping
            None => vars.res(&b.0, &mut evals).map(|r| {
                let c = sse(&r);
                (b.0, r, c, false)
            }),
        },
    };
    let Some(done) = refined else { return failed(evals) };
    if covariance {
        return conclude(&vars, done, s, evals);
    }
    let (v, r, cost, conv) = done;
    let (theta, nominal, x0) = vars.split(&v);
    FitResult {
        theta,
        std: vec![f64::NAN; k],
        nominal,
        nominal_std: vec![f64::NAN; kn],
        nominal_correlation: vec![],
        effect_covariance: None,
        x0,
        sse: cost,
        n_res: r.len(),
        status: if conv { FitStatus::Converged } else { FitStatus::MaxIterations },
        evaluations: evals,
    }
}

/// The problem of the start phase where it is stepped more coarsely than `pb`:
/// [`FitSettings::start_coarsening`] times fewer sub-steps, where that leaves at least
/// [`MIN_START_SUBSTEPS`].
fn start_phase_problem<'a>(pb: &Problem<'a>, s: &FitSettings) -> Option<Problem<'a>> {
    let k = pb.substeps / s.start_coarsening.max(1);
    (k >= MIN_START_SUBSTEPS && k < pb.substeps).then(|| pb.with_substeps(k)).flatten()
}

/// Nothing to fit: the nominal model from a known initial state.
fn nothing_to_fit(vars: &Vars, x0_init: &[f64], evals: &mut usize) -> FitResult {
    let r = vars.res(&[], evals);
    let (cost, n_res, status) = match &r {
        Some(r) => (sse(r), r.len(), FitStatus::Converged),
        None => (f64::INFINITY, 0, FitStatus::Failed),
    };
    FitResult {
        theta: vec![],
        std: vec![],
        nominal: vec![],
        nominal_std: vec![],
        nominal_correlation: vec![],
        effect_covariance: None,
        x0: x0_init.to_vec(),
        sse: cost,
        n_res,
        status,
        evaluations: *evals,
    }
}

/// The starts in solver units (`k` effect parameters): start `i` of every part together, then the
/// freed nominal parameters `nomv` and the scaled initial state `x0v`. A warm start keeps the
/// given leading parameters and takes the starts of the parts beyond them.
fn starts(pb: &Problem, k: usize, warm: Option<&[f64]>, nomv: &[f64], x0v: &[f64]) -> Vec<Vec<f64>> {
    let nstart = if warm.is_some_and(|w| w.len() >= k) {
        1
    } else {
        pb.parts.iter().map(|h| h.starts.len()).max().unwrap_or(1).max(1)
    };
    // The parts the warm start's leading parameters cover.
    let w = warm.unwrap_or(&[]);
    let mut off = 0;
    let given: Vec<Option<&[f64]>> = pb
        .parts
        .iter()
        .map(|h| {
            let part = (off < w.len()).then(|| &w[off..(off + h.k()).min(w.len())]);
            off += h.k();
            part
        })
        .collect();
    expand_starts(pb, &given, nstart, nomv, x0v)
}

/// The starts of one group of [`fit_groups`] in solver units: the given parts' parameters,
/// the others at start `i` of their grids (as many starts as the longest grid among them; one
/// where every part is given), then `nomv` and `x0v`. Given parameters of the wrong length
/// count as not given.
fn group_starts(pb: &Problem, group: &PartStarts, nomv: &[f64], x0v: &[f64]) -> Vec<Vec<f64>> {
    let given: Vec<Option<&[f64]>> = (0..pb.parts.len())
        .map(|j| group.get(j).and_then(|g| g.as_deref()).filter(|w| w.len() == pb.parts[j].k()))
        .collect();
    let grids = pb.parts.iter().zip(&given).filter(|(_, g)| g.is_none()).map(|(h, _)| h.starts.len());
    expand_starts(pb, &given, grids.max().unwrap_or(1).max(1), nomv, x0v)
}

/// `nstart` starts in solver units: for start `i`, each part's `given` parameters (physical
/// units, mapped to unit coordinates) or else start `i` of its grid, then `nomv` and `x0v`.
fn expand_starts(pb: &Problem, given: &[Option<&[f64]>], nstart: usize, nomv: &[f64], x0v: &[f64]) -> Vec<Vec<f64>> {
    (0..nstart)
        .map(|i| {
            let mut v: Vec<f64> = Vec::new();
            for (h, g) in pb.parts.iter().zip(given) {
                match g {
                    Some(w) => v.extend(w.iter().enumerate().map(|(c, x)| h.unit_of(c, *x))),
                    None => v.extend(h.starts[i % h.starts.len()].iter()),
                }
            }
            v.extend(nomv.iter());
            v.extend(x0v.iter());
            v
        })
        .collect()
}

/// Where [`lm`] ends: `(v, r, cost, converged)`.
type LmEnd = (Vec<f64>, Vec<f64>, f64, bool);

/// A start kept by [`best_start`] and its residual: `None` not evaluated yet, `Some(None)` its
/// simulation failed (in the screening).
type KeptStart = (Vec<f64>, Option<Option<Vec<f64>>>);

/// Screens the starts (more than `keep`: the best `keep` by their first cost), runs
/// `max_iter_start` iterations from each kept one and returns the best end point (the first
/// of equals). The kept starts are iterated in parallel where the settings say so (the same
/// result either way).
fn best_start(
    vars: &Vars,
    starts: Vec<Vec<f64>>,
    keep: usize,
    s: &FitSettings,
    evals: &mut usize,
) -> Option<(Vec<f64>, Vec<f64>, f64, bool)> {
    // Each start with its residual where already evaluated (by the screening).
    let kept: Vec<KeptStart> = if starts.len() > keep {
        let mut scored: Vec<(f64, Vec<f64>, Option<Vec<f64>>)> = starts
            .into_iter()
            .map(|v| {
                let r = vars.res(&v, evals);
                (r.as_deref().map_or(f64::INFINITY, sse), v, r)
            })
            .collect();
        scored.sort_by(|a, b| a.0.total_cmp(&b.0));
        scored.into_iter().take(keep).map(|(_, v, r)| (v, Some(r))).collect()
    } else {
        starts.into_iter().map(|v| (v, None)).collect()
    };
    let run = |(v, r): (Vec<f64>, Option<Option<Vec<f64>>>)| {
        let mut e = 0;
        let out = match r {
            Some(Some(r)) => Some(lm_from(vars, v, r, s.max_iter_start, s, &mut e)),
            Some(None) => None,
            None => lm(vars, v, s.max_iter_start, s, &mut e),
        };
        (out, e)
    };
    let done: Vec<(Option<LmEnd>, usize)> = if s.parallel && kept.len() > 1 {
        kept.into_par_iter().map(run).collect()
    } else {
        kept.into_iter().map(run).collect()
    };
    let mut best: Option<(Vec<f64>, Vec<f64>, f64, bool)> = None;
    for (res, e) in done {
        *evals += e;
        if let Some(res) = res {
            if best.as_ref().is_none_or(|b| res.2 < b.2) {
                best = Some(res);
            }
        }
    }
    best
}

/// The result at the solution `(v, r, cost, converged)`: parameters in physical units, their
/// 1-sigma (the larger of Gauss-Newton and the batch-means sandwich) and the fit's status.
fn conclude(vars: &Vars, done: (Vec<f64>, Vec<f64>, f64, bool), s: &FitSettings, mut evals: usize) -> FitResult {
    let (v, r, cost, conv) = done;
    let (pb, k, kn) = (vars.pb, vars.k, vars.kn);
    // Gauss-Newton covariance of the effect parameters.
    let J = jacobian(vars, &v, &r, s.tol_fd, s.parallel, &mut evals);
    let nres = r.len();
    let dof = (nres as f64 - v.len() as f64).max(1.0);
    let s2 = cost / dof;
    let JtJ = J.transpose() * &J;
    let slope = pb.slope(&v[..k]);
    // Physical units per solver unit: effect slopes, then the nominal scales.
    let unit: Vec<f64> = slope.iter().map(|s| s.abs()).chain(vars.ns.iter().copied()).collect();
    let inverse = JtJ.clone().try_inverse();
    let nominal_correlation = inverse.as_ref().map_or(vec![], |inv| correlation_block(inv, k, kn));
    let mut effect_covariance = None;
    let std_all: Vec<f64> = match inverse {
        Some(inv) => {
            // The larger of the white-noise and the coloured-residual (batch-means sandwich)
            // variances: the report never claims more precision than either supports.
            let sandwich = &inv * long_run_score_covariance(&J, &r, pb.p) * &inv;
            let physical = |m: &DMatrix<f64>| DMatrix::from_fn(k, k, |i, j| m[(i, j)] * unit[i] * unit[j]);
            effect_covariance =
                Some(EffectCovariance { gauss_newton: physical(&(&inv * s2)), sandwich: physical(&sandwich) });
            (0..k + kn).map(|i| (s2 * inv[(i, i)]).max(sandwich[(i, i)]).max(0.0).sqrt() * unit[i]).collect()
        }
        None => vec![f64::NAN; k + kn],
    };
    let std = std_all[..k].to_vec();
    let nominal_std = std_all[k..].to_vec();
    let (theta, nominal, x0) = vars.split(&v);
    // Stuck fits: a parameter without influence, or one clipped at its upper bound (a freed
    // nominal parameter: at either of its bounds).
    let col_norm = |c: usize| J.column(c).norm();
    let scale = (0..v.len()).map(col_norm).fold(0.0, f64::max);
    let status = if (0..k + kn).any(|c| col_norm(c) <= 1e-9 * scale.max(1e-300) || col_norm(c) == 0.0) {
        FitStatus::ZeroGradient
    } else if (0..k).any(|c| v[c] >= 1.0 - 1e-9) || (k..k + kn).any(|c| vars.nominal_at_bound(&v, c)) {
        FitStatus::AtBound
    } else if conv {
        FitStatus::Converged
    } else {
        FitStatus::MaxIterations
    };
    FitResult {
        theta,
        std,
        nominal,
        nominal_std,
        nominal_correlation,
        effect_covariance,
        x0,
        sse: cost,
        n_res: nres,
        status,
        evaluations: evals,
    }
}

/// Row `i` of a correlation matrix as `(name, r)` for every other parameter (`names` in the
/// matrix's order); empty where the matrix was not computed.
pub fn correlations_with_others<'n>(
    names: impl Iterator<Item = &'n str>,
    matrix: &[Vec<f64>],
    i: usize,
) -> Vec<(String, f64)> {
    let Some(row) = matrix.get(i) else { return vec![] };
    names.zip(row).enumerate().filter(|(j, _)| *j != i).map(|(_, (n, r))| (n.to_string(), *r)).collect()
}

/// The correlation matrix of the `n` parameters from index `from` of the covariance (or any
/// positive multiple of it) `cov`; `NaN` where a variance is not positive.
pub fn correlation_block(cov: &DMatrix<f64>, from: usize, n: usize) -> Vec<Vec<f64>> {
    (0..n)
        .map(|i| {
            (0..n)
                .map(|j| {
                    let (a, b) = (cov[(from + i, from + i)], cov[(from + j, from + j)]);
                    if a > 0.0 && b > 0.0 {
                        (cov[(from + i, from + j)] / (a * b).sqrt()).clamp(-1.0, 1.0)
                    } else {
                        f64::NAN
                    }
                })
                .collect()
        })
        .collect()
}

/// Starts iterated after screening (see [`fit`]).
pub const SCREENED_STARTS: usize = 3;

/// Starts iterated after the pooled screening of [`fit_groups`]: twice [`SCREENED_STARTS`], as
/// the groups' starts come from different readings (the pair search's scaled and own estimates,
/// each with the other effect's start grid). On the slowest pair case (fresh seed 9862,
/// `backlash_inertia + input_delay` #1) 3 kept starts ended 5-164 worse in BIC than one fit per
/// group on 3 of 10 pairs, 6 ended as well or better on all but one (at a bound before).
pub const POOLED_KEPT_STARTS: usize = 6;

/// Estimation segments of at least this many samples run the start phase of [`fit`] on a
/// leading part (at least half of this and a third of the segment), the final iterations on the
/// whole: the cost of the multi-start phase stops growing with the record.
pub const LONG_RECORD: usize = 24_000;

/// How many times more coarsely the start phase of a multi-start fit steps the simulation
/// ([`FitSettings::start_coarsening`]). The start phase only ranks the starts' basins and
/// iterates [`FitSettings::max_iter_start`] times from the best few; the refinement and the
/// covariance run at the stepping the recording needs. A lightly damped plant or a stiff play
/// needs 32-64 sub-steps per sample, where most of a pair search's cost was its start phase.
pub const START_COARSENING: usize = 4;

/// The fewest sub-steps per sample the start phase is coarsened to (a problem stepped at fewer
/// than `START_COARSENING * MIN_START_SUBSTEPS` keeps its own stepping there): below 4 the
/// stepping moves a backlash inertia's optimum by several per cent (BENCHMARKS, "The stepping
/// check refits from the starts only where the estimate moved").
pub const MIN_START_SUBSTEPS: usize = 4;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench_gen::gauss;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    /// Variance of the fitted mean of `r` (one parameter, `J = 1`): sandwich over Gauss-Newton.
    fn sandwich_over_gauss_newton(r: &[f64]) -> f64 {
        let n = r.len() as f64;
        let J = DMatrix::from_element(r.len(), 1, 1.0);
        let s2 = r.iter().map(|x| x * x).sum::<f64>() / (n - 1.0);
        let gn = s2 / n;
        let sandwich = long_run_score_covariance(&J, r, 1)[(0, 0)] / (n * n);
        sandwich / gn
    }

    #[test]
    fn white_residuals_keep_the_gauss_newton_variance() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let r: Vec<f64> = (0..20_000).map(|_| gauss(&mut rng)).collect();
        let ratio = sandwich_over_gauss_newton(&r);
        assert!((0.6..1.6).contains(&ratio), "white noise: sandwich / GN = {ratio}");
    }

    #[test]
    fn coloured_residuals_widen_the_variance_by_the_long_run_factor() {
        // AR(1), rho = 0.9: the variance of a mean is (1 + rho) / (1 - rho) = 19 times the
        // white-noise formula. Gauss-Newton alone (ratio 1) would fail this check.
        let rho = 0.9;
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut x = 0.0;
        let r: Vec<f64> = (0..50_000)
            .map(|_| {
                x = rho * x + gauss(&mut rng);
                x
            })
            .collect();
        let ratio = sandwich_over_gauss_newton(&r);
        assert!((13.0..25.0).contains(&ratio), "AR(1) 0.9: sandwich / GN = {ratio}, expected about 17-19");
        assert_eq!(residual_correlation_length(&r, 1, 1000), 10, "1/e crossing of 0.9^k is at k = 10");
    }

    #[test]
    fn interleaved_outputs_use_time_lags() {
        // Two outputs, time-major: output 0 is AR(1), output 1 white. The correlation length is
        // measured in time steps (pooled), not in stacked indices.
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut x = 0.0;
        let mut r = Vec::new();
        for _ in 0..20_000 {
            x = 0.9 * x + gauss(&mut rng);
            r.push(x);
            r.push(gauss(&mut rng));
        }
        let l = residual_correlation_length(&r, 2, 1000);
        assert!((3..=10).contains(&l), "pooled correlation length {l}");
    }

    /// A covariance's correlation, named row by row; a parameter without variance gets `NaN`.
    #[test]
    fn correlation_of_a_known_covariance() {
        let cov = DMatrix::from_row_slice(3, 3, &[4.0, 2.0, 0.0, 2.0, 9.0, 0.0, 0.0, 0.0, 0.0]);
        let c = correlation_block(&cov, 0, 3);
        assert!((c[0][1] - 1.0 / 3.0).abs() < 1e-15 && (c[1][0] - c[0][1]).abs() == 0.0);
        assert_eq!((c[0][0], c[1][1]), (1.0, 1.0));
        assert!(c[2][0].is_nan() && c[0][2].is_nan());
        let row = correlations_with_others(["a", "b", "c"].into_iter(), &c, 1);
        assert_eq!(row.len(), 2);
        assert_eq!((row[0].0.as_str(), row[0].1), ("a", c[1][0]));
        assert!(correlations_with_others(["a"].into_iter(), &[], 0).is_empty());
        // from an offset: the block of the last two
        assert!((correlation_block(&cov, 1, 2)[0][0] - 1.0).abs() < 1e-15);
    }
}
