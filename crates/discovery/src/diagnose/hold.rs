//! The input hold between samples and the sub-steps per sample.
//!
//! First choice ([`first_choice`]): a requested hold stands; `auto` fits the nominal model
//! under both holds and takes the lower BIC (decisive at the tie margin). Sub-steps: doubled
//! from `h <= tau_fast / substep_ratio` until the simulated output changes by less than the
//! tolerance ([`crate::discretisation`]).
//!
//! Second look ([`overturned_by_effects`], `auto` only, once): the nominal's preference can be
//! an artefact of the missing effect, so the best few single effects are refitted under the
//! other hold; where one beats the best effect of this hold by the tie margin (by any margin
//! for an input delay, with which the hold is confounded), the hold is switched and the
//! diagnosis is redone.
use super::report::HoldReport;
use super::settings::HoldChoice;
use super::setup::Setup;
use crate::discretisation::SubstepCheck;
use crate::fit::{self, FitResult};
use crate::hypothesis::Kind;
use crate::select::{self, candidate, FitContext, Ranked};
use dynamics::extended::InputHold;

/// The hold (requested, or `auto` by the nominal fit), its report and the sub-steps under it.
pub(super) fn first_choice(data: &Setup) -> (InputHold, HoldReport, SubstepCheck) {
    let s = data.s;
    let first_hold = match s.input_hold {
        HoldChoice::Fixed(h) => h,
        HoldChoice::Auto => InputHold::Foh,
    };
    let mut disc = data.converge_nominal(first_hold, data.k0);
    let (hold, hold_report) = match s.input_hold {
        HoldChoice::Fixed(_) => (
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
            let fz = data.fit_nominal(&data.context(InputHold::Zoh, disc.substeps, data.x_scale.clone()));
            let ff = data.fit_nominal(&data.context(InputHold::Foh, disc.substeps, data.x_scale.clone()));
            let (bz, bf) = (select::bic(fz.sse, data.n_res, 0), select::bic(ff.sse, data.n_res, 0));
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
        disc = data.converge_nominal(hold, disc.substeps);
    }
    (hold, hold_report, disc)
}

/// Auto hold: do the best effects confirm the nominal's choice `hold`? The nominal's
/// preference can be an artefact of the missing effect. The best few singles (clearing the
/// BIC `margin`) are asked (a flexible wrong effect, e.g. a cogging force, can rank first under
/// the wrong hold and fit no better under the other). Asked once per diagnosis (until
/// `report.effect_delta_bic` is set), only where the nominal residual is not adequate.
///
/// Returns the other hold and the note that explains the switch where one of them fits better
/// under it (then `report` states the switch); `None` where the choice stands.
pub(super) fn overturned_by_effects(
    data: &Setup,
    ctx: &FitContext,
    nom: &FitResult,
    singles: &[Ranked],
    margin: f64,
    nominal_adequate: bool,
    hold: InputHold,
    report: &mut HoldReport,
) -> Option<(InputHold, String)> {
    let s = data.s;
    if !(s.input_hold == HoldChoice::Auto && report.effect_delta_bic.is_none() && !nominal_adequate) {
        return None;
    }
    let n_res = data.n_res;
    // Another hold must beat the best single of this one (not only the effect's own fit).
    let best_bic = singles.first().map_or(f64::INFINITY, |b| b.bic);
    let leading = singles.iter().filter(|c| candidate::nominal_scores(ctx, nom).0 - c.bic >= margin).take(3);
    for (i, c) in leading.enumerate() {
        let other = if hold == InputHold::Zoh { InputHold::Foh } else { InputHold::Zoh };
        let ctx_o = data.context(other, ctx.substeps, data.x_scale.clone());
        let fo = fit::FitSettings { max_iter: 10, ..s.fit.clone() };
        let r_o = fit::fit(&c.problem(&ctx_o), &c.x0, &ctx_o.x_scale, Some(&c.params), &fo);
        let d = select::bic(c.sse_estimation, n_res, 0) - select::bic(r_o.sse, n_res, 0) - (c.bic - best_bic);
        if i == 0 {
            report.effect_delta_bic = Some(d);
        }
        // With an input delay, hold and delay are confounded (a zero-order hold acts like
        // a first-order hold delayed by h/2): the nominal's preference says nothing and
        // the effect's comparison decides, by any margin.
        let has_delay = c.parts.iter().any(|h| {
            matches!(h.kind, Kind::InputDelay | Kind::InputOn { op: crate::fit::input_effects::InputOp::Delay, .. })
        });
        let threshold = if has_delay { 0.0 } else { s.select.tie_bic };
        if d > threshold {
            let note = format!(
                "Input hold: the nominal model preferred {} (by {:.1} in BIC), but {} fitted with {} beats the best effect with {} by {d:.1} in BIC: the missing effect had biased the nominal's choice; the diagnosis was redone with {}.",
                hold.name(),
                report.delta_bic.unwrap_or(0.0),
                c.label,
                other.name(),
                hold.name(),
                other.name()
            );
            report.effect_delta_bic = Some(d);
            report.chosen = other.name();
            report.switched = true;
            return Some((other, note));
        }
    }
    None
}

/// The note that states the hold and how it was chosen (none after a switch: its own note
/// says why).
pub(super) fn note(report: &HoldReport, hold: InputHold, tie_bic: f64) -> Option<String> {
    match (report.requested, report.decisive) {
        (HoldChoice::Auto, _) if report.switched => None,
        (HoldChoice::Auto, true) => Some(format!(
            "Input hold: {} (chosen from the data: the nominal model fits better by {:.1} in BIC than with {}).",
            hold.name(),
            report.delta_bic.unwrap_or(0.0),
            if hold == InputHold::Zoh { "foh" } else { "zoh" }
        )),
        (HoldChoice::Auto, false) => Some(format!(
            "Input hold: {} by a margin of {:.1} in BIC, below the tie margin {}: the recording does not tell zero- from first-order hold (sampling fast against the dynamics).",
            hold.name(),
            report.delta_bic.unwrap_or(0.0),
            tie_bic
        )),
        _ => Some(format!("Input hold: {} (as requested).", hold.name())),
    }
}
