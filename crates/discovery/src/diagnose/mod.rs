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
//!
//! [`diagnose`] runs the stages in order, each in its own place:
//! 1. [`settings`]: [`DiagnoseSettings::validate`] against the model and the recording;
//!    `setup`: the recording prepared (signals, weights, noise level, scales, initial state).
//! 2. `hold`: hold and discretisation, then the nominal fit under them.
//! 3. `pass`: nominal residual -> localisation -> hypotheses -> selection and
//!    cross-validation ([`crate::select`]); the pass is redone where the best effects overturn
//!    an `auto` hold or the selected model needs more sub-steps.
//! 4. Conclusion (here): recorded columns the model leaves out, the initial state.
//! 5. `refit`: the selected model's uncertainty (jackknife), an input delay's reading under
//!    the other hold (`hold`: its interval covers both where the data cannot tell the holds
//!    apart), and the fitted model (`fitted.toml`).
//! 6. Report: `verdict` (headline and text), `notes`, [`report`] (the types of
//!    `report.json`) and `markdown` (`report.md`, [`Report::to_markdown`]).
//!
//! Long records: [`screen`] runs the above on a leading part with every hypothesis, then on the
//! whole record with the hypotheses it kept (again with every one where the whole record shows
//! more than the leading part did).
//!
//! An effect that acts only beyond the estimation segment (`extend`): where the model is left
//! incomplete and what is missing acts after the estimation segment (a candidate stuck there
//! halves the held-out error, or the residual's largest window starts after it), the record is
//! diagnosed again with a longer estimation segment.
//!
//! Several recordings of one machine: [`joint`] ([`diagnose_recordings`]) runs the above on
//! each, then selects among the models they selected by leave-one-recording-out validation
//! and fits the selected one jointly.
pub mod joint;
pub mod report;
pub mod settings;

mod extend;
mod hold;
mod markdown;
mod notes;
mod pass;
mod refit;
pub mod screen;
mod setup;
mod verdict;

pub use crate::select::{CvResult, Ranked, NOMINAL_REFIT, NOT_TESTABLE_SHARE};
pub use hold::ScreenedHold;
pub use joint::{diagnose_recordings, JointReport};
pub use report::{
    DerivedParameter, Explained, FittedEffect, HoldReport, InitialStateReport, LocalisationInfo, NominalValue,
    Remaining, Report, Series, FITTED_INPUT_FILE,
};
pub use settings::{DiagnoseSettings, HoldChoice, InitialState, Metric, SERVO_FIT_PERCENT};

use crate::fit::missing_input::{self, MissingInput, MISSING_MARGIN, MISSING_SHARE};
use crate::metrics::{self, Fit};
use crate::select::{self, Selection};
use crate::{DiscoveryError, Recording};
use model::System;
use pass::{NominalFindings, Pass};
use refit::{Fitted, Uncertainty};
use setup::Setup;
use verdict::Headline;

/// Diagnoses `rec` against nominal model `sys`.
pub fn diagnose(sys: &System, rec: &Recording, s: &DiagnoseSettings) -> Result<Report, DiscoveryError> {
    Ok(diagnose_selected(sys, rec, s)?.0)
}

/// What a one-recording diagnosis selected, as the joint diagnosis of several recordings
/// ([`joint`]) takes it up: the hold and sub-steps it settled on, the scales its hypotheses'
/// parameters are mapped with, and the selected model.
pub(crate) struct Selected {
    pub hold: dynamics::extended::InputHold,
    pub substeps: usize,
    pub scales: crate::hypothesis::Scales,
    pub chosen: Option<Ranked>,
}

/// [`diagnose`], with what it selected.
pub(crate) fn diagnose_selected(
    sys: &System,
    rec: &Recording,
    s: &DiagnoseSettings,
) -> Result<(Report, Selected), DiscoveryError> {
    s.validate(sys, rec)?;
    let first = screened_or_whole(sys, rec, s)?;
    extend::extended(sys, rec, s, first, screened_or_whole)
}

/// A long record screened ([`screen`]), any other diagnosed whole.
fn screened_or_whole(
    sys: &System,
    rec: &Recording,
    s: &DiagnoseSettings,
) -> Result<(Report, Selected), DiscoveryError> {
    match screen::head(rec, s) {
        Some(head) => screen::diagnose_screened(sys, rec, &head, s, diagnose_whole),
        None => diagnose_whole(sys, rec, s),
    }
}

