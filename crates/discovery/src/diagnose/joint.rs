//! Several recordings of one machine (issue 28 item 3): one model fitted jointly, selected by
//! leave-one-recording-out validation ([`diagnose_recordings`]).
//!
//! 1. Each recording fitted on is diagnosed on its own ([`super::diagnose`]); the model each
//!    selects (its effects, its grey-box refit) is a candidate, and so is the grey-box refit
//!    alone where the model file frees parameters (`[fit] free`).
//! 2. Every model is judged on every recording with its initial state fitted there (the
//!    recording's nuisance; the model's parameters held): the RMSE over the whole record, and
//!    the weighted mean square `MS_r = SSE_r / N_r` (output weights of that recording).
//!    The nominal model so judged is the reference `MS0_r`.
//! 3. Each recording's own refit judged on the others: one that improves its own recording
//!    and worsens another is reported as such, and is never adopted as it is.
//! 4. With two or more recordings, leave-one-recording-out: each candidate's shared
//!    parameters refitted jointly on all recordings but one ([`crate::fit::joint`], each its
//!    own initial state), judged on the one left out. A candidate is accepted when it worsens
//!    no left-out recording (`MS_r <= MS0_r` on each) and gains on average
//!    (`mean_r MS_r / MS0_r <= 1 - min_val_gain`); the accepted one with the least mean ratio
//!    is selected, none: the nominal model stands. With one recording, its own selection
//!    (accepted by its blocked cross-validation) is the candidate.
//! 5. The selected model fitted jointly on every recording; judged on each recording given
//!    to validate on (`--validate-on`), it is not adopted where it worsens one of them.
//!
//! `fitted.toml`: the model file with the joint fit's parameters and effects, the first
//! recording's fitted initial state and its input (to replay that recording).
use super::markdown::{fmt_units, g4};
use super::setup::Setup;
use super::{diagnose_selected, DiagnoseSettings, Report, Selected};
use crate::fit::joint::{fit_joint, Shared};
use crate::fit::{FreeNominal, Problem, Refit};
use crate::physics::{Hypothesis, Kind, Scales};
use crate::select::{FitContext, NOMINAL_REFIT};
use crate::{DiscoveryError, Recording};
use model::System;
use serde::Serialize;

/// A model the joint diagnosis can select: effects (with the scales that map their
/// parameters) and whether the freed nominal parameters are refitted.
#[derive(Clone)]
struct Candidate {
    label: String,
    parts: Vec<Hypothesis>,
    refit: bool,
    scales: Scales,
    /// Its fit on the recording that selected it (the start of its joint fits).
    start: Shared,
    /// The recording whose diagnosis selected it (`None`: the grey-box refit alone).
    origin: Option<usize>,
}

/// The joint diagnosis of several recordings.
#[derive(Debug, Clone, Serialize)]
pub struct JointReport {
    pub model: String,
    /// The recordings fitted on, then those validated on.
    pub recordings: Vec<RecordingRow>,
    /// Each recording's own refit judged on every recording.
    pub own_fits: Vec<OwnFit>,
    /// Leave-one-recording-out validation of each candidate (two or more recordings).
    pub candidates: Vec<CandidateRow>,
    /// The model adopted: a candidate's label, or `nominal`.
    pub selected: String,
    pub effects: Vec<JointEffect>,
    pub nominal_refit: Vec<JointValue>,
    /// Units of the outputs (`[signals] y`).
    pub units: Vec<String>,
    pub verdict: String,
    pub notes: Vec<String>,
    /// Each recording's own diagnosis: its verdict.
    pub per_recording: Vec<(String, String)>,
    /// `fitted.toml`.
    #[serde(skip)]
    pub fitted_model: Option<System>,
}

/// One recording's RMSE per output (whole record, its initial state fitted there) under each
/// model.
#[derive(Debug, Clone, Serialize)]
pub struct RecordingRow {
    pub source: String,
    /// `fit` (fitted on) or `validation` (`--validate-on`).
    pub role: &'static str,
    pub samples: usize,
    pub dt: f64,
    /// The nominal model.
    pub rmse_nominal: Vec<f64>,
    /// This recording's own refit (one-recording diagnosis), where it selected one.
    pub rmse_own_fit: Option<Vec<f64>>,
    /// The selected model fitted on the other recordings (left out; two or more recordings).
    pub rmse_left_out: Option<Vec<f64>>,
    /// The adopted model (the joint fit; the nominal where nothing is adopted).
    pub rmse_joint: Vec<f64>,
    /// Whether the adopted model is worse here than the nominal (weighted mean square).
    pub worse_than_nominal: bool,
}

