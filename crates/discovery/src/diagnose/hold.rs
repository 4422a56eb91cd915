//! The input hold between samples and the sub-steps per sample.
//!
//! First choice ([`first_choice`]): a requested hold stands; `auto` fits the nominal model
//! under both holds and takes the lower BIC (decisive at the tie margin). Sub-steps: doubled
//! from `h <= tau_fast / substep_ratio` until the simulated output changes by less than the
//! tolerance ([`crate::discretisation`]).
//!
//! Second look ([`overturned_by_effects`], `auto` only, once): the nominal's preference can be
//! an artefact of the missing effect, so the best few single effects are refitted under the
//! other hold; where one beats the best effect of this hold by the tie margin (an input
//! delay too), the hold is switched and the diagnosis is redone. Once the selection has
//! settled ([`selected_model_prefers_other`], once), its model is refitted under the other
//! hold; where it fits better there, the hold is switched (a switch by the effects undone) and
//! the diagnosis redone. Where it does not, the ranking's readings that can still ask for the
//! other hold are refitted under it ([`ranking_prefers_other`]): a delay stopped at its bound
//! under the zero-order hold, and the best rivals of a model of two effects.
//!
//! Delay under an unknown hold ([`delay_under_both_holds`], `auto` only): a selected input
//! delay is refitted under the other hold; where the two fits differ by less than the tie
//! margin the recording cannot tell "zero-order hold + tau" from "first-order hold + tau +
//! h/2", and the delay's 1-sigma is widened by the distance between the two readings (so that
//! its 1-sigma interval reaches the other reading, and its 2-sigma interval that reading's own
//! 2-sigma: the truth lies at either reading, and half the distance left it at 1.4-1.95 sigma
//! from the one reported whenever it lay at the other, BENCHMARKS "Issue 27 on seeds
//! 10966-10980").
use super::report::HoldReport;
use super::settings::HoldChoice;
use super::setup::Setup;
use crate::discretisation::SubstepCheck;
use crate::fit::input_effects::InputOp;
use crate::fit::{self, FitResult};
use crate::hypothesis::Kind;
use crate::select::{self, candidate, FitContext, Ranked};
use dynamics::extended::InputHold;

/// The hold (requested, or `auto` by the nominal fit), its report and the sub-steps under it;
/// with `auto`, the nominal fits it compared `(hold, sub-steps, fit)` (the pass reuses the one
/// of its own hold and sub-steps instead of fitting it again).
pub(super) fn first_choice(data: &Setup) -> (InputHold, HoldReport, SubstepCheck, Vec<(InputHold, usize, FitResult)>) {
    let s = data.s;
    let first_hold = match s.input_hold {
        HoldChoice::Fixed(h) => h,
        HoldChoice::Auto => InputHold::Foh,
    };
    let mut disc = data.converge_nominal(first_hold, data.k0);
    let mut fits = Vec::new();
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
                effects_undecided: false,
                delay_delta_bic: None,
                delay_other_hold: vec![],
                delay_ambiguous: false,
            },
        ),
        HoldChoice::Auto => {
            let fit_under = |h: InputHold| data.fit_nominal(&data.context(h, disc.substeps, data.x_scale.clone()));
            let (fz, ff) = if s.parallel {
                rayon::join(|| fit_under(InputHold::Zoh), || fit_under(InputHold::Foh))
            } else {
                (fit_under(InputHold::Zoh), fit_under(InputHold::Foh))
            };
            let (bz, bf) = (select::bic(fz.sse, data.n_res, 0), select::bic(ff.sse, data.n_res, 0));
            let preferred = if bz < bf { InputHold::Zoh } else { InputHold::Foh };
            let d = (bz - bf).abs();
            let (sse_zoh, sse_foh) = (fz.sse, ff.sse);
            fits = vec![(InputHold::Zoh, disc.substeps, fz), (InputHold::Foh, disc.substeps, ff)];
            let (hold, effect_delta_bic, switched) = second_look_of_screening(s.screened_hold, preferred);
            (
                hold,
                HoldReport {
                    requested: HoldChoice::Auto,
                    chosen: hold.name(),
                    sse_zoh: Some(sse_zoh),
                    sse_foh: Some(sse_foh),
                    delta_bic: Some(d),
                    decisive: d >= s.select.tie_bic,
                    effect_delta_bic,
                    switched,
                    effects_undecided: false,
                    delay_delta_bic: None,
                    delay_other_hold: vec![],
                    delay_ambiguous: false,
                },
            )
        }
    };
    if hold != first_hold {
        disc = data.converge_nominal(hold, disc.substeps);
    }
    (hold, hold_report, disc, fits)
}