/// [`diagnose_selected`] on the whole of `rec` with the library the settings allow (no
/// screening).
fn diagnose_whole(sys: &System, rec: &Recording, s: &DiagnoseSettings) -> Result<(Report, Selected), DiscoveryError> {
    // `parallel: false` holds for the fits' Jacobians and starts too.
    let serial = s.serial_fits();
    let s = serial.as_ref().unwrap_or(s);
    let data = Setup::new(sys, rec, s)?;
    // Hold and discretisation, then the nominal fit under them.
    let mut pass = Pass::first(&data);
    // Nominal residual -> localisation -> hypotheses -> selection and cross-validation,
    // redone where the effects overturn the hold or the selected model needs more sub-steps.
    let (nominal, selection) = pass.run(&data)?;
    let mut notes = std::mem::take(&mut pass.notes);
    // What the selection leaves standing: missing inputs, the initial state.
    let mut outcome = conclude(&data, &pass, &nominal, selection, &mut notes);
    // A hold the best effect does not confirm (for a selected delay, its reading under both
    // holds below says so, with the delay's interval).
    pass.hold_report.effects_undecided = hold::effects_undecided(
        &pass.hold_report,
        outcome.chosen.as_ref().is_some_and(hold::has_delay),
        s.select.tie_bic,
    );
    notes::selection(&data, &pass, nominal.delta_bic_disc, &outcome.cv_rejected, &mut notes);
    // Refit: the selected model's uncertainty and the fitted model.
    let unc = refit::uncertainty(&data, &pass.ctx, outcome.chosen.as_mut(), pass.finer_fit.as_ref());
    // An input delay under an `auto` hold: its reading under the other hold, and its
    // interval widened to cover both where the recording cannot tell the holds apart.
    if let Some(note) =
        hold::delay_under_both_holds(&data, &pass.ctx, pass.hold, outcome.chosen.as_mut(), &mut pass.hold_report)
    {
        notes.push(note);
    }
    let chosen = outcome.chosen.as_ref();
    let mut fitted = refit::fitted(&data, &pass.ctx, pass.hold, &pass.nom, &nominal.nom_sim, chosen, &unc, &mut notes);
    // The delay under the other hold as refitted (not the h/2 shift alone), where it was.
    if let Some(&v) = pass.hold_report.delay_other_hold.first() {
        for e in fitted.effects.iter_mut() {
            if let Some(o) = e.other_hold.as_mut().filter(|_| v.is_finite()) {
                o.1[0].1 = v;
            }
        }
    }
    // Report: headline, verdict, notes.
    let headline = verdict::headline(&data, &outcome.fit_before, &fitted.fit_after, &mut notes);
    let held_out = verdict::held_out_extension(&outcome.ranking, outcome.chosen.as_ref());
    // What the final model leaves: something still missing and where, or why it is not.
    let leftover = remaining(&data, &pass, &nominal, &outcome, &fitted, held_out.clone());
    let mut verdict = verdict::verdict(
        nominal.nominal_adequate,
        &nominal.residual_nominal,
        &outcome.missing_inputs,
        outcome.chosen.as_ref(),
        &outcome.equivalents,
        &fitted.nominal_refit,
        &outcome.cv_rejected,
        held_out.as_ref(),
        leftover.explained(),
        &headline.text,
    );
    if let Leftover::Missing(r) = &leftover {
        verdict += &format!("; {}", verdict::still_missing(r, outcome.chosen.as_ref(), s.max_effects));
    }
    notes::closing(&data, &pass, &outcome, &fitted, headline.use_rmse, &mut notes);
    let selected = Selected {
        hold: pass.hold,
        substeps: pass.ctx.substeps,
        scales: pass.ctx.scales.clone(),
        chosen: outcome.chosen.clone(),
    };
    Ok((assemble(&data, pass, nominal, outcome, unc, fitted, headline, (verdict, leftover), notes), selected))
}

/// The residual's RMS must exceed the noise level (difference estimator) by this factor for
/// the model to be called incomplete: a misfit within the noise, however coloured, is not
/// evidence of missing physics worth a second effect (a converged single effect leaves 0.95-1.08
/// on the benchmark; two effects with one missed leave 1.4 and more).
pub const INCOMPLETE_NOISE_RATIO: f64 = 1.1;

