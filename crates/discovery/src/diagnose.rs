//! The diagnosis pipeline: nominal fit, residual tests, localisation, hypotheses, selection,
//! fitted model and report.
//!
//! Segments: the first `estimation_fraction` (default 70 %) of the record is the estimation
//! segment (every hypothesis is fitted on it and ranked by BIC there); the rest is the
//! validation segment, simulated free-running from the start of the record with the
//! estimation fit (the fit % reported). A candidate is accepted by blocked cross-validation
//! over `cv_folds` contiguous folds of the whole record (each fold held out in turn, the
//! hypothesis and the nominal refitted on the others, the held-out fold predicted by a
//! free run through it), not by one validation segment.
//!
//! Before any of that: the input hold (zero- or first-order, `auto` by the nominal fit), the
//! sub-steps per sample (by convergence against the noise level, see [`crate::discretisation`])
//! and the initial state (the model file's when it states one, else estimated).
use crate::discretisation::{self, SubstepCheck};
use crate::fit::jackknife::{self, Jackknife};
use crate::fit::missing_input::{self, MissingInput, MISSING_MARGIN, MISSING_SHARE};
use crate::fit::{self, FitResult, FitSettings, FreeNominal, Problem, Refit};
use crate::hypothesis::{self, Hypothesis, Kind, Scales};
use crate::localise::{self, Localisation, RegimeShare, Window};
use crate::metrics::{self, Fit};
use crate::residual::{self, ResidualTests};
use crate::select::{self, SelectSettings};
use crate::{DiscoveryError, Recording};
use dynamics::extended::{ExtendedModel, InputHold, StepMaps};
use model::effects::Effect;
use model::{Input, SimDefaults, System};
use rayon::prelude::*;
use serde::Serialize;

/// Settings of the diagnosis.
#[derive(Debug, Clone)]
pub struct DiagnoseSettings {
    /// Fraction of the record used for estimation. Default 0.7.
    pub estimation_fraction: f64,
    /// Largest number of linear sub-steps per sample. Default 64.
    pub max_substeps: usize,
    /// First number of sub-steps tried: `h <= tau_fast / substep_ratio`. Default 10.
    pub substep_ratio: f64,
    /// Sub-steps are doubled until the simulated output changes by at most this fraction of
    /// the noise level (weighted RMS). Default 0.1.
    pub substep_tol: f64,
    /// Input between samples: `Auto` (decided by the nominal fit), `Zoh` or `Foh`.
    pub input_hold: HoldChoice,
    /// The initial state stated by the model file (`None`: not stated, estimated).
    pub initial_state: Option<InitialState>,
    /// Estimate the initial state even when the model file states one. Default false.
    pub estimate_x0: bool,
    /// Contiguous folds of the blocked cross-validation. Default 5.
    pub cv_folds: usize,
    /// Candidates (best BIC first) cross-validated per selection step, until one passes.
    /// Default 3.
    pub max_cv: usize,
    /// LM iterations per fold refit (from the estimation fit). Default 6.
    pub cv_iter: usize,
    /// LM iterations per fold of the jackknife of the selected model's parameters (its
    /// model-error spread over `cv_folds` contiguous folds of the estimation segment, see
    /// [`crate::fit::jackknife`]); 0 leaves the jackknife out. Default 6.
    pub jackknife_iter: usize,
    /// Greatest number of effects added by forward selection. Default 2.
    pub max_effects: usize,
    /// How many of the best single hypotheses are tried as second effects. Default 4.
    pub max_second: usize,
    /// Lags of the residual tests. Default 20.
    pub lags: usize,
    pub fit: FitSettings,
    pub select: SelectSettings,
    /// Run hypotheses in parallel (rayon). Default true.
    pub parallel: bool,
    /// Refit the nominal parameters the model file frees (`[fit] free`). Default true.
    pub refit_nominal: bool,
    /// Headline metric of the verdict: `Auto` (RMSE in the output's units when a validation
    /// fit % exceeds 99 %, else fit %), `Fit` or `Rmse`.
    pub metric: Metric,
}

/// Headline metric of the verdict (`--metric`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Metric {
    /// RMSE when a validation fit % exceeds [`SERVO_FIT_PERCENT`] (a tightly tracking loop
    /// saturates fit %), else fit %.
    #[default]
    Auto,
    Fit,
    Rmse,
}

impl Metric {
    /// From `auto`, `fit` or `rmse`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "auto" => Some(Metric::Auto),
            "fit" => Some(Metric::Fit),
            "rmse" => Some(Metric::Rmse),
            _ => None,
        }
    }
}

/// Fit % above which `Metric::Auto` headlines the RMSE.
pub const SERVO_FIT_PERCENT: f64 = 99.0;

impl Default for DiagnoseSettings {
    fn default() -> Self {
        Self {
            estimation_fraction: 0.7,
            max_substeps: 64,
            substep_ratio: 10.0,
            substep_tol: 0.1,
            input_hold: HoldChoice::Auto,
            initial_state: None,
            estimate_x0: false,
            cv_folds: 5,
            max_cv: 3,
            cv_iter: 6,
            jackknife_iter: 6,
            max_effects: 2,
            max_second: 4,
            lags: 20,
            fit: FitSettings::default(),
            select: SelectSettings::default(),
            parallel: true,
            refit_nominal: true,
            metric: Metric::Auto,
        }
    }
}

/// How the input behaves between samples (`--input-hold`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum HoldChoice {
    /// Decided from the data: the hold under which the nominal model fits better.
    #[default]
    Auto,
    /// Zero-order hold: each sample held until the next (a digital controller's command).
    Zoh,
    /// First-order hold: linear interpolation between samples.
    Foh,
}

impl HoldChoice {
    /// From `auto`, `zoh` or `foh`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "auto" => Some(HoldChoice::Auto),
            "zoh" => Some(HoldChoice::Zoh),
            "foh" => Some(HoldChoice::Foh),
            _ => None,
        }
    }
}

/// An initial state stated by the model file.
#[derive(Debug, Clone, PartialEq)]
pub struct InitialState {
    pub x0: Vec<f64>,
    /// Backlash output `z0` when stated (else at rest in the play, `z0 = C x0`).
    pub z0: Option<Vec<f64>>,
}

/// Which input hold was used and why.
#[derive(Debug, Clone, Serialize)]
pub struct HoldReport {
    /// `auto`, `zoh` or `foh` as requested.
    pub requested: HoldChoice,
    /// `zoh` or `foh`.
    pub chosen: &'static str,
    /// Nominal estimation SSE (weighted) under each hold (`None` where not computed).
    pub sse_zoh: Option<f64>,
    pub sse_foh: Option<f64>,
    /// `BIC(other hold) - BIC(chosen)` of the nominal model (same parameter count).
    pub delta_bic: Option<f64>,
    /// Whether the data decide (`delta_bic` at least the tie margin).
    pub decisive: bool,
    /// `auto` only: `BIC(best single effect, chosen hold) - BIC(same effect refitted with
    /// the other hold)` (negative: the effect confirms the hold). The nominal's preference can
    /// be an artefact of the missing effect; where the best effect prefers the other hold by
    /// the tie margin (by any margin when it is an input delay, with which the hold is
    /// confounded), the hold is switched and the diagnosis redone.
    pub effect_delta_bic: Option<f64>,
    /// Whether the hold was switched by that check.
    pub switched: bool,
}

/// The initial state used.
#[derive(Debug, Clone, Serialize)]
pub struct InitialStateReport {
    /// `model file` or `estimated`.
    pub source: &'static str,
    /// Nominal `x0` (fixed or fitted).
    pub x0: Vec<f64>,
    /// With the model file's `x0`: `BIC(fixed) - BIC(estimated)` of the nominal model
    /// (a large value says the file's `x0` does not match the recording's start).
    pub delta_bic_free: Option<f64>,
}

/// The blocked cross-validation of one hypothesis against the model it would extend.
#[derive(Debug, Clone, Serialize)]
pub struct CvResult {
    /// `sum_j SSE_j(hypothesis) / sum_j SSE_j(base)` over the held-out folds.
    pub ratio: f64,
    /// Held-out SSE per fold (weighted), hypothesis and base.
    pub sse: Vec<f64>,
    pub sse_base: Vec<f64>,
    /// Share of the hypothesis' influence on the prediction (`yhat - yhat_base`, squared)
    /// that falls in its largest fold.
    pub max_fold_share: f64,
    /// `passed`, `failed` or `not_testable` (the influence is confined to one fold: the
    /// other folds cannot estimate it, so held-out data cannot test it).
    pub status: &'static str,
}

/// File name of the input samples written beside `fitted.toml` (the model's `input.file`).
pub const FITTED_INPUT_FILE: &str = "fitted-input.csv";

/// One fitted effect in the report.
#[derive(Debug, Clone, Serialize)]
pub struct FittedEffect {
    pub kind: String,
    pub label: String,
    pub description: String,
    pub params: Vec<(String, f64)>,
    /// Reported 1-sigma: `sqrt(statistical^2 + jackknife^2)` ([`crate::fit::jackknife::combine`];
    /// the statistical part alone where the jackknife is not defined).
    pub uncertainty: Vec<(String, f64)>,
    /// Its statistical part: the larger of Gauss-Newton and the batch-means sandwich (noise,
    /// white or coloured, for an exact model).
    pub uncertainty_statistical: Vec<(String, f64)>,
    /// Its model-error part: the delete-a-group jackknife over contiguous folds of the
    /// estimation segment, widened by [`crate::fit::jackknife::t_factor`] for its degrees of
    /// freedom (`NaN`, JSON `null`, where not computed).
    pub uncertainty_jackknife: Vec<(String, f64)>,
    /// `input_delay` only: the equivalent parameters under the other input hold (a zero-order
    /// hold acts as a first-order hold delayed by h/2): `(hold, params)`. Where the data do not
    /// decide the hold (see the report's `hold`), the recording cannot tell the two apart and
    /// the user's knowledge of the hold must.
    pub other_hold: Option<(String, Vec<(String, f64)>)>,
}

