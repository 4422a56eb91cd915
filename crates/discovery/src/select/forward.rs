//! Selection among the fitted singles: the best few that clear the BIC margin are
//! cross-validated against the nominal model until one passes; a generalisation must also beat
//! its simpler form on held-out folds; then greedy forward selection adds effects (or the
//! grey-box refit) while a combination clears the margin against the current model and passes
//! its cross-validation. Every fit ends in the ranking with its evidence.
use super::candidate::{failed_fit, fit_hypothesis, nominal_scores, Ranked};
use super::context::FitContext;
use super::cross_validation::{cross_validate, cv_sse_of};
use super::Plan;
use crate::fit::{self, FitResult};
use crate::hypothesis;
use rayon::prelude::*;

/// The outcome of selection.
pub struct Selection {
    /// Every fitted hypothesis: conclusive fits by BIC, stuck ones last.
    pub ranking: Vec<Ranked>,
    /// The selected model (`None`: nothing is added).
    pub chosen: Option<Ranked>,
    /// Hypotheses indistinguishable from the selected single (BIC within `tie_bic`).
    pub ties: Vec<String>,
    /// Candidates that passed the BIC margin but failed cross-validation (label, CV ratio,
    /// the ratio required).
    pub cv_rejected: Vec<(String, f64, String)>,
}

/// Selects among the fitted singles by BIC (margin `margin`) and blocked cross-validation,
/// greedy forward; nothing is selected when the nominal residual is adequate.
pub(crate) fn select_all(
    ctx: &FitContext,
    plan: &Plan,
    mut singles: Vec<Ranked>,
    nom: &FitResult,
    nominal_adequate: bool,
    margin: f64,
) -> Selection {
    let (bic_nom, val_sse_nom) = nominal_scores(ctx, nom);
    let sel = Selector { ctx, plan, bic_nom, val_sse_nom, margin };
    let nominal_ranked = sel.nominal_ranked(nom);
    let mut chosen: Option<Ranked> = None;
    let mut ties = Vec::new();
    let mut cv_rejected = Vec::new();
    let mut extra: Vec<Ranked> = Vec::new();
    if !nominal_adequate {
        let base_sse = cv_sse_of(ctx, plan, &nominal_ranked);
        sel.accept_best_single(&mut singles, &nominal_ranked, &base_sse, &mut cv_rejected);
        sel.prefer_simpler_form(&mut singles, &nominal_ranked, &base_sse, &mut cv_rejected);
        // `max_effects` bounds the effects of the selected model, the first one included (0:
        // the nominal model, refitted where it frees parameters, and nothing added)
        if let Some(best) = singles.iter().find(|r| r.beats_nominal && r.parts.len() <= plan.max_effects) {
            ties = sel.ties(&singles, best);
            let (mut cur, tried) = sel.forward(&singles, best.clone(), &base_sse);
            extra = tried;
            // Something left after the greedy steps: pairs of the best singles, fitted jointly.
            if plan.max_effects >= 2 && sel.something_left(&cur) {
                let (better, pairs) = sel.pair_search(&singles, &extra, &cur);
                extra.extend(pairs);
                if let Some(b) = better {
                    cur = b;
                }
            }
            chosen = Some(cur);
        }
    }
    let ranking = rank(singles.into_iter().chain(extra).collect());
    if let Some(c) = chosen.as_mut() {
        c.evidence = evidence_of(c);
    }
    Selection { ranking, chosen, ties, cv_rejected }
}

/// What every step of the selection shares.
struct Selector<'c, 'a> {
    ctx: &'c FitContext<'a>,
    plan: &'c Plan<'c>,
    /// BIC and validation SSE of the nominal model.
    bic_nom: f64,
    val_sse_nom: f64,
    /// BIC margin a candidate must clear (settings' margin plus the discretisation allowance).
    margin: f64,
}

impl Selector<'_, '_> {
    /// The nominal model as the base of the first cross-validation.
    fn nominal_ranked(&self, nom: &FitResult) -> Ranked {
        Ranked {
            label: "nominal".into(),
            kinds: vec![],
            params: vec![],
            std: vec![],
            refit: false,
            nominal: vec![],
            nominal_std: vec![],
            nominal_correlation: vec![],
            sse_estimation: nom.sse,
            bic: self.bic_nom,
            delta_bic: 0.0,
            validation: failed_fit(self.ctx.p),
            validation_ratio: 1.0,
            beats_nominal: false,
            status: nom.status,
            evidence: String::new(),
            cv: None,
            x0: nom.x0.clone(),
            val_sse: self.val_sse_nom,
            parts: vec![],
        }
    }