/// What [`remaining`] found in the final model's residual.
enum Leftover {
    /// Not judged: the nominal model was adequate, or a recorded input is missing from it.
    NotJudged,
    /// White about zero, or not white but not missing physics either (coloured noise, or a
    /// misfit within the noise).
    Explained(Explained),
    /// Something is still missing: the model is incomplete.
    Missing(Remaining),
}

impl Leftover {
    fn explained(&self) -> Option<&Explained> {
        match self {
            Leftover::Explained(e) => Some(e),
            _ => None,
        }
    }
}

/// What the final model (selected, else nominal) leaves unexplained where the nominal was not
/// adequate and no missing input was found: `Some` (the model is incomplete) where its residual
/// is not white, unless one of two documented reasons says the colour is not missing physics:
/// - coloured measurement noise: the residual with an AR(1) filter removed
///   ([`crate::residual::prewhiten_ar1`]) is white, and its mean is within the zero-mean bound
///   widened for that colour (`sqrt((1 + rho) / (1 - rho))`: coloured noise has zero mean; a
///   missed sensor offset does not, and a filter with `rho` near 1 whitens any slow misfit:
///   an input delay with a missed offset, fresh seed 2792, left Q = 12015 with a mean 9 times
///   its bound, white once filtered). Requiring the filtered residual uncorrelated with the
///   input too called the digital `none` case of development seed 2712 incomplete (its
///   whitened nominal residual follows the input, an artefact of the hold, not physics);
/// - a misfit within the noise: its RMS is at most [`INCOMPLETE_NOISE_RATIO`] times the noise
///   level, except where the residual is above the noise level at all (ratio above 1),
///   correlated with the input, **and** an extension of the selected model gains the selection
///   margin in BIC but was not confirmed on held-out folds ([`verdict::unconfirmed_extension`]:
///   the estimation data say more is there). Development seeds: Coulomb friction or a constant
///   force with a missed input delay left 1.03-1.04 times the noise with the pair 16-77
///   better in BIC; a correctly named gap width (seed 27, the negative control of
///   `tests/two_effects.rs`) left 0.99 with an extension 26 better, not called incomplete. The
///   line at 1 is thin (a noise level from 1000-2000 samples is uncertain by about 2 %).
///
/// Neither exempts a model that a fitted candidate beats on the held-out segment by half
/// ([`verdict::held_out_extension`], `held_out`): the effect acts where the estimation data do not reach.
///
/// With the localisation of that residual; where an exemption applies, which one.
fn remaining(
    data: &Setup,
    pass: &Pass,
    nominal: &NominalFindings,
    outcome: &Outcome,
    fitted: &Fitted,
    held_out: Option<(String, f64)>,
) -> Leftover {
    let t = &fitted.residual_fitted;
    if nominal.nominal_adequate || outcome.missing_inputs.iter().any(|c| c.missing) {
        return Leftover::NotJudged;
    }
    let (ctx, n, p) = (&pass.ctx, data.n_samp, data.p);
    let e_fit: Vec<f64> = ctx.y.iter().zip(&fitted.fit_sim.y).map(|(a, b)| a - b).collect();
    let (e_w, ar1) = crate::residual::prewhiten_ar1(&e_fit, n, p);
    // a residual white about a mean off zero is something left too (a missing offset)
    let mean_off_zero = crate::residual::mean_off_zero(&e_fit, n, p, &ar1, data.lag_step);
    let rms_over_noise: Vec<f64> = (0..p)
        .map(|i| {
            let ms = (0..n).map(|k| e_fit[k * p + i].powi(2)).sum::<f64>() / n.max(1) as f64;
            ms.sqrt() / data.noise[i].max(1e-300)
        })
        .collect();
    let explained = |reason, q_auto_ar1, ar1, rms_over_noise| {
        Leftover::Explained(Explained {
            reason,
            q_auto: t.q_auto,
            q_auto_threshold: t.q_auto_threshold,
            q_auto_ar1,
            ar1,
            rms_over_noise,
            uncorrelated: t.uncorrelated,
        })
    };
    if t.white && !mean_off_zero {
        return explained("white", t.q_auto, ar1, rms_over_noise);
    }
    let t_w = data.residual_tests(&e_w, &ctx.w);
    let margin = data.s.select.margin_bic + nominal.delta_bic_disc;
    let unconfirmed = verdict::unconfirmed_extension(&outcome.ranking, outcome.chosen.as_ref(), margin);
    let within_noise = rms_over_noise.iter().all(|&r| r <= INCOMPLETE_NOISE_RATIO);
    let above_noise = rms_over_noise.iter().any(|&r| r > 1.0);
    let exempt =
        !mean_off_zero && (t_w.white || (within_noise && (t.uncorrelated || unconfirmed.is_none() || !above_noise)));
    if exempt && held_out.is_none() {
        return explained(if t_w.white { "noise_colour" } else { "within_noise" }, t_w.q_auto, ar1, rms_over_noise);
    }
    let contact = fitted.fit_sim.contact.iter().any(|&c| c).then_some(&fitted.fit_sim.contact[..]);
    let loc = crate::localise::localise(data.rec.t0, data.dt, &ctx.y, &e_fit, p, &ctx.w, data.m, contact, 10);
    Leftover::Missing(Remaining {
        q_auto: t.q_auto,
        q_auto_threshold: t.q_auto_threshold,
        q_auto_ar1: t_w.q_auto,
        ar1,
        rms_over_noise,
        uncorrelated: t.uncorrelated,
        uncorrelated_ar1: t_w.uncorrelated,
        mean_off_zero,
        unconfirmed_extension: unconfirmed,
        held_out_extension: held_out,
        windows: loc.windows,
        regimes: loc.regimes.into_iter().filter(|g| g.enriched).collect(),
    })
}