/// The hold of a long record diagnosed whole after its screening ([`super::screen`]): the
/// screening's second look ([`overturned_by_effects`]) stands for the whole record where the
/// whole record's nominal prefers (`preferred`) the hold the screening's nominal did. Returns
/// the hold, the effects' BIC preference and whether the hold was switched by them;
/// `(preferred, None, false)`: the second look is taken on the whole record.
fn second_look_of_screening(screened: Option<ScreenedHold>, preferred: InputHold) -> (InputHold, Option<f64>, bool) {
    match screened {
        Some(h) if h.switched && other_hold(h.hold) == preferred => (h.hold, h.effect_delta_bic, true),
        Some(h) if !h.switched && h.hold == preferred && h.effect_delta_bic.is_some() => {
            (preferred, h.effect_delta_bic, false)
        }
        _ => (preferred, None, false),
    }
}

/// What a screening's hold choice found ([`super::screen`]; `DiagnoseSettings::screened_hold`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScreenedHold {
    /// The hold the screening settled on.
    pub hold: InputHold,
    /// Its effects' BIC preference for it (the second look), where taken.
    pub effect_delta_bic: Option<f64>,
    /// Whether the effects switched it from the nominal's preference.
    pub switched: bool,
}

/// Auto hold: do the best effects confirm the nominal's choice `hold`? The nominal's
/// preference can be an artefact of the missing effect. The best few singles (clearing the
/// BIC `margin`) are asked (a flexible wrong effect, e.g. a cogging force, can rank first under
/// the wrong hold and fit no better under the other), and the input delay wherever it ranks
/// (started h/2 later or earlier). Asked once per diagnosis (until
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
    let bic_nom = candidate::nominal_scores(ctx, nom).0;
    let mut leading: Vec<&Ranked> = singles.iter().filter(|c| bic_nom - c.bic >= margin).take(3).collect();
    let n_leading = leading.len();
    // The input delay too, wherever it ranks: hold and delay trade off, so under this hold a
    // delay that the other hold reads as tau may need a negative one (a first-order-held
    // input delayed by less than h/2 read under a zero-order hold) and rank nowhere.
    if let Some(d) = singles.iter().find(|c| has_delay(c)) {
        if !leading.iter().any(|c| std::ptr::eq(*c, d)) {
            leading.push(d);
        }
    }
    let other = other_hold(hold);
    for (i, c) in leading.into_iter().enumerate() {
        let fo = fit::FitSettings { max_iter: 10, ..s.fit.clone() };
        let (ctx_o, r_o) = refit_under_other_hold(data, c, hold, ctx.substeps, data.x_scale.clone(), &fo);
        let d = select::bic(c.sse_estimation, n_res, 0) - select::bic(r_o.sse, n_res, 0) - (c.bic - best_bic);
        if i == 0 {
            report.effect_delta_bic = Some(d);
        }
        // Under the other hold it must also clear the selection margin against this hold's
        // nominal (automatic for the leading effects, which clear it here; the delay asked
        // wherever it ranks must earn it: on a zero-order-held recording with nothing missing,
        // "first-order hold + h/2" can beat the best effect, the nominal itself, by a few BIC).
        let bic_o = bic_under_other_hold(c, r_o.sse, n_res);
        if bic_nom - bic_o < margin {
            continue;
        }
        // The delay asked beyond the leading effects overturns a decisive nominal choice on its
        // own: its evidence is counted for the colour of its residual, (1 - rho)/(1 + rho)
        // independent samples per sample (AR(1) 0.57 noise on a zero-order-held recording
        // with nothing missing: first-order hold + h/2 beat it by 11.8, 3.2 once deflated).
        if i >= n_leading {
            let deflate = colour_deflation(&c.problem(&ctx_o), &r_o);
            if d * deflate <= s.select.tie_bic || (bic_nom - bic_o) * deflate < margin {
                continue;
            }
        }
        // The tie margin for every effect, an input delay included: with a delay, hold and
        // delay are confounded (a zero-order hold acts like a first-order hold delayed by
        // h/2) and the two fits differ by a fraction of a BIC unit; switching on that would
        // override the nominal's preference on noise (issue 27 item 1). Where the delay
        // cannot tell the holds apart, [`delay_under_both_holds`] widens its interval.
        if d > s.select.tie_bic {
            let note = format!(
                "Input hold: the nominal model preferred {} (by {:.1} in BIC), but {} fitted with {} beats the best effect with {} by {d:.1} in BIC: the missing effect had biased the nominal's choice; the diagnosis was redone with {}.",
                hold.name(),
                report.delta_bic.unwrap_or(0.0),
                c.label,
                other.name(),
                hold.name(),
                other.name()
            );
            report.switch_to(other, d);
            return Some((other, note));
        }
    }
    None
}

