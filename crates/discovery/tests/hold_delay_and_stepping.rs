//! Issue 27 items 1 and 3: a delay under an unknown input hold (its interval covers both
//! readings where the recording cannot tell the holds apart; the report's header states the
//! hold used) and a discretisation converged before judging (the generator's delayed held
//! input integrated exactly; an effect whose gain is the simulator's stepping error is not
//! reported; a stated stepping error above the noise is not accepted).
use discovery::bench;
use discovery::bench_gen::plant_sim;
use discovery::bench_gen::{self, Profile};
use discovery::bench_gen::{Plant, Signal};
use discovery::diagnose::{HoldChoice, HoldReport};
use discovery::{diagnose, DiagnoseSettings, InitialState};
use dynamics::extended::{ExtendedModel, InputHold};
use model::effects::Effect;
use nalgebra::DMatrix;

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

/// Default settings with the case's true initial state (as `bench::run_case_with` passes it).
fn with_known_state(case: &bench_gen::Case) -> DiagnoseSettings {
    let known = InitialState {
        x0: case.nominal.x0.iter().copied().collect(),
        z0: Some(case.nominal.z0.iter().copied().collect()),
    };
    DiagnoseSettings { initial_state: Some(known), ..DiagnoseSettings::default() }
}

/// A damped oscillator without play, as the generator and as a model file.
fn oscillator() -> (Plant, model::System) {
    let pl = Plant {
        A: DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -25.0, -3.0]),
        B: DMatrix::from_row_slice(2, 1, &[0.0, 25.0]),
        C: DMatrix::from_row_slice(1, 2, &[1.0, 0.0]),
        E: DMatrix::from_row_slice(2, 1, &[0.0, 0.0]),
        half_width: 0.0,
        vel: 1,
        omega0: 5.0,
        zeta: 0.3,
    };
    let text = "name = \"osc\"\n[plant]\nA = [[0.0, 1.0], [-25.0, -3.0]]\nB = [[0.0], [25.0]]\nC = [[1.0, 0.0]]\nE = [[0.0], [0.0]]\n[input]\nkind = \"sine\"\namplitudes = [1.0]\nomega = 1.0\n[initial]\nx0 = [0.0, 0.0]\nz0 = [0.0]\n";
    (pl, model::parse_str(text).unwrap())
}

#[test]
fn the_generator_integrates_a_delayed_held_input_exactly() {
    // The benchmark's truth for a delay under a zero- or first-order hold: the held input
    // switches (or bends) at k h + tau, between the generator's fine grid points. Reference:
    // the exact discretisation under that hold with the delay split at that instant
    // (dynamics::extended, exact to rounding, tests/hold_and_discretisation.rs).
    let (pl, sys) = oscillator();
    let sig = Signal::Multisine { a: vec![1.0, 0.4, 0.2], omega: vec![1.3, 4.1, 9.7], phi: vec![0.0, 1.0, 2.0] };
    let dt = 0.01;
    let ns = 1500;
    let w: Vec<f64> = (0..ns).map(|k| sig.eval(k as f64 * dt)).collect();
    for hold in [InputHold::Zoh, InputHold::Foh] {
        let exact_at = |eff: &Effect| {
            ExtendedModel::new(&sys, std::slice::from_ref(eff), dt, 1)
                .unwrap()
                .with_hold(hold)
                .simulate(&w, dt, &[0.0, 0.0])
                .y
        };
        let y_range = {
            let y = ExtendedModel::new(&sys, &[], dt, 1).unwrap().with_hold(hold).simulate(&w, dt, &[0.0, 0.0]).y;
            y.iter().copied().fold(f64::NEG_INFINITY, f64::max) - y.iter().copied().fold(f64::INFINITY, f64::min)
        };
        for frac in [0.013, 0.37, 0.61] {
            let delay = (3.0 + frac) * dt;
            let eff = Effect::InputDelay { delay };
            let gen =
                plant_sim::simulate(&pl, 0.0, Some(&eff), &sig, &[0.0, 0.0], dt, ns, plant_sim::Drive::Held(hold));
            let exact = exact_at(&eff);
            let d = max_abs_diff(&gen, &exact) / y_range;
            // RK2 on a grid of h/20 with the switching instant on the grid: O((omega h/20)^2).
            assert!(
                d < 2e-5,
                "{hold:?}, delay {frac} h into the sample: generator off the exact response by {d:.2e} of the range"
            );
            // Negative control: the same delay off by a quarter of the generator's fine step
            // (before, the switching instant was rounded to that grid: up to half a step off) is
            // visibly another response.
            let dr = max_abs_diff(&exact_at(&Effect::InputDelay { delay: delay + 0.25 * dt / 20.0 }), &exact) / y_range;
            eprintln!("{hold:?}, delay {frac}: generator {d:.2e}, shifted {dr:.2e}");
            assert!(dr > 10.0 * d, "{hold:?}: a delay off by h/80 went unnoticed: {dr:.2e} against {d:.2e}");
        }
    }
}