/// What the selection leaves standing.
struct Outcome {
    /// Nominal model on the validation segment.
    fit_before: Fit,
    ranking: Vec<Ranked>,
    /// The selected model (`None` too where a recorded input is missing from the model).
    chosen: Option<Ranked>,
    ties: Vec<String>,
    equivalents: Vec<select::Equivalent>,
    cv_rejected: Vec<(String, f64, String)>,
    missing_inputs: Vec<MissingInput>,
    initial_state: InitialStateReport,
}

/// The nominal model's validation fit, the recorded columns the model leaves out (an input
/// the model lacks is not physics to be stood in for by an effect: nothing is selected then),
/// and the initial state.
fn conclude(
    data: &Setup,
    pass: &Pass,
    nominal: &NominalFindings,
    selection: Selection,
    notes: &mut Vec<String>,
) -> Outcome {
    let (ctx, nom_sim) = (&pass.ctx, &nominal.nom_sim);
    let (p, k_est, n_samp) = (data.p, data.k_est, data.n_samp);
    let mut fit_before = metrics::fit(&ctx.y, &nom_sim.y, p, k_est, n_samp, data.dt);
    fit_before.tracking_fit_percent =
        metrics::tracking_fit(&ctx.y, &nom_sim.y, &ctx.w, (p, ctx.m), &data.sys.signals.reference, k_est, n_samp);
    let Selection { ranking, mut chosen, mut ties, cv_rejected, mut equivalents } = selection;
    let missing_inputs = missing_inputs(data, pass, nominal, &ranking);
    if missing_inputs.iter().any(|c| c.missing) {
        // An input the model leaves out is not physics to be stood in for by an effect.
        chosen = None;
        ties.clear();
        equivalents.clear();
    }
    let initial_state = initial_state(data, pass, chosen.is_none(), notes);
    Outcome { fit_before, ranking, chosen, ties, equivalents, cv_rejected, missing_inputs, initial_state }
}

/// Recorded columns the model does not use: does the residual follow one of them?
fn missing_inputs(data: &Setup, pass: &Pass, nominal: &NominalFindings, ranking: &[Ranked]) -> Vec<MissingInput> {
    let rec = data.rec;
    if nominal.nominal_adequate || rec.extra.is_empty() {
        return vec![];
    }
    let best = ranking
        .iter()
        .filter(|r| r.sse_estimation.is_finite())
        .min_by(|a, b| a.sse_estimation.total_cmp(&b.sse_estimation));
    let (best_share, best_label) = best
        .map(|r| ((1.0 - r.sse_estimation / pass.nom.sse.max(1e-300)).max(0.0), r.label.clone()))
        .unwrap_or((0.0, "none".into()));
    let ctx = &pass.ctx;
    rec.extra
        .iter()
        .filter_map(|(name, u)| {
            let share = missing_input::explained_share(
                data.sys,
                u,
                &nominal.e_nom,
                &ctx.weights,
                data.k_est,
                data.dt,
                ctx.substeps,
                pass.hold,
            )?;
            Some(MissingInput {
                column: name.clone(),
                explained: share,
                best_hypothesis_explained: best_share,
                best_hypothesis: best_label.clone(),
                missing: share >= MISSING_SHARE && share > best_share + MISSING_MARGIN,
            })
        })
        .collect()
}