/// A recording's own refit judged on every recording.
#[derive(Debug, Clone, Serialize)]
pub struct OwnFit {
    pub recording: String,
    pub label: String,
    /// RMSE per recording (the order of `recordings`), per output.
    pub rmse: Vec<Vec<f64>>,
    pub improves_own: bool,
    /// Recordings it predicts worse than the nominal model.
    pub worsens: Vec<String>,
    /// Never adopted as it is: its model is a candidate of the leave-one-recording-out
    /// selection; this says why it could not be.
    pub note: String,
}

/// Leave-one-recording-out validation of one candidate.
#[derive(Debug, Clone, Serialize)]
pub struct CandidateRow {
    pub label: String,
    /// The recording whose diagnosis selected it (`all` for the grey-box refit alone).
    pub from: String,
    /// Per recording fitted on: RMSE per output when left out, and `MS / MS0` there.
    pub rmse_left_out: Vec<Vec<f64>>,
    pub ratio: Vec<f64>,
    pub mean_ratio: f64,
    pub accepted: bool,
    pub reason: String,
}

/// An effect of the adopted model.
#[derive(Debug, Clone, Serialize)]
pub struct JointEffect {
    pub label: String,
    pub params: Vec<(String, f64)>,
    /// Gauss-Newton 1-sigma of the joint fit.
    pub uncertainty: Vec<(String, f64)>,
}

/// A freed nominal parameter of the adopted model.
#[derive(Debug, Clone, Serialize)]
pub struct JointValue {
    pub name: String,
    pub nominal: f64,
    pub value: f64,
    pub std: f64,
    /// Statistical correlation with each other freed parameter (Gauss-Newton, joint fit).
    pub correlation: Vec<(String, f64)>,
}

/// A model judged on one recording: its fitted initial state, RMSE per output and weighted
/// mean square.
struct Judged {
    x0: Vec<f64>,
    rmse: Vec<f64>,
    ms: f64,
}

/// The per-recording data of the joint diagnosis.
struct Rec<'a> {
    setup: Setup<'a>,
    ctx: FitContext<'a>,
}

