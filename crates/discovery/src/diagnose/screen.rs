//! Long records (issue 27 item 5): the hypotheses are screened on a leading part, and the
//! whole record judges only what the screening kept.
//!
//! The diagnosis costs time in proportion to the record's length times the hypotheses fitted
//! (every single, second effects, pairs, each with its cross-validation folds). On a record
//! longer than [`SCREEN_FACTOR`] times [`DiagnoseSettings::screen_samples`] (default
//! [`SCREEN_SAMPLES`]):
//! 1. the leading `screen_samples` samples are diagnosed in full (every hypothesis of the
//!    library);
//! 2. the whole record is diagnosed with the library narrowed to what that screening kept
//!    (`kept`): the parts of its selected model and their simpler forms, its ties and
//!    equivalent readings, and its best singles by BIC, each started from its screening fit.
//!    The whole record's nominal fit, residual tests, hold, sub-steps, selection,
//!    cross-validation, stepping check and uncertainty are computed as always, on every
//!    sample: every number reported is the whole record's;
//! 3. where the whole record says the narrowed model is incomplete and the screening's was not
//!    (something acts outside the leading part), the whole record is diagnosed again with the
//!    full library: the screening never hides what the record shows, it only spares work where
//!    the leading part already said it.
//!
//! The report's `screening` states which of these happened.
use super::settings::DiagnoseSettings;
use super::{Report, ScreenedHold, Selected};
use crate::select::NOMINAL_REFIT;
use crate::{DiscoveryError, Recording};
use model::System;
use serde::Serialize;

/// Records longer than [`SCREEN_FACTOR`] times this many samples are screened on their leading
/// part of this length (`DiagnoseSettings::screen_samples`; `0` never screens): as long as the
/// generator's longest ordinary cases, on which the diagnosis's accuracy is measured.
pub const SCREEN_SAMPLES: usize = 4_000;

/// Only records longer than this many times `screen_samples` are screened: below, the whole
/// record's diagnosis costs about as much as the screening saves.
pub const SCREEN_FACTOR: usize = 2;

/// The screening's best singles (by BIC, conclusive fits that beat the nominal's BIC) kept for
/// the whole record beside its selected model.
pub const SCREEN_BEST_SINGLES: usize = 1;

/// What the screening of a long record did (`report.json` `screening`).
#[derive(Debug, Clone, Serialize)]
pub struct Screening {
    /// Leading samples the library was screened on.
    pub samples: usize,
    /// The model the screening selected (`none`: nothing).
    pub selected: String,
    /// The hypotheses the whole record was diagnosed with.
    pub kept: Vec<String>,
    /// Whether the whole record was diagnosed again with the full library (it found the
    /// narrowed model incomplete where the screening's was not).
    pub full_library: bool,
}

/// The leading part of `rec` to screen on, where `rec` is longer than the settings allow
/// (`None`: diagnose as a whole).
pub(super) fn head(rec: &Recording, s: &DiagnoseSettings) -> Option<Recording> {
    let h = s.screen_samples;
    if h == 0 || rec.len() <= h.saturating_mul(SCREEN_FACTOR) || s.library.is_some() {
        return None;
    }
    Some(rec.leading(h))
}

/// The single hypotheses (labels) the whole record is diagnosed with after a screening that
/// reported `rep` and selected `sel`: the selected model's parts and their simpler forms, its
/// ties and equivalent readings, the best [`SCREEN_BEST_SINGLES`] singles by BIC. The grey-box
/// refit is always among the singles where the model frees parameters.
pub(super) fn kept(rep: &Report, sel: &Selected) -> Vec<String> {
    let mut keep: Vec<String> = Vec::new();
    let mut add = |l: &str| {
        let l = l.trim();
        if !l.is_empty() && l != NOMINAL_REFIT && !keep.iter().any(|k| k == l) {
            keep.push(l.to_string());
        }
    };
    if let Some(c) = &sel.chosen {
        for h in &c.parts {
            add(&h.kind.label());
            if let Some(simple) = h.kind.simpler_form() {
                add(&simple.label());
            }
        }
    }
    for l in rep.ties.iter().chain(rep.equivalents.iter().map(|e| &e.label)) {
        l.split(" + ").for_each(&mut add);
    }
    rep.ranking
        .iter()
        .filter(|r| r.parts.len() == 1 && !r.refit && r.status.conclusive() && r.delta_bic > 0.0)
        .take(SCREEN_BEST_SINGLES)
        .for_each(|r| add(&r.label));
    keep
}