#[test]
fn a_delay_under_an_unknown_hold_is_covered_by_its_interval() {
    // Seed 2701 case 2 of the digital profile: a zero-order-held command sampled at 2.65 ms,
    // an input delay of 2.48 ms, the hold not passed to the tool. Before: the hold was
    // switched to foh on a BIC difference below the tie margin (the nominal preferred zoh),
    // the delay read 3.79 ms +- 0.066 ms (20 sigma off, the h/2 of the other hold).
    let s = DiagnoseSettings::default();
    let case = bench_gen::generate_profile("input_delay", 2701, 2, Profile::Digital);
    let r = bench::run_case_with("input_delay", 2701, 2, Profile::Digital, &s);
    assert_eq!(r.predicted, "input_delay", "{r:?}");
    let (e, t, sd) = (r.est_param.unwrap(), r.true_param.unwrap(), r.est_std.unwrap());
    assert!(
        (e - t).abs() <= 2.0 * sd,
        "delay {e:.4e} +- {sd:.2e} against the truth {t:.4e}: {:.1} sigma",
        (e - t).abs() / sd
    );
    // The report's header states the hold used, and whether the delay tells the holds apart.
    let known = InitialState {
        x0: case.nominal.x0.iter().copied().collect(),
        z0: Some(case.nominal.z0.iter().copied().collect()),
    };
    let rep = diagnose(&case.nominal, &case.recording, &DiagnoseSettings { initial_state: Some(known), ..s }).unwrap();
    let md = rep.to_markdown(&[]);
    assert!(md.contains(&format!("Input hold: **{}**", rep.hold.chosen)), "{md}");
    assert!(rep.hold.delay_delta_bic.is_some(), "{:?}", rep.hold);
    if rep.hold.delay_ambiguous {
        assert!(md.contains("the hold is not known from the data"), "{md}");
        let other = rep.hold.delay_other_hold[0];
        // The 1-sigma interval reaches the other reading too (half the distance between the
        // readings, the widening before, left it at 2 sigma).
        assert!((other - e).abs() <= sd, "other reading {other:.4e} outside {e:.4e} +- {sd:.2e}");
    }
}