/// Diagnoses `sys` against the recordings `recs` jointly (see the module documentation);
/// `validate_on` are judged, never fitted on.
pub fn diagnose_recordings(
    sys: &System,
    recs: &[Recording],
    validate_on: &[Recording],
    s: &DiagnoseSettings,
) -> Result<JointReport, DiscoveryError> {
    // `parallel: false` holds for the fits' Jacobians and starts too.
    let serial = s.serial_fits();
    let s = serial.as_ref().unwrap_or(s);
    let first = checked_recordings(sys, recs, validate_on, s)?;
    // 1. Each recording on its own.
    let mut singles: Vec<(Report, Selected)> = Vec::new();
    for r in recs {
        singles.push(diagnose_selected(sys, r, s).map_err(|e| in_recording(r, e))?);
    }
    let n_fit = recs.len();
    let all: Vec<&Recording> = recs.iter().chain(validate_on).collect();
    let setups: Vec<Setup> =
        all.iter().map(|r| Setup::new(sys, r, s).map_err(|e| in_recording(r, e))).collect::<Result<_, _>>()?;
    let data = recording_data(sys, setups, &singles, recs[0].dt);
    let free = if s.refit_nominal { FreeNominal::of(sys) } else { None };
    let units: Vec<String> = (0..first.p()).map(|i| sys.signals.y_unit(i).to_string()).collect();
    let mut notes = Vec::new();
    // 2. The nominal model on every recording.
    let nominal = Candidate {
        label: "nominal".into(),
        parts: vec![],
        refit: false,
        scales: singles[0].1.scales.clone(),
        start: Shared { theta: vec![], nominal: vec![] },
        origin: None,
    };
    let x0_nominal: Vec<Vec<f64>> = data.iter().map(|d| d.setup.x0_init.clone()).collect();
    let base: Vec<Judged> = data
        .iter()
        .enumerate()
        .map(|(j, d)| judge(d, &nominal, &nominal.start, &x0_nominal[j], free.as_ref(), s))
        .collect();
    // Candidates: each recording's selection, and the grey-box refit alone.
    let (own_cands, cands) = candidates(&singles, free.as_ref());
    // 3. Each recording's own refit on every recording.
    let (own_fits, own_rmse) = own_fits(&data, &all, &base, &own_cands, free.as_ref(), s);
    // 4. Leave one recording out.
    let fit_idx: Vec<usize> = (0..n_fit).collect();
    let (rows, best) = if n_fit >= 2 {
        leave_one_out(&data, recs, &base, &cands, free.as_ref(), s)
    } else {
        (vec![], (!cands.is_empty()).then_some((0, f64::NAN)))
    };
    // 5. The selected model fitted on every recording, checked on those validated on.
    let adopted = best.and_then(|(ci, _)| {
        adopt(&data, &all, &fit_idx, &cands[ci], &base, free.as_ref(), &units, s, &mut notes).map(|(sh, j)| (ci, sh, j))
    });
    let selected = adopted.as_ref().map(|a| a.0);
    let (final_cand, final_shared, final_judged): (&Candidate, Shared, &[Judged]) = match &adopted {
        Some((ci, sh, judged)) => (&cands[*ci], sh.clone(), judged),
        None => (&nominal, nominal.start.clone(), &base),
    };
    let std = joint_std(&data, &fit_idx, final_cand, &final_shared, final_judged, free.as_ref(), s);
    // The report.
    let left_out = selected.filter(|_| n_fit >= 2).and_then(|ci| rows.get(ci));
    let recordings = recording_rows(&all, n_fit, &base, &own_rmse, left_out, final_judged);
    let pb0 = problem(&data[0].ctx, final_cand, free.as_ref(), &final_shared.nominal);
    let effects = joint_effects(final_cand, &final_shared, &std.0);
    let nominal_refit = nominal_values(free.as_ref(), final_cand, &final_shared, &std.1, &std.2);
    if final_cand.parts.iter().any(|h| matches!(h.kind, Kind::InputOn { .. })) {
        notes.push("An effect on one input of several cannot be stated in a model file: fitted.toml omits it.".into());
    }
    let fitted_model =
        fitted_system(sys, &singles[0].0, &pb0, &final_shared, &final_judged[0].x0, &nominal_refit, &mut notes);
    let why = if cands.is_empty() {
        "no recording's diagnosis selects a model other than the nominal"
    } else if selected.is_none() && best.is_some() {
        "the selected model worsens a recording validated on"
    } else {
        "no candidate gains without worsening a left-out recording"
    };
    let verdict = verdict(&recordings, &final_cand.label, n_fit, &units, why);
    Ok(JointReport {
        model: sys.name.clone(),
        recordings,
        own_fits,
        candidates: rows,
        selected: final_cand.label.clone(),
        effects,
        nominal_refit,
        units,
        verdict,
        notes,
        per_recording: singles.iter().map(|(r, _)| (r.recording.clone(), r.verdict.clone())).collect(),
        fitted_model: Some(fitted_model),
    })
}

/// Candidate `cand` fitted on the recordings `fit_idx` (the first of `all`; the one
/// recording's own estimate where there is one) and judged on each: its shared parameters and
/// judgements where it worsens none of the recordings validated on (those after them), else
/// `None` with a note naming the recordings it worsens.
#[allow(clippy::too_many_arguments)]
fn adopt(
    data: &[Rec],
    all: &[&Recording],
    fit_idx: &[usize],
    cand: &Candidate,
    base: &[Judged],
    free: Option<&FreeNominal>,
    units: &[String],
    s: &DiagnoseSettings,
    notes: &mut Vec<String>,
) -> Option<(Shared, Vec<Judged>)> {
    let n_fit = fit_idx.len();
    let sh = if n_fit >= 2 { fit_on(data, fit_idx, cand, base, free, s) } else { cand.start.clone() };
    let judged: Vec<Judged> = data.iter().enumerate().map(|(j, d)| judge(d, cand, &sh, &base[j].x0, free, s)).collect();
    let worse: Vec<usize> = (n_fit..all.len()).filter(|&j| judged[j].ms > base[j].ms).collect();
    if worse.is_empty() {
        return Some((sh, judged));
    }
    let which: Vec<String> = worse
        .iter()
        .map(|&j| {
            format!("{} {} -> {}", all[j].source, fmt_units(&base[j].rmse, units), fmt_units(&judged[j].rmse, units))
        })
        .collect();
    notes.push(format!(
        "{} fitted on the recordings worsens the recording(s) validated on ({}): not adopted, the nominal model stands.",
        cand.label,
        which.join("; ")
    ));
    None
}