/// Auto hold, once the selection has settled (once per diagnosis): the selected model refitted
/// under the other hold. Where it fits better there by more than the tie margin, the hold is
/// switched to it and the diagnosis redone, the effects not asked again. Returns that hold and
/// the note that says why.
///
/// - After a switch by the effects ([`overturned_by_effects`]) this undoes it: a single effect
///   that misses a second one can prefer the wrong hold. Fresh pairs seed 10721 (digital)
///   `coulomb_friction + backlash_inertia` #1, a zero-order-held recording, was switched to
///   the first-order hold by a single that fitted 315.9 better there; under it the selection
///   settled on backlash inertia + load-dependent friction, 355 in BIC worse than the true pair
///   under the zero-order hold.
/// - Without a switch the nominal's choice can be the missing effects' artefact that no single
///   overturns: development pairs seed 10726 (digital) `constant_force + backlash_inertia` #0,
///   zero-order held; the nominal preferred the first-order hold by 89.2, no single fitted
///   better under the other, and the pair selected under it left a residual Q of 2684
///   (30 under the zero-order hold).
///
/// A model with an input delay is left to [`delay_under_both_holds`]: delay and hold trade off
/// (its interval covers both readings where they tie once the residual's colour is counted).
/// A long record diagnosed whole after its screening keeps the hold the screening's selected
/// model was asked about (the refit on 50,000 samples cost 0.5 s of the record's 7.3 s).
pub(super) fn selected_model_prefers_other(
    data: &Setup,
    ctx: &FitContext,
    chosen: Option<&Ranked>,
    hold: InputHold,
    report: &mut HoldReport,
) -> Option<(InputHold, String)> {
    let c = chosen?;
    let s = data.s;
    if s.input_hold != HoldChoice::Auto || s.screened_hold.is_some() || (!report.switched && has_delay(c)) {
        return None;
    }
    let other = other_hold(hold);
    let (_, r_o) = refit_under_other_hold(data, c, hold, ctx.substeps, data.x_scale.clone(), &s.fit);
    // `BIC(this hold) - BIC(the other hold)`, the same parameters
    let d = select::bic(c.sse_estimation, data.n_res, 0) - select::bic(r_o.sse, data.n_res, 0);
    if !(d > s.select.tie_bic) {
        return None;
    }
    let note = if report.switched {
        format!(
            "Input hold: the effects had switched it to {} (one fitted better there by {:.1} in BIC), but the model selected under {} ({}) fits better with {} by {d:.1}: the switch was undone and the diagnosis redone with {}.",
            hold.name(),
            report.effect_delta_bic.unwrap_or(f64::NAN),
            hold.name(),
            c.label,
            other.name(),
            other.name()
        )
    } else {
        format!(
            "Input hold: the nominal model preferred {} (by {:.1} in BIC), but the model selected under it ({}) fits better with {} by {d:.1}: the missing effects had biased the nominal's choice; the diagnosis was redone with {}.",
            hold.name(),
            report.delta_bic.unwrap_or(f64::NAN),
            c.label,
            other.name(),
            other.name()
        )
    };
    report.switch_to(other, -d);
    Some((other, note))
}

