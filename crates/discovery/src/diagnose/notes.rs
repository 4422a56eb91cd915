//! The report's notes that qualify the selection ([`selection`]: resampling, input hold,
//! discretisation, candidates rejected by cross-validation) and the fitted model ([`closing`]:
//! constant outputs, grey-box refit, saturated fit %, twins a recording cannot tell apart,
//! friction, input delay against hold). Notes of the stages themselves (hold switch, sub-step
//! rerun, initial state, replayed input, headline) are written where they arise.
use super::hold;
use super::pass::Pass;
use super::refit::Fitted;
use super::report::HoldReport;
use super::settings::HoldChoice;
use super::setup::Setup;
use super::Outcome;
use crate::discretisation::SubstepCheck;
use crate::hypothesis::{self, Kind};
use crate::metrics;
use crate::select::NOMINAL_REFIT;
use dynamics::extended::InputHold;

/// Notes on the data and the selection: resampled time stamps, the input hold, a
/// discretisation that did not converge, candidates that failed cross-validation.
pub(super) fn selection(
    data: &Setup,
    pass: &Pass,
    delta_bic_disc: f64,
    cv_rejected: &[(String, f64, String)],
    notes: &mut Vec<String>,
) {
    let rec = data.rec;
    if !rec.resampled && rec.rows_in_file > rec.len() {
        notes.push(format!("The last of the {} rows, a shorter final step off the uniform grid of dt = {:.6} s (the end of a thinned simulation), was left out.", rec.rows_in_file, data.dt));
    }
    if rec.resampled {
        notes.push(format!("Irregular time stamps ({} rows) were resampled by linear interpolation to a uniform grid of dt = {:.6} s ({} samples).", rec.rows_in_file, data.dt, data.n_samp));
    }
    notes.extend(hold::note(&pass.hold_report, pass.hold, data.s.select.tie_bic));
    let disc: &SubstepCheck = &pass.disc;
    if !disc.converged {
        notes.push(format!(
            "The simulation did not converge within {} sub-steps per sample (change {:.2e} against the tolerance {:.2e}): effects whose gain is within the remaining error ({:.1} in BIC) are not accepted.",
            data.max_sub,
            disc.ladder.last().map_or(f64::NAN, |l| l.1),
            disc.tolerance,
            delta_bic_disc
        ));
    }
    for (l, r, req) in cv_rejected {
        notes.push(format!(
            "{l} improves the estimation fit beyond the BIC margin but not the held-out folds (CV SSE ratio {r:.3}, {req} required): rejected."
        ));
    }
}

/// Notes on the fitted model (after the verdict).
pub(super) fn closing(
    data: &Setup,
    pass: &Pass,
    outcome: &Outcome,
    fitted: &Fitted,
    use_rmse: bool,
    notes: &mut Vec<String>,
) {
    let fit_before = &outcome.fit_before;
    if !fit_before.constant_outputs.is_empty() {
        notes.push(format!(
            "The measured output(s) {} are constant on the validation segment (standard deviation at most {} of the whole record's): fit % is undefined there (null in report.json) and the validation is judged by the RMSE and the validation SSE ratio instead.",
            fit_before.constant_outputs.iter().map(|i| format!("y{}", i + 1)).collect::<Vec<_>>().join(", "),
            metrics::TOL_CONSTANT
        ));
    }
    grey_box(data, outcome, fitted, notes);
    if fit_before.fit_percent.iter().flatten().any(|f| *f > 97.0) && !use_rmse {
        notes.push("Plain fit % is above 97 % (a tightly tracking loop saturates it): judge by the RMSE ratio (validation_ratio), the velocity fit and BIC instead.".into());
    }
    let (chosen, ties) = (outcome.chosen.as_ref(), &outcome.ties);
    let twin = matches!(
        chosen.and_then(|c| c.parts.first()).map(|h| h.kind),
        Some(Kind::ConstantForce { .. } | Kind::SensorOffset)
    ) || ties.iter().any(|t| t.starts_with("constant_force") || t.starts_with("sensor_offset"));
    if twin {
        if data.x0_fixed {
            notes.push("A constant force and a sensor offset are told apart here by the known initial state (the model file's x0): an offset shifts y(0) itself, a force only bends the trajectory after it.".into());
        } else {
            notes.push("A constant force b on state j and a sensor offset C F^{-1} e_j b are observationally equivalent when the initial state is free (the play is translation invariant): the recording cannot tell them apart; physics must (or a known x0 in the model file).".into());
        }
    }
    notes.extend(hypothesis::friction_notes(&fitted.effects_chosen, ties));
    if chosen.is_some_and(|c| c.parts.iter().any(|h| h.kind == Kind::InputDelay)) {
        notes.push(input_delay_note(data, pass.hold, &pass.hold_report, fitted));
    } else if pass.hold == InputHold::Zoh && pass.hold_report.requested == HoldChoice::Auto {
        // A zero-order hold chosen from the data may stand for a delay under the other hold:
        // a delay near h/2 of a continuous or interpolated command cannot be told from it.
        notes.push(format!(
            "The zero-order hold was chosen from the data, and it acts like a first-order hold delayed by h/2 = {:.3e} s: a continuous or linearly interpolated command delayed by about that much reads the same, and no delay is added here. If the plant sees such a command, run with --input-hold foh to read the delay.",
            0.5 * data.dt
        ));
    }
}

/// The model file's freed nominal parameters: refitted (and which are not identifiable) or
/// not selected.
fn grey_box(data: &Setup, outcome: &Outcome, fitted: &Fitted, notes: &mut Vec<String>) {
    let Some(free) = &data.free_nominal else { return };
    let nominal_refit = &fitted.nominal_refit;
    if nominal_refit.is_empty() {
        let r = outcome.ranking.iter().find(|r| r.refit && r.parts.is_empty());
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

/// An input delay trades off against the input hold: its value under the other hold.
fn input_delay_note(data: &Setup, hold: InputHold, hold_report: &HoldReport, fitted: &Fitted) -> String {
    format!(
        "An input delay trades off against the input hold: a zero-order hold acts like a first-order hold delayed by h/2 = {:.3e} s. The delay is reported for the {} hold; under the {} hold it is {} (effects[].other_hold).{}",
        0.5 * data.dt,
        hold.name(),
        if hold == InputHold::Zoh { "foh" } else { "zoh" },
        fitted.effects.iter().filter_map(|e| e.other_hold.as_ref()).map(|o| format!("{:.4e} s", o.1[0].1)).collect::<Vec<_>>().join(", "),
        match hold_report.delay_delta_bic {
            Some(_) if hold_report.delay_ambiguous => " The recording cannot tell the holds apart with this delay: its sigma covers both readings (see the note on the input hold and delay).".to_string(),
            Some(d) => format!(" The delay model fits the {} hold better by {:.1} in BIC.", if d > 0.0 { hold.name() } else if hold == InputHold::Zoh { "foh" } else { "zoh" }, d.abs()),
            None => String::new(),
        }
    )
}
