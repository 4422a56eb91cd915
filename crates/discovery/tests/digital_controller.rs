//! Digital controllers in the loop (issue 28 item 2): the physical model of a carriage under a
//! sampled cascade (`[controller]`), refitted by `diagnose` on one kind of experiment,
//! predicts another kind.
//!
//! Fast tests use development seed 1. The measurement over fresh seeds is
//! `digital_controller_benchmark` (ignored): `cargo test -p discovery --release --test
//! digital_controller -- --ignored --nocapture`, seeds from `CASCADE_SEEDS` (default `1`),
//! plants per seed from `CASCADE_PLANTS` (default 4, from `CASCADE_FIRST_PLANT`, default 0),
//! sub-steps per sample `CASCADE_SUBSTEPS` (default 16; each fit is repeated at twice as many
//! and the largest parameter shift reported in sigma).
use discovery::bench_gen::servo_cascade::{self as sc, CascadeTruth, Experiment};
use discovery::{diagnose, DiagnoseSettings, InitialState, Recording};
use dynamics::extended::ExtendedModel;
use model::System;

/// The nominal's departure from the truth: mass +25 %, viscous x 1.6, Coulomb x 0.6.
/// The controller's gains `(kp, kv)` as the model file states them.
fn nominal(tr: &CascadeTruth, gains: (f64, f64)) -> System {
    model::parse_str(&sc::model_text(1.25 * tr.mass, 1.6 * tr.viscous, 0.6 * tr.coulomb, gains, sc::DELAY)).unwrap()
}

fn settings(max_effects: usize, substeps: Option<usize>) -> DiagnoseSettings {
    let mut s = DiagnoseSettings {
        initial_state: Some(InitialState { x0: vec![0.0, 0.0], z0: Some(vec![0.0]) }),
        max_effects,
        ..Default::default()
    };
    if let Some(k) = substeps {
        s.max_substeps = k;
        s.substep_ratio = 1e9; // start at the cap
    }
    s
}

/// RMSE of `sys` simulated (from rest) on the whole of `rec`.
fn rmse_on(sys: &System, rec: &Recording, substeps: usize) -> f64 {
    let w: Vec<f64> = rec.w.iter().map(|r| r[0]).collect();
    let y: Vec<f64> = rec.y.iter().map(|r| r[0]).collect();
    let o = ExtendedModel::new(sys, &[], rec.dt, substeps).unwrap().simulate(&w, rec.dt, &[0.0, 0.0]);
    (o.y.iter().zip(&y).map(|(a, b)| (a - b).powi(2)).sum::<f64>() / y.len() as f64).sqrt()
}

/// The fitted `M`, `Fv`, `Fc` and their 1-sigma.
fn physical(r: &discovery::Report) -> [(f64, f64); 3] {
    let get = |name: &str| {
        let v = r.nominal_refit.iter().find(|v| v.name == name);
        v.map_or((f64::NAN, f64::NAN), |v| (v.value, v.std))
    };
    [get("M"), get("Fv"), get("Fc")]
}

#[test]
fn the_refitted_cascade_model_predicts_the_other_experiment() {
    let (seed, idx) = (1, 0);
    let tr = sc::truth(seed, idx);
    let multi = sc::record(seed, idx, Experiment::Multisine);
    let tri = sc::record(seed, idx, Experiment::Triangle);
    let r = diagnose(&nominal(&tr, (tr.kp, tr.kv)), &multi, &settings(0, None)).unwrap();
    let p = physical(&r);
    eprintln!("{}\nsubsteps {}\n{:?}\ntruth {tr:?}", r.verdict, r.substeps, p);
    let fitted = r.fitted_model.as_ref().unwrap();
    let pred = rmse_on(fitted, &tri, r.substeps);
    let direct = diagnose(&nominal(&tr, (tr.kp, tr.kv)), &tri, &settings(0, None)).unwrap();
    let own = rmse_on(direct.fitted_model.as_ref().unwrap(), &tri, direct.substeps);
    eprintln!("prediction RMSE on the triangle {pred:e}, direct fit {own:e}, ratio {:.3}", pred / own);
    for ((v, _), truth) in p.iter().zip([tr.mass, tr.viscous, tr.coulomb]) {
        assert!((v / truth - 1.0).abs() < 0.05, "{v} against {truth}");
    }
    assert!(pred <= 1.2 * own, "{pred:e} against {own:e}");
}