#[test]
fn a_delay_whose_holds_differ_only_by_the_noise_colour_covers_both_readings() {
    // Seed 10601 case 1 of the mixed profile: a continuous command sampled at 1.07 ms, delayed
    // by 0.74 ms, AR(1) 0.68 noise. The delay model fits the zero-order hold better by 7.4 in
    // BIC, above the tie margin 6 counted as if every residual were independent, but 1.7 once
    // counted for the residual's colour. Before, the zero-order reading 0.19 ms +- 0.03 ms was
    // reported alone, 20 sigma from the continuous command's delay (the first-order reading,
    // 0.73 ms, matched it).
    let r = bench::run_case_with("input_delay", 10601, 1, Profile::Mixed, &DiagnoseSettings::default());
    assert_eq!(r.predicted, "input_delay", "{r:?}");
    let (e, t, sd) = (r.est_param.unwrap(), r.true_param.unwrap(), r.est_std.unwrap());
    assert!((e - t).abs() <= 2.0 * sd, "delay {e:.4e} +- {sd:.2e} against the truth {t:.4e}");
    let case = bench_gen::generate_profile("input_delay", 10601, 1, Profile::Mixed);
    let rep = diagnose(&case.nominal, &case.recording, &with_known_state(&case)).unwrap();
    let d = rep.hold.delay_delta_bic.expect("the delay is refitted under the other hold");
    // control: the raw BIC difference alone would call the holds apart
    assert!(d.abs() > DiagnoseSettings::default().select.tie_bic, "raw difference {d}");
    assert!(rep.hold.delay_ambiguous, "{:?}", rep.hold);
    // The 1-sigma interval reaches the other reading (0.73 ms here; half the distance, the
    // widening before, left it at 2 sigma).
    let other = r.est_param_other_hold.expect("the delay under the other hold");
    assert!((other - e).abs() <= sd, "other reading {other:.4e} outside {e:.4e} +- {sd:.2e}");
    // a selection that cleared the margin with the stepping allowance carries no note of the
    // waiver (`diagnose/pass.rs` tests the note where it is due)
    assert!(!rep.notes.iter().any(|n| n.contains("took part in that choice")), "{:?}", rep.notes);
}

#[test]
fn a_saturation_reached_mostly_after_the_estimation_segment_is_named() {
    // Seed 10603 case 1 of the digital profile: an input saturation reached mostly after the
    // estimation segment. With the simulator's first-order play step (until 2026-11-28) the
    // single gained 13.6 in BIC against a margin of 17.6 (10 plus 7.6 of stepping allowance)
    // and cut the held-out error to 0.081 of the nominal's; before the waiver the recording was
    // read as nothing. The second-order step leaves an allowance of 0.1 here, and the single
    // clears the margin itself; the waiver's note is tested in `diagnose/pass.rs` (no recording
    // of the seeds 10601-10603 needs it now).
    let case = bench_gen::generate_profile("input_saturation", 10603, 1, Profile::Digital);
    let rep = diagnose(&case.nominal, &case.recording, &with_known_state(&case)).unwrap();
    assert_eq!(rep.selected(), "input_saturation", "{}", rep.verdict);
    assert!(rep.delta_bic_discretisation < 1.0, "allowance {}", rep.delta_bic_discretisation);
}

#[test]
fn a_delay_under_half_a_sample_is_found_under_the_other_hold() {
    // Seed 9302 case 3 of the mixed profile: a linearly interpolated (first-order-held)
    // command sampled at 1.85 ms, delayed by 0.66 ms (a third of a sample). The nominal prefers
    // the zero-order hold by 632 in BIC (it acts as a delay of h/2 = 0.93 ms), under which the
    // delay would be negative. Before, the second look at the hold refitted only the three
    // leading singles under the other hold, the delay was not among them, and the recording
    // was read as direction-dependent friction + cogging.
    let r = bench::run_case_with("input_delay", 9302, 3, Profile::Mixed, &DiagnoseSettings::default());
    assert_eq!(r.predicted, "input_delay", "{r:?}");
    assert_eq!(r.hold_used, "foh", "{r:?}");
    let (e, t, sd) = (r.est_param.unwrap(), r.true_param.unwrap(), r.est_std.unwrap());
    assert!((e - t).abs() <= 2.0 * sd, "delay {e:.4e} +- {sd:.2e} against the truth {t:.4e}");
}

