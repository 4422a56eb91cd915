//! The friction library in the diagnosis (issue 14 items 4 and 7): the generator's classes
//! `stribeck_friction`, `asymmetric_coulomb` and `cogging` are named and their parameters
//! recovered; the cogging period scan finds the period.
//!
//! The full measurement (8 plants per class, none and coulomb_friction alongside) is
//! `cargo test --release -p discovery --test friction_library -- --ignored` (seeds from
//! `FRICTION_BENCH_SEEDS`, default the held-out 401,402; about 1 min), equivalently
//! `cargo run --release -p discovery --example bench_one 8 SEED classic friction`.
use discovery::bench_gen::{self, FRICTION_CLASSES};
use discovery::hypothesis::{self, Kind, Scales};
use discovery::DiagnoseSettings;
use dynamics::extended::ExtendedModel;
use model::effects::Effect;

#[test]
fn cogging_scan_finds_the_period_and_the_hypothesis_is_offered() {
    let case = bench_gen::generate("cogging", 101, 0);
    let Some(Effect::Cogging { period, amplitude, .. }) = case.truth else { panic!("{:?}", case.truth) };
    let sys = &case.nominal;
    let (scales, base) = scales_with_nominal(&case);
    let peaks = hypothesis::cogging_scan(sys, &scales, 0, 1);
    let (p, a_s, a_c) = (peaks[0].period, peaks[0].amplitude_sin, peaks[0].amplitude_cos);
    assert!((p / period - 1.0).abs() < 0.02, "period {p} vs {period}");
    assert!((a_s.hypot(a_c) / amplitude - 1.0).abs() < 0.5, "amplitude {} vs {amplitude}", a_s.hypot(a_c));
    let kinds: Vec<Kind> = hypothesis::candidates(sys, &scales).iter().map(|h| h.kind).collect();
    for k in [
        Kind::StribeckFriction { state: 1 },
        Kind::AsymmetricCoulomb { state: 1 },
        Kind::Cogging { state: 1, position_state: 0 },
    ] {
        assert!(kinds.contains(&k), "{k:?} missing from {kinds:?}");
    }
    // Without the nominal run there is no scan and no cogging hypothesis.
    assert!(hypothesis::cogging_scan(sys, &base, 0, 1).is_empty());
    assert!(!hypothesis::candidates(sys, &base).iter().any(|h| matches!(h.kind, Kind::Cogging { .. })));
    // A narrowed library states exactly its own hypotheses (by label or by name), the same as
    // the full list filtered; cogging (whose scan runs over the record) only where asked.
    let all = hypothesis::candidates(sys, &scales);
    for lib in [vec!["coulomb_friction(x2)".to_string()], vec!["cogging".into(), "gap_width".into()], vec![]] {
        let narrowed: Vec<Kind> = hypothesis::candidates_in(sys, &scales, Some(&lib)).iter().map(|h| h.kind).collect();
        let filtered: Vec<Kind> =
            all.iter().map(|h| h.kind).filter(|k| discovery::physics::in_library(&lib, *k)).collect();
        assert_eq!(narrowed, filtered, "library {lib:?}");
        assert_eq!(
            narrowed.contains(&Kind::Cogging { state: 1, position_state: 0 }),
            lib[..].contains(&"cogging".into())
        );
    }
    // Negative control: the unnarrowed list holds more than any of them.
    assert!(all.len() > 3);
}

/// The scales of `case`'s recording with its nominal run (4 sub-steps, the first 70 % the
/// estimation segment) and without it.
fn scales_with_nominal(case: &bench_gen::Case) -> (Scales, Scales) {
    let sys = &case.nominal;
    let (w, y): (Vec<f64>, Vec<f64>) =
        case.recording.w.iter().zip(&case.recording.y).map(|(a, b)| (a[0], b[0])).unzip();
    let dt = case.recording.dt;
    let nom = ExtendedModel::new(sys, &[], dt, 4).unwrap().simulate(&w, dt, sys.x0.as_slice());
    let yr = y.iter().copied().fold(f64::NEG_INFINITY, f64::max) - y.iter().copied().fold(f64::INFINITY, f64::min);
    let base = Scales {
        y_range: vec![yr],
        w_range: vec![2.0],
        w_absmax: 1.0,
        tau_slow: 5.0,
        dt,
        duration: 60.0,
        ..Default::default()
    };
    let k_est = (0.7 * y.len() as f64) as usize;
    (base.clone().with_nominal(&nom.x, &nom.y, &y, k_est), base)
}

#[test]
fn cogging_scan_offers_a_peak_per_band_beside_an_alias() {
    // Mixed-profile development seed 10211 case 0 (6.48 ms sampling, up to 0.27 of the 5.0
    // position range per sample): the scan's largest gain is at a period of 0.177, an alias of
    // the sample-held regressor, and the fit started there named cogging at 2.6 times its
    // amplitude. The true period (1.64) lies in the top band, whose peak is now a start too.
    use discovery::bench_gen::Profile;
    let case = bench_gen::generate_profile("cogging", 10211, 0, Profile::Mixed);
    let Some(Effect::Cogging { period, .. }) = case.truth else { panic!("{:?}", case.truth) };
    let (scales, _) = scales_with_nominal(&case);
    let peaks = hypothesis::cogging_scan(&case.nominal, &scales, 0, 1);
    let near = |p: f64| (p / period - 1.0).abs() < 0.2;
    // Control: the scan's best peak alone (the old start) is the alias.
    assert!(!near(peaks[0].period), "{peaks:?}");
    assert!(peaks.iter().any(|q| near(q.period)), "no peak within 20 % of {period}: {peaks:?}");
}

