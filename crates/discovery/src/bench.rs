//! The concealed-effect benchmark: generates cases with [`crate::bench_gen`], diagnoses each
//! with [`crate::diagnose`] (which knows nothing of the generator) and scores the names and
//! parameters.
pub mod next_experiment;

use crate::bench_gen::{self, Conditions, Profile, CLASSES, FRICTION_CLASSES};
use crate::diagnose::{diagnose, DiagnoseSettings};
use crate::physics;
use model::effects::{names, Effect};
use serde::Serialize;

/// Outcome of one case.
#[derive(Debug, Clone, Serialize)]
pub struct CaseResult {
    pub class: String,
    pub index: usize,
    pub description: String,
    /// Hold, sample period, noise colour and damping of the case.
    pub conditions: Conditions,
    pub nominal_fit: f64,
    /// Name of the first selected effect (`none` when nothing was added).
    pub predicted: String,
    /// Every selected effect.
    pub selected: String,
    /// Hypotheses reported as indistinguishable from the selected one.
    pub ties: Vec<String>,
    pub correct: bool,
    /// The truth is the selected effect or one reported as tied with it.
    pub correct_or_tied: bool,
    /// The report's `model_incomplete` (a single named effect must not be called incomplete).
    pub model_incomplete: bool,
    /// `|estimate - truth| / |truth|` of the effect's main parameter, when the name is right
    /// (an input delay: its reading under the generator's hold convention, which the report
    /// states beside the one of the hold used).
    pub param_error: Option<f64>,
    /// The same for every parameter of a friction-library effect ([`all_params`]).
    pub param_errors: Vec<(String, f64)>,
    pub true_param: Option<f64>,
    /// The reported estimate (an input delay: under the hold the diagnosis used).
    pub est_param: Option<f64>,
    /// An input delay's reading under the other hold (report's `other_hold`).
    pub est_param_other_hold: Option<f64>,
    /// The hold the diagnosis used (`zoh` or `foh`).
    pub hold_used: String,
    /// Reported 1-sigma uncertainty of the estimate: the statistical part (Gauss-Newton or
    /// coloured-residual sandwich, the larger) combined with the fold jackknife's model-error
    /// spread (see [`crate::fit::jackknife`]).
    pub est_std: Option<f64>,
    /// Its statistical part alone.
    pub est_std_statistical: Option<f64>,
    /// Its jackknife part alone (widened for its degrees of freedom, as it enters the sigma).
    pub est_std_jackknife: Option<f64>,
    pub fit_before: f64,
    pub fit_after: f64,
    /// BIC gain over the nominal of the selected model (0 when nothing was added).
    pub delta_bic_selected: f64,
    /// Best BIC gain of a ranked single of the true class (`None`: not ranked, or the truth is
    /// `none`). Above `delta_bic_selected`: the selection missed a better reading; at or below
    /// it: the recording prefers what was selected (a miss no selection rule can avoid).
    pub delta_bic_truth: Option<f64>,
    pub seconds: f64,
    /// A diagnosis error (should not happen).
    pub error: Option<String>,
    /// How the returned model predicts the machine's next experiment (`BENCH_NEXT=1`; a
    /// prediction's error goes to `error`).
    pub next: Option<next_experiment::NextScore>,
}

/// A prediction of the next experiment whose RMSE is at most this factor over the noise floor
/// is at the floor (the benchmark's summary): a tenth above what the noise alone leaves.
pub const NEXT_AT_FLOOR: f64 = 1.1;

/// The benchmark's result.
#[derive(Debug, Clone, Serialize)]
pub struct BenchResult {
    pub classes: Vec<String>,
    /// `confusion[true][predicted]`; the last column counts predictions outside the classes.
    pub confusion: Vec<Vec<usize>>,
    pub cases: Vec<CaseResult>,
}

/// Main parameter of an effect (the one the generator sets; declared by its family,
/// [`physics::Family::main_parameter`]).
pub fn main_param(e: &Effect) -> f64 {
    physics::main_parameter(e).0
}

/// Name of the hypothesis parameter that is the main parameter (for its reported
/// uncertainty); `None` where the main parameter is derived from several (the report's
/// `effects[].derived`).
fn main_param_name(e: &Effect) -> Option<&'static str> {
    physics::main_parameter(e).1
}