#[test]
fn the_header_states_the_hold_used_after_a_switch() {
    let h = HoldReport {
        requested: HoldChoice::Auto,
        chosen: "foh",
        sse_zoh: Some(1.0),
        sse_foh: Some(2.0),
        delta_bic: Some(1234.5),
        decisive: true,
        effect_delta_bic: Some(8.0),
        switched: true,
        effects_undecided: false,
        delay_delta_bic: None,
        delay_other_hold: vec![],
        delay_ambiguous: false,
    };
    let text = h.header();
    assert!(text.contains("preferred zoh by 1234.5") && text.contains("switched"), "{text}");
    // Negative control: without the switch the nominal's preference is the reason given.
    let kept = HoldReport { switched: false, chosen: "zoh", ..h };
    assert!(!kept.header().contains("switched") && kept.header().contains("than with foh"), "{}", kept.header());
    assert!(!kept.header().contains("not confirmed"), "{}", kept.header());
    // Kept, but the best effect fits both holds alike: the header says the data do not confirm it.
    let undecided = HoldReport { effect_delta_bic: Some(0.8), effects_undecided: true, ..kept.clone() };
    assert!(undecided.header().contains("alike (+0.8): not confirmed"), "{}", undecided.header());
}

/// The stepping tests' wide play in the loop (the catching-up projection is first order in the
/// step), driven by two sines over 600 samples of 50 ms.
struct WidePlay {
    sys: model::System,
    w: Vec<f64>,
    dt: f64,
}

impl WidePlay {
    fn new() -> Self {
        let text = "name = \"play\"\n[plant]\nA = [[0.0, 1.0], [-4.0, -0.4]]\nB = [[0.0], [4.0]]\nC = [[1.0, 0.0]]\nE = [[0.0], [-4.0]]\n[theta]\nshape = \"interval\"\nhalf_width = 0.3\n[input]\nkind = \"sine\"\namplitudes = [1.0]\nomega = 1.0\n[initial]\nx0 = [0.0, 0.0]\nz0 = [0.0]\n";
        let dt = 0.05;
        let w = (0..600).map(|k| (0.9 * k as f64 * dt).sin() + 0.4 * (2.7 * k as f64 * dt).sin()).collect();
        Self { sys: model::parse_str(text).unwrap(), w, dt }
    }

    /// Its output at `k` sub-steps per sample.
    fn y(&self, k: usize) -> Vec<f64> {
        ExtendedModel::new(&self.sys, &[], self.dt, k).unwrap().simulate(&self.w, self.dt, &[0.0, 0.0]).y
    }

    /// Standard deviation of `y` over the record.
    fn sd(y: &[f64]) -> f64 {
        let m = y.iter().sum::<f64>() / y.len() as f64;
        (y.iter().map(|v| (v - m).powi(2)).sum::<f64>() / y.len() as f64).sqrt()
    }

    /// The output at 256 sub-steps with uniform noise of standard deviation `noise` output
    /// standard deviations, diagnosed at a cap of one sub-step per sample (first-order hold,
    /// known state): the report and the noise level in output standard deviations (the fit's
    /// units).
    fn diagnose_at_one_substep(&self, noise: f64) -> (discovery::Report, f64) {
        let clean = self.y(256);
        let sd = Self::sd(&clean);
        let y: Vec<Vec<f64>> = clean
            .iter()
            .enumerate()
            .map(|(k, v)| vec![v + noise * sd * 3f64.sqrt() * 2.0 * (((k * 7919) % 1000) as f64 / 1000.0 - 0.5)])
            .collect();
        let t: Vec<f64> = (0..y.len()).map(|k| k as f64 * self.dt).collect();
        let u = self.w.iter().map(|v| vec![*v]).collect();
        let rec = discovery::Recording::from_samples("play", &t, u, y, None);
        let s = DiagnoseSettings {
            initial_state: Some(InitialState { x0: vec![0.0, 0.0], z0: Some(vec![0.0]) }),
            input_hold: HoldChoice::Fixed(InputHold::Foh),
            max_substeps: 1,
            ..Default::default()
        };
        let r = diagnose(&self.sys, &rec, &s).unwrap();
        let y_sd = Self::sd(&rec.y.iter().map(|v| v[0]).collect::<Vec<f64>>());
        let noise_w = r.noise_level[0] / y_sd;
        (r, noise_w)
    }
}