#[test]
fn a_wrong_controller_gain_is_detected_by_a_worse_fit() {
    // Negative control of the refit, on the clean recording (no quantisation, no noise: the
    // recording's 0.4 um noise floor hides model errors below it). The position gain 2x off
    // in the model file is nearly absorbed by M, Fv, Fc (u = kv (kp (w - y) - v_hat): M, Fv,
    // Fc scaled and Fv raised by the moved share of kv reproduce the motion except for the
    // lag of v_hat behind v); the fit is still measurably worse. The correct gains reach the
    // stepping error only.
    let (seed, idx) = (1, 0);
    let tr = sc::truth(seed, idx);
    let clean = sc::record_with_noise(seed, idx, Experiment::Multisine, false);
    let good = diagnose(&nominal(&tr, (tr.kp, tr.kv)), &clean, &settings(0, None)).unwrap();
    let bad = diagnose(&nominal(&tr, (2.0 * tr.kp, tr.kv)), &clean, &settings(0, None)).unwrap();
    let (e_good, e_bad) = (good.fit_after.rmse[0], bad.fit_after.rmse[0]);
    eprintln!(
        "clean recording: validation RMSE with the true kp {e_good:e}, with kp x 2 {e_bad:e}\n{}\n{}",
        good.verdict, bad.verdict
    );
    assert!(e_bad > 3.0 * e_good, "{e_bad:e} against {e_good:e}");
    // and a computation delay left out is seen on the noisy recording itself
    let multi = sc::record(seed, idx, Experiment::Multisine);
    let text = sc::model_text(1.25 * tr.mass, 1.6 * tr.viscous, 0.6 * tr.coulomb, (tr.kp, tr.kv), 0);
    let no_delay = diagnose(&model::parse_str(&text).unwrap(), &multi, &settings(0, None)).unwrap();
    let with_delay = diagnose(&nominal(&tr, (tr.kp, tr.kv)), &multi, &settings(0, None)).unwrap();
    let (e0, e1) = (no_delay.fit_after.rmse[0], with_delay.fit_after.rmse[0]);
    eprintln!("noisy recording: validation RMSE without the computation delay {e0:e}, with it {e1:e}");
    assert!(e0 > 1.5 * e1, "{e0:e} against {e1:e}");
}

/// Full diagnosis (effects searched) of the multisine case with `text` as the model.
fn full(text: &str, rec: &Recording) -> discovery::Report {
    diagnose(&model::parse_str(text).unwrap(), rec, &settings(2, None)).unwrap()
}

#[test]
fn with_the_digital_controller_no_spurious_effect_is_added() {
    // The continuous stand-in for the cascade (no sampling, hold or computation delay) has to
    // explain the loop's phase lag by something (on this case Stribeck friction and an input
    // delay; input saturation on a fresh seed, BENCHMARKS.md); the model with `[controller]`
    // needs none.
    let (seed, idx) = (1, 0);
    let tr = sc::truth(seed, idx);
    let multi = sc::record(seed, idx, Experiment::Multisine);
    let (m0, v0, c0) = (1.25 * tr.mass, 1.6 * tr.viscous, 0.6 * tr.coulomb);
    let digital = full(&sc::model_text(m0, v0, c0, (tr.kp, tr.kv), sc::DELAY), &multi);
    let stand_in = full(&sc::stand_in_text(&tr, m0, v0, c0), &multi);
    eprintln!(
        "digital: {} | {}\nstand-in: {} | {}",
        digital.selected(),
        digital.verdict,
        stand_in.selected(),
        stand_in.verdict
    );
    assert_eq!(digital.selected(), "none", "{}", digital.verdict);
    assert_ne!(stand_in.selected(), "none", "{}", stand_in.verdict);
    // The stand-in fits worse, or stands in for the controller's sampling and computation
    // delay by an input delay (found since the selection goes on while the residual says
    // something is left, issue 27 item 4).
    assert!(
        stand_in.fit_after.rmse[0] > 2.0 * digital.fit_after.rmse[0]
            || stand_in.effects.iter().any(|e| e.kind == "input_delay"),
        "{}",
        stand_in.verdict
    );
}

fn env_list(name: &str, default: &str) -> Vec<u64> {
    std::env::var(name).unwrap_or_else(|_| default.into()).split(',').filter_map(|s| s.trim().parse().ok()).collect()
}