/// Every identifiable parameter of a friction-library effect, `(name, value)` (the main
/// parameter alone for the other effects; see [`physics::Family::every_parameter`]).
pub fn all_params(e: &Effect) -> Vec<(&'static str, f64)> {
    physics::every_parameter(e).unwrap_or_else(|| vec![("main", main_param(e))])
}

/// Settings `s` with the true initial state of `case` (its nominal model's `x0`, `z0`) where
/// they state none, as the model file written by `discover-bench --write-cases` does.
pub fn with_case_start(case: &bench_gen::Case, s: &DiagnoseSettings) -> DiagnoseSettings {
    let mut s = s.clone();
    if s.initial_state.is_none() {
        s.initial_state = Some(crate::diagnose::InitialState {
            x0: case.nominal.x0.iter().copied().collect(),
            z0: Some(case.nominal.z0.iter().copied().collect()),
        });
    }
    s
}

/// Runs one case of the classic profile.
pub fn run_case(class: &'static str, seed: u64, index: usize, s: &DiagnoseSettings) -> CaseResult {
    run_case_with(class, seed, index, Profile::Classic, s)
}

/// Runs one case of `profile`. The nominal model of a case states the true initial state, as
/// the model file written by `discover-bench --write-cases` does; it is handed to diagnose as
/// the model file's `x0`/`z0` unless `s.estimate_x0` frees it.
pub fn run_case_with(
    class: &'static str,
    seed: u64,
    index: usize,
    profile: Profile,
    s: &DiagnoseSettings,
) -> CaseResult {
    let case = bench_gen::generate_profile(class, seed, index, profile);
    let s = with_case_start(&case, s);
    let start = std::time::Instant::now();
    let r = diagnose(&case.nominal, &case.recording, &s);
    let mut out = CaseResult::unscored(class, index, &case, start.elapsed().as_secs_f64());
    match r {
        Err(e) => out.error = Some(e.to_string()),
        Ok(rep) => {
            out.predicted = rep.effects.first().map(|e| e.kind.clone()).unwrap_or_else(|| "none".into());
            out.selected = rep.selected();
            out.hold_used = rep.hold.chosen.to_string();
            out.ties = rep.ties.clone();
            out.correct = out.predicted == class;
            out.correct_or_tied = out.correct || rep.ties.iter().any(|t| t.split('(').next() == Some(class));
            out.model_incomplete = rep.model_incomplete;
            out.fit_before = rep.fit_before.fit_percent[0].unwrap_or(f64::NAN);
            out.fit_after = rep.fit_after.fit_percent[0].unwrap_or(f64::NAN);
            out.delta_bic_selected = selected_gain(&rep);
            out.delta_bic_truth = rep
                .ranking
                .iter()
                .filter(|r| !r.refit && r.kinds.len() == 1 && r.kinds[0] == class)
                .map(|r| r.delta_bic)
                .reduce(f64::max);
            if out.correct {
                score_estimate(&case, &rep, &mut out);
            }
            out.next = next_score(&case, &rep, &s, &mut out.error);
        }
    }
    out
}

impl CaseResult {
    /// A case's result before its diagnosis is scored (`error` until then).
    fn unscored(class: &'static str, index: usize, case: &bench_gen::Case, seconds: f64) -> Self {
        CaseResult {
            class: class.into(),
            index,
            description: case.description.clone(),
            conditions: case.conditions.clone(),
            nominal_fit: case.nominal_fit,
            predicted: "error".into(),
            selected: "error".into(),
            ties: vec![],
            correct: false,
            correct_or_tied: false,
            model_incomplete: false,
            param_error: None,
            param_errors: vec![],
            true_param: case.truth.as_ref().map(main_param),
            est_param: None,
            est_param_other_hold: None,
            hold_used: String::new(),
            est_std: None,
            est_std_statistical: None,
            est_std_jackknife: None,
            fit_before: f64::NAN,
            fit_after: f64::NAN,
            delta_bic_selected: f64::NAN,
            delta_bic_truth: None,
            seconds,
            error: None,
            next: None,
        }
    }
}