/// A delay read under the zero-order hold at its lower bound: at most this share of the
/// sample interval (a first-order-held command delayed by less than h/2 needs a negative delay
/// there, and its fit stops at 0).
pub const DELAY_AT_BOUND_SHARE: f64 = 1e-3;

/// Auto hold, zero-order, once the selection has settled without a delay (once per diagnosis,
/// beside [`selected_model_prefers_other`]): the best model of `ranking` whose input delay
/// stopped at 0 is refitted under the first-order hold. Under the zero-order hold a
/// first-order-held command delayed by less than h/2 needs a negative delay, so that model
/// ranks below what absorbs the lag otherwise, and no single asks for the other hold where a
/// larger effect comes first. Fresh pairs seed 10914 (mixed) `input_delay + sensor_offset` #1,
/// a delay of 6.3 ms at 15.1 ms sampling: the nominal preferred the zero-order hold by 124.4,
/// sensor offset + input delay read the delay as 0 there (+2188.5), and sensor offset +
/// backlash inertia was selected (+2293.5).
///
/// Asked only where the zero-order hold is the nominal's choice that no effect overturned.
///
/// Where that model fits better under the first-order hold than the selected model does under
/// the zero-order one by more than the tie margin, its residual's colour counted
/// ([`colour_deflation`]), the hold is switched and the diagnosis redone; that model is
/// returned to be carried (it stands only where it beats the redone selection by the margin
/// and passes its cross-validation, `select::forward::adopt_carried`).
fn delay_at_bound_prefers_other(q: &Question, report: &mut HoldReport) -> Option<(InputHold, String, Ranked)> {
    let Question { data, ranking, c, hold, .. } = *q;
    let s = data.s;
    // After a switch by the effects ([`overturned_by_effects`], which asked the delay too) the
    // zero-order hold was chosen over the first-order one with the effects in: fresh singles
    // seed 10923 (mixed) `asymmetric_coulomb` #3, zero-order held, went back to the first-order
    // hold with a delay of 0.92 h/2 (the zero-order hold's equivalent) without that guard.
    if hold != InputHold::Zoh || report.switched {
        return None;
    }
    let at_bound = |r: &Ranked| {
        let at = delay_offsets(r);
        !at.is_empty() && at.iter().all(|&i| r.params.get(i).is_some_and(|&d| d <= DELAY_AT_BOUND_SHARE * data.dt))
    };
    let r = ranking.iter().filter(|r| at_bound(r)).min_by(|a, b| a.bic.total_cmp(&b.bic))?;
    let d = q.gain_under_other_hold(r)?;
    if !(d > s.select.tie_bic) {
        return None;
    }
    let other = other_hold(hold);
    let note = format!(
        "Input hold: the nominal model preferred {} (by {:.1} in BIC), where {} reads its delay as 0 (a first-order-held command delayed by less than h/2 needs a negative one there); with {} it fits better than the model selected under {} ({}) by {d:.1} (counted for its residual's colour): the diagnosis was redone with {}.",
        hold.name(),
        report.delta_bic.unwrap_or(f64::NAN),
        r.label,
        other.name(),
        hold.name(),
        c.label,
        other.name()
    );
    report.switch_to(other, -d);
    Some((other, note, r.clone()))
}