/// [`super::diagnose_selected`] of a long record: screened on `head`, then judged whole.
/// `whole` diagnoses a recording under settings (the unscreened pipeline).
pub(super) fn diagnose_screened(
    sys: &System,
    rec: &Recording,
    head: &Recording,
    s: &DiagnoseSettings,
    whole: impl Fn(&System, &Recording, &DiagnoseSettings) -> Result<(Report, Selected), DiscoveryError>,
) -> Result<(Report, Selected), DiscoveryError> {
    // The leading part selects; the whole record checks the stepping and the uncertainty.
    let screening = DiagnoseSettings { finer_check: false, jackknife_iter: 0, ..s.clone() };
    let (head_rep, head_sel) = whole(sys, head, &screening)?;
    let keep = kept(&head_rep, &head_sel);
    let screened_hold = Some(ScreenedHold {
        hold: head_sel.hold,
        effect_delta_bic: head_rep.hold.effect_delta_bic,
        switched: head_rep.hold.switched,
    });
    let screened_singles = Some(head_rep.ranking.iter().filter(|r| r.parts.len() == 1 && !r.refit).cloned().collect());
    let narrowed = DiagnoseSettings { library: Some(keep.clone()), screened_hold, screened_singles, ..s.clone() };
    let (mut rep, mut sel) = whole(sys, rec, &narrowed)?;
    let h = head.len();
    let mut note = format!(
        "Record of {} samples: the hypotheses were screened on its first {h} (selected there: {}); the whole record was diagnosed with {} alone{}.",
        rec.len(),
        head_rep.selected(),
        if keep.is_empty() { "the nominal model".to_string() } else { keep.join(", ") },
        if rep.free_parameters.is_empty() { "" } else { " and the grey-box refit" },
    );
    let full_library = shows_more(&rep, &head_rep);
    if full_library {
        (rep, sel) = whole(sys, rec, s)?;
        note += " The whole record left that model incomplete where its first part did not: it was diagnosed again with every hypothesis.";
    } else {
        note += " `--screen-samples 0` diagnoses the whole record with every hypothesis.";
    }
    if rep.hold.switched && rep.hold.effect_delta_bic == head_rep.hold.effect_delta_bic && !full_library {
        note += &format!(
            " Input hold: the effects of the first part preferred {} over the nominal's choice (by {:.1} in BIC); the whole record was diagnosed with {}.",
            rep.hold.chosen,
            rep.hold.effect_delta_bic.unwrap_or(f64::NAN),
            rep.hold.chosen
        );
    }
    rep.notes.insert(0, note);
    rep.screening = Some(Screening { samples: h, selected: head_rep.selected(), kept: keep, full_library });
    Ok((rep, sel))
}

/// The whole record's misfit (RMS over the noise level, any output) must exceed the
/// screening's by this factor, where both call their model incomplete, for the whole library
/// to run again on the whole record.
pub const MORE_LEFT_RATIO: f64 = 1.5;

/// Whether the whole record (`whole`, narrowed to what the screening kept) leaves more than
/// the screening did (`head`): incomplete where the screening's model was complete, or, both
/// incomplete, a misfit [`MORE_LEFT_RATIO`] times the screening's (an effect acting mostly
/// after the leading part, beside one the screening named).
fn shows_more(whole: &Report, head: &Report) -> bool {
    let worst = |r: &Report| r.remaining.as_ref().map_or(0.0, |m| m.rms_over_noise.iter().copied().fold(0.0, f64::max));
    match (&whole.remaining, &head.remaining) {
        (None, _) => false,
        (Some(_), None) => true,
        (Some(_), Some(_)) => worst(whole) > MORE_LEFT_RATIO * worst(head),
    }
}
