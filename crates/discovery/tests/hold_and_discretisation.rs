//! Issue 13: input hold (exact ZOH / FOH discretisation, `auto` from the data), sub-steps by
//! convergence, stuck fits, starts over decades, blocked cross-validation. Every check has a
//! negative control.
mod common;
use discovery::bench_gen::{self, Profile};
use discovery::diagnose::HoldChoice;
use discovery::fit::{self, FitSettings, FitStatus};
use discovery::hypothesis::{self, Kind, Scales};
use discovery::{diagnose, DiagnoseSettings, InitialState, Recording};
use dynamics::extended::{ExtendedModel, InputHold};
use model::effects::Effect;

fn scalar_sys() -> model::System {
    // x' = -a x + w (a = 2), y = x, no play.
    let text = "name = \"lag\"\n[plant]\nA = [[-2.0]]\nB = [[1.0]]\nC = [[1.0]]\nE = [[0.0]]\n[input]\nkind = \"sine\"\namplitudes = [1.0]\nomega = 1.0\n[initial]\nx0 = [0.0]\nz0 = [0.0]\n";
    model::parse_str(text).unwrap()
}

/// A benchmark case diagnosed with its true initial state handed over, as the benchmark does.
fn diagnose_known_state(case: &bench_gen::Case) -> discovery::Report {
    let s = DiagnoseSettings {
        initial_state: Some(InitialState {
            x0: case.nominal.x0.iter().copied().collect(),
            z0: Some(case.nominal.z0.iter().copied().collect()),
        }),
        ..Default::default()
    };
    diagnose(&case.nominal, &case.recording, &s).unwrap()
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

#[test]
fn zero_order_hold_is_the_exact_discretisation() {
    let sys = scalar_sys();
    let (a, dt) = (2.0f64, 0.1);
    let w: Vec<f64> = (0..200).map(|k| (0.37 * k as f64).sin() + if k % 7 == 0 { 1.0 } else { 0.0 }).collect();
    let ext = ExtendedModel::new(&sys, &[], dt, 1).unwrap().with_hold(InputHold::Zoh);
    let y = ext.simulate(&w, dt, &[0.3]).y;
    // x_{k+1} = e^{-a dt} x_k + (1 - e^{-a dt}) / a w_k.
    let phi = (-a * dt).exp();
    let mut x = 0.3;
    let mut exact = Vec::new();
    for &wk in &w {
        exact.push(x);
        x = phi * x + (1.0 - phi) / a * wk;
    }
    assert!(max_diff(&y, &exact) < 1e-13, "ZOH off the closed form by {}", max_diff(&y, &exact));
    // Negative control: linear interpolation (the former assumption) is a different model.
    let yf = ExtendedModel::new(&sys, &[], dt, 1).unwrap().simulate(&w, dt, &[0.3]).y;
    assert!(max_diff(&yf, &exact) > 1e-3);
}

/// The signal the plant sees, sampled on a grid `L` times finer, for each hold and delay.
fn fine_input(w: &[f64], dt: f64, delay: f64, l: usize, hold: InputHold) -> Vec<f64> {
    let n = w.len();
    (0..(n - 1) * l + 1)
        .map(|j| {
            let tau = j as f64 / l as f64 - delay / dt;
            match hold {
                InputHold::Zoh => w[if tau <= 0.0 { 0 } else { ((tau + 1e-9).floor() as usize).min(n - 1) }],
                InputHold::Foh => {
                    if tau <= 0.0 {
                        w[0]
                    } else {
                        let i = (tau.floor() as usize).min(n - 2);
                        let f = tau - i as f64;
                        w[i] * (1.0 - f) + w[i + 1] * f
                    }
                }
            }
        })
        .collect()
}

#[test]
fn a_delay_between_samples_is_integrated_exactly_for_both_holds() {
    let sys = scalar_sys();
    let dt = 0.1;
    let w: Vec<f64> = (0..120).map(|k| (0.29 * k as f64).sin() + 0.5 * (1.3 * k as f64).cos()).collect();
    let delay = 0.23 * dt + 2.0 * dt; // breakpoints 0.23 of the way into each interval
    let l = 100; // 0.23 dt lies on the fine grid
    for hold in [InputHold::Zoh, InputHold::Foh] {
        let coarse = ExtendedModel::new(&sys, &[Effect::InputDelay { delay }], dt, 1)
            .unwrap()
            .with_hold(hold)
            .simulate(&w, dt, &[0.0])
            .y;
        // Reference: the same continuous input, on a fine grid whose samples contain every
        // breakpoint, without delay (for ZOH the fine samples are held, for FOH interpolated).
        let wf = fine_input(&w, dt, delay, l, hold);
        let fine = ExtendedModel::new(&sys, &[], dt / l as f64, 1)
            .unwrap()
            .with_hold(hold)
            .simulate(&wf, dt / l as f64, &[0.0])
            .y;
        let at: Vec<f64> = (0..w.len()).map(|k| fine[k * l]).collect();
        let d = max_diff(&coarse, &at);
        assert!(d < 1e-10, "{hold:?}: delayed input off the exact response by {d}");
        // Negative control: the delay rounded to whole samples is visibly different.
        let rounded = ExtendedModel::new(&sys, &[Effect::InputDelay { delay: 2.0 * dt }], dt, 1)
            .unwrap()
            .with_hold(hold)
            .simulate(&w, dt, &[0.0])
            .y;
        assert!(max_diff(&rounded, &at) > 1e-3, "{hold:?}: rounding the delay went unnoticed");
    }
}

#[test]
fn auto_hold_follows_the_data_and_removes_the_spurious_delay() {
    // A digital-profile recording (zero-order-held command) of an exact nominal model.
    let case = bench_gen::generate_profile("none", 1, 0, Profile::Digital);
    let known = InitialState {
        x0: case.nominal.x0.iter().copied().collect(),
        z0: Some(case.nominal.z0.iter().copied().collect()),
    };
    let s = DiagnoseSettings { initial_state: Some(known.clone()), ..Default::default() };
    let r = diagnose(&case.nominal, &case.recording, &s).unwrap();
    assert_eq!(r.hold.chosen, "zoh", "{:?}", r.hold);
    assert!(r.hold.decisive, "{:?}", r.hold);
    assert_eq!(r.selected(), "none", "false alarm under the right hold: {}", r.verdict);
    // Negative control: forcing linear interpolation on the same recording "repairs" it with
    // an input delay of about half a sample (the failure of issue 13).
    let sf = DiagnoseSettings {
        input_hold: HoldChoice::Fixed(InputHold::Foh),
        initial_state: Some(known),
        ..Default::default()
    };
    let rf = diagnose(&case.nominal, &case.recording, &sf).unwrap();
    assert_eq!(rf.selected(), "input_delay", "{}", rf.verdict);
    let d = rf.effects[0].params[0].1;
    let h = case.recording.dt;
    assert!((d / h - 0.5).abs() < 0.15, "spurious delay {d} against h/2 = {}", h / 2.0);
    // And a recording of a continuous input (classic profile) is read as first-order hold.
    let c = bench_gen::generate("none", 1, 0);
    let rc = diagnose(&c.nominal, &c.recording, &DiagnoseSettings::default()).unwrap();
    assert_eq!(rc.hold.chosen, "foh", "{:?}", rc.hold);
}

#[test]
fn sub_steps_are_chosen_by_convergence_with_the_play() {
    // A wide play in the loop: the eigenvalue rule asks for 1 sub-step, the play's catching-up
    // projection needs more.
    let text = "name = \"play\"\n[plant]\nA = [[0.0, 1.0], [-4.0, -0.4]]\nB = [[0.0], [4.0]]\nC = [[1.0, 0.0]]\nE = [[0.0], [-4.0]]\n[theta]\nshape = \"interval\"\nhalf_width = 0.3\n[input]\nkind = \"sine\"\namplitudes = [1.0]\nomega = 1.0\n[initial]\nx0 = [0.0, 0.0]\nz0 = [0.0]\n";
    let sys = model::parse_str(text).unwrap();
    let dt = 0.05;
    let w: Vec<f64> = (0..2000).map(|k| (0.9 * k as f64 * dt).sin() + 0.4 * (2.7 * k as f64 * dt).sin()).collect();
    let sim = |k: usize| Some(ExtendedModel::new(&sys, &[], dt, k).unwrap().simulate(&w, dt, &[0.0, 0.0]).y);
    let y = sim(1).unwrap();
    let m = y.iter().sum::<f64>() / y.len() as f64;
    let sd = (y.iter().map(|v| (v - m).powi(2)).sum::<f64>() / y.len() as f64).sqrt();
    let tol = 1e-3; // in units of the output's standard deviation
    let c = discovery::discretisation::converge(sim, 1, 64, &[1.0 / sd], tol);
    assert!(c.converged && c.substeps > 1, "{c:?}");
    assert!(c.ladder[0].1 > tol, "k = 1 already converged: {c:?}");
    // The reported error bounds the true error of the chosen k (reference: 256 sub-steps).
    let truth = sim(256).unwrap();
    let err = discovery::discretisation::rms_w(&sim(c.substeps).unwrap(), &truth, &[1.0 / sd]);
    assert!(err <= c.error_rms * 1.5, "true error {err} above the estimate {}", c.error_rms);
    // Negative control: capped at 1 sub-step it is reported as not converged.
    let c1 = discovery::discretisation::converge(sim, 1, 1, &[1.0 / sd], tol);
    assert!(!c1.converged && c1.substeps == 1);
}

/// A mass with Coulomb friction at 0.2 % of the hypothesis' bound (issue 13, cause 3).
fn small_friction_problem() -> (model::System, Vec<f64>, Vec<f64>, f64, Scales) {
    let text = "name = \"mass\"\n[plant]\nA = [[0.0, 1.0], [-1.0, -0.04]]\nB = [[0.0], [1.0]]\nC = [[1.0, 0.0]]\nE = [[0.0], [0.0]]\n[input]\nkind = \"sine\"\namplitudes = [1.0]\nomega = 1.0\n[initial]\nx0 = [0.0, 0.0]\nz0 = [0.0]\n";
    let sys = model::parse_str(text).unwrap();
    let dt = 0.05;
    let n = 1500;
    // Near resonance of a lightly damped mass (Q = 25): the output range, and with it the
    // friction bound range(y) / static gain, is far above the driving force.
    let w: Vec<f64> = (0..n).map(|k| 0.5 * (k as f64 * dt).sin() + 0.2 * (0.6 * k as f64 * dt + 1.0).sin()).collect();
    let y0 = ExtendedModel::new(&sys, &[], dt, 4).unwrap().simulate(&w, dt, &[0.0, 0.0]).y;
    let yr = y0.iter().copied().fold(f64::NEG_INFINITY, f64::max) - y0.iter().copied().fold(f64::INFINITY, f64::min);
    let scales = Scales {
        y_range: vec![yr],
        w_range: vec![3.0],
        w_absmax: 1.5,
        tau_slow: 6.7,
        dt,
        duration: n as f64 * dt,
        ..Default::default()
    };
    let bound = yr; // static gain 1: the hypothesis' bound is range(y)
    let level = 0.002 * bound; // 0.2 % of the bound
    let y = ExtendedModel::new(&sys, &[Effect::CoulombFriction { state: 1, level }], dt, 4)
        .unwrap()
        .simulate(&w, dt, &[0.0, 0.0])
        .y;
    (sys, w, y, level, scales)
}

#[test]
fn starts_over_decades_find_a_small_friction_and_stuck_fits_are_flagged() {
    let (sys, w, y, level, scales) = small_friction_problem();
    let h = hypothesis::candidates(&sys, &scales)
        .into_iter()
        .find(|h| h.kind == Kind::CoulombFriction { state: 1 })
        .unwrap();
    assert!((h.upper[0] / level - 500.0).abs() < 1.0, "truth at 0.2 % of the bound");
    let pb = |h: &hypothesis::Hypothesis| common::scalar_problem(&sys, h, &scales, &w, &y, w.len(), 1.0, 4);
    // Known initial state (empty x scale).
    let r = fit::fit(&pb(&h), &[0.0, 0.0], &[], None, &FitSettings::default());
    assert!((r.theta[0] / level - 1.0).abs() < 0.05, "decade starts: level {} vs {level}", r.theta[0]);
    assert!(r.status.conclusive(), "{:?}", r.status);
    // Negative control: the former starts at 10/40/80 % of the bound (linear coordinates)
    // stick the mass for the whole record: zero gradient, flagged as stuck.
    let mut old = h.clone();
    old.log_shift = vec![None];
    old.starts = vec![vec![0.1], vec![0.4], vec![0.8]];
    let r = fit::fit(&pb(&old), &[0.0, 0.0], &[], None, &FitSettings::default());
    assert_eq!(r.status, FitStatus::ZeroGradient, "level {} ({:?})", r.theta[0], r.status);
    assert!(!r.status.conclusive());
}

#[test]
fn an_effect_confined_to_one_fold_is_reported_not_testable() {
    // Input saturation that only the first fifth of the record reaches: blocked
    // cross-validation cannot test it (the other folds never clip); it is accepted on the
    // estimation evidence with that status. Negative control: clipping spread over the
    // record passes cross-validation.
    let case = bench_gen::generate("none", 5, 0);
    let sys = &case.nominal;
    let dt = case.recording.dt;
    let n = case.recording.len();
    let x0: Vec<f64> = sys.x0.iter().copied().collect();
    let run = |amp: &dyn Fn(usize) -> f64| {
        let w: Vec<f64> =
            (0..n).map(|k| amp(k) * ((0.8 * k as f64 * dt).sin() + 0.4 * (0.31 * k as f64 * dt + 1.0).sin())).collect();
        let truth = [Effect::InputSaturation { limit: 0.9 }];
        let clean = ExtendedModel::new(sys, &truth, dt, 8).unwrap().simulate(&w, dt, &x0).y;
        let sd = {
            let m = clean.iter().sum::<f64>() / n as f64;
            (clean.iter().map(|v| (v - m).powi(2)).sum::<f64>() / n as f64).sqrt()
        };
        // Deterministic pseudo-noise at about 1 % of the output's spread.
        let y: Vec<Vec<f64>> = clean
            .iter()
            .enumerate()
            .map(|(k, v)| vec![v + 0.01 * sd * 3f64.sqrt() * 2.0 * (((k * 7919) % 1000) as f64 / 1000.0 - 0.5)])
            .collect();
        let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        let rec = Recording::from_samples("sat", &t, w.iter().map(|v| vec![*v]).collect(), y, None);
        let s = DiagnoseSettings {
            initial_state: Some(InitialState { x0: x0.clone(), z0: None }),
            input_hold: HoldChoice::Fixed(InputHold::Foh),
            max_effects: 1,
            ..Default::default()
        };
        diagnose(sys, &rec, &s).unwrap()
    };
    let r = run(&|k| if k < n / 6 { 1.4 } else { 0.6 });
    assert_eq!(r.selected(), "input_saturation", "{}", r.verdict);
    let sat = r.ranking.iter().find(|x| x.label == "input_saturation").unwrap();
    let cv = sat.cv.as_ref().expect("cross-validated");
    assert_eq!(cv.status, "not_testable", "{cv:?}");
    assert!(r.verdict.contains("not testable"), "{}", r.verdict);
    let r2 = run(&|_| 1.4);
    assert_eq!(r2.selected(), "input_saturation", "{}", r2.verdict);
    let cv2 = r2.ranking.iter().find(|x| x.label == "input_saturation").unwrap().cv.clone().unwrap();
    assert_eq!(cv2.status, "passed", "{cv2:?}");
}

#[test]
fn a_hold_switched_by_one_effect_is_undone_by_the_selected_model() {
    // Digital-profile seed 10721, Coulomb friction + backlash inertia #1, a zero-order-held
    // recording: a single effect that misses the other fitted 315.9 better under the
    // first-order hold, the hold was switched, and under it the selection settled on backlash
    // inertia + load-dependent friction, 355 in BIC worse than the true pair under the
    // zero-order hold. The selected model is now refitted under the nominal's hold, prefers
    // it, and the switch is undone. (A switch the selected model confirms stands:
    // `a_delay_under_half_a_sample_is_found_under_the_other_hold` in
    // `hold_delay_and_stepping.rs`, read under the first-order hold.)
    let case = bench_gen::generate_pair(["coulomb_friction", "backlash_inertia"], 10721, 1, Profile::Digital).unwrap();
    let r = diagnose_known_state(&case);
    // Control: the effects did switch the hold first.
    assert!(r.notes.iter().any(|n| n.contains("the diagnosis was redone with foh")), "{:?}", r.notes);
    assert!(r.notes.iter().any(|n| n.contains("the switch was undone")), "{:?}", r.notes);
    assert_eq!((r.hold.chosen, r.hold.switched), ("zoh", false), "{:?}", r.hold);
    let kinds: Vec<&str> = r.effects.iter().map(|e| e.kind.as_str()).collect();
    assert!(kinds.contains(&"coulomb_friction") && kinds.contains(&"backlash_inertia"), "{}", r.verdict);
}

#[test]
fn a_delay_carried_to_the_other_hold_starts_half_a_sample_away() {
    // Mixed-profile seed 10801, input delay #1: a continuous command delayed by 1.42 ms, sampled
    // at 3.34 ms. Under the zero-order hold the delay reads -0.25 ms, clipped to 0; the delay
    // fitted under the first-order hold switched the hold. The next pass started each single
    // from its fit of the pass before, the delay from 0, where its fit did not move (+-6.5 in
    // BIC, nothing selected). A change of hold moves a delay by h/2, and its start is moved so.
    let case = bench_gen::generate_profile("input_delay", 10801, 1, Profile::Mixed);
    let r = diagnose_known_state(&case);
    // Control: the effects switched the hold, so the second pass started from the first one's fits.
    assert!(r.notes.iter().any(|n| n.contains("the diagnosis was redone with foh")), "{:?}", r.notes);
    assert_eq!(r.selected(), "input_delay", "{}", r.verdict);
    let d = r.effects[0].params[0].1;
    let truth = 1.4157615816645806e-3;
    assert!((d - truth).abs() < 0.1 * truth, "delay {d:.4e} against {truth:.4e}");
}

#[test]
fn the_selected_model_overturns_a_hold_that_no_single_effect_did() {
    // Digital-profile pairs seed 10726, constant force + backlash inertia #0, a zero-order-held
    // recording: the nominal model prefers the first-order hold by 89.2 in BIC, and no single
    // effect fits better under the other. The pair selected under the first-order hold left a
    // residual Q of 2684; refitted under the zero-order hold it fits 761 better, and the
    // diagnosis is redone there.
    let case = bench_gen::generate_pair(["constant_force", "backlash_inertia"], 10726, 0, Profile::Digital).unwrap();
    let r = diagnose_known_state(&case);
    // Control: the nominal model did prefer the first-order hold.
    assert!(r.hold.sse_foh.unwrap() < r.hold.sse_zoh.unwrap(), "{:?}", r.hold);
    assert!(r.notes.iter().any(|n| n.contains("the model selected under it")), "{:?}", r.notes);
    assert_eq!((r.hold.chosen, r.hold.switched), ("zoh", true), "{:?}", r.hold);
    let kinds: Vec<&str> = r.effects.iter().map(|e| e.kind.as_str()).collect();
    assert!(kinds.contains(&"constant_force") && kinds.contains(&"backlash_inertia"), "{}", r.verdict);
    assert!(!r.model_incomplete, "{}", r.verdict);
}

#[test]
fn the_model_that_switched_the_hold_stands_where_the_redone_selection_ends_worse() {
    // Classic-profile pairs seed 10814, gap width + Coulomb friction #0, a continuous command
    // sampled at 101 ms: the nominal model prefers the zero-order hold by 661.8, the pair
    // selected under it fits 737 better under the first-order hold, and the selection redone
    // there read an input backlash (residual Q 2015). The pair refitted under the new hold
    // stands: it fits better than what the redone selection found.
    let case = bench_gen::generate_pair(["gap_width", "coulomb_friction"], 10814, 0, Profile::Classic).unwrap();
    let r = diagnose_known_state(&case);
    // Control: the selected model switched the hold.
    assert!(r.notes.iter().any(|n| n.contains("the model selected under it")), "{:?}", r.notes);
    assert!(r.notes.iter().any(|n| n.contains("that model stands")), "{:?}", r.notes);
    let kinds: Vec<&str> = r.effects.iter().map(|e| e.kind.as_str()).collect();
    assert!(kinds.contains(&"gap_width") && kinds.contains(&"coulomb_friction"), "{}", r.verdict);
    assert!(!r.model_incomplete, "{}", r.verdict);
}

#[test]
fn a_first_order_held_delay_under_half_a_sample_beside_an_offset_switches_the_hold() {
    // Mixed-profile pairs seed 10914, input delay + sensor offset #1: a first-order-held
    // command delayed by 6.3 ms, sampled at 15.1 ms. The nominal model prefers the zero-order
    // hold by 124.4 in BIC; there the delay would be negative, so sensor offset + input delay
    // read it as 0 (+2188.5) and sensor offset + backlash inertia was selected (+2293.5). Under
    // the first-order hold the true pair fits better and is selected.
    let case = bench_gen::generate_pair(["input_delay", "sensor_offset"], 10914, 1, Profile::Mixed).unwrap();
    let r = diagnose_known_state(&case);
    // Control: the nominal model did prefer the zero-order hold.
    assert!(r.hold.sse_zoh.unwrap() < r.hold.sse_foh.unwrap(), "{:?}", r.hold);
    assert!(r.notes.iter().any(|n| n.contains("reads its delay as 0")), "{:?}", r.notes);
    assert_eq!((r.hold.chosen, r.hold.switched), ("foh", true), "{:?}", r.hold);
    let kinds: Vec<&str> = r.effects.iter().map(|e| e.kind.as_str()).collect();
    assert!(kinds.contains(&"input_delay") && kinds.contains(&"sensor_offset"), "{}", r.verdict);
    let d = r.effects.iter().find(|e| e.kind == "input_delay").unwrap();
    let (est, sd) = (d.params[0].1, d.uncertainty[0].1);
    let truth = 0.006279839857144656;
    assert!((est - truth).abs() <= 2.0 * sd, "delay {est:.4e} +- {sd:.1e} against {truth:.4e}");
}

#[test]
fn a_delay_at_zero_under_a_zero_order_held_recording_leaves_the_hold() {
    // Negative control of the check above: a zero-order-held recording with a sensor offset
    // alone. The input delay reads 0 there too, but under the first-order hold (delay near
    // h/2) it fits no better than the offset selected under the zero-order hold: the hold
    // stays, nothing is added beside the offset.
    let case = (0..16)
        .map(|i| bench_gen::generate_profile("sensor_offset", 4242, i, Profile::Digital))
        .find(|c| c.conditions.hold == "zoh")
        .expect("a zero-order-held case");
    let r = diagnose_known_state(&case);
    let dt = case.conditions.dt;
    // The check had a model to ask: a delay read as 0.
    assert!(
        r.ranking
            .iter()
            .any(|c| c.kinds.iter().any(|k| k == "input_delay") && c.params.last().is_some_and(|&d| d <= 1e-3 * dt)),
        "{:?}",
        r.ranking.iter().map(|c| (&c.label, &c.params)).collect::<Vec<_>>()
    );
    assert!(!r.notes.iter().any(|n| n.contains("reads its delay as 0")), "{:?}", r.notes);
    assert_eq!((r.hold.chosen, r.hold.switched), ("zoh", false), "{:?}", r.hold);
    assert_eq!(r.selected(), "sensor_offset", "{}", r.verdict);
}