/// Like with like: the same kind and, for forces, the same state (a force on another state
/// is an observationally equivalent but different parameter).
fn same_site(a: &Effect, b: &Effect) -> bool {
    match (a, b) {
        (Effect::CoulombFriction { state: i, .. }, Effect::CoulombFriction { state: j, .. })
        | (Effect::ConstantForce { state: i, .. }, Effect::ConstantForce { state: j, .. })
        | (Effect::StribeckFriction { state: i, .. }, Effect::StribeckFriction { state: j, .. })
        | (Effect::AsymmetricCoulomb { state: i, .. }, Effect::AsymmetricCoulomb { state: j, .. })
        | (Effect::LoadFriction { state: i, .. }, Effect::LoadFriction { state: j, .. })
        | (Effect::Cogging { state: i, .. }, Effect::Cogging { state: j, .. }) => i == j,
        _ => a.kind() == b.kind(),
    }
}

/// The report's label of a force acting on a state (`coulomb_friction(x2)`; empty for the
/// other effects, whose kind names them).
fn state_label(t: &Effect) -> String {
    match t {
        Effect::CoulombFriction { state, .. }
        | Effect::ConstantForce { state, .. }
        | Effect::StribeckFriction { state, .. }
        | Effect::AsymmetricCoulomb { state, .. }
        | Effect::LoadFriction { state, .. }
        | Effect::Cogging { state, .. } => format!("{}(x{})", t.kind(), state + 1),
        _ => String::new(),
    }
}

/// A correctly named single: its main parameter's error against the truth and its reported
/// sigmas (the effect fitted at the true site; nothing where it was fitted elsewhere).
fn score_estimate(case: &bench_gen::Case, rep: &crate::Report, out: &mut CaseResult) {
    let fitted = rep.fitted_model.as_ref().map(|m| m.effects.list.clone()).unwrap_or_default();
    let Some(t) = case.truth.as_ref() else { return };
    let Some(e) = fitted.iter().find(|e| same_site(t, e)) else { return };
    // An input delay: the report states it under the hold used and, with `other_hold`, under
    // the other. The parameter error compares like with like (the reading under the
    // generator's convention: `foh` for the continuous signal, `zoh` for held samples); the
    // coverage (`est_param` against `est_std`) scores the reported reading whatever hold the
    // tool used (the hold is never passed to it: where the data cannot tell the holds apart,
    // the delay's interval must cover both readings).
    let (tv, ev) = (main_param(t), main_param(e));
    let other = rep
        .effects
        .iter()
        .find(|f| f.kind == names::INPUT_DELAY)
        .and_then(|f| f.other_hold.as_ref())
        .filter(|_| matches!(t, Effect::InputDelay { .. }));
    let truth_hold = if case.conditions.hold == "zoh" { "zoh" } else { "foh" };
    let ev_convention = other.filter(|o| o.0 == truth_hold).map_or(ev, |o| o.1[0].1);
    out.est_param_other_hold = other.map(|o| o.1[0].1);
    out.est_param = Some(ev);
    out.param_error = Some((ev_convention - tv).abs() / tv.abs().max(1e-300));
    if let Some(truth_params) = physics::every_parameter(t) {
        out.param_errors = truth_params
            .iter()
            .zip(all_params(e))
            .map(|((n, a), (_, b))| (n.to_string(), (b - a).abs() / a.abs().max(1e-300)))
            .collect();
    }
    let label = state_label(t);
    // The main parameter's sigma: that of its hypothesis parameter, or of the report's derived
    // main parameter (Stribeck static level, cogging amplitude).
    let sd = |pick: fn(&crate::diagnose::FittedEffect) -> &Vec<(String, f64)>,
              pick_derived: fn(&crate::diagnose::DerivedParameter) -> f64| {
        let f = rep.effects.iter().find(|f| f.kind == t.kind() && (label.is_empty() || f.label == label))?;
        match main_param_name(t) {
            Some(name) => pick(f).iter().find(|u| u.0 == name).map(|u| u.1),
            None => f.derived.as_ref().map(pick_derived),
        }
    };
    out.est_std = sd(|f| &f.uncertainty, |d| d.uncertainty);
    out.est_std_statistical = sd(|f| &f.uncertainty_statistical, |d| d.uncertainty_statistical);
    out.est_std_jackknife = sd(|f| &f.uncertainty_jackknife, |d| d.uncertainty_jackknife);
}

