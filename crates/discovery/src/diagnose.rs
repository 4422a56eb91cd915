//! The diagnosis pipeline: nominal fit, residual tests, localisation, hypotheses, selection,
//! fitted model and report.
//!
//! Segments: the first `estimation_fraction` (default 70 %) of the record is the estimation
//! segment (all fitting, initial state included, uses only it); the rest is the validation
//! segment, simulated free-running from the start of the record and never fitted.
use crate::fit::{self, FitResult, FitSettings, Problem};
use crate::hypothesis::{self, Hypothesis, Kind, Scales};
use crate::localise::{self, Localisation, RegimeShare, Window};
use crate::metrics::{self, Fit};
use crate::residual::{self, ResidualTests};
use crate::select::{self, SelectSettings};
use crate::simulate::{ExtendedModel, StepMaps};
use crate::{DiscoveryError, Recording};
use model::effects::Effect;
use model::{Input, SimDefaults, System};
use rayon::prelude::*;
use serde::Serialize;

/// Settings of the diagnosis.
#[derive(Debug, Clone)]
pub struct DiagnoseSettings {
    /// Fraction of the record used for estimation. Default 0.7.
    pub estimation_fraction: f64,
    /// Largest number of linear sub-steps per sample. Default 8.
    pub max_substeps: usize,
    /// Sub-steps are chosen so that `h <= tau_fast / substep_ratio`. Default 10.
    pub substep_ratio: f64,
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
}

impl Default for DiagnoseSettings {
    fn default() -> Self {
        Self {
            estimation_fraction: 0.7,
            max_substeps: 8,
            substep_ratio: 10.0,
            max_effects: 2,
            max_second: 4,
            lags: 20,
            fit: FitSettings::default(),
            select: SelectSettings::default(),
            parallel: true,
        }
    }
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
    pub uncertainty: Vec<(String, f64)>,
}

/// One hypothesis (single or composite) with its fit.
#[derive(Debug, Clone, Serialize)]
pub struct Ranked {
    pub label: String,
    pub kinds: Vec<String>,
    pub params: Vec<f64>,
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
    #[serde(skip)]
    pub x0: Vec<f64>,
    #[serde(skip)]
    pub val_sse: f64,
    #[serde(skip)]
    pub parts: Vec<Hypothesis>,
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
    pub estimation_segment: [f64; 2],
    pub validation_segment: [f64; 2],
    pub tau_slow: f64,
    /// Nominal model (initial state fitted) on the validation segment.
    pub fit_before: Fit,
    /// Selected model on the validation segment.
    pub fit_after: Fit,
    pub residual_nominal: ResidualTests,
    pub residual_fitted: ResidualTests,
    /// Whether the nominal residual passes both tests.
    pub nominal_adequate: bool,
    pub verdict: String,
    pub effects: Vec<FittedEffect>,
    /// Hypotheses indistinguishable from the selected one (BIC within `tie_bic`).
    pub ties: Vec<String>,
    pub windows: Vec<Window>,
    pub regimes: Vec<RegimeShare>,
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
    x_scale: Vec<f64>,
    x0_init: Vec<f64>,
}

impl<'a> Ctx<'a> {
    fn problem(&'a self, fixed: Vec<Effect>, parts: Vec<Hypothesis>) -> Problem<'a> {
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
            k_est: self.k_est,
            weights: self.weights.clone(),
            maps: self.maps.clone(),
            substeps: self.substeps,
        }
    }
    fn weighted_sse(&self, yhat: &[f64], k0: usize, k1: usize) -> f64 {
        let p = self.p;
        (k0 * p..k1 * p).map(|i| ((yhat[i] - self.y[i]) * self.weights[i % p]).powi(2)).sum()
    }
}

