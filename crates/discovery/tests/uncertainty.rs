//! Issue 13 item 7: the reported sigma includes the model-error spread of a delete-a-group
//! jackknife over contiguous folds of the estimation segment. Each check has a negative control.
mod common;
use discovery::fit::jackknife::{self, Estimate};
use discovery::fit::{self, FitSettings, Problem};
use discovery::hypothesis::{self, Kind};
use dynamics::extended::ExtendedModel;
use model::effects::Effect;

fn mass(k: f64) -> model::System {
    let text = format!(
        "name = \"mass\"\n[plant]\nA = [[0.0, 1.0], [{}, -1.2]]\nB = [[0.0], [1.0]]\nC = [[1.0, 0.0]]\nE = [[0.0], [0.0]]\n[input]\nkind = \"sine\"\namplitudes = [1.0]\nomega = 1.0\n[initial]\nx0 = [0.0, 0.0]\nz0 = [0.0]\n",
        -k
    );
    model::parse_str(&text).unwrap()
}

/// A damped mass-spring (stiffness 4) pushed by a constant force 0.3, 1 % pseudo-noise.
fn recording() -> (Vec<f64>, Vec<f64>, f64, f64) {
    let (dt, n, force) = (0.02, 1500, 0.3);
    let w: Vec<f64> = (0..n)
        .map(|k| {
            let t = k as f64 * dt;
            (0.9 * t).sin() + 0.5 * (2.3 * t + 1.0).sin() + 0.3 * (0.21 * t).sin()
        })
        .collect();
    let truth = [Effect::ConstantForce { state: 1, force }];
    let y = ExtendedModel::new(&mass(4.0), &truth, dt, 4).unwrap().simulate(&w, dt, &[0.0, 0.0]).y;
    let yr = y.iter().copied().fold(f64::NEG_INFINITY, f64::max) - y.iter().copied().fold(f64::INFINITY, f64::min);
    let y: Vec<f64> =
        y.iter().enumerate().map(|(k, v)| v + 0.01 * yr * (((k * 7919) % 1000) as f64 / 1000.0 - 0.5)).collect();
    (w, y, dt, force)
}

/// Fits a constant force with nominal stiffness `k` (the truth is 4) on the first 70 % and
/// jackknifes it with `iters` iterations per fold: (estimate, statistical sigma, jackknife).
fn fit_and_jackknife(k: f64, iters: usize) -> (f64, f64, jackknife::Jackknife) {
    let (w, y, dt, _) = recording();
    let sys = mass(k);
    let n = w.len();
    let k_est = 7 * n / 10;
    let yr = y.iter().copied().fold(f64::NEG_INFINITY, f64::max) - y.iter().copied().fold(f64::INFINITY, f64::min);
    let scales = common::test_scales(yr, n, dt);
    let h = hypothesis::candidates(&sys, &scales)
        .into_iter()
        .find(|h| h.kind == Kind::ConstantForce { state: 1 })
        .expect("constant force on the velocity state is a candidate");
    let pb = |exclude: Option<(usize, usize)>| Problem {
        exclude,
        ..common::scalar_problem(&sys, &h, &scales, &w, &y, k_est, 1.0 / yr, 4)
    };
    let s = FitSettings::default();
    let full = fit::fit(&pb(None), &[0.0, 0.0], &[], None, &s);
    let est = Estimate { theta: &full.theta, nominal: &full.nominal, x0: &full.x0 };
    let j = jackknife::refit_folds(|f| pb(Some(f)), est, &[], k_est, 5, iters, &s, false);
    (full.theta[0], full.std[0], j)
}