/// How `rep`'s model predicts `case`'s next experiment (`None` without one); a prediction
/// that fails is the case's `error`.
fn next_score(
    case: &bench_gen::Case,
    rep: &crate::Report,
    s: &DiagnoseSettings,
    error: &mut Option<String>,
) -> Option<next_experiment::NextScore> {
    match next_experiment::score(case, rep, s)? {
        Ok(n) => Some(n),
        Err(e) => {
            *error = Some(format!("next experiment: {e}"));
            None
        }
    }
}

/// The selected model's BIC gain over the nominal, from the ranking (0 when nothing was added).
fn selected_gain(rep: &crate::Report) -> f64 {
    if rep.effects.is_empty() {
        return 0.0;
    }
    let chosen = rep.effects.iter().map(|e| e.label.clone()).collect::<Vec<_>>().join(" + ");
    rep.ranking.iter().find(|r| r.label == chosen).map_or(f64::NAN, |r| r.delta_bic)
}

/// Runs `cases` cases of every class (classic profile).
pub fn run(cases: usize, seed: u64, s: &DiagnoseSettings, progress: impl FnMut(&CaseResult)) -> BenchResult {
    run_with(cases, seed, Profile::Classic, s, progress)
}

/// Runs `cases` cases of every class of `profile`.
pub fn run_with(
    cases: usize,
    seed: u64,
    profile: Profile,
    s: &DiagnoseSettings,
    progress: impl FnMut(&CaseResult),
) -> BenchResult {
    run_classes(&CLASSES, cases, seed, profile, s, progress)
}

/// The classes of a named set: `classic` ([`CLASSES`]), `friction` (`none`,
/// `coulomb_friction` and [`FRICTION_CLASSES`]: the friction library against its simplest
/// member and against false alarms), `all`, or a comma-separated list of class names.
pub fn class_set(name: &str) -> Option<Vec<&'static str>> {
    let all = bench_gen::all_classes();
    match name {
        "classic" => Some(CLASSES.to_vec()),
        "friction" => {
            Some([bench_gen::NONE, names::COULOMB_FRICTION].iter().chain(FRICTION_CLASSES.iter()).copied().collect())
        }
        "all" => Some(all),
        list => {
            // each class once, in the order first named (`none,none,...` is one class)
            let mut set: Vec<&'static str> = Vec::new();
            for c in list.split(',') {
                let class = all.iter().find(|a| **a == c.trim()).copied()?;
                if !set.contains(&class) {
                    set.push(class);
                }
            }
            Some(set)
        }
    }
}