/// One hypothesis (single or composite) with its fit.
#[derive(Debug, Clone, Serialize)]
pub struct Ranked {
    pub label: String,
    pub kinds: Vec<String>,
    pub params: Vec<f64>,
    /// Statistical 1-sigma (the larger of Gauss-Newton and the sandwich); the selected
    /// model's reported sigma (`effects[].uncertainty`) adds the jackknife's model-error spread.
    pub std: Vec<f64>,
    pub sse_estimation: f64,
    pub bic: f64,
    /// `BIC_nominal - BIC` (positive: better than nominal).
    pub delta_bic: f64,
    pub validation: Fit,
    /// Validation SSE / nominal validation SSE.
    pub validation_ratio: f64,
    pub beats_nominal: bool,
    pub status: fit::FitStatus,
    /// `for` (accepted against the model it extends), `against` (a conclusive fit that
    /// does not pay), `inconclusive: ...` (a stuck fit, never evidence against its effect).
    pub evidence: String,
    /// Blocked cross-validation, where run.
    pub cv: Option<CvResult>,
    /// Whether the freed nominal parameters (`[fit] free`) are refitted in this hypothesis.
    pub refit: bool,
    /// Their fitted values and 1-sigma uncertainties (empty without a refit; names in the
    /// report's `nominal_refit`).
    pub nominal: Vec<f64>,
    pub nominal_std: Vec<f64>,
    #[serde(skip)]
    pub x0: Vec<f64>,
    #[serde(skip)]
    pub val_sse: f64,
    #[serde(skip)]
    pub parts: Vec<Hypothesis>,
}

/// Label of the grey-box refit hypothesis ("the plant's parameters were off").
pub const NOMINAL_REFIT: &str = "nominal_refit";

/// One refitted nominal parameter in the report.
#[derive(Debug, Clone, Serialize)]
pub struct NominalValue {
    /// `plant.X[i][j]`.
    pub name: String,
    /// Value in the model file.
    pub nominal: f64,
    /// Fitted value (written into `fitted.toml`).
    pub value: f64,
    /// 1-sigma uncertainty (as for effects; `NaN`, JSON `null`, where not identifiable).
    pub std: f64,
    /// Its statistical and jackknife (model-error) parts, as for effects.
    pub std_statistical: f64,
    pub std_jackknife: f64,
    /// `value / nominal - 1` (`None` for a zero nominal).
    pub relative_change: Option<f64>,
    pub bounds: Option<(f64, f64)>,
}

/// Scales and null reference of the localisation (see [`localise`]).
#[derive(Debug, Clone, Serialize)]
pub struct LocalisationInfo {
    pub scales: localise::Scales,
    pub null: localise::NullReference,
}

/// Time series kept for figures.
#[derive(Debug, Clone, Default)]
pub struct Series {
    pub t: Vec<f64>,
    pub p: usize,
    pub y: Vec<f64>,
    pub yhat_nominal: Vec<f64>,
    pub yhat_fitted: Vec<f64>,
    pub energy: Vec<f64>,
}

/// The diagnosis report (`report.json`).
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    pub model: String,
    pub recording: String,
    pub samples: usize,
    pub dt: f64,
    pub resampled: bool,
    pub substeps: usize,
    /// Input hold between samples.
    pub hold: HoldReport,
    /// Sub-step convergence of the nominal model (and of the final model).
    pub discretisation: SubstepCheck,
    pub discretisation_final: Option<SubstepCheck>,
    /// Noise level of each output (difference estimator, units of y).
    pub noise_level: Vec<f64>,
    /// BIC gain the remaining discretisation error could buy (added to the selection margin).
    pub delta_bic_discretisation: f64,
    pub initial_state: InitialStateReport,
    pub estimation_segment: [f64; 2],
    pub validation_segment: [f64; 2],
    pub tau_slow: f64,
    /// Nominal model (initial state fitted) on the validation segment.
    pub fit_before: Fit,
    /// Selected model on the validation segment.
    pub fit_after: Fit,
    /// `fit` or `rmse`: what the verdict's headline states (see [`Metric`]).
    pub headline_metric: &'static str,
    /// The verdict's metric part (fit % or RMSE in units, velocity RMSE and fit %).
    pub headline: String,
    /// Units of the outputs (`[signals] y`; empty strings where not stated).
    pub units: Vec<String>,
    /// Grey-box refit: the freed nominal parameters (`[fit] free`) as selected (empty when
    /// the refit was not selected or none is freed), written into `fitted.toml`.
    pub nominal_refit: Vec<NominalValue>,
    /// The freed nominal parameters' names (`[fit] free`), refitted or not.
    pub free_parameters: Vec<String>,
    /// Recorded columns that are not model inputs, tested as missing inputs.
    pub missing_inputs: Vec<MissingInput>,
    pub residual_nominal: ResidualTests,
    pub residual_fitted: ResidualTests,
    /// Whether the nominal residual passes both tests.
    pub nominal_adequate: bool,
    pub verdict: String,
    pub effects: Vec<FittedEffect>,
    /// What the reported 1-sigma of the fitted parameters includes, and what it does not.
    pub uncertainty_method: String,
    /// The jackknife of the selected model (fold estimates), where computed.
    pub jackknife: Option<Jackknife>,
    /// Hypotheses indistinguishable from the selected one (BIC within `tie_bic`).
    pub ties: Vec<String>,
    pub windows: Vec<Window>,
    pub regimes: Vec<RegimeShare>,
    /// Localisation of the derived velocity residual (the servo metrics' differentiation).
    pub velocity_windows: Vec<Window>,
    pub velocity_regimes: Vec<RegimeShare>,
    /// Data-derived scales and the null reference of the localisation.
    pub localisation: LocalisationInfo,
    pub ranking: Vec<Ranked>,
    pub notes: Vec<String>,
    #[serde(skip)]
    pub fitted_model: Option<System>,
    #[serde(skip)]
    pub series: Series,
}

struct Ctx<'a> {
    sys: &'a System,
    scales: Scales,
    w: Vec<f64>,
    y: Vec<f64>,
    m: usize,
    p: usize,
    dt: f64,
    n: usize,
    k_est: usize,
    weights: Vec<f64>,
    maps: StepMaps,
    substeps: usize,
    /// Scales of the free initial state; empty when it is fixed (model file).
    x_scale: Vec<f64>,
    x0_init: Vec<f64>,
    hold: InputHold,
    z0: Option<Vec<f64>>,
    /// Freed nominal parameters (`[fit] free`), if any.
    free: Option<&'a FreeNominal>,
}