    /// Singles: cross-validates the best few (`max_cv`) that clear the BIC margin against the
    /// nominal model, until one passes.
    fn accept_best_single(
        &self,
        singles: &mut [Ranked],
        nominal_ranked: &Ranked,
        base_sse: &[f64],
        cv_rejected: &mut Vec<(String, f64, String)>,
    ) {
        let (ctx, plan) = (self.ctx, self.plan);
        let mut tried = 0;
        for r in singles.iter_mut() {
            if self.bic_nom - r.bic < self.margin || tried >= plan.max_cv {
                continue;
            }
            tried += 1;
            let cv = cross_validate(ctx, plan, r, nominal_ranked, base_sse);
            r.beats_nominal = cv.status != "failed";
            if !r.beats_nominal {
                cv_rejected.push((r.label.clone(), cv.ratio, format!("at most {:.2}", 1.0 - plan.select.min_val_gain)));
            }
            r.cv = Some(cv);
            if r.beats_nominal {
                // The best accepted single is found; the rest keep their BIC evidence only.
                break;
            }
        }
    }

    /// A generalisation of a simpler single (hypothesis::simpler_form: Stribeck or
    /// direction-dependent friction over Coulomb friction) must also beat it on held-out folds;
    /// where it does not (and the simpler form passes against the nominal), the simpler form
    /// is accepted instead.
    fn prefer_simpler_form(
        &self,
        singles: &mut [Ranked],
        nominal_ranked: &Ranked,
        base_sse: &[f64],
        cv_rejected: &mut Vec<(String, f64, String)>,
    ) {
        let (ctx, plan) = (self.ctx, self.plan);
        let Some(bi) = singles.iter().position(|r| r.beats_nominal) else { return };
        let simple = singles[bi].parts.first().and_then(|h| hypothesis::simpler_form(h.kind));
        let si = simple.and_then(|k| singles.iter().position(|r| r.parts.len() == 1 && r.parts[0].kind == k));
        let (Some(si), 1) = (si, singles[bi].parts.len()) else { return };
        let sb = &singles[si];
        let sse_s = cv_sse_of(ctx, plan, sb);
        let cv = cross_validate(ctx, plan, &singles[bi], sb, &sse_s);
        if cv.status != "not_testable" && !hypothesis::nested_supported(&cv.sse, &sse_s) {
            let cv0 = cross_validate(ctx, plan, &singles[si], nominal_ranked, base_sse);
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

    /// Singles that clear the margin and whose BIC is within `tie_bic` of the best.
    fn ties(&self, singles: &[Ranked], best: &Ranked) -> Vec<String> {
        singles
            .iter()
            .filter(|r| {
                r.label != best.label
                    && self.bic_nom - r.bic >= self.margin
                    && (r.bic - best.bic).abs() < self.plan.select.tie_bic
            })
            .map(|r| r.label.clone())
            .collect()
    }

    /// Greedy forward selection from `best` (at most `max_effects` effects; the nominal refit
    /// counts as a step, it adds parameters, not as an effect): the selected model and every
    /// combination fitted on the way.
    fn forward(&self, singles: &[Ranked], best: Ranked, base_sse: &[f64]) -> (Ranked, Vec<Ranked>) {
        let (ctx, plan) = (self.ctx, self.plan);
        let mut extra: Vec<Ranked> = Vec::new();
        let mut cur = best;
        while cur.parts.len() < plan.max_effects {
            let seconds: Vec<&Ranked> = singles
                .iter()
                .filter(|r| match r.parts.first() {
                    None => r.refit && !cur.refit,
                    Some(h) => !cur.parts.iter().any(|p| p.kind.name() == h.kind.name()),
                })
                .take(plan.max_second)
                .collect();
            let f = |r: &&Ranked| {
                let mut parts = cur.parts.clone();
                parts.extend(r.parts.first().cloned());
                let refit = match (cur.refit, r.refit, ctx.free) {
                    (true, _, _) => Some(cur.nominal.clone()),
                    (false, true, Some(free)) => Some(free.nominal.clone()),
                    _ => None,
                };
                fit_hypothesis(
                    ctx,
                    plan,
                    parts,
                    refit,
                    Some(cur.params.clone()),
                    &cur.x0,
                    self.bic_nom,
                    self.val_sse_nom,
                )
            };
            let mut combos: Vec<Ranked> =
                if plan.parallel { seconds.par_iter().map(f).collect() } else { seconds.iter().map(f).collect() };
            combos.sort_by(|a, b| a.bic.total_cmp(&b.bic));
            let next = self.accept_combination(&mut combos, &cur, base_sse);
            extra.extend(combos.iter().cloned());
            match next {
                Some(nx) => cur = nx,
                None => break,
            }
        }
        (cur, extra)
    }

    /// Whether `cur`'s residual says something is left: not white, nor once an AR(1) noise
    /// colour is removed (coloured measurement noise alone passes then).
    fn something_left(&self, cur: &Ranked) -> bool {
        let ctx = self.ctx;
        let Some((lags, step)) = self.plan.whiteness else { return false };
        let Some(sim) = cur.problem(ctx).simulate(&cur.params, &cur.x0, None) else { return false };
        let e: Vec<f64> = ctx.y.iter().zip(&sim.y).map(|(a, b)| a - b).collect();
        let test = |e: &[f64]| crate::residual::test_outputs(e, &ctx.w, ctx.n, ctx.m, ctx.p, lags, step).white;
        !test(&e) && !test(&crate::residual::prewhiten_ar1(&e, ctx.n, ctx.p).0)
    }

    /// Where the greedy steps leave something (issue 27 item 4): the greedy second effect is
    /// fitted from the first's estimate, which has absorbed what it could of the second effect
    /// (a friction level raised to stand in for a wider gap), and its candidates are the best
    /// singles, which may all be variants of the first (every friction law). Here every pair
    /// of distinct, non-rival kinds among the best [`PAIR_POOL`] singles that clear the margin
    /// is fitted jointly from both singles' own estimates; the best pairs that clear the margin
    /// against `cur` are cross-validated against it until one passes (returned). A pair with a
    /// generalisation (Stribeck over Coulomb friction) gives way to the pair with its simpler
    /// form where that also passes against `cur` and the generalisation is not supported over
    /// it on held-out folds. Also returned: every pair fitted (for the ranking).
    fn pair_search(&self, singles: &[Ranked], tried: &[Ranked], cur: &Ranked) -> (Option<Ranked>, Vec<Ranked>) {
        let (ctx, plan) = (self.ctx, self.plan);
        let pool: Vec<&Ranked> = singles
            .iter()
            .filter(|r| {
                r.parts.len() == 1
                    && !r.refit
                    && self.bic_nom - r.bic >= self.margin
                    && matches!(r.status, fit::FitStatus::Converged | fit::FitStatus::MaxIterations)
            })
            .take(PAIR_POOL)
            .collect();
        let same_labels = |a: &[String], b: &[String]| {
            let (mut a, mut b) = (a.to_vec(), b.to_vec());
            a.sort();
            b.sort();
            a == b
        };
        let label_of = |r: &Ranked| r.parts.iter().map(|h| h.kind.label()).collect::<Vec<_>>();
        let mut todo: Vec<(&Ranked, &Ranked)> = Vec::new();
        for (i, a) in pool.iter().enumerate() {
            for b in &pool[i + 1..] {
                let (ka, kb) = (a.parts[0].kind, b.parts[0].kind);
                let labels = vec![ka.label(), kb.label()];
                if rivals(ka, kb)
                    || tried.iter().chain(std::iter::once(cur)).any(|t| !t.refit && same_labels(&label_of(t), &labels))
                {
                    continue;
                }
                todo.push((a, b));
            }
        }
        // Each single's estimate has absorbed part of the other effect: started from both
        // estimates and from both scaled down (PAIR_START_SCALES), the best fit kept.
        let f = |(a, b): &(&Ranked, &Ranked)| {
            PAIR_START_SCALES
                .iter()
                .map(|&c| {
                    let warm: Vec<f64> = a.params.iter().chain(&b.params).map(|v| c * v).collect();
                    fit_hypothesis(
                        ctx,
                        plan,
                        vec![a.parts[0].clone(), b.parts[0].clone()],
                        None,
                        Some(warm),
                        &a.x0,
                        self.bic_nom,
                        self.val_sse_nom,
                    )
                })
                .min_by(|x, y| x.bic.total_cmp(&y.bic))
                .expect("at least one start")
        };
        let mut pairs: Vec<Ranked> =
            if plan.parallel { todo.par_iter().map(f).collect() } else { todo.iter().map(f).collect() };
        pairs.sort_by(|a, b| a.bic.total_cmp(&b.bic));
        let cur_sse = cur.cv.as_ref().map(|c| c.sse.clone()).unwrap_or_else(|| cv_sse_of(ctx, plan, cur));
        let Some(mut best) = self.accept_combination(&mut pairs, cur, &cur_sse) else { return (None, pairs) };
        // The simpler form of a generalisation in the pair, where it does as well.
        for (i, h) in best.parts.clone().iter().enumerate() {
            let Some(simple) = h.kind.simpler_form() else { continue };
            let mut labels = label_of(&best);
            labels[i] = simple.label();
            let Some(si) = pairs.iter().position(|r| same_labels(&label_of(r), &labels)) else { continue };
            let sse_s = cv_sse_of(ctx, plan, &pairs[si]);
            let cv = cross_validate(ctx, plan, &best, &pairs[si], &sse_s);
            if cv.status == "not_testable" || hypothesis::nested_supported(&cv.sse, &sse_s) {
                continue;
            }
            let cv0 = cross_validate(ctx, plan, &pairs[si], cur, &cur_sse);
            if cv0.status != "failed" {
                best.beats_nominal = false;
                if let Some(b) = pairs.iter_mut().find(|r| r.label == best.label) {
                    b.beats_nominal = false;
                }
                pairs[si].beats_nominal = true;
                pairs[si].cv = Some(cv0);
                best = pairs[si].clone();
                break;
            }
        }
        (Some(best), pairs)
    }

    /// Cross-validates the best few combinations that clear the margin against `cur`, until
    /// one passes (returned).
    fn accept_combination(&self, combos: &mut [Ranked], cur: &Ranked, base_sse: &[f64]) -> Option<Ranked> {
        let cur_sse = cur.cv.as_ref().map(|c| c.sse.clone()).unwrap_or_else(|| base_sse.to_vec());
        let mut tried = 0;
        for c in combos.iter_mut() {
            if cur.bic - c.bic < self.margin || tried >= self.plan.max_cv {
                continue;
            }
            tried += 1;
            let cv = cross_validate(self.ctx, self.plan, c, cur, &cur_sse);
            c.beats_nominal = cv.status != "failed";
            c.cv = Some(cv);
            if c.beats_nominal {
                return Some(c.clone());
            }
        }
        None
    }
}

/// How many of the best singles the pair search draws its pairs from.
pub const PAIR_POOL: usize = 6;

/// The pair search's starts: both singles' estimates times each of these.
pub const PAIR_START_SCALES: [f64; 3] = [1.0, 0.6, 0.3];

/// Two kinds that stand for the same physics (the same kind, or one the simpler form of the
/// other, or two generalisations of one simpler form): not paired.
fn rivals(a: hypothesis::Kind, b: hypothesis::Kind) -> bool {
    let (sa, sb) = (a.simpler_form(), b.simpler_form());
    a.name() == b.name() || sa == Some(b) || sb == Some(a) || (sa.is_some() && sa == sb)
}

/// Evidence of every fit; conclusive fits by BIC, stuck ones last (they are not evidence
/// either way).
fn rank(mut ranking: Vec<Ranked>) -> Vec<Ranked> {
    for r in ranking.iter_mut() {
        r.evidence = evidence_of(r);
    }
    ranking.sort_by(|a, b| {
        let (ia, ib) = (a.evidence.starts_with("inconclusive"), b.evidence.starts_with("inconclusive"));
        ia.cmp(&ib).then(a.bic.total_cmp(&b.bic))
    });
    ranking
}

/// `for` (accepted), `against` (a conclusive fit that does not pay) or `inconclusive: ...`.
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