/// The initial state used; with the model file's `x0`, how much freeing it would gain (a note
/// where that clears the margin and nothing was selected).
fn initial_state(data: &Setup, pass: &Pass, nothing_chosen: bool, notes: &mut Vec<String>) -> InitialStateReport {
    let nom = &pass.nom;
    if !data.x0_fixed {
        return InitialStateReport { source: "estimated", x0: nom.x0.clone(), delta_bic_free: None };
    }
    let bic_nom = select::bic(nom.sse, data.n_res, pass.ctx.x_scale.len());
    let free = data.fit_nominal(&data.context(pass.hold, pass.ctx.substeps, data.x_scale_free.clone()));
    let d = bic_nom - select::bic(free.sse, data.n_res, data.nx);
    if d > data.s.select.margin_bic && nothing_chosen {
        notes.push(format!(
            "The model file's initial state may not match the start of the recording: with the nominal model, estimating it would gain {d:.1} in BIC. Run with --estimate-x0 if the file's x0 is not the recorded machine's."
        ));
    }
    InitialStateReport { source: "model file", x0: nom.x0.clone(), delta_bic_free: Some(d) }
}

/// The report of the stages' results.
fn assemble(
    data: &Setup,
    pass: Pass,
    nominal: NominalFindings,
    outcome: Outcome,
    unc: Uncertainty,
    fitted: Fitted,
    headline: Headline,
    (verdict, leftover): (String, Leftover),
    notes: Vec<String>,
) -> Report {
    let (rec, n_samp, k_est) = (data.rec, data.n_samp, data.k_est);
    let loc = nominal.loc;
    let series = Series {
        t: (0..n_samp).map(|k| rec.time(k)).collect(),
        p: data.p,
        y: pass.ctx.y.clone(),
        yhat_nominal: nominal.nom_sim.y.clone(),
        yhat_fitted: fitted.fit_sim.y.clone(),
        energy: loc.energy.clone(),
    };
    Report {
        model: data.sys.name.clone(),
        recording: rec.source.clone(),
        samples: n_samp,
        dt: data.dt,
        resampled: rec.resampled,
        substeps: pass.ctx.substeps,
        hold: pass.hold_report,
        discretisation: pass.disc,
        discretisation_final: pass.disc_final,
        noise_level: data.noise.clone(),
        delta_bic_discretisation: nominal.delta_bic_disc,
        initial_state: outcome.initial_state,
        estimation_segment: [rec.time(0), rec.time(k_est - 1)],
        validation_segment: [rec.time(k_est), rec.time(n_samp - 1)],
        tau_slow: data.tau_slow,
        fit_before: outcome.fit_before,
        fit_after: fitted.fit_after,
        headline_metric: headline.metric,
        headline: headline.text,
        units: headline.units,
        nominal_refit: fitted.nominal_refit,
        free_parameters: data.free_nominal.as_ref().map(|f| f.names()).unwrap_or_default(),
        missing_inputs: outcome.missing_inputs,
        residual_nominal: nominal.residual_nominal,
        residual_fitted: fitted.residual_fitted,
        nominal_adequate: nominal.nominal_adequate,
        model_incomplete: matches!(leftover, Leftover::Missing(_)),
        residual_explained: leftover.explained().cloned(),
        remaining: match leftover {
            Leftover::Missing(r) => Some(r),
            _ => None,
        },
        verdict,
        effects: fitted.effects,
        uncertainty_method: unc.method,
        jackknife: unc.jack,
        ties: outcome.ties,
        equivalents: outcome.equivalents,
        windows: loc.windows,
        regimes: loc.regimes,
        velocity_windows: loc.velocity_windows,
        velocity_regimes: loc.velocity_regimes,
        localisation: LocalisationInfo { scales: loc.scales, null: loc.null },
        ranking: outcome.ranking,
        notes,
        screening: None,
        fitted_model: Some(fitted.system),
        series,
    }
}