impl<'a> Ctx<'a> {
    fn problem(&'a self, fixed: Vec<Effect>, parts: Vec<Hypothesis>) -> Problem<'a> {
        self.problem_on(fixed, parts, self.k_est, None)
    }
    /// The problem of `parts` with the freed nominal parameters refitted from `nominal` (or
    /// held at the model file's values: `None`).
    fn problem_r(&'a self, parts: Vec<Hypothesis>, nominal: Option<&[f64]>) -> Problem<'a> {
        self.with_refit(self.problem(vec![], parts), nominal)
    }
    /// The problem of a fitted hypothesis (its freed nominal parameters at their fit).
    fn problem_of(&'a self, r: &Ranked) -> Problem<'a> {
        self.problem_r(r.parts.clone(), r.refit.then_some(&r.nominal[..]))
    }
    fn with_refit(&'a self, mut pb: Problem<'a>, nominal: Option<&[f64]>) -> Problem<'a> {
        if let (Some(free), Some(v)) = (self.free, nominal) {
            pb.refit = Some(Refit { free, values: v.to_vec() });
        }
        pb
    }
    /// The problem with residuals on `[0, k_end)` minus `exclude`.
    fn problem_on(
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
    fn weighted_sse(&self, yhat: &[f64], k0: usize, k1: usize) -> f64 {
        self.weighted_sse_between(yhat, &self.y, k0, k1)
    }
    fn weighted_sse_between(&self, a: &[f64], b: &[f64], k0: usize, k1: usize) -> f64 {
        let p = self.p;
        (k0 * p..k1 * p).map(|i| ((a[i] - b[i]) * self.weights[i % p]).powi(2)).sum()
    }
}

fn flat(v: &[Vec<f64>]) -> Vec<f64> {
    v.iter().flat_map(|r| r.iter().copied()).collect()
}

/// Nominal fit and the quantities derived from it at one hold and sub-step count.
struct Selection {
    ranking: Vec<Ranked>,
    chosen: Option<Ranked>,
    ties: Vec<String>,
    /// Candidates that passed the BIC margin but failed cross-validation (label, CV ratio,
    /// the ratio required).
    cv_rejected: Vec<(String, f64, String)>,
}

fn failed_fit(p: usize) -> Fit {
    Fit {
        fit_percent: vec![Some(f64::NEG_INFINITY); p],
        rmse: vec![f64::INFINITY; p],
        velocity_fit_percent: vec![Some(f64::NEG_INFINITY); p],
        velocity_rmse: vec![f64::INFINITY; p],
        constant_outputs: vec![],
        tracking_fit_percent: vec![],
    }
}

/// Fits one (composite) hypothesis on the estimation segment; `refit`: the freed nominal
/// parameters are fitted too, from these values.
#[allow(clippy::too_many_arguments)]
fn run_one(
    ctx: &Ctx,
    s: &DiagnoseSettings,
    parts: Vec<Hypothesis>,
    refit: Option<Vec<f64>>,
    warm: Option<Vec<f64>>,
    x0: &[f64],
    bic_nom: f64,
    val_sse_nom: f64,
) -> Ranked {
    let (p, n_samp, k_est, nx) = (ctx.p, ctx.n, ctx.k_est, ctx.x_scale.len());
    let pb = ctx.problem_r(parts.clone(), refit.as_deref());
    let r: FitResult = fit::fit(&pb, x0, &ctx.x_scale, warm.as_deref(), &s.fit);
    let (val, val_sse) = match pb.simulate_with(&r.theta, &r.nominal, &r.x0, None) {
        Some(sim) => (metrics::fit(&ctx.y, &sim.y, p, k_est, n_samp, ctx.dt), ctx.weighted_sse(&sim.y, k_est, n_samp)),
        None => (failed_fit(p), f64::INFINITY),
    };
    let b = select::bic(r.sse, k_est * p, pb.k() + pb.k_nominal() + nx);
    let is_refit = pb.refit.is_some();
    let labels = is_refit.then(|| NOMINAL_REFIT.to_string()).into_iter();
    Ranked {
        label: labels.clone().chain(parts.iter().map(|h| h.kind.label())).collect::<Vec<_>>().join(" + "),
        kinds: labels.chain(parts.iter().map(|h| h.kind.name().to_string())).collect(),
        params: r.theta.clone(),
        std: r.std.clone(),
        refit: is_refit,
        nominal: r.nominal.clone(),
        nominal_std: r.nominal_std.clone(),
        sse_estimation: r.sse,
        bic: b,
        delta_bic: bic_nom - b,
        validation: val,
        validation_ratio: val_sse / val_sse_nom.max(1e-300),
        beats_nominal: false,
        status: r.status,
        evidence: String::new(),
        cv: None,
        x0: r.x0,
        val_sse,
        parts,
    }
}

/// Fold boundaries of the blocked cross-validation.
fn folds(n: usize, k: usize) -> Vec<(usize, usize)> {
    (0..k).map(|j| (j * n / k, (j + 1) * n / k)).collect()
}

/// Held-out SSE per fold of `parts` (refitted on the other folds from `params`, `x0`), and
/// the full-record prediction of the estimation fit.
fn cv_sse(
    ctx: &Ctx,
    s: &DiagnoseSettings,
    parts: &[Hypothesis],
    nominal: Option<&[f64]>,
    params: &[f64],
    x0: &[f64],
) -> Option<Vec<f64>> {
    let n = ctx.n;
    let fs = fit::FitSettings { max_iter_start: s.cv_iter, max_iter: 0, ..s.fit.clone() };
    let one = |&(b0, b1): &(usize, usize)| -> Option<f64> {
        let pb = ctx.with_refit(ctx.problem_on(vec![], parts.to_vec(), n, Some((b0, b1))), nominal);
        let (theta, nom, x0f) = if pb.k() == 0 && pb.k_nominal() == 0 && ctx.x_scale.is_empty() {
            (vec![], vec![], x0.to_vec())
        } else {
            // With the first fold held out, a free initial state is left to folds that start
            // after the loop has forgotten it: the refit could move it anywhere and the held-out
            // error would measure that, not the effect. It stays at the estimation fit's value
            // there (the same for every hypothesis, the nominal included).
            let x_scale: &[f64] = if b0 == 0 { &[] } else { &ctx.x_scale };
            let r = fit::fit(&pb, x0, x_scale, Some(params), &fs);
            (r.theta, r.nominal, r.x0)
        };
        let sim = pb.simulate_with(&theta, &nom, &x0f, None)?;
        Some(ctx.weighted_sse(&sim.y, b0, b1))
    };
    let fl = folds(n, s.cv_folds);
    let v: Vec<Option<f64>> = if s.parallel { fl.par_iter().map(one).collect() } else { fl.iter().map(one).collect() };
    v.into_iter().collect()
}

/// Cross-validates `cand` against `base` (held-out SSE per fold `base_sse`).
fn cross_validate(ctx: &Ctx, s: &DiagnoseSettings, cand: &Ranked, base: &Ranked, base_sse: &[f64]) -> CvResult {
    let fl = folds(ctx.n, s.cv_folds);
    let sim = |r: &Ranked| ctx.problem_of(r).simulate(&r.params, &r.x0, None).map(|o| o.y);
    let infl: Vec<f64> = match (sim(cand), sim(base)) {
        (Some(a), Some(b)) => fl.iter().map(|&(b0, b1)| ctx.weighted_sse_between(&a, &b, b0, b1)).collect(),
        _ => vec![1.0; fl.len()],
    };
    let tot: f64 = infl.iter().sum();
    let max_fold_share = if tot > 0.0 { infl.iter().copied().fold(0.0, f64::max) / tot } else { 1.0 };
    let sse = cv_sse(ctx, s, &cand.parts, cand.refit.then_some(&cand.nominal[..]), &cand.params, &cand.x0)
        .unwrap_or_else(|| vec![f64::INFINITY; fl.len()]);
    let ratio = sse.iter().sum::<f64>() / base_sse.iter().sum::<f64>().max(1e-300);
    // Confined to one fold: the other folds cannot estimate it, and the refit of that fold
    // starts from the estimation fit (which saw it), so its held-out score would be leaked.
    let status = if max_fold_share > NOT_TESTABLE_SHARE {
        "not_testable"
    } else if ratio <= 1.0 - s.select.min_val_gain {
        "passed"
    } else {
        "failed"
    };
    CvResult { ratio, sse, sse_base: base_sse.to_vec(), max_fold_share, status }
}

/// An effect whose influence on the prediction lies above this share in one fold cannot be
/// tested on held-out data (the other folds do not visit its regime).
pub const NOT_TESTABLE_SHARE: f64 = 0.9;

fn evidence_of(r: &Ranked) -> String {
    if r.beats_nominal {
        return match r.cv.as_ref().map(|c| c.status) {
            Some("not_testable") => "for (supported by the estimation data, not testable on validation)".into(),
            _ => "for".into(),
        };
    }
    match r.status {
        fit::FitStatus::ZeroGradient => "inconclusive: stuck fit (zero gradient)".into(),
        fit::FitStatus::AtBound => "inconclusive: clipped at a bound".into(),
        fit::FitStatus::Failed => "inconclusive: simulation failed".into(),
        _ => match &r.cv {
            Some(c) => format!("against: held-out folds (CV SSE ratio {:.3})", c.ratio),
            None => "against".into(),
        },
    }
}

/// Fits every hypothesis, selects by BIC (margin `margin`) and blocked cross-validation,
/// greedy forward.
/// Fits every single hypothesis on the estimation segment (sorted by BIC).
///
/// `prev`: the singles of an earlier pass of the same diagnosis (after a change of input hold or
/// of sub-steps, which moves each optimum a little): a hypothesis whose earlier fit converged
/// (or ran out of iterations) starts from that estimate alone instead of all its starts; a stuck
/// or failed earlier fit gets all its starts again.
fn fit_singles(ctx: &Ctx, s: &DiagnoseSettings, sys: &System, nom: &FitResult, prev: Option<&[Ranked]>) -> Vec<Ranked> {
    let (bic_nom, val_sse_nom) = nominal_scores(ctx, nom);
    let mut cands = hypothesis::candidates(sys, &ctx.scales);
    // Several inputs: play, saturation and delay on each input alone, too.
    cands.extend(crate::fit::input_effects::candidates(sys, &ctx.scales, &ctx.w));
    let warm = |h: &Hypothesis| -> Option<Vec<f64>> {
        let label = h.kind.label();
        prev?
            .iter()
            .find(|r| !r.refit && r.parts.len() == 1 && r.label == label)
            .filter(|r| matches!(r.status, fit::FitStatus::Converged | fit::FitStatus::MaxIterations))
            .filter(|r| r.params.len() == h.k() && r.params.iter().all(|v| v.is_finite()))
            .map(|r| r.params.clone())
    };
    let one = |h: &Hypothesis| run_one(ctx, s, vec![h.clone()], None, warm(h), &nom.x0, bic_nom, val_sse_nom);
    let mut singles: Vec<Ranked> =
        if s.parallel { cands.par_iter().map(one).collect() } else { cands.iter().map(one).collect() };
    // Grey-box refit: the freed nominal parameters alone, ranked with the effects ("the
    // plant's parameters were off" is a hypothesis of its own, not missing physics).
    if let Some(free) = ctx.free {
        singles.push(run_one(ctx, s, vec![], Some(free.nominal.clone()), None, &nom.x0, bic_nom, val_sse_nom));
    }
    singles.sort_by(|a, b| a.bic.total_cmp(&b.bic));
    singles
}

/// BIC of the nominal fit and its validation SSE.
fn nominal_scores(ctx: &Ctx, nom: &FitResult) -> (f64, f64) {
    let bic_nom = select::bic(nom.sse, ctx.k_est * ctx.p, ctx.x_scale.len());
    let val_sse_nom = ctx
        .problem(vec![], vec![])
        .simulate(&[], &nom.x0, None)
        .map_or(f64::INFINITY, |o| ctx.weighted_sse(&o.y, ctx.k_est, ctx.n));
    (bic_nom, val_sse_nom)
}

/// Selects among the fitted singles by BIC (margin `margin`) and blocked cross-validation,
/// greedy forward.
fn select_all(
    ctx: &Ctx,
    s: &DiagnoseSettings,
    mut singles: Vec<Ranked>,
    nom: &FitResult,
    nominal_adequate: bool,
    margin: f64,
) -> Selection {
    let p = ctx.p;
    let (bic_nom, val_sse_nom) = nominal_scores(ctx, nom);
    let nominal_ranked = Ranked {
        label: "nominal".into(),
        kinds: vec![],
        params: vec![],
        std: vec![],
        refit: false,
        nominal: vec![],
        nominal_std: vec![],
        sse_estimation: nom.sse,
        bic: bic_nom,
        delta_bic: 0.0,
        validation: failed_fit(p),
        validation_ratio: 1.0,
        beats_nominal: false,
        status: nom.status,
        evidence: String::new(),
        cv: None,
        x0: nom.x0.clone(),
        val_sse: val_sse_nom,
        parts: vec![],
    };
    let mut chosen: Option<Ranked> = None;
    let mut ties = Vec::new();
    let mut cv_rejected = Vec::new();
    let mut extra: Vec<Ranked> = Vec::new();
    if !nominal_adequate {
        let base_sse = cv_sse(ctx, s, &[], None, &[], &nom.x0).unwrap_or_else(|| vec![f64::INFINITY; s.cv_folds]);
        // Singles: cross-validate the best few that clear the BIC margin.
        let mut tried = 0;
        for r in singles.iter_mut() {
            if bic_nom - r.bic < margin || tried >= s.max_cv {
                continue;
            }
            tried += 1;
            let cv = cross_validate(ctx, s, r, &nominal_ranked, &base_sse);
            r.beats_nominal = cv.status != "failed";
            if !r.beats_nominal {
                cv_rejected.push((r.label.clone(), cv.ratio, format!("at most {:.2}", 1.0 - s.select.min_val_gain)));
            }
            r.cv = Some(cv);
            if r.beats_nominal {
                // The best accepted single is found; the rest keep their BIC evidence only.
                break;
            }
        }
        // A generalisation of a simpler single (hypothesis::simpler_form: Stribeck or
        // direction-dependent friction over Coulomb friction) must also beat it on held-out folds.
        if let Some(bi) = singles.iter().position(|r| r.beats_nominal) {
            let simple = singles[bi].parts.first().and_then(|h| hypothesis::simpler_form(h.kind));
            let si = simple.and_then(|k| singles.iter().position(|r| r.parts.len() == 1 && r.parts[0].kind == k));
            if let (Some(si), 1) = (si, singles[bi].parts.len()) {
                let sb = &singles[si];
                let sse_s = cv_sse(ctx, s, &sb.parts, sb.refit.then_some(&sb.nominal[..]), &sb.params, &sb.x0)
                    .unwrap_or_else(|| vec![f64::INFINITY; s.cv_folds]);
                let cv = cross_validate(ctx, s, &singles[bi], sb, &sse_s);
                if cv.status != "not_testable" && !hypothesis::nested_supported(&cv.sse, &sse_s) {
                    let cv0 = cross_validate(ctx, s, &singles[si], &nominal_ranked, &base_sse);
                    if cv0.status != "failed" {
                        let label = format!("{} (against {})", singles[bi].label, singles[si].label);
                        let req = format!(
                            "at most {:.2}, or at most {:.2} with every fold lower",
                            hypothesis::NESTED_MAX_CV_RATIO,
                            hypothesis::NESTED_CONSISTENT_MAX_CV_RATIO
                        );
                        cv_rejected.push((label, cv.ratio, req));
                        singles[bi].beats_nominal = false;
                        singles[bi].cv = Some(cv);
                        singles[si].beats_nominal = true;
                        singles[si].cv = Some(cv0);
                    }
                }
            }
        }
        if let Some(best) = singles.iter().find(|r| r.beats_nominal) {
            ties = singles
                .iter()
                .filter(|r| {
                    r.label != best.label && bic_nom - r.bic >= margin && (r.bic - best.bic).abs() < s.select.tie_bic
                })
                .map(|r| r.label.clone())
                .collect();
            let mut cur = best.clone();
            // Greedy forward selection.
            // The nominal refit counts as a step (it adds parameters), not as an effect.
            while cur.parts.len() < s.max_effects {
                let seconds: Vec<&Ranked> = singles
                    .iter()
                    .filter(|r| match r.parts.first() {
                        None => r.refit && !cur.refit,
                        Some(h) => !cur.parts.iter().any(|p| p.kind.name() == h.kind.name()),
                    })
                    .take(s.max_second)
                    .collect();
                let f = |r: &&Ranked| {
                    let mut parts = cur.parts.clone();
                    parts.extend(r.parts.first().cloned());
                    let refit = match (cur.refit, r.refit, ctx.free) {
                        (true, _, _) => Some(cur.nominal.clone()),
                        (false, true, Some(free)) => Some(free.nominal.clone()),
                        _ => None,
                    };
                    run_one(ctx, s, parts, refit, Some(cur.params.clone()), &cur.x0, bic_nom, val_sse_nom)
                };
                let mut combos: Vec<Ranked> =
                    if s.parallel { seconds.par_iter().map(f).collect() } else { seconds.iter().map(f).collect() };
                combos.sort_by(|a, b| a.bic.total_cmp(&b.bic));
                let cur_sse = cur.cv.as_ref().map(|c| c.sse.clone()).unwrap_or_else(|| base_sse.clone());
                let mut next = None;
                let mut tried = 0;
                for c in combos.iter_mut() {
                    if cur.bic - c.bic < margin || tried >= s.max_cv {
                        continue;
                    }
                    tried += 1;
                    let cv = cross_validate(ctx, s, c, &cur, &cur_sse);
                    c.beats_nominal = cv.status != "failed";
                    c.cv = Some(cv);
                    if c.beats_nominal {
                        next = Some(c.clone());
                        break;
                    }
                }
                extra.extend(combos.iter().cloned());
                match next {
                    Some(nx) => cur = nx,
                    None => break,
                }
            }
            chosen = Some(cur);
        }
    }
    let mut ranking: Vec<Ranked> = singles.into_iter().chain(extra).collect();
    for r in ranking.iter_mut() {
        r.evidence = evidence_of(r);
    }
    // Conclusive fits by BIC; stuck ones last (they are not evidence either way).
    ranking.sort_by(|a, b| {
        let (ia, ib) = (a.evidence.starts_with("inconclusive"), b.evidence.starts_with("inconclusive"));
        ia.cmp(&ib).then(a.bic.total_cmp(&b.bic))
    });
    if let Some(c) = chosen.as_mut() {
        c.evidence = evidence_of(c);
    }
    Selection { ranking, chosen, ties, cv_rejected }
}

/// Diagnoses `rec` against nominal model `sys`.
pub fn diagnose(sys: &System, rec: &Recording, s: &DiagnoseSettings) -> Result<Report, DiscoveryError> {
    if !(0.2..=0.95).contains(&s.estimation_fraction) {
        return Err(DiscoveryError::BadSetting {
            field: "estimation_fraction",
            value: s.estimation_fraction,
            reason: "must lie in [0.2, 0.95]",
        });
    }
    if s.cv_folds < 2 {
        return Err(DiscoveryError::BadSetting {
            field: "cv_folds",
            value: s.cv_folds as f64,
            reason: "at least 2 folds are needed",
        });
    }
    let (m, p) = (rec.m(), rec.p());
    if sys.m() != m {
        return Err(DiscoveryError::DimensionMismatch {
            what: "inputs m",
            model: sys.m(),
            recording: m,
            columns: "w columns".into(),
        });
    }
    if sys.p() != p {
        return Err(DiscoveryError::DimensionMismatch {
            what: "outputs p",
            model: sys.p(),
            recording: p,
            columns: "y columns".into(),
        });
    }
    let nx = sys.n();
    if let Some(is) = &s.initial_state {
        if is.x0.len() != nx {
            return Err(DiscoveryError::BadSetting {
                field: "initial_state.x0 length",
                value: is.x0.len() as f64,
                reason: "must equal the model's n",
            });
        }
        if is.z0.as_ref().is_some_and(|z| z.len() != p) {
            return Err(DiscoveryError::BadSetting {
                field: "initial_state.z0 length",
                value: is.z0.as_ref().map_or(0, |z| z.len()) as f64,
                reason: "must equal the model's p",
            });
        }
    }
    let mu = sys.mu();
    if !(mu < 0.0) {
        return Err(DiscoveryError::Unstable { mu });
    }
    let tau_slow = 1.0 / mu.abs();
    if rec.duration() < 3.0 * tau_slow {
        return Err(DiscoveryError::TooShort { duration: rec.duration(), tau_slow });
    }
    let n_samp = rec.len();
    let dt = rec.dt;
    let w = flat(&rec.w);
    let y = flat(&rec.y);
    let k_est = ((n_samp as f64) * s.estimation_fraction).round() as usize;
    let max_sub = s.max_substeps.max(1);
    let fast = sys.eig_F().iter().map(|c| c.norm()).fold(0.0, f64::max);
    let k0 = if fast > 0.0 { ((dt * fast * s.substep_ratio).ceil() as usize).clamp(1, max_sub) } else { 1 };
    let range = |v: &[f64], c: usize, j: usize| {
        let lo = (0..v.len() / c).map(|k| v[k * c + j]).fold(f64::INFINITY, f64::min);
        let hi = (0..v.len() / c).map(|k| v[k * c + j]).fold(f64::NEG_INFINITY, f64::max);
        hi - lo
    };
    let scales = Scales {
        y_range: (0..p).map(|i| range(&y, p, i)).collect(),
        w_range: (0..m).map(|j| range(&w, m, j)).collect(),
        w_absmax: w.iter().map(|v| v.abs()).fold(0.0, f64::max),
        tau_slow,
        dt,
        duration: rec.duration(),
        ..Default::default()
    };
    let weights: Vec<f64> = (0..p)
        .map(|i| {
            let mean = (0..n_samp).map(|k| y[k * p + i]).sum::<f64>() / n_samp as f64;
            let var = (0..n_samp).map(|k| (y[k * p + i] - mean).powi(2)).sum::<f64>() / n_samp as f64;
            1.0 / var.sqrt().max(1e-300)
        })
        .collect();
    let noise = discretisation::noise_level(&y, p);
    let noise_w = ((0..p).map(|i| (noise[i] * weights[i]).powi(2)).sum::<f64>() / p as f64).sqrt().max(1e-6);
    let tol = s.substep_tol * noise_w;
    // Initial state: the model file's when stated (fixed unless --estimate-x0), else the
    // minimum-norm solution of C x0 = y_0, fitted.
    let x0_fixed = s.initial_state.is_some() && !s.estimate_x0;
    let C = &sys.C;
    let x0_init: Vec<f64> = match &s.initial_state {
        Some(is) => is.x0.clone(),
        None => {
            let y0 = nalgebra::DVector::from_column_slice(&y[..p]);
            C.clone().pseudo_inverse(1e-12).map(|pi| (pi * y0).iter().copied().collect()).unwrap_or(vec![0.0; nx])
        }
    };
    let z0: Option<Vec<f64>> = if x0_fixed { s.initial_state.as_ref().and_then(|i| i.z0.clone()) } else { None };
    let sim_nominal = |hold: InputHold, k: usize| -> Option<Vec<f64>> {
        let ext = ExtendedModel::new(sys, &[], dt, k).ok()?.with_hold(hold);
        let o = ext.simulate_from(&w, dt, &x0_init, z0.as_deref());
        o.finite.then_some(o.y)
    };
    let probe = ExtendedModel::new(sys, &[], dt, k0)?.simulate(&w, dt, &x0_init);
    let scales = scales.with_nominal(&probe.x, &probe.y, &y, k_est);
    let xmax = probe.x_rms.iter().copied().fold(0.0, f64::max).max(1e-9);
    let x_scale_free: Vec<f64> = probe.x_rms.iter().map(|v| v.max(1e-3 * xmax)).collect();
    let x_scale: Vec<f64> = if x0_fixed { vec![] } else { x_scale_free.clone() };
    let free_nominal = if s.refit_nominal { FreeNominal::of(sys) } else { None };
    let mk_ctx = |hold: InputHold, k: usize, x_scale: Vec<f64>| Ctx {
        sys,
        scales: scales.clone(),
        w: w.clone(),
        y: y.clone(),
        m,
        p,
        dt,
        n: n_samp,
        k_est,
        weights: weights.clone(),
        maps: StepMaps::new(&sys.F(), &sys.B, &sys.E, dt / k as f64),
        substeps: k,
        x_scale,
        x0_init: x0_init.clone(),
        hold,
        z0: z0.clone(),
        free: free_nominal.as_ref(),
    };
    let fit_nominal = |ctx: &Ctx| fit::fit(&ctx.problem(vec![], vec![]), &ctx.x0_init, &ctx.x_scale, None, &s.fit);
    let n_res = k_est * p;

    // Input hold and sub-steps.
    let first_hold = if s.input_hold == HoldChoice::Zoh { InputHold::Zoh } else { InputHold::Foh };
    let mut disc = discretisation::converge(|k| sim_nominal(first_hold, k), k0, max_sub, &weights, tol);
    let (mut hold, mut hold_report) = match s.input_hold {
        HoldChoice::Zoh | HoldChoice::Foh => (
            first_hold,
            HoldReport {
                requested: s.input_hold,
                chosen: first_hold.name(),
                sse_zoh: None,
                sse_foh: None,
                delta_bic: None,
                decisive: false,
                effect_delta_bic: None,
                switched: false,
            },
        ),
        HoldChoice::Auto => {
            let fz = fit_nominal(&mk_ctx(InputHold::Zoh, disc.substeps, x_scale.clone()));
            let ff = fit_nominal(&mk_ctx(InputHold::Foh, disc.substeps, x_scale.clone()));
            let (bz, bf) = (select::bic(fz.sse, n_res, 0), select::bic(ff.sse, n_res, 0));
            let hold = if bz < bf { InputHold::Zoh } else { InputHold::Foh };
            let d = (bz - bf).abs();
            (
                hold,
                HoldReport {
                    requested: HoldChoice::Auto,
                    chosen: hold.name(),
                    sse_zoh: Some(fz.sse),
                    sse_foh: Some(ff.sse),
                    delta_bic: Some(d),
                    decisive: d >= s.select.tie_bic,
                    effect_delta_bic: None,
                    switched: false,
                },
            )
        }
    };
    if hold != first_hold {
        disc = discretisation::converge(|k| sim_nominal(hold, k), disc.substeps, max_sub, &weights, tol);
    }
    let mut ctx = mk_ctx(hold, disc.substeps, x_scale.clone());
    let mut nom = fit_nominal(&ctx);
    let mut disc_final: Option<SubstepCheck> = None;
    let mut notes = Vec::new();
    let mut pass = 0;
    let mut prev_singles: Option<Vec<Ranked>> = None;
    let (sel, e_nom, residual_nominal, nominal_adequate, nom_sim, loc, delta_bic_disc) = 'hold: loop {
        let nom_sim =
            ctx.problem(vec![], vec![]).simulate(&[], &nom.x0, None).ok_or(DiscoveryError::Unstable { mu })?;
        let e_nom: Vec<f64> = ctx.y.iter().zip(&nom_sim.y).map(|(a, b)| a - b).collect();
        let lag_step = ((tau_slow / dt) / 10.0).floor().max(1.0) as usize;
        let residual_nominal = tests_for(&e_nom, &ctx.w, n_samp, m, p, s.lags, lag_step);
        let nominal_adequate = residual_nominal.white && residual_nominal.uncorrelated && residual_nominal.zero_mean;
        let nominal_ext = ExtendedModel::from_maps(sys, &[], ctx.maps.clone(), ctx.substeps)?;
        let contact = nominal_ext.has_play().then_some(&nom_sim.contact[..]);
        // window sizes from the data (velocity scale, residual correlation length), not tau_slow
        let loc: Localisation = localise::localise(rec.t0, dt, &ctx.y, &e_nom, p, &ctx.w, m, contact, 10);
        let err = disc.error_rms.max(disc_final.as_ref().map_or(0.0, |d| d.error_rms));
        let delta_bic_disc = discretisation::delta_bic_of_error(err, nom.sse / n_res as f64, n_res);
        let margin = s.select.margin_bic + delta_bic_disc;
        // State scales and the nominal run for data-derived bounds and starts (hypothesis.rs).
        ctx.scales = ctx.scales.clone().with_nominal(&nom_sim.x, &nom_sim.y, &ctx.y, k_est);
        let singles = fit_singles(&ctx, s, sys, &nom, prev_singles.as_deref());
        // Auto hold: do the best effects confirm the nominal's choice? The nominal's
        // preference can be an artefact of the missing effect. The best few singles are
        // asked (a flexible wrong effect, e.g. a cogging force, can rank first under the
        // wrong hold and fit no better under the other).
        if s.input_hold == HoldChoice::Auto && hold_report.effect_delta_bic.is_none() && !nominal_adequate {
            // Another hold must beat the best single of this one (not only the effect's own fit).
            let best_bic = singles.first().map_or(f64::INFINITY, |b| b.bic);
            let leading = singles.iter().filter(|c| nominal_scores(&ctx, &nom).0 - c.bic >= margin).take(3);
            for (i, c) in leading.enumerate() {
                let other = if hold == InputHold::Zoh { InputHold::Foh } else { InputHold::Zoh };
                let ctx_o = mk_ctx(other, ctx.substeps, x_scale.clone());
                let fo = fit::FitSettings { max_iter: 10, ..s.fit.clone() };
                let r_o = fit::fit(&ctx_o.problem_of(c), &c.x0, &ctx_o.x_scale, Some(&c.params), &fo);
                let d = select::bic(c.sse_estimation, n_res, 0) - select::bic(r_o.sse, n_res, 0) - (c.bic - best_bic);
                if i == 0 {
                    hold_report.effect_delta_bic = Some(d);
                }
                // With an input delay, hold and delay are confounded (a zero-order hold acts like
                // a first-order hold delayed by h/2): the nominal's preference says nothing and
                // the effect's comparison decides, by any margin.
                let has_delay = c.parts.iter().any(|h| {
                    matches!(
                        h.kind,
                        Kind::InputDelay | Kind::InputOn { op: crate::fit::input_effects::InputOp::Delay, .. }
                    )
                });
                let threshold = if has_delay { 0.0 } else { s.select.tie_bic };
                if d > threshold {
                    notes.push(format!(
                        "Input hold: the nominal model preferred {} (by {:.1} in BIC), but {} fitted with {} beats the best effect with {} by {d:.1} in BIC: the missing effect had biased the nominal's choice; the diagnosis was redone with {}.",
                        hold.name(),
                        hold_report.delta_bic.unwrap_or(0.0),
                        c.label,
                        other.name(),
                        hold.name(),
                        other.name()
                    ));
                    hold = other;
                    hold_report.effect_delta_bic = Some(d);
                    hold_report.chosen = other.name();
                    hold_report.switched = true;
                    disc = discretisation::converge(|k| sim_nominal(hold, k), ctx.substeps, max_sub, &weights, tol);
                    ctx = mk_ctx(hold, disc.substeps, x_scale.clone());
                    nom = fit_nominal(&ctx);
                    disc_final = None;
                    prev_singles = Some(singles);
                    continue 'hold;
                }
            }
        }
        let sel = select_all(&ctx, s, singles, &nom, nominal_adequate, margin);
        // Final model: does it need more sub-steps than the nominal?
        if let Some(c) = &sel.chosen {
            let effects = ctx.problem(vec![], c.parts.clone()).effects(&c.params);
            let x0c = c.x0.clone();
            let sys_c = match (c.refit, &free_nominal) {
                (true, Some(f)) => f.system_at(&c.nominal),
                _ => sys.clone(),
            };
            let chk = discretisation::converge(
                |k| {
                    let ext = ExtendedModel::new(&sys_c, &effects, dt, k).ok()?.with_hold(hold);
                    let o = ext.simulate_from(&w, dt, &x0c, z0.as_deref());
                    o.finite.then_some(o.y)
                },
                ctx.substeps,
                max_sub,
                &weights,
                tol,
            );
            let more = chk.substeps > ctx.substeps;
            disc_final = Some(chk);
            if more && pass == 0 {
                pass += 1;
                let k = disc_final.as_ref().map_or(ctx.substeps, |d| d.substeps);
                notes.push(format!(
                    "The selected model ({}) needed {k} sub-steps per sample where the nominal converged at {}: the whole selection was rerun at {k}.",
                    c.label, ctx.substeps
                ));
                disc = discretisation::converge(|k| sim_nominal(hold, k), k, max_sub, &weights, tol);
                ctx = mk_ctx(hold, disc.substeps, x_scale.clone());
                nom = fit_nominal(&ctx);
                prev_singles = Some(sel.ranking.clone());
                continue;
            }
        }
        break (sel, e_nom, residual_nominal, nominal_adequate, nom_sim, loc, delta_bic_disc);
    };
    let substeps = ctx.substeps;
    let bic_nom = select::bic(nom.sse, n_res, ctx.x_scale.len());
    let mut fit_before = metrics::fit(&ctx.y, &nom_sim.y, p, k_est, n_samp, dt);
    let reference = &sys.signals.reference;
    fit_before.tracking_fit_percent =
        metrics::tracking_fit(&ctx.y, &nom_sim.y, &ctx.w, (p, ctx.m), reference, k_est, n_samp);
    let Selection { ranking, mut chosen, mut ties, cv_rejected } = sel;
    // Recorded columns the model does not use: does the residual follow one of them?
    let missing_inputs: Vec<MissingInput> = if nominal_adequate || rec.extra.is_empty() {
        vec![]
    } else {
        let best = ranking
            .iter()
            .filter(|r| r.sse_estimation.is_finite())
            .min_by(|a, b| a.sse_estimation.total_cmp(&b.sse_estimation));
        let (best_share, best_label) = best
            .map(|r| ((1.0 - r.sse_estimation / nom.sse.max(1e-300)).max(0.0), r.label.clone()))
            .unwrap_or((0.0, "none".into()));
        rec.extra
            .iter()
            .filter_map(|(name, u)| {
                let share = missing_input::explained_share(sys, u, &e_nom, &ctx.weights, k_est, dt, substeps, hold)?;
                Some(MissingInput {
                    column: name.clone(),
                    explained: share,
                    best_hypothesis_explained: best_share,
                    best_hypothesis: best_label.clone(),
                    missing: share >= MISSING_SHARE && share > best_share + MISSING_MARGIN,
                })
            })
            .collect()
    };
    let missing: Vec<&MissingInput> = missing_inputs.iter().filter(|c| c.missing).collect();
    if !missing.is_empty() {
        // An input the model leaves out is not physics to be stood in for by an effect.
        chosen = None;
        ties.clear();
    }
    // Initial state report (with the model file's x0: how much freeing it would gain).
    let initial_state = if x0_fixed {
        let free = fit_nominal(&mk_ctx(hold, substeps, x_scale_free.clone()));
        let d = bic_nom - select::bic(free.sse, n_res, nx);
        if d > s.select.margin_bic && chosen.is_none() {
            notes.push(format!(
                "The model file's initial state may not match the start of the recording: with the nominal model, estimating it would gain {d:.1} in BIC. Run with --estimate-x0 if the file's x0 is not the recorded machine's."
            ));
        }
        InitialStateReport { source: "model file", x0: nom.x0.clone(), delta_bic_free: Some(d) }
    } else {
        InitialStateReport { source: "estimated", x0: nom.x0.clone(), delta_bic_free: None }
    };
    if rec.resampled {
        notes.push(format!("Irregular time stamps ({} rows) were resampled by linear interpolation to a uniform grid of dt = {:.6} s ({} samples).", rec.rows_in_file, dt, n_samp));
    }
    match (hold_report.requested, hold_report.decisive) {
        (HoldChoice::Auto, _) if hold_report.switched => {}
        (HoldChoice::Auto, true) => notes.push(format!(
            "Input hold: {} (chosen from the data: the nominal model fits better by {:.1} in BIC than with {}).",
            hold.name(),
            hold_report.delta_bic.unwrap_or(0.0),
            if hold == InputHold::Zoh { "foh" } else { "zoh" }
        )),
        (HoldChoice::Auto, false) => notes.push(format!(
            "Input hold: {} by a margin of {:.1} in BIC, below the tie margin {}: the recording does not tell zero- from first-order hold (sampling fast against the dynamics).",
            hold.name(),
            hold_report.delta_bic.unwrap_or(0.0),
            s.select.tie_bic
        )),
        _ => notes.push(format!("Input hold: {} (as requested).", hold.name())),
    }
    if !disc.converged {
        notes.push(format!(
            "The simulation did not converge within {} sub-steps per sample (change {:.2e} against the tolerance {:.2e}): effects whose gain is within the remaining error ({:.1} in BIC) are not accepted.",
            max_sub,
            disc.ladder.last().map_or(f64::NAN, |l| l.1),
            disc.tolerance,
            delta_bic_disc
        ));
    }
    for (l, r, req) in &cv_rejected {
        notes.push(format!(
            "{l} improves the estimation fit beyond the BIC margin but not the held-out folds (CV SSE ratio {r:.3}, {req} required): rejected."
        ));
    }

    // Reported uncertainty: the statistical sigma of the fit (the larger of Gauss-Newton and
    // the batch-means sandwich) combined with the model-error spread of a delete-a-group
    // jackknife over contiguous folds of the estimation segment (fit::jackknife).
    let mut std_stat: (Vec<f64>, Vec<f64>) = (vec![], vec![]);
    let mut jack: Option<Jackknife> = None;
    if let Some(c) = chosen.as_mut() {
        std_stat = (c.std.clone(), c.nominal_std.clone());
        if s.jackknife_iter > 0 && (!c.params.is_empty() || c.refit) {
            let nominal = c.refit.then_some(&c.nominal[..]);
            let j = jackknife::refit_folds(
                |f| ctx.with_refit(ctx.problem_on(vec![], c.parts.clone(), k_est, Some(f)), nominal),
                jackknife::Estimate { theta: &c.params, nominal: &c.nominal, x0: &c.x0 },
                &ctx.x_scale,
                k_est,
                s.cv_folds,
                s.jackknife_iter,
                &s.fit,
                s.parallel,
            );
            let g = j.estimates.len();
            for (sd, jd) in c.std.iter_mut().zip(&j.std) {
                *sd = jackknife::combine(*sd, jackknife::jackknife_part(*jd, g));
            }
            for (sd, jd) in c.nominal_std.iter_mut().zip(&j.nominal_std) {
                *sd = jackknife::combine(*sd, jackknife::jackknife_part(*jd, g));
            }
            jack = Some(j);
        }
    }
    let jack_resolved = jack.as_ref().is_some_and(|j| j.estimates.len() >= 2);
    let uncertainty_method = format!(
        "1 sigma = sqrt(s_stat^2 + (c s_jack)^2): s_stat the larger of Gauss-Newton and a batch-means sandwich (noise, white or coloured), s_jack a delete-a-group jackknife over {} contiguous folds of the estimation segment (each left out in turn, the selected model refitted on the rest: the spread that model error causes across the record, noise included), c = t_{}(0.975) / 1.96 = {:.2} so that +-2 sigma keeps 95 % coverage with the jackknife's {} degrees of freedom. {}A model error that shifts every fold alike (a bias constant over the record) is not seen by any resampling and is not included.",
        s.cv_folds,
        s.cv_folds - 1,
        jackknife::t_factor(s.cv_folds - 1),
        s.cv_folds - 1,
        match (&jack, jack_resolved) {
            (Some(_), true) => String::new(),
            (Some(j), false) => format!("Here the jackknife is not resolved ({} of {} fold refits moved from the full estimate, which is determined finer than the solver's steps): s_stat alone. ", j.estimates.len(), j.folds.len()),
            (None, _) => "The jackknife was not computed here (no effect parameters, or disabled): s_stat alone. ".into(),
        }
    );

    // Fitted model and its residual.
    let (effects_chosen, x0_fit) = match &chosen {
        Some(c) => {
            let pb = ctx.problem(vec![], c.parts.clone());
            (pb.effects(&c.params), c.x0.clone())
        }
        None => (vec![], nom.x0.clone()),
    };
    let fit_sim = match &chosen {
        Some(c) => ctx.problem_of(c).simulate(&c.params, &c.x0, None),
        None => None,
    }
    .unwrap_or(nom_sim.clone());
    let mut fit_after = metrics::fit(&ctx.y, &fit_sim.y, p, k_est, n_samp, dt);
    fit_after.tracking_fit_percent =
        metrics::tracking_fit(&ctx.y, &fit_sim.y, &ctx.w, (p, ctx.m), reference, k_est, n_samp);
    let e_fit: Vec<f64> = ctx.y.iter().zip(&fit_sim.y).map(|(a, b)| a - b).collect();
    let lag_step = ((tau_slow / dt) / 10.0).floor().max(1.0) as usize;
    let residual_fitted = tests_for(&e_fit, &ctx.w, n_samp, m, p, s.lags, lag_step);
    let mut fitted_sys = sys.clone();
    // Grey-box refit: the fitted nominal parameters replace the model file's, and each is
    // recorded with its nominal value and uncertainty (`[fit.result]`).
    let nominal_refit: Vec<NominalValue> = match (&chosen, &free_nominal) {
        (Some(c), Some(f)) if c.refit => f
            .params
            .iter()
            .enumerate()
            .map(|(i, fp)| NominalValue {
                name: fp.name.clone(),
                nominal: f.nominal[i],
                value: c.nominal[i],
                std: c.nominal_std[i],
                std_statistical: std_stat.1.get(i).copied().unwrap_or(f64::NAN),
                std_jackknife: jack
                    .as_ref()
                    .and_then(|j| j.nominal_std.get(i).map(|v| jackknife::jackknife_part(*v, j.estimates.len())))
                    .unwrap_or(f64::NAN),
                relative_change: (f.nominal[i] != 0.0).then(|| c.nominal[i] / f.nominal[i] - 1.0),
                bounds: fp.bounds,
            })
            .collect(),
        _ => vec![],
    };
    if let (Some(f), false) = (&free_nominal, nominal_refit.is_empty()) {
        fitted_sys = f.apply(&fitted_sys, &nominal_refit.iter().map(|v| v.value).collect::<Vec<_>>());
        fitted_sys.fit.result = nominal_refit
            .iter()
            .map(|v| model::model_file::FitRecord {
                name: v.name.clone(),
                nominal: v.nominal,
                value: v.value,
                std: v.std,
            })
            .collect();
    }
    fitted_sys.effects.list.extend(effects_chosen.iter().cloned());
    fitted_sys.x0 = nalgebra::DVector::from_column_slice(&x0_fit);
    fitted_sys.z0 = match &z0 {
        Some(z) => nalgebra::DVector::from_column_slice(z),
        None => &fitted_sys.C * &fitted_sys.x0,
    };
    fitted_sys.name = format!("{} (fitted by moreau diagnose)", sys.name);
    // The recording's input (on the uniform grid the fit used, time from 0) and the fit's
    // step, so that `moreau simulate fitted.toml` reproduces the fitted curve. The model
    // file's input is interpolated linearly between its samples: a zero-order hold is
    // written as two samples per interval (at t_k and one sub-step before t_{k+1}), so that
    // only the last sub-step of each interval ramps.
    // Per-input effects (several inputs) are applied to the written input: the input the
    // plant sees on the sub-step grid, written as samples of that grid.
    let input_ops = match &chosen {
        Some(c) => ctx.problem(vec![], c.parts.clone()).input_ops(&c.params),
        None => vec![],
    };
    let (w_rows, n_rows, dt_rows, sub_rows): (Vec<Vec<f64>>, usize, f64, usize) = if input_ops.is_empty() {
        (rec.w.clone(), n_samp, dt, substeps)
    } else {
        let wf = crate::fit::input_effects::transform(&ctx.w, m, dt, substeps, hold, &input_ops);
        let nf = wf.len() / m;
        notes.push(format!(
            "{} act(s) on one input only, which a model file cannot state: fitted.toml's input file ({FITTED_INPUT_FILE}) holds the input as the plant sees it (after these effects, on the grid of {substeps} sub-step(s) per sample), and its effect list omits them.",
            input_ops.iter().map(|o| o.0.label(o.1)).collect::<Vec<_>>().join(", ")
        ));
        (wf.chunks(m).map(|r| r.to_vec()).collect(), nf, dt / substeps as f64, 1)
    };
    let sub_w = sub_rows.max(2);
    let h_sub = dt_rows / sub_w as f64;
    let (t_in, w_in): (Vec<f64>, Vec<Vec<f64>>) = match hold {
        InputHold::Foh => ((0..n_rows).map(|k| k as f64 * dt_rows).collect(), w_rows),
        InputHold::Zoh => {
            let mut t = Vec::with_capacity(2 * n_rows);
            let mut wv = Vec::with_capacity(2 * n_rows);
            for (k, row) in w_rows.iter().enumerate() {
                t.push(k as f64 * dt_rows);
                wv.push(row.clone());
                if k + 1 < n_rows {
                    t.push((k + 1) as f64 * dt_rows - h_sub);
                    wv.push(row.clone());
                }
            }
            (t, wv)
        }
    };
    fitted_sys.input = Input::Samples { path: FITTED_INPUT_FILE.into(), t: t_in, w: w_in, period: None };
    let sim_dt = if hold == InputHold::Zoh { h_sub } else { dt_rows / sub_rows as f64 };
    fitted_sys.sim = SimDefaults { dt: sim_dt, periods: 1, t_end: Some((n_samp - 1) as f64 * dt) };
    if hold == InputHold::Zoh {
        notes.push(format!(
            "fitted.toml replays the held input with linear interpolation over the last of {sub_w} sub-steps of each sample (its input file has two points per sample): `moreau simulate` reproduces the fit up to that ramp."
        ));
    }
    let effects: Vec<FittedEffect> = match &chosen {
        Some(c) => {
            let mut off = 0;
            c.parts
                .iter()
                .map(|h| {
                    let k = h.k();
                    let fe = FittedEffect {
                        kind: h.kind.name().into(),
                        label: h.kind.label(),
                        description: h.kind.description(),
                        params: h.names.iter().zip(&c.params[off..off + k]).map(|(n, v)| (n.to_string(), *v)).collect(),
                        uncertainty: h
                            .names
                            .iter()
                            .zip(&c.std[off..off + k])
                            .map(|(n, v)| (n.to_string(), *v))
                            .collect(),
                        uncertainty_statistical: h
                            .names
                            .iter()
                            .enumerate()
                            .map(|(i, n)| (n.to_string(), std_stat.0.get(off + i).copied().unwrap_or(f64::NAN)))
                            .collect(),
                        uncertainty_jackknife: h
                            .names
                            .iter()
                            .enumerate()
                            .map(|(i, n)| {
                                let part = jack.as_ref().and_then(|j| {
                                    j.std.get(off + i).map(|v| jackknife::jackknife_part(*v, j.estimates.len()))
                                });
                                (n.to_string(), part.unwrap_or(f64::NAN))
                            })
                            .collect(),
                        other_hold: (h.kind == Kind::InputDelay).then(|| {
                            let d = c.params[off];
                            let (name, v) = match hold {
                                InputHold::Zoh => ("foh", d + 0.5 * dt),
                                InputHold::Foh => ("zoh", (d - 0.5 * dt).max(0.0)),
                            };
                            (name.to_string(), vec![("delay".to_string(), v)])
                        }),
                    };
                    off += k;
                    fe
                })
                .collect()
        }
        None => vec![],
    };
    let untestable = chosen.as_ref().is_some_and(|c| c.cv.as_ref().is_some_and(|v| v.status == "not_testable"));
    let units: Vec<String> = (0..p).map(|i| sys.signals.y_unit(i).to_string()).collect();
    let use_rmse = match s.metric {
        Metric::Rmse => true,
        Metric::Fit => false,
        Metric::Auto => metrics::saturated(&fit_before, &fit_after, SERVO_FIT_PERCENT),
    };
    let headline_metric = if use_rmse || !fit_before.constant_outputs.is_empty() { "rmse" } else { "fit" };
    let headline = if use_rmse {
        metrics::headline_rmse(&fit_before, &fit_after, &units)
    } else if fit_before.constant_outputs.is_empty() {
        format!("validation fit {} -> {} %", fmt_opt(&fit_before.fit_percent), fmt_opt(&fit_after.fit_percent))
    } else {
        format!(
            "validation RMSE {} -> {}; fit % undefined, the validation output is constant",
            fmt_units(&fit_before.rmse, &units),
            fmt_units(&fit_after.rmse, &units)
        )
    };
    if use_rmse && s.metric == Metric::Auto {
        notes.push(format!(
            "The validation fit % exceeds {SERVO_FIT_PERCENT} % (a tightly tracking loop saturates it): the verdict states the RMSE in the output's units{} and the derived velocity's RMSE and fit % (5-point moving average, then central difference, the same filter on measurement and simulation).",
            if units.iter().all(|u| u.is_empty()) { " (no `[signals] y` unit in the model file: unitless)" } else { "" }
        ));
    }
    let refit_only = chosen.as_ref().is_some_and(|c| c.refit && c.parts.is_empty());
    let verdict = if nominal_adequate {
        "no missing physics found: the nominal residual is white, zero-mean and uncorrelated with the input (1 % level)"
            .to_string()
    } else if !missing.is_empty() {
        missing
            .iter()
            .map(|c| {
                format!(
                    "input {} is missing from the model: fed through the nominal dynamics it explains {:.0} % of the nominal residual (the best hypothesis of the library, {}, {:.0} %); add it to the model's inputs (a column of B) instead of fitting an effect",
                    c.column,
                    100.0 * c.explained,
                    c.best_hypothesis,
                    100.0 * c.best_hypothesis_explained
                )
            })
            .collect::<Vec<_>>()
            .join("; ")
    } else if let Some(c) = &chosen {
        let tail = if untestable {
            " (supported by the estimation data; not testable on validation: its effect lies in one fold of the record)"
        } else {
            ""
        };
        if refit_only {
            format!(
                "the plant's parameters were off, not missing physics: {}{tail} ({headline})",
                fmt_nominal(&nominal_refit)
            )
        } else if c.refit {
            let effects_label = c.parts.iter().map(|h| h.kind.label()).collect::<Vec<_>>().join(" + ");
            format!(
                "missing physics: {effects_label}{tail}, with the plant's parameters refitted ({}) ({headline})",
                fmt_nominal(&nominal_refit)
            )
        } else {
            format!("missing physics: {}{tail} ({headline})", c.label)
        }
    } else if !cv_rejected.is_empty() {
        format!(
            "the nominal residual is not white; {} improve(s) the estimation fit but not the held-out folds of the blocked cross-validation, so nothing is added (see the ranking)",
            cv_rejected.iter().map(|c| c.0.clone()).collect::<Vec<_>>().join(", ")
        )
    } else {
        "the nominal residual is not white, but no effect of the library improves the fit by the required margin (BIC beyond the discretisation error, and held-out folds): the mismatch is outside the library".to_string()
    };
    if !fit_before.constant_outputs.is_empty() {
        notes.push(format!(
            "The measured output(s) {} are constant on the validation segment (standard deviation at most {} of the whole record's): fit % is undefined there (null in report.json) and the validation is judged by the RMSE and the validation SSE ratio instead.",
            fit_before.constant_outputs.iter().map(|i| format!("y{}", i + 1)).collect::<Vec<_>>().join(", "),
            metrics::TOL_CONSTANT
        ));
    }
    if let Some(free) = &free_nominal {
        if nominal_refit.is_empty() {
            let r = ranking.iter().find(|r| r.refit && r.parts.is_empty());
            notes.push(format!(
                "The model file frees {} ([fit] free); refitting them was not selected{}: the nominal values stand.",
                free.names().join(", "),
                r.map_or(String::new(), |r| format!(
                    " ({NOMINAL_REFIT}: delta BIC {:.1} against the nominal, evidence {})",
                    r.delta_bic, r.evidence
                ))
            ));
        } else {
            notes.push(format!(
                "Grey-box refit of {} (the model file's [fit] free): fitted jointly with the effects by the same Levenberg-Marquardt, ranked as the hypothesis `{NOMINAL_REFIT}` against the effects and cross-validated like them; the fitted values replace the nominal ones in fitted.toml ([fit.result] keeps both). Uncertainties as for effects; a parameter that the record does not excite has a large or undefined one.",
                free.names().join(", ")
            ));
            let loose: Vec<String> = nominal_refit
                .iter()
                .filter(|v| !(v.std.is_finite() && v.std < v.value.abs().max(1e-300)))
                .map(|v| v.name.clone())
                .collect();
            if !loose.is_empty() {
                notes.push(format!(
                    "{} {} not identifiable from this record (1-sigma uncertainty above the value, or undefined): the record does not excite it, or it trades off against another freed parameter (with Theta = {{0}}, `A` and `E` enter only through F = A + E C). Free fewer parameters or give bounds.",
                    loose.join(", "),
                    if loose.len() == 1 { "is" } else { "are" }
                ));
            }
        }
    }
    if fit_before.fit_percent.iter().flatten().any(|f| *f > 97.0) && !use_rmse {
        notes.push("Plain fit % is above 97 % (a tightly tracking loop saturates it): judge by the RMSE ratio (validation_ratio), the velocity fit and BIC instead.".into());
    }
    let twin = matches!(
        chosen.as_ref().and_then(|c| c.parts.first()).map(|h| h.kind),
        Some(Kind::ConstantForce { .. } | Kind::SensorOffset)
    ) || ties.iter().any(|t| t.starts_with("constant_force") || t.starts_with("sensor_offset"));
    if twin {
        if x0_fixed {
            notes.push("A constant force and a sensor offset are told apart here by the known initial state (the model file's x0): an offset shifts y(0) itself, a force only bends the trajectory after it.".into());
        } else {
            notes.push("A constant force b on state j and a sensor offset C F^{-1} e_j b are observationally equivalent when the initial state is free (the play is translation invariant): the recording cannot tell them apart; physics must (or a known x0 in the model file).".into());
        }
    }
    notes.extend(hypothesis::friction_notes(&effects_chosen, &ties));
    if chosen.as_ref().is_some_and(|c| c.parts.iter().any(|h| h.kind == Kind::InputDelay)) {
        notes.push(format!(
            "An input delay trades off against the input hold: a zero-order hold acts like a first-order hold delayed by h/2 = {:.3e} s. The delay is reported for the {} hold; under the {} hold it is {} (effects[].other_hold).{}",
            0.5 * dt,
            hold.name(),
            if hold == InputHold::Zoh { "foh" } else { "zoh" },
            effects.iter().filter_map(|e| e.other_hold.as_ref()).map(|o| format!("{:.4e} s", o.1[0].1)).collect::<Vec<_>>().join(", "),
            match hold_report.effect_delta_bic {
                Some(d) if d.abs() < s.select.tie_bic => format!(" The delay model fits both holds alike ({:.1} in BIC): the recording cannot tell which; use --input-hold if the hold is known.", d.abs()),
                _ => String::new(),
            }
        ));
    }
    let series = Series {
        t: (0..n_samp).map(|k| rec.time(k)).collect(),
        p,
        y: ctx.y.clone(),
        yhat_nominal: nom_sim.y.clone(),
        yhat_fitted: fit_sim.y.clone(),
        energy: loc.energy.clone(),
    };
    let _ = e_nom;
    Ok(Report {
        model: sys.name.clone(),
        recording: rec.source.clone(),
        samples: n_samp,
        dt,
        resampled: rec.resampled,
        substeps,
        hold: hold_report,
        discretisation: disc,
        discretisation_final: disc_final,
        noise_level: noise,
        delta_bic_discretisation: delta_bic_disc,
        initial_state,
        estimation_segment: [rec.time(0), rec.time(k_est - 1)],
        validation_segment: [rec.time(k_est), rec.time(n_samp - 1)],
        tau_slow,
        fit_before,
        fit_after,
        headline_metric,
        headline,
        units,
        nominal_refit,
        free_parameters: free_nominal.as_ref().map(|f| f.names()).unwrap_or_default(),
        missing_inputs,
        residual_nominal,
        residual_fitted,
        nominal_adequate,
        verdict,
        effects,
        uncertainty_method,
        jackknife: jack,
        ties,
        windows: loc.windows,
        regimes: loc.regimes,
        velocity_windows: loc.velocity_windows,
        velocity_regimes: loc.velocity_regimes,
        localisation: LocalisationInfo { scales: loc.scales, null: loc.null },
        ranking,
        notes,
        fitted_model: Some(fitted_sys),
        series,
    })
}

/// Residual tests of every output (all must pass).
fn tests_for(e: &[f64], w: &[f64], n: usize, m: usize, p: usize, lags: usize, lag_step: usize) -> ResidualTests {
    let mut t: Option<ResidualTests> = None;
    let us: Vec<Vec<f64>> = (0..m).map(|j| (0..n).map(|k| w[k * m + j]).collect()).collect();
    for i in 0..p {
        let ei: Vec<f64> = (0..n).map(|k| e[k * p + i]).collect();
        let ti = residual::test(&ei, &us, lags, lag_step);
        t = Some(match t {
            None => ti,
            Some(prev) => {
                let (white, unc, zm) =
                    (prev.white && ti.white, prev.uncorrelated && ti.uncorrelated, prev.zero_mean && ti.zero_mean);
                ResidualTests { white, uncorrelated: unc, zero_mean: zm, ..prev }
            }
        });
    }
    t.expect("p >= 1")
}

fn fmt_vec(v: &[f64]) -> String {
    v.iter().map(|x| format!("{x:.1}")).collect::<Vec<_>>().join(", ")
}

/// Fit % values, `undefined` where the measured segment is constant.
fn fmt_opt(v: &[Option<f64>]) -> String {
    v.iter()
        .map(|x| x.map_or("undefined (constant output)".to_string(), |x| format!("{x:.1}")))
        .collect::<Vec<_>>()
        .join(", ")
}

impl Report {
    /// The label of the selected hypothesis (`"none"` if nothing was added).
    pub fn selected(&self) -> String {
        if self.effects.is_empty() {
            "none".into()
        } else {
            self.effects.iter().map(|e| e.kind.clone()).collect::<Vec<_>>().join("+")
        }
    }

    /// `report.md`.
    pub fn to_markdown(&self, figures: &[(&str, &str)]) -> String {
        let mut s = String::new();
        s += &format!("# Diagnosis of `{}` against `{}`\n\n", self.recording, self.model);
        s += &format!("**Verdict:** {}\n\n", self.verdict);
        s += &format!(
            "Record: {} samples, dt = {:.6} s{}; simulation with {} exact linear sub-step(s) per sample. Estimation segment t in [{:.4}, {:.4}] s, validation segment t in [{:.4}, {:.4}] s (never fitted; free-run simulation from the start of the record). Slowest time constant of the nominal loop: {:.4} s.\n\n",
            self.samples, self.dt, if self.resampled { " (resampled from irregular stamps)" } else { "" }, self.substeps, self.estimation_segment[0], self.estimation_segment[1], self.validation_segment[0], self.validation_segment[1], self.tau_slow
        );
        s += &format!(
            "Input hold: **{}**{}. Sub-steps by convergence: {} (changes k -> 2k: {}; tolerance {:.2e}, i.e. {} of the noise level; remaining discretisation error {:.2e}{}, worth at most {:.1} in BIC, added to the selection margin). Noise level (difference estimator): {}. Initial state: {}{}.\n\n",
            self.hold.chosen,
            match (self.hold.requested, self.hold.delta_bic) {
                (HoldChoice::Auto, Some(d)) => format!(" (auto: the nominal model fits better by {d:.1} in BIC than with the other hold{})", if self.hold.decisive { "" } else { "; below the tie margin, not decisive" }),
                _ => " (as requested)".into(),
            },
            self.substeps,
            self.discretisation.ladder.iter().map(|(k, c)| format!("{k}: {c:.2e}")).collect::<Vec<_>>().join(", "),
            self.discretisation.tolerance,
            "a tenth",
            self.discretisation.error_rms,
            if self.discretisation.converged { "" } else { " (NOT converged)" },
            self.delta_bic_discretisation,
            self.noise_level.iter().map(|v| format!("{v:.3e}")).collect::<Vec<_>>().join(", "),
            self.initial_state.source,
            self.initial_state.delta_bic_free.map_or(String::new(), |d| format!(" (estimating it instead would gain {d:.1} in BIC with the nominal model)"))
        );
        s += "## Fit on the validation segment\n\n| | fit % | RMSE | velocity fit % | velocity RMSE |\n|---|---|---|---|---|\n";
        let vunits: Vec<String> = self.units.iter().map(|u| metrics::per_second(u)).collect();
        for (name, f) in [("nominal", &self.fit_before), ("fitted", &self.fit_after)] {
            s += &format!(
                "| {name} | {} | {} | {} | {} |\n",
                fmt_opt(&f.fit_percent),
                fmt_units(&f.rmse, &self.units),
                fmt_opt(&f.velocity_fit_percent),
                fmt_units(&f.velocity_rmse, &vunits)
            );
        }
        s += &format!(
            "\nHeadline ({}): {}. Velocity: derived from y by a 5-point moving average and a central difference, the same filter on measurement and simulation.\n\n",
            if self.headline_metric == "rmse" { "RMSE in the output's units" } else { "fit %" },
            self.headline
        );
        s += "## Residual tests (nominal model)\n\n";
        let r = &self.residual_nominal;
        s += &format!(
            "- mean: {:.3e} against the 99 % bound {:.3e}: **{}**\n- whiteness: Q = {:.1} against the 99 % threshold {:.1} ({} lags of {} sample(s)): **{}**\n- input cross-correlation: Q = {} against {:.1}: **{}**\n- after fitting: white = {}, uncorrelated = {} (Q = {:.1}, cross Q = {})\n\n",
            r.mean, r.mean_bound, if r.zero_mean { "zero mean" } else { "offset" }, r.q_auto, r.q_auto_threshold, r.lags, r.lag_step, if r.white { "white" } else { "not white" }, fmt_vec(&r.q_cross), r.q_cross_threshold, if r.uncorrelated { "uncorrelated" } else { "correlated" },
            self.residual_fitted.white, self.residual_fitted.uncorrelated, self.residual_fitted.q_auto, fmt_vec(&self.residual_fitted.q_cross)
        );
        s += &localise::markdown(
            [(&self.regimes, &self.windows), (&self.velocity_regimes, &self.velocity_windows)],
            &self.localisation.scales,
            &self.localisation.null,
            &self.units,
        );
        if !self.missing_inputs.is_empty() {
            s += "\n## Recorded signals that are not model inputs\n\nEach fed through the linearised nominal dynamics (on every state) and regressed on the nominal residual (estimation segment); reported missing when it explains at least half the residual and 10 points more than the best hypothesis of the library.\n\n| column | residual explained | best hypothesis (explains) | missing input |\n|---|---|---|---|\n";
            for c in &self.missing_inputs {
                s += &format!(
                    "| {} | {:.1} % | {} ({:.1} %) | {} |\n",
                    c.column,
                    100.0 * c.explained,
                    c.best_hypothesis,
                    100.0 * c.best_hypothesis_explained,
                    if c.missing { "**yes**" } else { "no" }
                );
            }
        }
        if !self.free_parameters.is_empty() {
            s += "\n## Plant parameters (grey-box refit)\n\n";
            if self.nominal_refit.is_empty() {
                s += &format!(
                    "Freed in the model file: {}. Refitting them was not selected (see `{NOMINAL_REFIT}` in the ranking): the nominal values stand.\n",
                    self.free_parameters.join(", ")
                );
            } else {
                s += "| parameter | nominal | fitted | 1 sigma | change | bounds |\n|---|---|---|---|---|---|\n";
                for v in &self.nominal_refit {
                    s += &format!(
                        "| {} | {} | {} | {} | {} | {} |\n",
                        v.name,
                        g4(v.nominal),
                        g4(v.value),
                        if v.std.is_finite() { format!("{:.2e}", v.std) } else { "undefined".into() },
                        v.relative_change.map_or("-".into(), |r| format!("{:+.2} %", 100.0 * r)),
                        v.bounds.map_or("-".into(), |(a, b)| format!("[{}, {}]", g4(a), g4(b)))
                    );
                }
            }
        }
        s += "\n## Effects added\n\n";
        if self.effects.is_empty() {
            s += "None.\n\n";
        } else {
            s += &format!("Uncertainty: {}\n\n", self.uncertainty_method);
        }
        for e in &self.effects {
            s += &format!("- **{}**: {}\n", e.label, e.description);
            for (i, ((n, v), (_, u))) in e.params.iter().zip(&e.uncertainty).enumerate() {
                let part = |l: &[(String, f64)]| l.get(i).map_or(f64::NAN, |x| x.1);
                let (st, jk) = (part(&e.uncertainty_statistical), part(&e.uncertainty_jackknife));
                s += &format!(
                    "  - {n} = {v:.6} +- {u:.2e} (1 sigma; statistical {st:.2e}, fold jackknife {})\n",
                    if jk.is_finite() { format!("{jk:.2e}") } else { "n/a".into() }
                );
            }
            if let Some((h, ps)) = &e.other_hold {
                for (n, v) in ps {
                    s += &format!("  - under the {h} hold instead: {n} = {v:.6}\n");
                }
            }
        }
        if !self.ties.is_empty() {
            s += &format!(
                "\nIndistinguishable on this recording (BIC within the tie margin): {}.\n",
                self.ties.join(", ")
            );
        }
        s += "\n## Ranking of all hypotheses\n\nSelection: BIC gain of at least the margin (plus the discretisation allowance) on the estimation segment, then blocked cross-validation over contiguous folds of the whole record (each held out in turn, the hypothesis and the model it extends refitted on the others). A stuck fit (zero gradient, clipped at a bound) is inconclusive, not evidence against its effect.\n\n| hypothesis | params | delta BIC | validation fit % | validation SSE ratio | CV SSE ratio | fit | evidence |\n|---|---|---|---|---|---|---|---|\n";
        for r in &self.ranking {
            let inconclusive = r.evidence.starts_with("inconclusive");
            let params = if r.refit {
                let nom: Vec<String> = r.nominal.iter().map(|v| g4(*v)).collect();
                let eff = fmt_e(&r.params);
                format!("{}plant: {}", if eff.is_empty() { String::new() } else { format!("{eff}; ") }, nom.join(", "))
            } else {
                fmt_e(&r.params)
            };
            s += &format!(
                "| {} | {} | {} | {} | {:.3} | {} | {:?} | {} |\n",
                r.label,
                params,
                if inconclusive { "n/a".to_string() } else { format!("{:.1}", r.delta_bic) },
                fmt_opt(&r.validation.fit_percent),
                r.validation_ratio,
                r.cv.as_ref().map_or("-".to_string(), |c| format!("{:.3} ({})", c.ratio, c.status)),
                r.status,
                r.evidence
            );
        }
        if !self.notes.is_empty() {
            s += "\n## Notes\n\n";
            for n in &self.notes {
                s += &format!("- {n}\n");
            }
        }
        if !figures.is_empty() {
            s += "\n## Figures\n\n";
            for (f, cap) in figures {
                s += &format!("![{cap}]({f})\n\n");
            }
        }
        s
    }
}

/// Refitted nominal parameters for a verdict: `name nominal -> value +- std (change %)`.
fn fmt_nominal(v: &[NominalValue]) -> String {
    v.iter()
        .map(|x| {
            format!(
                "{} {} -> {} +- {}{}",
                x.name,
                g4(x.nominal),
                g4(x.value),
                if x.std.is_finite() { format!("{:.2e}", x.std) } else { "undefined".into() },
                x.relative_change.map_or(String::new(), |r| format!(" ({:+.1} %)", 100.0 * r))
            )
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Four significant digits.
fn g4(x: f64) -> String {
    if x == 0.0 || (1e-3..1e5).contains(&x.abs()) {
        let d = (3 - x.abs().log10().floor() as i32).clamp(0, 6) as usize;
        format!("{x:.d$}")
    } else {
        format!("{x:.3e}")
    }
}

/// Values with their units (see [`metrics::fmt_quantity`]).
fn fmt_units(v: &[f64], units: &[String]) -> String {
    v.iter()
        .enumerate()
        .map(|(i, x)| metrics::fmt_quantity(*x, units.get(i).map_or("", |s| s.as_str())))
        .collect::<Vec<_>>()
        .join(", ")
}

fn fmt_e(v: &[f64]) -> String {
    v.iter().map(|x| format!("{x:.4e}")).collect::<Vec<_>>().join(", ")
}