/// The first recording, once every recording has the first's signals and passes the
/// settings' checks (each error names its recording).
fn checked_recordings<'r>(
    sys: &System,
    recs: &'r [Recording],
    validate_on: &[Recording],
    s: &DiagnoseSettings,
) -> Result<&'r Recording, DiscoveryError> {
    let Some(first) = recs.first() else {
        return Err(DiscoveryError::NoRecording);
    };
    for r in recs.iter().chain(validate_on).skip(1) {
        same_signals(first, r)?;
    }
    for r in recs.iter().chain(validate_on) {
        s.validate(sys, r).map_err(|e| in_recording(r, e))?;
    }
    Ok(first)
}

/// The report's row of each recording (fitted on, then validated on): the nominal, its own
/// refit, the selected candidate left out (`left_out`), the adopted model (`adopted`).
fn recording_rows(
    all: &[&Recording],
    n_fit: usize,
    base: &[Judged],
    own_rmse: &[Option<Vec<f64>>],
    left_out: Option<&CandidateRow>,
    adopted: &[Judged],
) -> Vec<RecordingRow> {
    all.iter()
        .enumerate()
        .map(|(j, r)| RecordingRow {
            source: r.source.clone(),
            role: if j < n_fit { "fit" } else { "validation" },
            samples: r.len(),
            dt: r.dt,
            rmse_nominal: base[j].rmse.clone(),
            rmse_own_fit: own_rmse[j].clone(),
            rmse_left_out: left_out.filter(|_| j < n_fit).map(|c| c.rmse_left_out[j].clone()),
            rmse_joint: adopted[j].rmse.clone(),
            worse_than_nominal: adopted[j].ms > base[j].ms * (1.0 + 1e-9),
        })
        .collect()
}

/// The fit context of each recording. Hold and sub-steps: each recording fitted on as its
/// diagnosis settled them; a recording validated on with the first recording's hold and
/// sub-step length (the sub-steps scaled by its sample time, between its own first count and
/// the most allowed; `dt0` the first recording's sample time).
fn recording_data<'a>(
    sys: &'a System,
    setups: Vec<Setup<'a>>,
    singles: &[(Report, Selected)],
    dt0: f64,
) -> Vec<Rec<'a>> {
    setups
        .into_iter()
        .enumerate()
        .map(|(j, setup)| {
            let (hold, substeps) = if j < singles.len() {
                (singles[j].1.hold, singles[j].1.substeps)
            } else {
                let sel = &singles[0].1;
                (
                    sel.hold,
                    ((sel.substeps as f64 * setup.dt / dt0).ceil() as usize)
                        .clamp(setup.k0.max(1), setup.max_sub.max(sel.substeps)),
                )
            };
            let ctx = detach(sys, setup.context(hold, substeps, setup.x_scale_free.clone()));
            Rec { setup, ctx }
        })
        .collect()
}

/// The candidates: each recording's selection (per recording, and once each: the first
/// where two select the same), and the grey-box refit alone (two or more recordings).
fn candidates(singles: &[(Report, Selected)], free: Option<&FreeNominal>) -> (Vec<Option<Candidate>>, Vec<Candidate>) {
    let own_cands: Vec<Option<Candidate>> = singles
        .iter()
        .enumerate()
        .map(|(i, (_, sel))| {
            sel.chosen.as_ref().map(|c| Candidate {
                label: c.label.clone(),
                parts: c.parts.clone(),
                refit: c.refit,
                scales: sel.scales.clone(),
                start: Shared { theta: c.params.clone(), nominal: if c.refit { c.nominal.clone() } else { vec![] } },
                origin: Some(i),
            })
        })
        .collect();
    let mut cands: Vec<Candidate> = Vec::new();
    for c in own_cands.iter().flatten() {
        if !cands.iter().any(|k| k.label == c.label) {
            cands.push(c.clone());
        }
    }
    if let Some(f) = free {
        if !cands.iter().any(|k| k.label == NOMINAL_REFIT) && singles.len() >= 2 {
            cands.push(Candidate {
                label: NOMINAL_REFIT.into(),
                parts: vec![],
                refit: true,
                scales: singles[0].1.scales.clone(),
                start: Shared { theta: vec![], nominal: f.nominal.clone() },
                origin: None,
            });
        }
    }
    (own_cands, cands)
}