#[test]
fn a_stepping_error_above_the_noise_is_not_accepted() {
    // Noise at 0.1 % of the output's spread and a cap of one sub-step per sample. Before: the
    // cap stood, with a stated stepping error several times the noise.
    let (r, noise_w) = WidePlay::new().diagnose_at_one_substep(1e-3);
    let d = &r.discretisation;
    assert!(d.ladder[0].1 > noise_w, "negative control: one sub-step is already within the noise: {d:?}");
    assert!(
        r.substeps > 1 && d.error_rms <= noise_w,
        "stated stepping error {:.2e} above the noise {noise_w:.2e} accepted: {d:?}",
        d.error_rms
    );
}

#[test]
fn a_stepping_error_within_the_noise_is_still_converged_to_the_tolerance() {
    // Noise four times the one-sub-step change: the stepping error (twice the change) is
    // within the noise but the change is above the tolerance (a tenth of the noise). Before:
    // the cap of one sub-step stood (not converged), and the error bought up to ~100 in BIC of
    // allowance on the selection margin.
    let play = WidePlay::new();
    let (y1, y2) = (play.y(1), play.y(2));
    let rms = (y1.iter().zip(&y2).map(|(a, b)| (a - b).powi(2)).sum::<f64>() / y1.len() as f64).sqrt();
    let change = rms / WidePlay::sd(&play.y(256));
    let (r, noise_w) = play.diagnose_at_one_substep(4.0 * change);
    let d = &r.discretisation;
    // Negative control: at one sub-step the error is within the noise and the change above
    // the tolerance (the case the old rule let stand).
    let c1 = d.ladder[0].1;
    assert!(2.0 * c1 <= noise_w && c1 > d.tolerance, "not the case under test: {d:?}, noise {noise_w:.2e}");
    assert!(r.substeps > 1 && d.converged, "a change above the tolerance stood at {} sub-steps: {d:?}", r.substeps);
    assert!(d.error_rms <= 2.0 * d.tolerance, "{d:?}");
}

#[test]
fn a_saturation_fit_starts_where_the_effect_can_act() {
    // Seed 2704 case 0 of the digital profile (a fresh seed of the measurement below): the
    // command's largest values fall in the validation segment, so every start of the limit
    // (fractions of the whole record's max |w|) clipped nothing in the estimation segment: zero
    // gradient, the fit stuck, "nothing added" with the nominal at 78 % fit. The starts now
    // derive from the estimation segment's max |w|.
    let r = bench::run_case_with("input_saturation", 2704, 0, Profile::Digital, &DiagnoseSettings::default());
    assert_eq!(r.predicted, "input_saturation", "{r:?}");
    let (e, t, sd) = (r.est_param.unwrap(), r.true_param.unwrap(), r.est_std.unwrap());
    assert!((e - t).abs() <= 2.0 * sd && (e - t).abs() <= 0.15 * t, "limit {e} +- {sd} against {t}");
}

/// The measurement behind BENCHMARKS.md's "diagnose: hold/delay and discretisation" section
/// (not a check: it prints and writes what it finds). Environment: `BENCH_SEED` (default
/// 2701), `BENCH_CASES` (per class, default 4), `BENCH_PROFILE` (`classic` or `digital`),
/// `BENCH_CLASSES` (a class set of [`discovery::bench::class_set`], default `input_delay`),
/// `BENCH_JSON` (where to write the cases as JSON). The hold is never passed to the tool.
/// `BENCH_PROFILE=digital BENCH_CLASSES=classic cargo test --release -p discovery --test
/// hold_delay_and_stepping -- --ignored --nocapture`.
#[test]
#[ignore = "minutes: the hold/delay and discretisation measurement"]
fn hold_delay_and_stepping_benchmark() {
    let env = |k: &str, d: &str| std::env::var(k).unwrap_or_else(|_| d.to_string());
    let seed: u64 = env("BENCH_SEED", "2701").parse().unwrap();
    let cases: usize = env("BENCH_CASES", "4").parse().unwrap();
    let profile = discovery::bench_gen::Profile::parse(&env("BENCH_PROFILE", "digital")).unwrap();
    let classes = discovery::bench::class_set(&env("BENCH_CLASSES", "input_delay")).unwrap();
    let json = std::env::var("BENCH_JSON").ok();
    let mut done: Vec<discovery::bench::CaseResult> = Vec::new();
    let r = discovery::bench::run_classes(&classes, cases, seed, profile, &Default::default(), |c| {
        eprintln!(
            "{} {}: {} (truth {:?}, estimate {:?} +- {:?}, hold used {}, {})",
            c.class,
            c.index,
            c.selected,
            c.true_param,
            c.est_param,
            c.est_std,
            c.hold_used,
            c.conditions.short()
        );
        // Written after every case: a run cut short still leaves what it measured.
        done.push(c.clone());
        if let Some(p) = &json {
            std::fs::write(p, serde_json::json!({ "cases": done }).to_string()).unwrap();
        }
    });
    println!("{}", r.to_text());
}

