//! An effect the estimation segment cannot see: where the selection stops with the model
//! incomplete because a candidate acts only in the validation segment (its estimation fit is
//! stuck at zero gradient: a saturation limit that only the last commands exceed) yet cuts the
//! held-out error to at most [`crate::select::DECISIVE_HELD_OUT_RATIO`] of the final model's,
//! the recording is diagnosed again with an estimation segment of [`EXTENDED_FRACTION`] of the
//! record. Where that diagnosis selects the effect, its report stands, with a note: the
//! effect's parameter is then estimated from data where it acts, and the last part of the
//! record (and the cross-validation folds, as always) still judge it. Otherwise the first
//! report stands (it says that the model is incomplete and names the effect).
//!
//! Development seed mixed 11008 (input saturation cases 2 and 3): limits 0.785 and 2.679, the
//! commands beyond them at 76-88 % of the record only; both read as "none, incomplete" with
//! the held-out error cut to 0.109 and 0.071 by the stuck saturation.
use super::{DiagnoseSettings, Report, Selected};
use crate::{DiscoveryError, Recording};
use model::System;

/// The estimation segment's share of the record in the second diagnosis.
pub const EXTENDED_FRACTION: f64 = 0.9;

/// The candidate that acts only beyond the estimation segment, where the first report names
/// one: its label.
fn beyond_estimation(rep: &Report) -> Option<&str> {
    let (label, _) = rep.remaining.as_ref()?.held_out_extension.as_ref()?;
    let stuck = rep.ranking.iter().any(|r| &r.label == label && r.status == crate::fit::FitStatus::ZeroGradient);
    stuck.then_some(label.as_str())
}

/// `first` (the diagnosis under `s`), or the diagnosis with the estimation segment extended
/// where that selects the effect the first could not see (module docs). `diagnose` runs the
/// pipeline under settings.
pub(super) fn extended(
    sys: &System,
    rec: &Recording,
    s: &DiagnoseSettings,
    first: (Report, Selected),
    diagnose: impl Fn(&System, &Recording, &DiagnoseSettings) -> Result<(Report, Selected), DiscoveryError>,
) -> Result<(Report, Selected), DiscoveryError> {
    if !first.0.model_incomplete || s.estimation_fraction >= EXTENDED_FRACTION {
        return Ok(first);
    }
    let Some(label) = beyond_estimation(&first.0).map(str::to_string) else { return Ok(first) };
    let wider = DiagnoseSettings { estimation_fraction: EXTENDED_FRACTION, ..s.clone() };
    let (mut rep, sel) = diagnose(sys, rec, &wider)?;
    let selected = sel.chosen.as_ref().is_some_and(|c| c.label.split('+').any(|part| part.trim() == label));
    if !selected {
        return Ok(first);
    }
    rep.notes.insert(
        0,
        format!(
            "{label} acts only beyond the estimation segment (the first {:.0} % of the record: its fit there was stuck, yet it cut the held-out error to {:.3}): the record was diagnosed again with the first {:.0} % as the estimation segment, and {label} was selected there; the last {:.0} % and the cross-validation folds judge it.",
            100.0 * s.estimation_fraction,
            first.0.remaining.as_ref().and_then(|m| m.held_out_extension.as_ref()).map_or(f64::NAN, |h| h.1),
            100.0 * EXTENDED_FRACTION,
            100.0 * (1.0 - EXTENDED_FRACTION),
        ),
    );
    Ok((rep, sel))
}