#[test]
fn fold_jackknife_is_computed_and_grows_with_model_error() {
    let (_, _, _, force) = recording();
    // Exact nominal: every fold refits, the spread is finite and non-negative, and the
    // combined sigma covers the truth.
    let (est, stat, j) = fit_and_jackknife(4.0, 6);
    assert_eq!(j.folds.len(), 5);
    assert_eq!(j.estimates.len(), 5, "every fold refitted");
    let jk = j.std[0];
    assert!(jk.is_finite() && jk >= 0.0, "jackknife sigma {jk}");
    assert!(
        j.estimates.iter().any(|e| (e[0] - est).abs() > 0.0),
        "fold refits moved from the start: {:?}",
        j.estimates
    );
    let sigma = jackknife::combine(stat, jackknife::jackknife_part(jk, 5));
    assert!(
        (est - force).abs() <= 2.0 * sigma,
        "exact model: {est} +- {sigma} (stat {stat}, jack {jk}) misses {force}"
    );
    // The exact model's sigma is the statistical one (its jackknife, about 0.2 of it here,
    // sees the same noise): the noise is counted once.
    assert_eq!(sigma, stat, "exact model: jackknife part {} below stat {stat}", jackknife::jackknife_part(jk, 5));
    // Negative control: a grossly wrong stiffness (2 instead of 4). The force then stands in
    // for the missing spring force differently in each part of the record (fold estimates
    // 0.02-0.18 here): the fold spread is orders of magnitude larger, its share of the sigma
    // grows (about 0.2 of the statistical sigma on the exact model, about 1 here), and the
    // jackknife's part (widened for its 4 degrees of freedom) sets the reported sigma.
    let (est_w, stat_w, jw) = fit_and_jackknife(2.0, 6);
    assert_eq!(jw.estimates.len(), 5);
    let jkw = jw.std[0];
    eprintln!("exact: {est} stat {stat} jack {jk}; wrong: {est_w} stat {stat_w} jack {jkw} {:?}", jw.estimates);
    assert!(jkw > 100.0 * jk, "wrong model: jackknife {jkw} not well above the exact model's {jk}");
    assert!(jkw / stat_w > 3.0 * jk / stat, "jackknife share: wrong {} vs exact {}", jkw / stat_w, jk / stat);
    let sigma_w = jackknife::combine(stat_w, jackknife::jackknife_part(jkw, 5));
    assert!(
        sigma_w > 1.3 * stat_w && sigma_w == jackknife::jackknife_part(jkw, 5),
        "the jackknife widens the wrong model's sigma: {sigma_w} vs {stat_w}"
    );
    // Negative control: fold "refits" that never leave the full estimate (no iterations) would
    // claim a zero spread; they are not counted, the jackknife is undefined and the sigma falls
    // back to the statistical one instead of a fake zero model error.
    let (_, stat0, j0) = fit_and_jackknife(2.0, 0);
    assert!(j0.estimates.is_empty(), "{:?}", j0.estimates);
    assert!(j0.std[0].is_nan());
    assert_eq!(jackknife::combine(stat0, jackknife::jackknife_part(j0.std[0], j0.estimates.len())), stat0);
}

#[test]
fn the_report_states_both_parts_of_the_sigma() {
    let case = discovery::bench_gen::generate("backlash", 11, 0);
    let run = |jackknife_iter: usize| {
        let s = discovery::DiagnoseSettings {
            initial_state: Some(discovery::InitialState {
                x0: case.nominal.x0.iter().copied().collect(),
                z0: Some(case.nominal.z0.iter().copied().collect()),
            }),
            jackknife_iter,
            ..Default::default()
        };
        discovery::diagnose(&case.nominal, &case.recording, &s).unwrap()
    };
    let r = run(6);
    assert_eq!(r.selected(), "backlash", "{}", r.verdict);
    let j = r.jackknife.as_ref().expect("jackknife of the selected model");
    assert_eq!(j.estimates.len(), 5);
    let e = &r.effects[0];
    for (((u, st), jk), sp) in
        e.uncertainty.iter().zip(&e.uncertainty_statistical).zip(&e.uncertainty_jackknife).zip(&e.uncertainty_stepping)
    {
        assert!(jk.1.is_finite() && jk.1 >= 0.0, "{jk:?}");
        let step = if sp.1.is_finite() { sp.1 } else { 0.0 };
        assert!((u.1 - st.1.max(jk.1).hypot(step)).abs() <= 1e-12 * u.1, "{u:?} from {st:?}, {jk:?} and {sp:?}");
        assert!(u.1 >= st.1);
    }
    assert!(!r.uncertainty_method.contains("not computed"), "{}", r.uncertainty_method);
    assert!(r.to_markdown(&[]).contains("fold jackknife"));
    // Negative control: without the jackknife the sigma is the statistical one and the report
    // says so instead of claiming the model error is covered.
    let r0 = run(0);
    assert!(r0.jackknife.is_none());
    let e0 = &r0.effects[0];
    assert!(e0.uncertainty_jackknife.iter().all(|x| x.1.is_nan()));
    // (The stepping part, where the selected model was refitted at a finer stepping, stays.)
    for ((u, st), sp) in e0.uncertainty.iter().zip(&e0.uncertainty_statistical).zip(&e0.uncertainty_stepping) {
        let step = if sp.1.is_finite() { sp.1 } else { 0.0 };
        assert!((u.1 - st.1.hypot(step)).abs() <= 1e-12 * u.1, "{u:?} from {st:?} and {sp:?}");
    }
    assert!(r0.uncertainty_method.contains("not computed"), "{}", r0.uncertainty_method);
}