/// The adopted model's freed nominal parameters (where refitted) with their sigma.
fn nominal_values(
    free: Option<&FreeNominal>,
    c: &Candidate,
    sh: &Shared,
    std: &[f64],
    correlation: &[Vec<f64>],
) -> Vec<JointValue> {
    match (free, c.refit) {
        (Some(f), true) => f
            .params
            .iter()
            .enumerate()
            .map(|(i, p)| JointValue {
                name: p.name.clone(),
                nominal: f.nominal[i],
                value: sh.nominal[i],
                std: std.get(i).copied().unwrap_or(f64::NAN),
                correlation: crate::fit::levenberg_marquardt::correlations_with_others(
                    f.params.iter().map(|q| q.name.as_str()),
                    correlation,
                    i,
                ),
            })
            .collect(),
        _ => vec![],
    }
}

/// Each recording's own refit (`own_cands`, per recording fitted on) judged on every
/// recording; its RMSE on its own recording.
fn own_fits(
    data: &[Rec],
    all: &[&Recording],
    base: &[Judged],
    own_cands: &[Option<Candidate>],
    free: Option<&FreeNominal>,
    s: &DiagnoseSettings,
) -> (Vec<OwnFit>, Vec<Option<Vec<f64>>>) {
    let mut out = Vec::new();
    let mut own_rmse: Vec<Option<Vec<f64>>> = vec![None; all.len()];
    for (i, cand) in own_cands.iter().enumerate() {
        let Some(cand) = cand else { continue };
        let judged: Vec<Judged> =
            data.iter().enumerate().map(|(j, d)| judge(d, cand, &cand.start, &base[j].x0, free, s)).collect();
        own_rmse[i] = Some(judged[i].rmse.clone());
        let improves_own = judged[i].ms < base[i].ms;
        let worsens: Vec<String> =
            (0..all.len()).filter(|&j| j != i && judged[j].ms > base[j].ms).map(|j| all[j].source.clone()).collect();
        let note = match (improves_own, worsens.is_empty()) {
            (true, false) => {
                format!("improves its own recording and worsens {}: not adopted as it is", worsens.join(", "))
            }
            (_, true) if all.len() > 1 => "worsens no other recording".into(),
            _ => "does not improve its own recording over the whole record".into(),
        };
        out.push(OwnFit {
            recording: all[i].source.clone(),
            label: cand.label.clone(),
            rmse: judged.iter().map(|j| j.rmse.clone()).collect(),
            improves_own,
            worsens,
            note,
        });
    }
    (out, own_rmse)
}

/// Leave-one-recording-out validation of each candidate on the recordings fitted on
/// (`recs`, the first of `data`); the accepted one with the least mean ratio.
fn leave_one_out(
    data: &[Rec],
    recs: &[Recording],
    base: &[Judged],
    cands: &[Candidate],
    free: Option<&FreeNominal>,
    s: &DiagnoseSettings,
) -> (Vec<CandidateRow>, Option<(usize, f64)>) {
    let fit_idx: Vec<usize> = (0..recs.len()).collect();
    let mut rows = Vec::new();
    let mut best: Option<(usize, f64)> = None;
    {
        for (ci, c) in cands.iter().enumerate() {
            let mut rmse = Vec::new();
            let mut ratio = Vec::new();
            for &j in &fit_idx {
                let others: Vec<usize> = fit_idx.iter().copied().filter(|&i| i != j).collect();
                let fitted = fit_on(data, &others, c, base, free, s);
                let judged = judge(&data[j], c, &fitted, &base[j].x0, free, s);
                ratio.push(judged.ms / base[j].ms.max(1e-300));
                rmse.push(judged.rmse);
            }
            let mean_ratio = ratio.iter().sum::<f64>() / ratio.len() as f64;
            let worse: Vec<String> = fit_idx
                .iter()
                .filter(|&&j| ratio[j].is_nan() || ratio[j] > 1.0)
                .map(|&j| recs[j].source.clone())
                .collect();
            let gain = 1.0 - s.select.min_val_gain;
            let (accepted, reason) = if !worse.is_empty() {
                (false, format!("worsens left-out {}", worse.join(", ")))
            } else if mean_ratio > gain {
                (false, format!("mean left-out MS ratio {} above {}", g4(mean_ratio), g4(gain)))
            } else {
                (true, "worsens no left-out recording and gains on average".into())
            };
            if accepted && best.is_none_or(|b| mean_ratio < b.1) {
                best = Some((ci, mean_ratio));
            }
            rows.push(CandidateRow {
                label: c.label.clone(),
                from: c.origin.map_or("all".into(), |i| recs[i].source.clone()),
                rmse_left_out: rmse,
                ratio,
                mean_ratio,
                accepted,
                reason,
            });
        }
    }
    (rows, best)
}