#[test]
fn a_stuck_generalisation_is_restarted_from_its_simpler_form() {
    // Mixed-profile seed 9303 case 3 (Stribeck friction, 6 ms sampling): the Stribeck law's own
    // starts ran its static excess to zero, where the Stribeck velocity has no influence, and
    // the fit stuck there (zero gradient: inconclusive). Restarted around the Coulomb level it
    // converges. (The recording does not show the breakaway: at 16 sub-steps the true law and
    // Coulomb friction differ by 0.1 % in SSE, so Coulomb friction stays the reading.)
    let case = bench_gen::generate_profile("stribeck_friction", 9303, 3, Profile::Mixed);
    let s = with_known_state(&case);
    let rep = diagnose(&case.nominal, &case.recording, &s).unwrap();
    let stribeck = rep.ranking.iter().find(|r| r.label == "stribeck_friction(x2)").expect("fitted");
    assert!(stribeck.status.conclusive(), "{:?} at {:?}", stribeck.status, stribeck.params);
    let coulomb = rep.ranking.iter().find(|r| r.label == "coulomb_friction(x2)").expect("fitted");
    // It nests Coulomb friction: it fits at least as well.
    assert!(stribeck.sse_estimation <= coulomb.sse_estimation * (1.0 + 1e-6), "{stribeck:?} {coulomb:?}");
}

#[test]
fn a_delay_the_zero_order_hold_absorbs_is_named_in_a_note_and_read_with_the_hold_given() {
    // Mixed-profile seed 9313 case 14: a linearly interpolated command at 1.27 ms, delayed by
    // 0.68 ms (about h/2). The zero-order hold, chosen from the data, acts as that delay: the
    // recording reads "no missing physics" and cannot say otherwise. The report says so and
    // how to read the delay; with the hold given, the delay is read within 2 sigma.
    let case = bench_gen::generate_profile("input_delay", 9313, 14, Profile::Mixed);
    let s = with_known_state(&case);
    let note = "acts like a first-order hold delayed by h/2";
    let auto = diagnose(&case.nominal, &case.recording, &s).unwrap();
    assert_eq!(auto.hold.chosen, "zoh", "{:?}", auto.hold);
    assert!(auto.effects.is_empty(), "{}", auto.selected());
    assert!(auto.notes.iter().any(|n| n.contains(note) && n.contains("--input-hold foh")), "{:#?}", auto.notes);
    let given = diagnose(
        &case.nominal,
        &case.recording,
        &DiagnoseSettings { input_hold: HoldChoice::Fixed(InputHold::Foh), ..s },
    )
    .unwrap();
    let delay = given.effects.iter().find(|e| e.kind == "input_delay").expect("the delay, with the hold given");
    let truth = match case.truth {
        Some(Effect::InputDelay { delay }) => delay,
        _ => unreachable!(),
    };
    let (d, sd) = (delay.params[0].1, delay.uncertainty[0].1);
    assert!((d - truth).abs() <= 2.0 * sd, "{d:.4e} +- {sd:.2e} against {truth:.4e}");
    // Negative control: with the hold given, the note on the chosen hold is not written.
    assert!(!given.notes.iter().any(|n| n.contains("was chosen from the data")), "{:#?}", given.notes);
}