/// How many rivals of a selected model of several effects [`rival_prefers_other`] refits
/// under the other hold. On its development case the true pair ranked sixth among them (the
/// first three did not switch the hold); each refit costs one pair fit (whole pair benchmark
/// runs took 0-7 % longer).
pub const HOLD_RIVALS: usize = 8;

/// Auto hold, once the selection has settled on several effects without a delay, where
/// neither [`selected_model_prefers_other`] nor [`delay_at_bound_prefers_other`] asked for
/// the other hold (once per diagnosis): the best [`HOLD_RIVALS`] models of `ranking` with as
/// many effects as the selected one, sharing one of its effects and without a delay, are
/// refitted under the other hold. With two effects missing the nominal's choice of hold can be
/// wrong, no single effect overturns it, and under the wrong hold the second effect's fit
/// finds a stand-in that the selected model keeps when refitted. Fresh pairs seed 11035
/// (mixed) `backlash_inertia + input_saturation` #0, the command zero-order held: the nominal
/// preferred the first-order hold by 66.8, the saturation fitted 475.8 worse under the other
/// hold, and input saturation + cogging was selected under it, a model that predicted the
/// machine's next recording 2.3 times worse than the nominal (BENCHMARKS "The machine's next
/// experiment").
///
/// Where a rival fits better under the other hold than the selected model under this one by
/// more than the tie margin, its residual's colour counted ([`colour_deflation`]), the hold is
/// switched and the diagnosis redone, and the rival is returned to be carried (as for
/// [`delay_at_bound_prefers_other`]).
fn rival_prefers_other(q: &Question, report: &mut HoldReport) -> Option<(InputHold, String, Ranked)> {
    let Question { ranking, c, hold, .. } = *q;
    if c.parts.len() < 2 {
        return None;
    }
    let mut rivals: Vec<&Ranked> = ranking
        .iter()
        .filter(|r| {
            r.label != c.label
                && !r.refit
                && r.parts.len() == c.parts.len()
                && !has_delay(r)
                && r.kinds.iter().any(|k| c.kinds.contains(k))
                && r.bic.is_finite()
        })
        .collect();
    rivals.sort_by(|a, b| a.bic.total_cmp(&b.bic));
    let (r, d) = rivals
        .into_iter()
        .take(HOLD_RIVALS)
        .filter_map(|r| q.gain_under_other_hold(r).map(|d| (r, d)))
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    if !(d > q.data.s.select.tie_bic) {
        return None;
    }
    let other = other_hold(hold);
    let note = format!(
        "Input hold: the model selected under {} ({}) does not fit better with {}, but {} does, by {d:.1} in BIC against it (counted for its residual's colour): with two effects missing, the nominal's choice of hold can be wrong; the diagnosis was redone with {}.",
        hold.name(),
        c.label,
        other.name(),
        r.label,
        other.name()
    );
    report.switch_to(other, -d);
    Some((other, note, r.clone()))
}

/// Whether an `auto` hold the nominal chose decisively, and the effects did not switch, is
/// left undecided by the best effect: it fits both holds within `tie_bic`
/// ([`HoldReport::effects_undecided`]). Not where the selected model has an input delay
/// (`delay_selected`: [`delay_under_both_holds`] reads it under both holds and states the
/// case, with the delay's interval).
pub(super) fn effects_undecided(report: &HoldReport, delay_selected: bool, tie_bic: f64) -> bool {
    report.requested == HoldChoice::Auto
        && report.decisive
        && !report.switched
        && !delay_selected
        && report.effect_delta_bic.is_some_and(|d| d.abs() <= tie_bic)
}

/// Whether model `c` has an input delay (on the input, or on one input of several).
pub(super) fn has_delay(c: &Ranked) -> bool {
    !delay_offsets(c).is_empty()
}