/// `ctx` without its borrow of the setup (the freed nominal parameters are the joint
/// diagnosis' own).
fn detach<'a>(sys: &'a System, ctx: FitContext<'_>) -> FitContext<'a> {
    FitContext {
        sys,
        scales: ctx.scales,
        w: ctx.w,
        y: ctx.y,
        m: ctx.m,
        p: ctx.p,
        dt: ctx.dt,
        n: ctx.n,
        k_est: ctx.k_est,
        weights: ctx.weights,
        maps: ctx.maps,
        substeps: ctx.substeps,
        x_scale: ctx.x_scale,
        x0_init: ctx.x0_init,
        hold: ctx.hold,
        z0: ctx.z0,
        free: None,
    }
}

/// Recordings of one machine have the same signals: inputs, outputs, a recorded backlash
/// output and the other columns.
fn same_signals(a: &Recording, b: &Recording) -> Result<(), DiscoveryError> {
    let names = |r: &Recording| r.extra.iter().map(|e| e.0.clone()).collect::<Vec<_>>().join(",");
    let differ = |what: &'static str, x: String, y: String| DiscoveryError::RecordingsDiffer {
        first: a.source.clone(),
        other: b.source.clone(),
        what,
        first_has: x,
        other_has: y,
    };
    if a.m() != b.m() {
        return Err(differ("inputs", a.m().to_string(), b.m().to_string()));
    }
    if a.p() != b.p() {
        return Err(differ("outputs", a.p().to_string(), b.p().to_string()));
    }
    if a.z.is_some() != b.z.is_some() {
        let z = |r: &Recording| if r.z.is_some() { "a z column" } else { "no z column" }.to_string();
        return Err(differ("backlash output", z(a), z(b)));
    }
    if names(a) != names(b) {
        return Err(differ("other columns", format!("[{}]", names(a)), format!("[{}]", names(b))));
    }
    Ok(())
}

fn in_recording(r: &Recording, e: DiscoveryError) -> DiscoveryError {
    match e {
        // the reader's errors name their file already
        DiscoveryError::Io { .. } | DiscoveryError::RecordingsDiffer { .. } => e,
        e => DiscoveryError::InRecording { path: r.source.clone(), reason: e.to_string() },
    }
}

/// The problem of candidate `c` on one recording: residuals on the whole record, the freed
/// nominal parameters (where refitted) at `nominal`.
fn problem<'a>(
    ctx: &'a FitContext<'a>,
    c: &'a Candidate,
    free: Option<&'a FreeNominal>,
    nominal: &[f64],
) -> Problem<'a> {
    let mut pb = ctx.problem_on(vec![], c.parts.clone(), ctx.n, None);
    pb.scales = &c.scales;
    if let (true, Some(f)) = (c.refit, free) {
        pb.refit = Some(Refit { free: f, values: nominal.to_vec() });
    }
    pb
}

/// Model `c` with parameters `sh` judged on recording `d`: its initial state fitted there
/// (from `x0`), RMSE per output and weighted mean square over the whole record.
fn judge(d: &Rec, c: &Candidate, sh: &Shared, x0: &[f64], free: Option<&FreeNominal>, s: &DiagnoseSettings) -> Judged {
    let pb = problem(&d.ctx, c, free, &sh.nominal);
    let f = fit_joint(
        std::slice::from_ref(&pb),
        sh,
        &[x0.to_vec()],
        std::slice::from_ref(&d.setup.x_scale_free),
        false,
        &s.fit,
    );
    let x0 = f.x0[0].clone();
    let (p, n) = (d.ctx.p, d.ctx.n);
    let rmse = match pb.simulate_with(&sh.theta, &sh.nominal, &x0, None) {
        Some(out) => (0..p)
            .map(|i| ((0..n).map(|k| (out.y[k * p + i] - d.ctx.y[k * p + i]).powi(2)).sum::<f64>() / n as f64).sqrt())
            .collect(),
        None => vec![f64::INFINITY; p],
    };
    let ms = if f.n_res[0] > 0 { f.sse[0] / f.n_res[0] as f64 } else { f64::INFINITY };
    Judged { x0, rmse, ms }
}