/// Runs `cases` cases of each of `classes` (its first should be `none`: the summary counts
/// false alarms on it and parameter errors on the others).
pub fn run_classes(
    classes: &[&'static str],
    cases: usize,
    seed: u64,
    profile: Profile,
    s: &DiagnoseSettings,
    mut progress: impl FnMut(&CaseResult),
) -> BenchResult {
    let mut results = Vec::new();
    for i in 0..cases {
        for &c in classes.iter() {
            let r = run_case_with(c, seed, i, profile, s);
            progress(&r);
            results.push(r);
        }
    }
    let k = classes.len();
    let mut confusion = vec![vec![0; k + 1]; k];
    for r in &results {
        let ti = classes.iter().position(|c| *c == r.class).expect("known class");
        let pi = classes.iter().position(|c| *c == r.predicted).unwrap_or(k);
        confusion[ti][pi] += 1;
    }
    BenchResult { classes: classes.iter().map(|s| s.to_string()).collect(), confusion, cases: results }
}

impl BenchResult {
    /// Confusion matrix and summary as text.
    pub fn to_text(&self) -> String {
        [self.confusion_text(), self.naming_text(), self.parameter_text(), self.next_text(), self.time_text()].concat()
    }

    /// The confusion matrix: true class per row, predicted per column (then `other`).
    fn confusion_text(&self) -> String {
        let short = |s: &str| s.chars().take(9).collect::<String>();
        let mut s = format!("{:>18}", "true \\ predicted");
        for c in &self.classes {
            s += &format!(" {:>9}", short(c));
        }
        s += &format!(" {:>9}\n", "other");
        for (i, row) in self.confusion.iter().enumerate() {
            s += &format!("{:>18}", self.classes[i]);
            for v in row {
                s += &format!(" {v:>9}");
            }
            s.push('\n');
        }
        s
    }

    /// Top-1 (with reported ties), false alarms on `none`, misses, and top-1 per class.
    fn naming_text(&self) -> String {
        let total = self.cases.len();
        let correct = self.cases.iter().filter(|c| c.correct).count();
        let tied = self.cases.iter().filter(|c| c.correct_or_tied).count();
        let non_none: Vec<&CaseResult> = self.cases.iter().filter(|c| c.class != "none").collect();
        let none: Vec<&CaseResult> = self.cases.iter().filter(|c| c.class == "none").collect();
        let false_alarms = none.iter().filter(|c| c.predicted != "none").count();
        let mut s = format!(
            "\ncorrect names: {correct}/{total} ({:.1} %); counting reported ties: {tied}/{total} ({:.1} %)\n",
            100.0 * correct as f64 / total.max(1) as f64,
            100.0 * tied as f64 / total.max(1) as f64
        );
        s += &format!(
            "false alarms on none: {false_alarms}/{} ({:.1} %)\n",
            none.len(),
            100.0 * false_alarms as f64 / none.len().max(1) as f64
        );
        s += &format!(
            "missed effects (predicted none): {}/{}\n",
            non_none.iter().filter(|c| c.predicted == "none").count(),
            non_none.len()
        );
        s += "\nper class: top-1 (incl. ties):\n";
        for c in self.classes.iter() {
            let rows: Vec<&CaseResult> = self.cases.iter().filter(|r| &r.class == c).collect();
            s += &format!(
                "  {c:>18}: {}/{} ({})\n",
                rows.iter().filter(|r| r.correct).count(),
                rows.len(),
                rows.iter().filter(|r| r.correct_or_tied).count()
            );
        }
        s
    }

    /// The main parameter's error per class (within 15 %, and in reported sigmas), every
    /// parameter of the friction library, and the pooled figures.
    fn parameter_text(&self) -> String {
        let mut s = "\nparameter error of the main parameter (correctly named cases):\n".to_string();
        for c in self.classes.iter().skip(1) {
            let mut e: Vec<f64> = self.cases.iter().filter(|r| &r.class == c).filter_map(|r| r.param_error).collect();
            if e.is_empty() {
                s += &format!("  {c:>18}: no correctly named case\n");
                continue;
            }
            e.sort_by(f64::total_cmp);
            let within = e.iter().filter(|x| **x <= 0.15).count();
            // Error in units of the reported uncertainty.
            let mut z: Vec<f64> = self
                .cases
                .iter()
                .filter(|r| &r.class == c)
                .filter_map(|r| match (r.est_param, r.true_param, r.est_std) {
                    (Some(e), Some(t), Some(sd)) => Some((e - t).abs() / sd),
                    _ => None,
                })
                .collect();
            z.sort_by(f64::total_cmp);
            let within2 = z.iter().filter(|x| **x <= 2.0).count();
            s += &format!(
                "  {c:>18}: median {:.1} %, max {:.1} %, within 15 %: {within}/{}; |error| / reported sigma: median {:.1}, within 2 sigma: {within2}/{}\n",
                100.0 * e[e.len() / 2],
                100.0 * e[e.len() - 1],
                e.len(),
                z.get(z.len() / 2).copied().unwrap_or(f64::NAN),
                z.len()
            );
        }
        s += &self.every_parameter_text();
        let (mut w1, mut w2, mut w2s, mut nz, mut w15, mut np) = (0, 0, 0, 0, 0, 0);
        for r in &self.cases {
            if let Some(e) = r.param_error {
                np += 1;
                w15 += usize::from(e <= 0.15);
            }
            if let (Some(e), Some(t), Some(sd)) = (r.est_param, r.true_param, r.est_std) {
                nz += 1;
                w1 += usize::from((e - t).abs() <= sd);
                w2 += usize::from((e - t).abs() <= 2.0 * sd);
                w2s += usize::from((e - t).abs() <= 2.0 * r.est_std_statistical.unwrap_or(sd));
            }
        }
        s += &format!(
            "all classes: main parameter within 15 %: {w15}/{np}; errors within 2 reported sigma: {w2}/{nz} ({w2s}/{nz} within 2 statistical sigma, without the jackknife)\n"
        );
        // A sigma that is exact covers about 68 % within 1 and 95 % within 2: more within 1 says
        // it is conservative, fewer that it is narrow.
        s += &format!("calibration: errors within 1 reported sigma: {w1}/{nz} (about 68 % for an exact sigma)\n");
        s
    }

    /// Every parameter of the friction-library effects: median, max, within 15 %.
    fn every_parameter_text(&self) -> String {
        let mut s = String::new();
        for c in self.classes.iter() {
            let rows: Vec<&CaseResult> =
                self.cases.iter().filter(|r| &r.class == c && !r.param_errors.is_empty()).collect();
            let Some(first) = rows.first() else { continue };
            s += &format!("  {c:>18}, every parameter:");
            for (i, (name, _)) in first.param_errors.iter().enumerate() {
                let mut e: Vec<f64> = rows.iter().filter_map(|r| r.param_errors.get(i).map(|p| p.1)).collect();
                e.sort_by(f64::total_cmp);
                let within = e.iter().filter(|x| **x <= 0.15).count();
                s += &format!(
                    " {name} median {:.1} %, max {:.1} %, within 15 %: {within}/{};",
                    100.0 * e[e.len() / 2],
                    100.0 * e[e.len() - 1],
                    e.len()
                );
            }
            s.push('\n');
        }
        s
    }

    /// Per class, how the returned models predict the machines' next experiments (empty
    /// without `BENCH_NEXT=1`): how many predict it within [`NEXT_AT_FLOOR`] of the noise
    /// floor, how many worse than the nominal model, and the median RMSE over the floor of
    /// the nominal and of the returned model.
    fn next_text(&self) -> String {
        let mut out = String::new();
        for class in &self.classes {
            let scores: Vec<&next_experiment::NextScore> =
                self.cases.iter().filter(|c| &c.class == class).filter_map(|c| c.next.as_ref()).collect();
            if scores.is_empty() {
                continue;
            }
            let at_floor = scores.iter().filter(|n| n.over_floor() <= NEXT_AT_FLOOR).count();
            let worse = scores.iter().filter(|n| n.rmse_fitted > n.rmse_nominal).count();
            let nominal = median(scores.iter().map(|n| n.rmse_nominal / n.rmse_truth).collect());
            let fitted = median(scores.iter().map(|n| n.over_floor()).collect());
            out += &format!(
                "{class:>20}: at the floor {at_floor}/{n}, worse than the nominal {worse}/{n}; RMSE / noise floor: nominal {nominal:.2}, returned {fitted:.2} (medians)\n",
                n = scores.len()
            );
        }
        if out.is_empty() {
            return out;
        }
        format!(
            "\nthe machine's next experiment (new input and noise), predicted by the returned model as it is:\n{out}"
        )
    }

    /// The diagnoses' total time and time per case.
    fn time_text(&self) -> String {
        let secs: f64 = self.cases.iter().map(|c| c.seconds).sum();
        format!("\ndiagnosis time: {secs:.1} s total, {:.2} s per case\n", secs / self.cases.len().max(1) as f64)
    }
}

/// The upper median of `v` (`NaN` where empty), as the tables' medians are read.
fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_class_named_twice_runs_once() {
        let many = vec!["none"; 10_000].join(",");
        assert_eq!(class_set(&many).unwrap(), [bench_gen::NONE]);
        let two = format!("{},none, {}", bench_gen::NONE, names::COULOMB_FRICTION);
        assert_eq!(class_set(&two).unwrap(), [bench_gen::NONE, names::COULOMB_FRICTION]);
        // negative control: an unknown name still refuses the list
        assert!(class_set("none,no-such-class").is_none());
    }
}

