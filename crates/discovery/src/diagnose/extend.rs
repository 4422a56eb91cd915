//! An effect the estimation segment cannot see. Where the selection leaves the model incomplete
//! and what is missing acts only after the estimation segment, the recording is diagnosed again
//! with an estimation segment of [`EXTENDED_FRACTION`] of the record. Two signs say so:
//! - a candidate whose estimation fit is stuck at zero gradient (it never acts there: a
//!   saturation limit that only the last commands exceed) cuts the held-out error to at most
//!   [`crate::select::DECISIVE_HELD_OUT_RATIO`] of the final model's; the second diagnosis must
//!   select that effect;
//! - the final residual's largest window (its energy share first) starts after the estimation
//!   segment; the second diagnosis must select an effect and leave nothing missing.
//!
//! Where it does, its report stands, with a note: the effect's parameter is then estimated from
//! data where it acts, and the last part of the record (and the cross-validation folds, as
//! always) still judge it. Otherwise the first report stands (it says that the model is
//! incomplete and where).
//!
//! Development seeds: mixed 11008, input saturation cases 2 and 3 (limits 0.785 and 2.679,
//! commands beyond them only at 76-88 % of the record), read as "none, incomplete" with the
//! held-out error cut to 0.109 and 0.071 by the stuck saturation; classic 11016, saturation
//! case 0 (limit 0.805), whose estimation fit converged to 0.564, a limit that made the held-out
//! fit worse, with 91 % of the residual energy at 76-88 % of the record.
use super::{DiagnoseSettings, Report, Selected};
use crate::{DiscoveryError, Recording};
use model::System;

/// The estimation segment's share of the record in the second diagnosis.
pub const EXTENDED_FRACTION: f64 = 0.9;

/// What says that the missing physics acts after the estimation segment.
enum Late {
    /// A candidate (label) stuck on the estimation segment that cuts the held-out error to the
    /// share given.
    Stuck(String, f64),
    /// The final residual's largest window, from and to (s).
    Window(f64, f64),
}

impl Late {
    /// The sign in `rep` (diagnosed under `s` on `rec`), if any.
    fn of(rep: &Report, rec: &Recording, s: &DiagnoseSettings) -> Option<Late> {
        let remaining = rep.remaining.as_ref()?;
        if let Some((label, share)) = &remaining.held_out_extension {
            let stuck =
                rep.ranking.iter().any(|r| &r.label == label && r.status == crate::fit::FitStatus::ZeroGradient);
            if stuck {
                return Some(Late::Stuck(label.clone(), *share));
            }
        }
        let k_est = s.estimation_samples(rec.len());
        let w = remaining.windows.first()?;
        (k_est < rec.len() && w.t_start >= rec.time(k_est)).then_some(Late::Window(w.t_start, w.t_end))
    }

    /// Whether the second diagnosis found what the sign pointed to.
    fn found(&self, rep: &Report, sel: &Selected) -> bool {
        match self {
            Late::Stuck(label, _) => {
                sel.chosen.as_ref().is_some_and(|c| c.parts.iter().any(|h| &h.kind.label() == label))
            }
            Late::Window(..) => sel.chosen.is_some() && !rep.model_incomplete,
        }
    }

    /// The first words of the note.
    fn why(&self, fraction: f64) -> String {
        let seg = format!("the first {:.0} % of the record", 100.0 * fraction);
        match self {
            Late::Stuck(label, share) => format!(
                "{label} acts only beyond the estimation segment ({seg}: its fit there was stuck, yet it cut the held-out error to {share:.3})"
            ),
            Late::Window(a, b) => format!(
                "What the model left concentrates after the estimation segment ({seg}), at t = {a:.3}-{b:.3} s"
            ),
        }
    }
}

/// `first` (the diagnosis under `s`), or the diagnosis with the estimation segment extended
/// where that finds what the first could not see (module docs). `diagnose` runs the pipeline
/// under settings.
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
    let Some(late) = Late::of(&first.0, rec, s) else { return Ok(first) };
    let wider = DiagnoseSettings { estimation_fraction: EXTENDED_FRACTION, ..s.clone() };
    let (mut rep, sel) = diagnose(sys, rec, &wider)?;
    if !late.found(&rep, &sel) {
        return Ok(first);
    }
    rep.notes.insert(
        0,
        format!(
            "{}: the record was diagnosed again with the first {:.0} % as the estimation segment, which selected {}; the last {:.0} % and the cross-validation folds judge it.",
            late.why(s.estimation_fraction),
            100.0 * EXTENDED_FRACTION,
            rep.selected(),
            100.0 * (1.0 - EXTENDED_FRACTION),
        ),
    );
    Ok((rep, sel))
}