#[test]
fn a_held_recording_with_nothing_missing_keeps_its_hold() {
    // Mixed-profile seed 9404 case 77: a zero-order-held command at 10.4 ms, nothing missing.
    // The hold's second look asks the input delay under the first-order hold wherever it ranks
    // (a_delay_under_half_a_sample_is_found_under_the_other_hold); "first-order hold + h/2"
    // beat the best effect under the zero-order hold, the nominal itself, by 6.6 in BIC, and
    // the hold was switched and a delay named. It must also clear the selection margin
    // against the nominal. Case 98 (AR(1) 0.57 noise): it beat it by 11.8, 3.2 once counted
    // for the colour of its residual; switched, Coulomb friction stood in for the hold.
    for i in [77, 98] {
        let r = bench::run_case_with("none", 9404, i, Profile::Mixed, &DiagnoseSettings::default());
        assert_eq!(r.predicted, "none", "{r:?}");
        assert_eq!(r.hold_used, "zoh", "{r:?}");
    }
}

#[test]
fn a_generalisation_at_another_minimum_is_refitted_from_its_simpler_form() {
    // Fresh mixed-profile seed 9893 case 3 (Stribeck friction, 19.7 ms sampling, truth: level
    // 0.61, static level 1.78, Stribeck velocity 0.78). The law's own starts converged to a
    // spike (Stribeck velocity 0.007, static level 5.9) that failed the held-out folds against
    // Coulomb friction (ratio 1.25): Coulomb friction was selected. Refitted from around the
    // Coulomb level too, the law reads the breakaway and passes.
    let case = bench_gen::generate_profile("stribeck_friction", 9893, 3, Profile::Mixed);
    let s = with_known_state(&case);
    let rep = diagnose(&case.nominal, &case.recording, &s).unwrap();
    assert_eq!(rep.selected(), "stribeck_friction", "{}", rep.verdict);
    let stribeck = rep.ranking.iter().find(|r| r.label == "stribeck_friction(x2)").expect("fitted");
    // parameters: level, static excess, Stribeck velocity (not the spike)
    assert!(stribeck.params[2] > 0.1 && stribeck.params[2] < 3.0, "{:?}", stribeck.params);
    let coulomb = rep.ranking.iter().find(|r| r.label == "coulomb_friction(x2)").expect("fitted");
    assert!(stribeck.sse_estimation < coulomb.sse_estimation, "{stribeck:?} {coulomb:?}");
}

#[test]
fn a_saturation_no_command_reaches_before_the_validation_segment_is_selected_on_a_longer_estimation_segment() {
    // Seed 10808 case 3 of the digital profile: no command of the estimation segment (the first
    // 70 %) reaches the limit, so the saturation's fit there is stuck at its start (zero
    // gradient, nothing to fit), where it cuts the held-out error to 0.113 of the nominal's.
    // The verdict said "the mismatch is outside the library"; then it named the saturation as
    // what the held-out segment shows (model incomplete); now the record is diagnosed again
    // with the first 90 % as the estimation segment (`diagnose/extend.rs`), where the
    // saturation is fitted and selected.
    let case = bench_gen::generate_profile("input_saturation", 10808, 3, Profile::Digital);
    let rep = diagnose(&case.nominal, &case.recording, &with_known_state(&case)).unwrap();
    assert_eq!(rep.selected(), "input_saturation", "{}", rep.verdict);
    assert!(!rep.model_incomplete, "{}", rep.verdict);
    let note = rep.notes.first().expect("the extension's note");
    assert!(note.contains("input_saturation acts only beyond the estimation segment"), "{note}");
    assert!(note.contains("its fit there was stuck, yet it cut the held-out error to 0.1"), "{note}");
    // Control: on the longer segment the fit converges.
    let sat = rep.ranking.iter().find(|r| r.label == "input_saturation").unwrap();
    assert_eq!(sat.status, discovery::fit::FitStatus::Converged, "{sat:?}");
}