/// The note that states the hold and how it was chosen (none after a switch: its own note
/// says why).
pub(super) fn note(report: &HoldReport, hold: InputHold, tie_bic: f64) -> Option<String> {
    match (report.requested, report.decisive) {
        (HoldChoice::Auto, _) if report.switched => None,
        (HoldChoice::Auto, true) if report.effects_undecided => {
            let other = other_hold(hold).name();
            Some(format!(
                "Input hold: {} (chosen from the data: the nominal model fits better by {:.1} in BIC than with {other}). The best effect, refitted with {other}, fits as well ({:+.1} in BIC, within the tie margin {tie_bic}): the nominal's preference may have come from the missing effect, and the recording does not confirm the hold. Where the sampled command is continuous or interpolated, run with --input-hold {other} and compare.",
                hold.name(),
                report.delta_bic.unwrap_or(0.0),
                report.effect_delta_bic.unwrap_or(f64::NAN)
            ))
        }
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

/// `(1 - rho)/(1 + rho)` for the lag-one autocorrelation `rho` of the fit `r`'s residual on
/// the estimation segment (the largest over the outputs; 1 where it cannot be simulated): the
/// share of independent samples that BIC differences should be counted with.
fn colour_deflation(pb: &fit::Problem, r: &FitResult) -> f64 {
    crate::residual::independent_share(pb.estimation_residual_rho(&r.theta, &r.nominal, &r.x0).unwrap_or(0.0))
}

/// What the ranking's other readings are asked against ([`ranking_prefers_other`]): the
/// selected model `c` of `ranking`, fitted under `hold` in `ctx`.
#[derive(Clone, Copy)]
struct Question<'q, 'd> {
    data: &'q Setup<'d>,
    ctx: &'q FitContext<'d>,
    ranking: &'q [Ranked],
    c: &'q Ranked,
    hold: InputHold,
}

impl Question<'_, '_> {
    /// `r` (of the ranking) refitted under the other hold: how much lower its BIC is there than
    /// the selected model's under `hold`, counted for its residual's colour
    /// ([`colour_deflation`]); `None` where the refit fails.
    fn gain_under_other_hold(&self, r: &Ranked) -> Option<f64> {
        let (data, hold) = (self.data, self.hold);
        let (ctx_o, r_o) = refit_under_other_hold(data, r, hold, self.ctx.substeps, data.x_scale.clone(), &data.s.fit);
        if r_o.status == fit::FitStatus::Failed || !r_o.sse.is_finite() {
            return None;
        }
        Some((self.c.bic - bic_under_other_hold(r, r_o.sse, data.n_res)) * colour_deflation(&r.problem(&ctx_o), &r_o))
    }
}

/// Once the selection has settled without a delay, and the selected model did not ask for the
/// other hold ([`selected_model_prefers_other`]; `auto` hold only, once per diagnosis): the
/// ranking's other readings that can, a delay stopped at its bound
/// ([`delay_at_bound_prefers_other`]) or a rival of a model of several effects
/// ([`rival_prefers_other`]). The hold to switch to, the note, and the reading to carry.
pub(super) fn ranking_prefers_other(
    data: &Setup,
    ctx: &FitContext,
    ranking: &[Ranked],
    chosen: Option<&Ranked>,
    hold: InputHold,
    report: &mut HoldReport,
) -> Option<(InputHold, String, Ranked)> {
    let c = chosen?;
    let asked = data.s.input_hold == HoldChoice::Auto && data.s.screened_hold.is_none();
    if !asked || has_delay(c) {
        return None;
    }
    let q = Question { data, ctx, ranking, c, hold };
    delay_at_bound_prefers_other(&q, report).or_else(|| rival_prefers_other(&q, report))
}

/// BIC of the fitted model `c` refitted under the other hold to the estimation SSE `sse_other`
/// (the same parameter count: only the likelihood term changes).
fn bic_under_other_hold(c: &Ranked, sse_other: f64, n_res: usize) -> f64 {
    c.bic - select::bic(c.sse_estimation, n_res, 0) + select::bic(sse_other, n_res, 0)
}

/// The hold that is not `hold`.
fn other_hold(hold: InputHold) -> InputHold {
    if hold == InputHold::Zoh {
        InputHold::Foh
    } else {
        InputHold::Zoh
    }
}

/// Fitted model `c` (of `hold`) refitted under the other hold at `substeps` sub-steps, from
/// its estimate with its delays shifted by the half sample the holds differ by
/// ([`delay_shifted_start`]): the other hold's fit context and the fit.
fn refit_under_other_hold<'d>(
    data: &'d Setup,
    c: &Ranked,
    hold: InputHold,
    substeps: usize,
    x_scale: Vec<f64>,
    fs: &fit::FitSettings,
) -> (FitContext<'d>, FitResult) {
    let ctx_o = data.context(other_hold(hold), substeps, x_scale);
    let r_o = fit::fit(&c.problem(&ctx_o), &c.x0, &ctx_o.x_scale, Some(&delay_shifted_start(c, hold, data.dt)), fs);
    (ctx_o, r_o)
}

/// The parameters of `c` (fitted under `hold`) as a start under the other hold: its delays
/// moved by the h/2 that a zero-order hold adds to a first-order one (`+h/2` from zoh to foh),
/// not below 0.
fn delay_shifted_start(c: &Ranked, hold: InputHold, dt: f64) -> Vec<f64> {
    let shift = if hold == InputHold::Zoh { 0.5 * dt } else { -0.5 * dt };
    let mut start = c.params.clone();
    for i in delay_offsets(c) {
        start[i] = (start[i] + shift).max(0.0);
    }
    start
}

/// A fit of one pass (under `hold`) as a warm start of the next pass under the other hold: its
/// delays moved by the half sample the holds differ by ([`delay_shifted_start`]). A hold change
/// moves every other optimum a little, but a delay by h/2: carried over as it was, a
/// first-order-held delay read as 0 under the zero-order hold (clipped there) starts the next
/// pass at 0, where its fit does not move (fresh seed 10801 `input_delay` #1, mixed: the delay
/// 1.4 ms, read as 0 under the first-order hold, and nothing selected).
pub(super) fn moved_to_other_hold(c: Ranked, hold: InputHold, dt: f64) -> Ranked {
    Ranked { params: delay_shifted_start(&c, hold, dt), ..c }
}

/// Offsets of the delay parameters of `c` (a delay of the input as a whole or of one input).
fn delay_offsets(c: &Ranked) -> Vec<usize> {
    let mut off = 0;
    let mut at = Vec::new();
    for h in &c.parts {
        if matches!(h.kind, Kind::InputDelay | Kind::InputOn { op: InputOp::Delay, .. }) {
            at.push(off);
        }
        off += h.k();
    }
    at
}

/// Auto hold and a selected input delay: the selected model refitted under the other hold
/// (its delays started shifted by -+h/2). Records `BIC(other) - BIC(this)` in
/// `report.delay_delta_bic` and the other reading of each delay in `report.delay_other_hold`;
/// where the difference, counted for the colour of the selected model's residual
/// (`(1 - rho)/(1 + rho)` independent samples per sample), is within the tie margin
/// (`report.delay_ambiguous`) the delays'
/// 1-sigma in `chosen.std` grows by the distance between the readings, and the note
/// that says so is returned. Call after the uncertainty is combined (it widens the final
/// sigma).
pub(super) fn delay_under_both_holds(
    data: &Setup,
    ctx: &FitContext,
    hold: InputHold,
    chosen: Option<&mut Ranked>,
    report: &mut HoldReport,
) -> Option<String> {
    let s = data.s;
    let c = chosen?;
    if s.input_hold != HoldChoice::Auto {
        return None;
    }
    let at = delay_offsets(c);
    if at.is_empty() {
        return None;
    }
    let other = other_hold(hold);
    let (_, r_o) = refit_under_other_hold(data, c, hold, ctx.substeps, ctx.x_scale.clone(), &s.fit);
    let d = select::bic(r_o.sse, data.n_res, 0) - select::bic(c.sse_estimation, data.n_res, 0);
    report.delay_delta_bic = Some(d);
    report.delay_other_hold = at.iter().map(|&i| r_o.theta.get(i).copied().unwrap_or(f64::NAN)).collect();
    // Counted for the colour of the selected model's residual, as the hold's own evidence
    // above: fresh seed 10601 `input_delay` #1 (continuous input, AR(1) 0.68 noise) fitted the
    // zero-order hold better by 7.4 in BIC, 1.4 independent-sample units, and its zero-order
    // reading (0.19 ms +- 0.03) lay 20 sigma from the delay of the continuous input (0.74 ms),
    // which the first-order reading (0.73 ms) matched.
    let d_counted = d * crate::residual::independent_share(c.residual_rho(ctx));
    if !(d_counted.is_finite() && d_counted.abs() < s.select.tie_bic) {
        return None;
    }
    report.delay_ambiguous = true;
    let mut widened = Vec::new();
    for (j, &i) in at.iter().enumerate() {
        let gap = (report.delay_other_hold[j] - c.params[i]).abs();
        if gap.is_finite() {
            c.std[i] += gap;
            widened.push(format!(
                "{:.4e} s (this hold) and {:.4e} s ({})",
                c.params[i],
                report.delay_other_hold[j],
                other.name()
            ));
        }
    }
    Some(format!(
        "Input hold and delay: the delay model fits the {} and the {} hold alike ({:+.1} in BIC, {:+.1} counted for the residual's colour, within the tie margin {}): the recording cannot tell which hold the plant saw, and the delay reads {}. Its reported 1-sigma is widened by the distance between the readings, so that +-1 sigma reaches both; use --input-hold if the hold is known.",
        hold.name(),
        other.name(),
        d,
        d_counted,
        s.select.tie_bic,
        widened.join("; ")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_decisive_hold_the_best_effect_fits_alike_is_undecided() {
        let kept = HoldReport {
            requested: HoldChoice::Auto,
            chosen: "zoh",
            sse_zoh: Some(6.1),
            sse_foh: Some(7.4),
            delta_bic: Some(254.7),
            decisive: true,
            effect_delta_bic: Some(0.8),
            switched: false,
            effects_undecided: false,
            delay_delta_bic: None,
            delay_other_hold: vec![],
            delay_ambiguous: false,
        };
        // chirp 10953 #1: zoh by 254.7 for the nominal, the best effect +0.8 either way
        assert!(effects_undecided(&kept, false, 6.0));
        assert!(effects_undecided(&HoldReport { effect_delta_bic: Some(-5.9), ..kept.clone() }, false, 6.0));
        // negative controls: the effect confirms the hold, the hold was switched, the nominal
        // was not decisive, the hold was requested, the effects were never asked
        assert!(!effects_undecided(&HoldReport { effect_delta_bic: Some(-6.1), ..kept.clone() }, false, 6.0));
        assert!(!effects_undecided(&HoldReport { switched: true, ..kept.clone() }, false, 6.0));
        assert!(!effects_undecided(&HoldReport { decisive: false, ..kept.clone() }, false, 6.0));
        let fixed = HoldReport { requested: HoldChoice::Fixed(InputHold::Zoh), ..kept.clone() };
        assert!(!effects_undecided(&fixed, false, 6.0));
        assert!(!effects_undecided(&HoldReport { effect_delta_bic: None, ..kept.clone() }, false, 6.0));
        // a selected delay is read under both holds, with its interval, elsewhere
        assert!(!effects_undecided(&kept, true, 6.0));
    }
}