/// The shared parameters of `c` fitted jointly on the recordings `idx` (each its own initial
/// state, from the nominal's there).
fn fit_on(
    data: &[Rec],
    idx: &[usize],
    c: &Candidate,
    base: &[Judged],
    free: Option<&FreeNominal>,
    s: &DiagnoseSettings,
) -> Shared {
    if c.parts.is_empty() && !c.refit {
        return c.start.clone();
    }
    let pbs: Vec<Problem> = idx.iter().map(|&j| problem(&data[j].ctx, c, free, &c.start.nominal)).collect();
    let x0: Vec<Vec<f64>> = idx.iter().map(|&j| base[j].x0.clone()).collect();
    let xs: Vec<Vec<f64>> = idx.iter().map(|&j| data[j].setup.x_scale_free.clone()).collect();
    let f = fit_joint(&pbs, &c.start, &x0, &xs, true, &s.fit);
    if f.sse.iter().all(|v| v.is_finite()) {
        f.shared
    } else {
        c.start.clone()
    }
}

/// Gauss-Newton 1-sigma of the adopted model's shared parameters (effects, nominal) at its
/// joint fit (one evaluation of the joint problem's Jacobian).
fn joint_std(
    data: &[Rec],
    idx: &[usize],
    c: &Candidate,
    sh: &Shared,
    judged: &[Judged],
    free: Option<&FreeNominal>,
    s: &DiagnoseSettings,
) -> (Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
    if c.parts.is_empty() && !c.refit {
        return (vec![], vec![], vec![]);
    }
    let pbs: Vec<Problem> = idx.iter().map(|&j| problem(&data[j].ctx, c, free, &sh.nominal)).collect();
    let x0: Vec<Vec<f64>> = idx.iter().map(|&j| judged[j].x0.clone()).collect();
    let xs: Vec<Vec<f64>> = idx.iter().map(|&j| data[j].setup.x_scale_free.clone()).collect();
    // From the solution: the solver stops at once and reports the sigma there.
    let settings = crate::fit::FitSettings { max_iter: 1, ..s.fit.clone() };
    let f = fit_joint(&pbs, sh, &x0, &xs, true, &settings);
    (f.std, f.nominal_std, f.nominal_correlation)
}

/// The adopted effects with their parameters and sigma.
fn joint_effects(c: &Candidate, sh: &Shared, std: &[f64]) -> Vec<JointEffect> {
    let mut off = 0;
    c.parts
        .iter()
        .map(|h| {
            let k = h.k();
            let e = JointEffect {
                label: h.kind.label(),
                params: h.names.iter().zip(&sh.theta[off..off + k]).map(|(n, v)| (n.to_string(), *v)).collect(),
                uncertainty: h
                    .names
                    .iter()
                    .enumerate()
                    .map(|(i, n)| (n.to_string(), std.get(off + i).copied().unwrap_or(f64::NAN)))
                    .collect(),
            };
            off += k;
            e
        })
        .collect()
}

/// `fitted.toml`: the model file with the adopted parameters and effects, the first
/// recording's initial state and replayed input (from its own diagnosis).
fn fitted_system(
    sys: &System,
    first: &Report,
    pb: &Problem,
    sh: &Shared,
    x0: &[f64],
    nominal_refit: &[JointValue],
    notes: &mut Vec<String>,
) -> System {
    let mut out = sys.clone();
    if let (Some(f), false) = (&pb.refit, nominal_refit.is_empty()) {
        match f.free.apply(&out, &sh.nominal) {
            Ok(s) => out = s,
            Err(e) => notes.push(format!("the refitted parameters are not written to the fitted model: {e}")),
        }
        out.fit.result = nominal_refit
            .iter()
            .map(|v| model::model_file::FitRecord {
                name: v.name.clone(),
                nominal: v.nominal,
                value: v.value,
                std: v.std,
                correlation: v.correlation.clone(),
            })
            .collect();
    }
    out.effects.list.extend(pb.effects(&sh.theta));
    out.x0 = nalgebra::DVector::from_column_slice(x0);
    out.z0 = &out.C * &out.x0;
    if let Some(f) = &first.fitted_model {
        out.input = f.input.clone();
        out.sim = f.sim.clone();
    }
    out.name = format!("{} (fitted by moreau diagnose to several recordings)", sys.name);
    out
}