/// Outcome of one case with two concealed effects ([`bench_gen::generate_pair`], issue 27
/// item 4).
#[derive(Debug, Clone, Serialize)]
pub struct PairResult {
    pub pair: [String; 2],
    pub index: usize,
    pub description: String,
    /// Every selected effect (`none` when nothing was added).
    pub selected: String,
    /// How many of the two concealed classes the selected model names.
    pub named: usize,
    /// The most of them that the selected model or one of the readings the report names as
    /// fitting as well (`equivalents`) names, each reading also read through the identity the
    /// report's friction note states (direction-dependent Coulomb friction is Coulomb friction
    /// plus a constant force on the same state): the truth is among the readings the recording
    /// cannot tell apart.
    pub named_or_equivalent: usize,
    /// The report's equivalent readings (labels).
    pub equivalents: Vec<String>,
    /// BIC gain over the nominal of the selected model, and of the true pair of effects where
    /// the diagnosis fitted it (the ranking's entry with exactly the two concealed kinds).
    pub delta_bic_selected: f64,
    pub delta_bic_true_pair: Option<f64>,
    /// The report's `model_incomplete`.
    pub model_incomplete: bool,
    /// Portmanteau statistic of the final residual and its threshold.
    pub q_final: f64,
    pub q_threshold: f64,
    pub seconds: f64,
    pub error: Option<String>,
    /// How the returned model predicts the machine's next experiment (`BENCH_NEXT=1`).
    pub next: Option<next_experiment::NextScore>,
}