#[test]
#[ignore = "benchmark: about a minute per plant at 16 sub-steps; see the module documentation"]
fn digital_controller_benchmark() {
    let seeds = env_list("CASCADE_SEEDS", "1");
    let plants = env_list("CASCADE_PLANTS", "4").first().copied().unwrap_or(4) as usize;
    let first = env_list("CASCADE_FIRST_PLANT", "0").first().copied().unwrap_or(0) as usize;
    // sub-steps per sample of the fits (Coulomb friction is stepped implicitly, first order at
    // the stick-slip transitions): K, checked against 2K
    #[allow(non_snake_case)]
    let K = env_list("CASCADE_SUBSTEPS", "16").first().copied().unwrap_or(16) as usize;
    println!("| seed | plant | M err % | Fv err % | Fc err % | max shift at 2K sub-steps (sigma) | multisine fit -> triangle RMSE (um) | triangle fit on triangle (um) | ratio | triangle fit: M / Fv / Fc err % (M err / its sigma) | triangle fit -> multisine (um) | multisine fit on multisine (um) | ratio |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    let (mut worst_err, mut worst_ratio, mut worst_shift) = (0.0f64, 0.0f64, 0.0f64);
    for &seed in &seeds {
        for idx in first..first + plants {
            let tr = sc::truth(seed, idx);
            let multi = sc::record(seed, idx, Experiment::Multisine);
            let tri = sc::record(seed, idx, Experiment::Triangle);
            let nom = nominal(&tr, (tr.kp, tr.kv));
            let on_multi = diagnose(&nom, &multi, &settings(0, Some(K))).unwrap();
            let on_tri = diagnose(&nom, &tri, &settings(0, Some(K))).unwrap();
            let k = on_multi.substeps;
            assert_eq!(k, K);
            let finer = diagnose(&nom, &multi, &settings(0, Some(2 * k))).unwrap();
            assert_eq!(finer.substeps, 2 * K);
            let (p, pf) = (physical(&on_multi), physical(&finer));
            let errs: Vec<f64> =
                p.iter().zip([tr.mass, tr.viscous, tr.coulomb]).map(|((v, _), t)| 100.0 * (v / t - 1.0)).collect();
            let shift = p.iter().zip(&pf).map(|((a, s), (b, _))| (a - b).abs() / s).fold(0.0, f64::max);
            let fm = on_multi.fitted_model.as_ref().unwrap();
            let ft = on_tri.fitted_model.as_ref().unwrap();
            let (pred_tri, own_tri) = (rmse_on(fm, &tri, k), rmse_on(ft, &tri, on_tri.substeps));
            let (pred_multi, own_multi) = (rmse_on(ft, &multi, on_tri.substeps), rmse_on(fm, &multi, k));
            let (r1, r2) = (pred_tri / own_tri, pred_multi / own_multi);
            let tri_errs: Vec<String> = physical(&on_tri)
                .iter()
                .zip([tr.mass, tr.viscous, tr.coulomb])
                .map(|((v, _), t)| format!("{:+.2}", 100.0 * (v / t - 1.0)))
                .collect();
            let (m_t, m_sd) = physical(&on_tri)[0];
            let m_tri = format!("{} ({:+.1})", tri_errs.join(" / "), (m_t - tr.mass) / m_sd);
            println!(
                "| {seed} | {idx} | {:+.2} | {:+.2} | {:+.2} | {shift:.3} | {:.3} | {:.3} | {r1:.3} | {m_tri} | {:.3} | {:.3} | {r2:.3} |",
                errs[0],
                errs[1],
                errs[2],
                pred_tri * 1e6,
                own_tri * 1e6,
                pred_multi * 1e6,
                own_multi * 1e6
            );
            worst_err = errs.iter().fold(worst_err, |a, e| a.max(e.abs()));
            worst_ratio = worst_ratio.max(r1);
            worst_shift = worst_shift.max(shift);
        }
    }
    println!("K = {K}: worst |parameter error| {worst_err:.2} %, worst multisine -> triangle ratio {worst_ratio:.3}, worst shift at 2K sub-steps {worst_shift:.3} sigma");
    // acceptance of issue 28; the sub-step shift is reported (first order in 1/K: friction is
    // stepped implicitly inside each tick), not asserted
    assert!(worst_err < 5.0 && worst_ratio <= 1.2, "{worst_err} % {worst_ratio}");
}

#[test]
#[ignore = "benchmark: about a minute per plant; see the module documentation"]
fn stand_in_benchmark() {
    // Full diagnoses (effects searched) of the multisine recordings: the model with
    // `[controller]` against the continuous stand-in. Seeds and plants as the benchmark above.
    let seeds = env_list("CASCADE_SEEDS", "1");
    let plants = env_list("CASCADE_PLANTS", "4").first().copied().unwrap_or(4) as usize;
    println!("| seed | plant | [controller]: selected | validation RMSE (um) | M err % | stand-in: selected | validation RMSE (um) | M err % |");
    println!("|---|---|---|---|---|---|---|---|");
    let mut spurious = (0, 0);
    for &seed in &seeds {
        for idx in 0..plants {
            let tr = sc::truth(seed, idx);
            let multi = sc::record(seed, idx, Experiment::Multisine);
            let (m0, v0, c0) = (1.25 * tr.mass, 1.6 * tr.viscous, 0.6 * tr.coulomb);
            let d = full(&sc::model_text(m0, v0, c0, (tr.kp, tr.kv), sc::DELAY), &multi);
            let s = full(&sc::stand_in_text(&tr, m0, v0, c0), &multi);
            let m_err = |r: &discovery::Report| 100.0 * (physical(r)[0].0 / tr.mass - 1.0);
            println!(
                "| {seed} | {idx} | {} | {:.3} | {:+.2} | {} | {:.3} | {:+.2} |",
                d.selected(),
                d.fit_after.rmse[0] * 1e6,
                m_err(&d),
                s.selected(),
                s.fit_after.rmse[0] * 1e6,
                m_err(&s)
            );
            spurious.0 += usize::from(d.selected() != "none");
            spurious.1 += usize::from(s.selected() != "none");
        }
    }
    println!("effects added: with [controller] {}, continuous stand-in {}", spurious.0, spurious.1);
}