/// The verdict: the adopted model and the RMSE per recording, nominal -> adopted.
fn verdict(rows: &[RecordingRow], label: &str, n_fit: usize, units: &[String], why: &str) -> String {
    let per: Vec<String> = rows
        .iter()
        .map(|r| {
            format!(
                "{}{} {} -> {}",
                r.source,
                if r.role == "validation" { " (validation)" } else { "" },
                fmt_units(&r.rmse_nominal, units),
                fmt_units(&r.rmse_joint, units)
            )
        })
        .collect();
    let head = if label == "nominal" {
        format!("The nominal model is kept ({why})")
    } else if n_fit >= 2 {
        format!("Fitted jointly to {n_fit} recordings: {label}, selected by leave-one-recording-out validation")
    } else {
        format!("Fitted to one recording: {label}")
    };
    format!("{head}. RMSE per recording (nominal -> fitted): {}.", per.join("; "))
}

impl JointReport {
    /// `report.md`.
    pub fn to_markdown(&self) -> String {
        let u = &self.units;
        let opt = |v: &Option<Vec<f64>>| v.as_ref().map_or("-".to_string(), |x| fmt_units(x, u));
        let mut md =
            format!("# Diagnosis of {} recordings: {}\n\n{}\n\n", self.recordings.len(), self.model, self.verdict);
        md += "## RMSE per recording\n\nWhole record, each model with its initial state fitted on that recording. *own fit*: the recording's own one-recording diagnosis; *left out*: the adopted model fitted on the other recordings; *joint*: the adopted model fitted on every recording fitted on.\n\n";
        md += "| recording | role | nominal | own fit | left out | joint |\n|---|---|---:|---:|---:|---:|\n";
        for r in &self.recordings {
            md += &format!(
                "| `{}` | {} | {} | {} | {} | {}{} |\n",
                r.source,
                r.role,
                fmt_units(&r.rmse_nominal, u),
                opt(&r.rmse_own_fit),
                opt(&r.rmse_left_out),
                fmt_units(&r.rmse_joint, u),
                if r.worse_than_nominal { " (worse than nominal)" } else { "" }
            );
        }
        if !self.own_fits.is_empty() {
            md += "\n## Each recording's own refit on every recording\n\n| fitted on | model |";
            for r in &self.recordings {
                md += &format!(" on `{}` |", r.source);
            }
            md += " |\n|---|---|";
            md += &"---:|".repeat(self.recordings.len());
            md += "---|\n";
            for o in &self.own_fits {
                md += &format!("| `{}` | {} |", o.recording, o.label);
                for v in &o.rmse {
                    md += &format!(" {} |", fmt_units(v, u));
                }
                md += &format!(" {} |\n", o.note);
            }
        }
        if !self.candidates.is_empty() {
            md += "\n## Leave-one-recording-out selection\n\nEach model's shared parameters refitted on all recordings but one, judged on that one (RMSE; MS / MS0: weighted mean square against the nominal's).\n\n| model | from | left-out RMSE | MS / MS0 | accepted |\n|---|---|---|---|---|\n";
            for c in &self.candidates {
                md += &format!(
                    "| {} | `{}` | {} | {} | {}: {} |\n",
                    c.label,
                    c.from,
                    c.rmse_left_out.iter().map(|v| fmt_units(v, u)).collect::<Vec<_>>().join("; "),
                    c.ratio.iter().map(|v| g4(*v)).collect::<Vec<_>>().join("; "),
                    if c.accepted { "yes" } else { "no" },
                    c.reason
                );
            }
        }
        md += &format!("\n## Adopted model: {}\n\n", self.selected);
        for v in &self.nominal_refit {
            md += &format!("- {} = {} +- {} (nominal {})\n", v.name, g4(v.value), g4(v.std), g4(v.nominal));
        }
        for e in &self.effects {
            let p: Vec<String> = e
                .params
                .iter()
                .zip(&e.uncertainty)
                .map(|((n, v), (_, s))| format!("{n} = {} +- {}", g4(*v), g4(*s)))
                .collect();
            md += &format!("- {}: {}\n", e.label, p.join(", "));
        }
        md += "\n## Each recording on its own\n\n";
        for (r, v) in &self.per_recording {
            md += &format!("- `{r}`: {v}\n");
        }
        if !self.notes.is_empty() {
            md += "\n## Notes\n\n";
            for n in &self.notes {
                md += &format!("- {n}\n");
            }
        }
        md
    }
}