/// Runs case `index` of the pair `pair` (`None` where the pair cannot co-occur), the true
/// initial state handed over as in [`run_case_with`].
pub fn run_pair_case(
    pair: [&'static str; 2],
    seed: u64,
    index: usize,
    profile: Profile,
    s: &DiagnoseSettings,
) -> Option<PairResult> {
    let case = bench_gen::generate_pair(pair, seed, index, profile)?;
    let s = with_case_start(&case, s);
    let start = std::time::Instant::now();
    let r = diagnose(&case.nominal, &case.recording, &s);
    let mut out = PairResult {
        pair: [pair[0].into(), pair[1].into()],
        index,
        description: case.description.clone(),
        selected: "error".into(),
        named: 0,
        named_or_equivalent: 0,
        equivalents: vec![],
        delta_bic_selected: f64::NAN,
        delta_bic_true_pair: None,
        model_incomplete: false,
        q_final: f64::NAN,
        q_threshold: f64::NAN,
        seconds: start.elapsed().as_secs_f64(),
        error: None,
        next: None,
    };
    match r {
        Err(e) => out.error = Some(e.to_string()),
        Ok(rep) => {
            out.selected = rep.selected();
            let named_in =
                |kinds: &[String]| case.truths.iter().filter(|t| kinds.iter().any(|k| k == t.kind())).count();
            let selected: Vec<String> = rep.effects.iter().map(|e| e.kind.clone()).collect();
            out.named = named_in(&selected);
            let identity = |kinds: &[String]| -> Vec<String> {
                let mut k = kinds.to_vec();
                if kinds.iter().any(|k| k == names::ASYMMETRIC_COULOMB) {
                    k.extend([names::COULOMB_FRICTION.to_string(), names::CONSTANT_FORCE.to_string()]);
                }
                k
            };
            out.named_or_equivalent = rep
                .equivalents
                .iter()
                .map(|e| named_in(&identity(&e.kinds)))
                .fold(named_in(&identity(&selected)), usize::max);
            out.equivalents = rep.equivalents.iter().map(|e| e.label.clone()).collect();
            out.delta_bic_selected = selected_gain(&rep);
            out.delta_bic_true_pair = rep
                .ranking
                .iter()
                .filter(|r| !r.refit && r.kinds.len() == case.truths.len() && named_in(&r.kinds) == case.truths.len())
                .map(|r| r.delta_bic)
                .reduce(f64::max);
            out.model_incomplete = rep.model_incomplete;
            out.q_final = rep.residual_fitted.q_auto;
            out.q_threshold = rep.residual_fitted.q_auto_threshold;
            out.next = next_score(&case, &rep, &s, &mut out.error);
        }
    }
    Some(out)
}