fn flat(v: &[Vec<f64>]) -> Vec<f64> {
    v.iter().flat_map(|r| r.iter().copied()).collect()
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
    let fast = sys.eig_F().iter().map(|c| c.norm()).fold(0.0, f64::max);
    let substeps =
        if fast > 0.0 { ((dt * fast * s.substep_ratio).ceil() as usize).clamp(1, s.max_substeps.max(1)) } else { 1 };
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
    };
    let weights: Vec<f64> = (0..p)
        .map(|i| {
            let mean = (0..n_samp).map(|k| y[k * p + i]).sum::<f64>() / n_samp as f64;
            let var = (0..n_samp).map(|k| (y[k * p + i] - mean).powi(2)).sum::<f64>() / n_samp as f64;
            1.0 / var.sqrt().max(1e-300)
        })
        .collect();
    let maps = StepMaps::new(&sys.F(), &sys.B, &sys.E, dt / substeps as f64);
    // Initial state: minimum-norm solution of C x0 = y_0; scales from a nominal run.
    let C = &sys.C;
    let y0 = nalgebra::DVector::from_column_slice(&y[..p]);
    let x0_init: Vec<f64> =
        C.clone().pseudo_inverse(1e-12).map(|pi| (pi * y0).iter().copied().collect()).unwrap_or(vec![0.0; sys.n()]);
    let nominal_ext = ExtendedModel::from_maps(sys, &[], maps.clone(), substeps)?;
    let probe = nominal_ext.simulate(&w, dt, &x0_init);
    let xmax = probe.x_rms.iter().copied().fold(0.0, f64::max).max(1e-9);
    let x_scale: Vec<f64> = probe.x_rms.iter().map(|v| v.max(1e-3 * xmax)).collect();
    let ctx = Ctx { sys, scales, w, y, m, p, dt, n: n_samp, k_est, weights, maps, substeps, x_scale, x0_init };

    // Nominal model: only the initial state is fitted.
    let nom_pb = ctx.problem(vec![], vec![]);
    let nom = fit::fit(&nom_pb, &ctx.x0_init, &ctx.x_scale, None, &s.fit);
    let nom_sim = nom_pb.simulate(&[], &nom.x0, None).ok_or(DiscoveryError::Unstable { mu })?;
    let n_res = k_est * p;
    let nx = sys.n();
    let bic_nom = select::bic(nom.sse, n_res, nx);
    let val_sse_nom = ctx.weighted_sse(&nom_sim.y, k_est, n_samp);
    let fit_before = metrics::fit(&ctx.y, &nom_sim.y, p, k_est, n_samp, dt);
    let e_nom: Vec<f64> = ctx.y.iter().zip(&nom_sim.y).map(|(a, b)| a - b).collect();
    let lag_step = ((tau_slow / dt) / 10.0).floor().max(1.0) as usize;
    let tests_for = |e: &[f64]| {
        // Residual of output 0 weighted sum over outputs: test each output, combine (all must pass).
        let mut t: Option<ResidualTests> = None;
        for i in 0..p {
            let ei: Vec<f64> = (0..n_samp).map(|k| e[k * p + i]).collect();
            let us: Vec<Vec<f64>> = (0..m).map(|j| (0..n_samp).map(|k| ctx.w[k * m + j]).collect()).collect();
            let ti = residual::test(&ei, &us, s.lags, lag_step);
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
    };
    let residual_nominal = tests_for(&e_nom);
    let nominal_adequate = residual_nominal.white && residual_nominal.uncorrelated && residual_nominal.zero_mean;
    let contact = nominal_ext.has_play().then_some(&nom_sim.contact[..]);
    let half_width = ((0.1 * tau_slow / dt).round() as usize).max(3);
    let loc: Localisation = localise::localise(rec.t0, dt, &ctx.y, &e_nom, p, &ctx.w, m, contact, half_width, 10);

    // Single hypotheses.
    let cands = hypothesis::candidates(sys, &ctx.scales);
    let run_one = |parts: Vec<Hypothesis>, fixed: Vec<Effect>, warm: Option<Vec<f64>>, x0: &[f64]| -> Ranked {
        let pb = ctx.problem(fixed, parts.clone());
        let r: FitResult = fit::fit(&pb, x0, &ctx.x_scale, warm.as_deref(), &s.fit);
        let (val, val_sse) = match pb.simulate(&r.theta, &r.x0, None) {
            Some(sim) => (metrics::fit(&ctx.y, &sim.y, p, k_est, n_samp, dt), ctx.weighted_sse(&sim.y, k_est, n_samp)),
            None => (
                Fit {
                    fit_percent: vec![Some(f64::NEG_INFINITY); p],
                    rmse: vec![f64::INFINITY; p],
                    velocity_fit_percent: vec![Some(f64::NEG_INFINITY); p],
                    constant_outputs: vec![],
                },
                f64::INFINITY,
            ),
        };
        let k = pb.k() + nx;
        let b = select::bic(r.sse, n_res, k);
        Ranked {
            label: parts.iter().map(|h| h.kind.label()).collect::<Vec<_>>().join(" + "),
            kinds: parts.iter().map(|h| h.kind.name().to_string()).collect(),
            params: r.theta.clone(),
            std: r.std.clone(),
            sse_estimation: r.sse,
            bic: b,
            delta_bic: bic_nom - b,
            validation: val,
            validation_ratio: val_sse / val_sse_nom.max(1e-300),
            beats_nominal: select::beats(b, val_sse, bic_nom, val_sse_nom, &s.select),
            status: r.status,
            x0: r.x0,
            val_sse,
            parts,
        }
    };
    let mut singles: Vec<Ranked> = if s.parallel {
        cands.par_iter().map(|h| run_one(vec![h.clone()], vec![], None, &nom.x0)).collect()
    } else {
        cands.iter().map(|h| run_one(vec![h.clone()], vec![], None, &nom.x0)).collect()
    };
    singles.sort_by(|a, b| a.bic.total_cmp(&b.bic));
    let mut ranking = singles.clone();
    let mut notes = Vec::new();
    if rec.resampled {
        notes.push(format!("Irregular time stamps ({} rows) were resampled by linear interpolation to a uniform grid of dt = {:.6} s ({} samples).", rec.rows_in_file, dt, n_samp));
    }
    let mut chosen: Option<Ranked> = None;
    let mut ties = Vec::new();
    if !nominal_adequate {
        if let Some(best) = singles.iter().find(|r| r.beats_nominal) {
            ties = singles
                .iter()
                .filter(|r| r.label != best.label && r.beats_nominal && (r.bic - best.bic).abs() < s.select.tie_bic)
                .map(|r| r.label.clone())
                .collect();
            let mut cur = best.clone();
            // Greedy forward selection.
            while cur.parts.len() < s.max_effects {
                let seconds: Vec<&Ranked> = singles
                    .iter()
                    .filter(|r| !cur.parts.iter().any(|p| p.kind.name() == r.parts[0].kind.name()))
                    .take(s.max_second)
                    .collect();
                let combos: Vec<Ranked> = {
                    let f = |r: &&Ranked| {
                        let mut parts = cur.parts.clone();
                        parts.push(r.parts[0].clone());
                        run_one(parts, vec![], Some(cur.params.clone()), &cur.x0)
                    };
                    if s.parallel {
                        seconds.par_iter().map(f).collect()
                    } else {
                        seconds.iter().map(f).collect()
                    }
                };
                ranking.extend(combos.iter().cloned());
                let next = combos
                    .into_iter()
                    .filter(|c| select::beats(c.bic, c.val_sse, cur.bic, cur.val_sse, &s.select))
                    .min_by(|a, b| a.bic.total_cmp(&b.bic));
                match next {
                    Some(nx) => cur = nx,
                    None => break,
                }
            }
            chosen = Some(cur);
        }
    }
    ranking.sort_by(|a, b| a.bic.total_cmp(&b.bic));

    // Fitted model and its residual.
    let (effects_chosen, x0_fit) = match &chosen {
        Some(c) => {
            let pb = ctx.problem(vec![], c.parts.clone());
            (pb.effects(&c.params), c.x0.clone())
        }
        None => (vec![], nom.x0.clone()),
    };
    let fit_pb = ctx.problem(effects_chosen.clone(), vec![]);
    let fit_sim = fit_pb.simulate(&[], &x0_fit, None).unwrap_or(nom_sim.clone());
    let fit_after = metrics::fit(&ctx.y, &fit_sim.y, p, k_est, n_samp, dt);
    let e_fit: Vec<f64> = ctx.y.iter().zip(&fit_sim.y).map(|(a, b)| a - b).collect();
    let residual_fitted = tests_for(&e_fit);
    let mut fitted_sys = sys.clone();
    fitted_sys.effects.list.extend(effects_chosen.iter().cloned());
    fitted_sys.x0 = nalgebra::DVector::from_column_slice(&x0_fit);
    fitted_sys.z0 = &sys.C * &fitted_sys.x0;
    fitted_sys.name = format!("{} (fitted by moreau diagnose)", sys.name);
    // The recording's input (on the uniform grid the fit used, time from 0) and the fit's
    // step, so that `moreau simulate fitted.toml` reproduces the fitted curve.
    fitted_sys.input = Input::Samples {
        path: FITTED_INPUT_FILE.into(),
        t: (0..n_samp).map(|k| k as f64 * dt).collect(),
        w: rec.w.clone(),
        period: None,
    };
    fitted_sys.sim = SimDefaults { dt: dt / substeps as f64, periods: 1, t_end: Some((n_samp - 1) as f64 * dt) };
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
                    };
                    off += k;
                    fe
                })
                .collect()
        }
        None => vec![],
    };
    let verdict = if nominal_adequate {
        "no missing physics found: the nominal residual is white, zero-mean and uncorrelated with the input (1 % level)"
            .to_string()
    } else if let Some(c) = &chosen {
        if fit_before.constant_outputs.is_empty() {
            format!(
                "missing physics: {} (validation fit {} -> {} %)",
                c.label,
                fmt_opt(&fit_before.fit_percent),
                fmt_opt(&fit_after.fit_percent)
            )
        } else {
            format!(
                "missing physics: {} (validation RMSE {} -> {}; fit % undefined, the validation output is constant)",
                c.label,
                fmt_e(&fit_before.rmse),
                fmt_e(&fit_after.rmse)
            )
        }
    } else {
        "the nominal residual is not white, but no effect of the library improves the fit by the required margin (BIC and validation): the mismatch is outside the library".to_string()
    };
    if !fit_before.constant_outputs.is_empty() {
        notes.push(format!(
            "The measured output(s) {} are constant on the validation segment (standard deviation at most {} of the whole record's): fit % is undefined there (null in report.json) and the validation is judged by the RMSE and the validation SSE ratio instead.",
            fit_before.constant_outputs.iter().map(|i| format!("y{}", i + 1)).collect::<Vec<_>>().join(", "),
            metrics::TOL_CONSTANT
        ));
    }
    if fit_before.fit_percent.iter().flatten().any(|f| *f > 97.0) {
        notes.push("Plain fit % is above 97 % (a tightly tracking loop saturates it): judge by the RMSE ratio (validation_ratio), the velocity fit and BIC instead.".into());
    }
    if matches!(chosen.as_ref().map(|c| c.parts[0].kind), Some(Kind::ConstantForce { .. } | Kind::SensorOffset))
        || ties.iter().any(|t| t.starts_with("constant_force") || t.starts_with("sensor_offset"))
    {
        notes.push("A constant force b on state j and a sensor offset C F^{-1} e_j b are observationally equivalent when the initial state is free (the play is translation invariant): the recording cannot tell them apart; physics must.".into());
    }
    let series = Series {
        t: (0..n_samp).map(|k| rec.time(k)).collect(),
        p,
        y: ctx.y.clone(),
        yhat_nominal: nom_sim.y.clone(),
        yhat_fitted: fit_sim.y.clone(),
        energy: loc.energy.clone(),
    };
    let _ = ctx.n;
    Ok(Report {
        model: sys.name.clone(),
        recording: rec.source.clone(),
        samples: n_samp,
        dt,
        resampled: rec.resampled,
        substeps,
        estimation_segment: [rec.time(0), rec.time(k_est - 1)],
        validation_segment: [rec.time(k_est), rec.time(n_samp - 1)],
        tau_slow,
        fit_before,
        fit_after,
        residual_nominal,
        residual_fitted,
        nominal_adequate,
        verdict,
        effects,
        ties,
        windows: loc.windows,
        regimes: loc.regimes,
        ranking,
        notes,
        fitted_model: Some(fitted_sys),
        series,
    })
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
        s += "## Fit on the validation segment\n\n| | fit % | RMSE | velocity fit % |\n|---|---|---|---|\n";
        s += &format!(
            "| nominal | {} | {} | {} |\n",
            fmt_opt(&self.fit_before.fit_percent),
            fmt_e(&self.fit_before.rmse),
            fmt_opt(&self.fit_before.velocity_fit_percent)
        );
        s += &format!(
            "| fitted | {} | {} | {} |\n\n",
            fmt_opt(&self.fit_after.fit_percent),
            fmt_e(&self.fit_after.rmse),
            fmt_opt(&self.fit_after.velocity_fit_percent)
        );
        s += "## Residual tests (nominal model)\n\n";
        let r = &self.residual_nominal;
        s += &format!(
            "- mean: {:.3e} against the 99 % bound {:.3e}: **{}**\n- whiteness: Q = {:.1} against the 99 % threshold {:.1} ({} lags of {} sample(s)): **{}**\n- input cross-correlation: Q = {} against {:.1}: **{}**\n- after fitting: white = {}, uncorrelated = {} (Q = {:.1}, cross Q = {})\n\n",
            r.mean, r.mean_bound, if r.zero_mean { "zero mean" } else { "offset" }, r.q_auto, r.q_auto_threshold, r.lags, r.lag_step, if r.white { "white" } else { "not white" }, fmt_vec(&r.q_cross), r.q_cross_threshold, if r.uncorrelated { "uncorrelated" } else { "correlated" },
            self.residual_fitted.white, self.residual_fitted.uncorrelated, self.residual_fitted.q_auto, fmt_vec(&self.residual_fitted.q_cross)
        );
        s += "## Where the mismatch is\n\n| regime | share of time | share of residual energy | enrichment |\n|---|---|---|---|\n";
        for g in &self.regimes {
            s += &format!(
                "| {} | {:.1} % | {:.1} % | {:.2} |\n",
                g.regime,
                100.0 * g.share_time,
                100.0 * g.share_energy,
                g.enrichment
            );
        }
        s += "\n| window | start (s) | end (s) | share of energy | share of time | dominant regime |\n|---|---|---|---|---|---|\n";
        for (i, w) in self.windows.iter().enumerate() {
            s += &format!(
                "| {} | {:.4} | {:.4} | {:.1} % | {:.1} % | {} ({:.0} %) |\n",
                i + 1,
                w.t_start,
                w.t_end,
                100.0 * w.share_energy,
                100.0 * w.share_time,
                w.dominant_regime,
                100.0 * w.dominant_fraction
            );
        }
        s += "\n## Effects added\n\n";
        if self.effects.is_empty() {
            s += "None.\n\n";
        }
        for e in &self.effects {
            s += &format!("- **{}**: {}\n", e.label, e.description);
            for ((n, v), (_, u)) in e.params.iter().zip(&e.uncertainty) {
                s += &format!(
                    "  - {n} = {v:.6} +- {u:.2e} (1 sigma: the larger of Gauss-Newton and a batch-means sandwich for coloured residuals; model error is not included)\n"
                );
            }
        }
        if !self.ties.is_empty() {
            s += &format!(
                "\nIndistinguishable on this recording (BIC within the tie margin): {}.\n",
                self.ties.join(", ")
            );
        }
        s += "\n## Ranking of all hypotheses\n\n| hypothesis | params | delta BIC | validation fit % | validation SSE ratio | accepted vs nominal |\n|---|---|---|---|---|---|\n";
        for r in &self.ranking {
            s += &format!(
                "| {} | {} | {:.1} | {} | {:.3} | {} |\n",
                r.label,
                fmt_e(&r.params),
                r.delta_bic,
                fmt_opt(&r.validation.fit_percent),
                r.validation_ratio,
                r.beats_nominal
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

fn fmt_e(v: &[f64]) -> String {
    v.iter().map(|x| format!("{x:.4e}")).collect::<Vec<_>>().join(", ")
}