#[test]
fn an_effect_that_cuts_the_held_out_error_overrules_residual_tests_that_pass() {
    // Mixed-profile seed 9331 case 2: a cogging force on a lightly damped plant (80 rad/s,
    // sampled at 0.96 ms, AR(1) noise). The residual tests average the residual over blocks of
    // a tenth of the slowest time constant (28 samples), where the cogging residual averages
    // out: the nominal passed them and nothing was selected, although cogging cuts the held-out
    // error to 0.074 of the nominal's (+4439 in BIC).
    use discovery::bench::run_case_with;
    use discovery::bench_gen::Profile;
    let r = run_case_with("cogging", 9331, 2, Profile::Mixed, &DiagnoseSettings::default());
    assert_eq!(r.predicted, "cogging", "{r:?}");
    // Negative control: on recordings without missing physics (the same profile and seed) no
    // effect comes near the overruling share, so nothing is named.
    for i in 0..3 {
        let n = run_case_with("none", 9331, i, Profile::Mixed, &DiagnoseSettings::default());
        assert_eq!(n.predicted, "none", "{n:?}");
    }
}

#[test]
fn an_untestable_effect_on_coloured_noise_needs_more_than_its_raw_gain() {
    // Mixed-profile seed 9504 cases 7 and 76: nothing missing, AR(1) noise (rho 0.85). A
    // saturation limit fitted to the noise on one stretch gained 26.4 and 11.8 in BIC (margin
    // about 10) and, its influence lying in one held-out fold, was accepted as "not testable".
    // Counted with the residual's colour ((1 - rho)/(1 + rho) independent samples per sample)
    // the gains are 2.1 and 1.0: nothing is named.
    use discovery::bench::run_case_with;
    use discovery::bench_gen::Profile;
    for i in [7, 76] {
        let r = run_case_with("none", 9504, i, Profile::Mixed, &DiagnoseSettings::default());
        assert_eq!(r.predicted, "none", "{r:?}");
    }
    // Negative control: a saturation that is there is still named on coloured noise.
    let r = run_case_with("input_saturation", 9301, 0, Profile::Mixed, &DiagnoseSettings::default());
    assert_eq!(r.predicted, "input_saturation", "{r:?}");
}

#[test]
fn friction_classes_fixed_seed_slice() {
    // One plant per class (development seed 101, case 3); the measurement is the ignored test.
    let s = DiagnoseSettings::default();
    for c in FRICTION_CLASSES {
        let r = discovery::bench::run_case(c, 101, 3, &s);
        assert!(r.error.is_none(), "{c}: {:?}", r.error);
        assert!(r.correct, "{c} named {} (ties {:?})", r.selected, r.ties);
        let e = r.param_error.expect("named correctly");
        assert!(e <= 0.15, "{c}: main parameter off by {:.1} %: {r:?}", 100.0 * e);
        assert!(r.fit_after > r.fit_before, "{c}: {r:?}");
    }
}

/// Coulomb friction under random steps (long rests, sticking at every dwell): its own starts
/// converged at a level of 0.231 against the truth's 0.347, 1,573 in BIC below the
/// direction-dependent law, which was selected. Refitted from that law's levels, Coulomb
/// friction is named, within its reported 2 sigma.
#[test]
fn coulomb_friction_under_random_steps_is_refitted_from_its_generalisation() {
    let case = bench_gen::generate_with_input(
        "coulomb_friction",
        10952,
        0,
        bench_gen::Profile::Mixed,
        bench_gen::ForcedInput::Steps,
    );
    let Some(Effect::CoulombFriction { level: truth, .. }) = case.truth else { panic!("{:?}", case.truth) };
    let s = discovery::bench::with_case_start(&case, &DiagnoseSettings::default());
    let r = discovery::diagnose(&case.nominal, &case.recording, &s).unwrap();
    assert_eq!(r.selected(), "coulomb_friction", "{}", r.verdict);
    let e = &r.effects[0];
    let (est, sd) = (e.params[0].1, e.uncertainty[0].1);
    assert!((est - truth).abs() <= 2.0 * sd, "level {est} +- {sd} against {truth}");
}

#[test]
#[ignore = "about 1 minute in release: the friction classes' measurement"]
fn friction_benchmark_eight_plants_per_class() {
    // The held-out seeds of BENCHMARKS.md (classic profile); `FRICTION_BENCH_SEEDS=101,102`
    // gives the development seeds, where stribeck_friction is named in 14/16 only.
    let seeds: Vec<u64> = std::env::var("FRICTION_BENCH_SEEDS")
        .unwrap_or_else(|_| "401,402".into())
        .split(',')
        .map(|s| s.trim().parse().expect("FRICTION_BENCH_SEEDS: comma-separated integers"))
        .collect();
    let classes = discovery::bench::class_set("friction").unwrap();
    let mut cases = Vec::new();
    for seed in seeds {
        let r = discovery::bench::run_classes(
            &classes,
            8,
            seed,
            bench_gen::Profile::Classic,
            &DiagnoseSettings::default(),
            |_| {},
        );
        eprintln!("seed {seed}:\n{}", r.to_text());
        cases.extend(r.cases);
    }
    for c in FRICTION_CLASSES {
        let rows: Vec<_> = cases.iter().filter(|x| x.class == c).collect();
        let named = rows.iter().filter(|x| x.correct_or_tied).count();
        let within = rows.iter().filter(|x| x.param_error.is_some_and(|e| e <= 0.15)).count();
        assert!(named * 10 >= rows.len() * 9, "{c}: named {named}/{}", rows.len());
        assert!(within * 10 >= rows.iter().filter(|x| x.correct).count() * 9, "{c}: within 15 %: {within}");
    }
    let none = cases.iter().filter(|x| x.class == "none" && x.predicted != "none").count();
    assert!(none <= 1, "{none} false alarms on none");
}