/// Issue 27 item 2: backlash inertia read 2-8 % off with a sigma of 0.4-1.3 %. On this case
/// (two-state plant, the generator's converged truth) the fitter stepped the play with 2
/// sub-steps per sample and, the coasting being first order in the step, read the time
/// constant 5.3 % high, 2.6 sigma (statistical and jackknife) off; the reported sigma then
/// included that stepping bias (extrapolated, first order) to cover the truth. Since the
/// coasting play is second order in the step (the output's velocity at a contact by a
/// backward difference, the plant seeing `q` change linearly while the output coasts), the
/// same 2 sub-steps read it 1.8 % high, within 2 sigma without the stepping part, and the
/// stepping part is a small share of the sigma. (The case of the first version of this test,
/// seed 7001 case 1, no longer needs the stepping part once the generator's own truth is
/// converged: part of its bias was the generator's.)
#[test]
fn backlash_inertia_sigma_includes_the_fitters_stepping_bias() {
    let case = discovery::bench_gen::generate("backlash_inertia", 8103, 2);
    let s = discovery::DiagnoseSettings {
        initial_state: Some(discovery::InitialState {
            x0: case.nominal.x0.iter().copied().collect(),
            z0: Some(case.nominal.z0.iter().copied().collect()),
        }),
        ..Default::default()
    };
    let r = discovery::diagnose(&case.nominal, &case.recording, &s).unwrap();
    assert_eq!(r.selected(), "backlash_inertia", "{}", r.verdict);
    let truth = discovery::bench::main_param(case.truth.as_ref().unwrap());
    let e = &r.effects[0];
    let (est, sigma) = (e.params[0].1, e.uncertainty[0].1);
    let (stat, jack, step) =
        (e.uncertainty_statistical[0].1, e.uncertainty_jackknife[0].1, e.uncertainty_stepping[0].1);
    eprintln!("truth {truth} est {est} sigma {sigma} (stat {stat} jack {jack} step {step}), {} sub-steps", r.substeps);
    assert!(step.is_finite() && step > 0.0, "stepping part {step}");
    assert!((est - truth).abs() <= 2.0 * sigma, "{est} +- {sigma} misses {truth}");
    assert!(r.uncertainty_method.contains("s_step"), "{}", r.uncertainty_method);
    assert!(r.to_markdown(&[]).contains(&format!("stepping {step:.2e}")));
    // The stepping bias is gone: the estimate is within 2 % and within 2 sigma without the
    // stepping part, which is under a fifth of the statistical sigma.
    assert!((est / truth - 1.0).abs() < 0.02, "{est} against {truth}");
    assert!((est - truth).abs() <= 2.0 * jackknife_free(stat, jack));
    assert!(step < 0.2 * stat, "stepping part {step} against statistical {stat}");
    // Negative control: the interval is not so wide that it covers a truth 10 % off.
    assert!((est - 1.1 * truth).abs() > 2.0 * sigma, "{est} +- {sigma} covers 1.1 x {truth}");
}

/// The reported sigma without its stepping part: statistical and jackknife parts combined.
fn jackknife_free(stat: f64, jack: f64) -> f64 {
    jackknife::combine(stat, jack)
}

#[test]
fn a_derived_main_parameter_has_a_sigma_that_covers_the_truth() {
    // Mixed-profile seed 9301 case 0 of each class whose main parameter is derived from several
    // fitted ones: a cogging force's amplitude = hypot(amplitude_sin, amplitude_cos) and a
    // Stribeck law's static level = level + static_excess. Before, the report gave them no
    // sigma (the benchmark could not score these classes' coverage at all).
    use discovery::bench;
    use discovery::bench_gen::Profile;
    for class in ["cogging", "stribeck_friction"] {
        let index = if class == "cogging" { 0 } else { 1 };
        let r = bench::run_case_with(class, 9301, index, Profile::Mixed, &discovery::DiagnoseSettings::default());
        assert_eq!(r.predicted, class, "{r:?}");
        let (e, t, sd) = (r.est_param.unwrap(), r.true_param.unwrap(), r.est_std.expect("a derived sigma"));
        assert!(sd.is_finite() && sd > 0.0, "{class}: sigma {sd}");
        assert!((e - t).abs() <= 2.0 * sd, "{class}: {e} +- {sd} against the truth {t}");
        // Negative control: the interval is not vacuous, a truth 30 % off lies outside it.
        assert!((e - 1.3 * t).abs() > 2.0 * sd, "{class}: {e} +- {sd} also covers 1.3 x the truth {t}");
    }
}
