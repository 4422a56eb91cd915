//! Two concealed effects at once (issue 27 item 4): the diagnosis names both, or its verdict
//! says that the model is still incomplete and where; a recording with one concealed effect,
//! once named, is not called incomplete (negative control).
use discovery::bench_gen::{self, Profile};
use discovery::{diagnose, DiagnoseSettings, Report};

/// The case's true initial state handed over, as the benchmark does.
fn run(case: &bench_gen::Case) -> Report {
    let s = DiagnoseSettings {
        initial_state: Some(discovery::diagnose::InitialState {
            x0: case.nominal.x0.iter().copied().collect(),
            z0: Some(case.nominal.z0.iter().copied().collect()),
        }),
        ..Default::default()
    };
    diagnose(&case.nominal, &case.recording, &s).unwrap()
}

/// How many of the case's concealed effects the report names.
fn named(case: &bench_gen::Case, r: &Report) -> usize {
    case.truths.iter().filter(|t| r.effects.iter().any(|e| e.kind == t.kind())).count()
}

#[test]
fn pair_generator_conceals_both_effects() {
    let case = bench_gen::generate_pair(["gap_width", "coulomb_friction"], 27, 2, Profile::Classic).unwrap();
    assert_eq!(case.truths.len(), 2);
    assert_eq!(case.classes, ["gap_width", "coulomb_friction"]);
    // Pairs that cannot co-occur are refused (a concealed backlash has no nominal play to widen).
    assert!(bench_gen::generate_pair(["backlash", "gap_width"], 27, 0, Profile::Classic).is_none());
    assert!(bench_gen::generate_pair(["coulomb_friction", "stribeck_friction"], 27, 0, Profile::Classic).is_none());
    assert!(bench_gen::pairs().iter().all(|p| bench_gen::pair_compatible(p[0], p[1])));
    // One class draws what it always did: the single case's truth is the pair's first.
    let single = bench_gen::generate_profile("gap_width", 27, 2, Profile::Classic);
    assert_eq!(single.truths.len(), 1);
    assert_eq!(single.classes, ["gap_width"]);
}

#[test]
fn a_missed_second_effect_is_said_to_be_missing() {
    // Wider gap and Coulomb friction at once (the case): where the selected model does
    // not name both, the verdict must say that something is still missing, and where.
    for index in [0, 2] {
        let case = bench_gen::generate_pair(["gap_width", "coulomb_friction"], 27, index, Profile::Classic).unwrap();
        let r = run(&case);
        let k = named(&case, &r);
        eprintln!("#{index}: {} named {k}, incomplete {}: {}", r.selected(), r.model_incomplete, r.verdict);
        if k < 2 {
            assert!(
                r.model_incomplete,
                "#{index}: one effect missed, but the model is not called incomplete: {}",
                r.verdict
            );
            assert!(r.verdict.contains("something is still missing"), "{}", r.verdict);
            let rem = r.remaining.as_ref().expect("what is left, with the incomplete model");
            assert!(rem.q_auto > rem.q_auto_threshold, "{rem:?}");
            assert!(r.to_markdown(&[]).contains("## Still missing"));
        }
    }
}

#[test]
fn two_effects_named_leave_a_complete_model() {
    // Input delay and sensor offset at once: both named, the residual white, nothing missing.
    let case = bench_gen::generate_pair(["input_delay", "sensor_offset"], 27, 0, Profile::Classic).unwrap();
    let r = run(&case);
    assert_eq!(named(&case, &r), 2, "{}", r.verdict);
    assert!(!r.model_incomplete && r.remaining.is_none(), "{}", r.verdict);
}

#[test]
fn one_named_effect_is_not_called_incomplete() {
    // Negative control: one concealed effect, named; the verdict does not say anything is missing.
    // The gap width (seed 27) leaves a residual that is not white, correlated with the input, at
    // 0.99 times the noise, with an extension 26 better in BIC that the held-out folds reject;
    // the digital backlash inertia (seed 2712) one white once its AR(1) noise colour is removed,
    // with such an extension too: neither is missing physics.
    for (class, seed, profile) in [
        ("coulomb_friction", 27, Profile::Classic),
        ("gap_width", 27, Profile::Classic),
        ("backlash_inertia", 2712, Profile::Digital),
    ] {
        let case = bench_gen::generate_profile(class, seed, 0, profile);
        let r = run(&case);
        assert_eq!(r.selected(), class, "{}", r.verdict);
        assert!(!r.model_incomplete, "{class}: {}", r.verdict);
        assert!(!r.verdict.contains("still missing"), "{}", r.verdict);
    }
}

#[test]
fn pair_search_fits_both_effects_jointly() {
    // Backlash and Coulomb friction at once (seed 27, case 0): the greedy forward step added a
    // second effect to a friction estimate that had absorbed the play and stopped at 2.3 times
    // the noise level, non-white. Where something is left, pairs of the best singles are fitted
    // jointly from their own estimates: a friction law and the backlash, white residual.
    let case = bench_gen::generate_pair(["backlash", "coulomb_friction"], 27, 0, Profile::Classic).unwrap();
    let r = run(&case);
    let kinds: Vec<&str> = r.effects.iter().map(|e| e.kind.as_str()).collect();
    assert!(kinds.contains(&"backlash"), "{}", r.verdict);
    assert!(kinds.iter().any(|k| k.contains("friction") || k.contains("coulomb")), "{}", r.verdict);
    assert!(r.residual_fitted.white && !r.model_incomplete, "{}", r.verdict);
}

#[test]
fn a_masked_partner_is_paired_with_the_first_effect() {
    // Backlash in the loop and Coulomb friction (development seed 2711, case 0): the loop
    // backlash gains nothing alone (-7 in BIC: the friction's misfit swamps it), so it never
    // entered the pair search's pool, and Stribeck friction + a backlash at the input was
    // selected, 1.6 times the noise level. The full model's effects are now paired with every
    // single: Coulomb friction + the loop backlash, white residual.
    let case = bench_gen::generate_pair(["backlash", "coulomb_friction"], 2711, 0, Profile::Classic).unwrap();
    let r = run(&case);
    assert_eq!(named(&case, &r), 2, "{}", r.verdict);
    assert!(r.residual_fitted.white && !r.model_incomplete, "{}", r.verdict);
}

#[test]
fn a_generalisation_in_a_pair_gives_way_to_its_simpler_form() {
    // Coulomb friction and a sensor offset (development seed 2711, case 0) were read as
    // direction-dependent friction + the offset although Coulomb friction + the offset, one
    // parameter fewer, fits 6 better in BIC: the simpler reading is selected.
    let case = bench_gen::generate_pair(["coulomb_friction", "sensor_offset"], 2711, 0, Profile::Classic).unwrap();
    let r = run(&case);
    let kinds: Vec<&str> = r.effects.iter().map(|e| e.kind.as_str()).collect();
    assert_eq!(named(&case, &r), 2, "{}", r.verdict);
    assert!(!kinds.contains(&"asymmetric_coulomb"), "{}", r.verdict);
}

#[test]
fn readings_that_fit_alike_are_named_together() {
    // Coulomb friction and a constant force (development seed 2712, digital, case 0): while
    // sliding they are direction-dependent friction, and with a sensor offset that reading fits
    // within the tie margin. The verdict names both readings instead of silently picking one.
    let case = bench_gen::generate_pair(["coulomb_friction", "constant_force"], 2712, 0, Profile::Digital).unwrap();
    let r = run(&case);
    assert_eq!(named(&case, &r), 2, "{}", r.verdict);
    assert!(!r.equivalents.is_empty(), "{}", r.verdict);
    assert!(r.verdict.contains(&format!("or equivalently {}", r.equivalents[0].label)), "{}", r.verdict);
    for e in &r.equivalents {
        assert!(e.delta_bic.abs() < 6.0, "{e:?}");
        assert!(r.verdict.contains(&e.label), "{}", r.verdict);
    }
    assert!(r.equivalents.iter().any(|e| e.kinds.iter().any(|k| k == "asymmetric_coulomb")), "{:?}", r.equivalents);
    assert!(r.to_markdown(&[]).contains("Other readings that fit as well"));
}

#[test]
fn a_missed_effect_within_the_noise_is_flagged_where_the_data_say_more() {
    // A constant force and a small input delay (development seed 2711, case 0): the delay alone
    // gains nothing (-5 in BIC), the force + delay pair 16 over the force but not on the
    // held-out folds. The force's residual, 1.03 times the noise level, correlated with the
    // input, was exempt as "within 1.1 times the noise"; with an unconfirmed extension above
    // the noise level the model is called incomplete, and the verdict names the extension.
    let case = bench_gen::generate_pair(["constant_force", "input_delay"], 2711, 0, Profile::Classic).unwrap();
    let r = run(&case);
    if named(&case, &r) < 2 {
        assert!(r.model_incomplete, "{}", r.verdict);
        let rem = r.remaining.as_ref().expect("what is left");
        let (label, gain) = rem.unconfirmed_extension.as_ref().expect("the extension the folds did not confirm");
        assert!(label.contains("input_delay") && *gain >= 10.0, "{label} {gain}");
        assert!(r.verdict.contains("did not pass the held-out folds"), "{}", r.verdict);
    }
}

#[test]
fn a_residual_off_zero_is_not_passed_as_coloured_noise() {
    // An input delay and a sensor offset (seed 2792, digital, case 0, AR(1) noise 0.86): read as
    // the delay + direction-dependent friction, the residual far from white (Q = 12015) but
    // white once an AR(1) filter of coefficient 0.93 is removed, so it passed as coloured
    // noise. Its mean is 9 times its zero-mean bound (5 with the bound widened for the colour):
    // coloured noise has zero mean, so the model is called incomplete.
    let case = bench_gen::generate_pair(["input_delay", "sensor_offset"], 2792, 0, Profile::Digital).unwrap();
    let r = run(&case);
    if named(&case, &r) < 2 {
        assert!(r.model_incomplete, "{}", r.verdict);
        assert!(r.remaining.as_ref().is_some_and(|m| m.mean_off_zero), "{:?}", r.remaining);
        assert!(r.verdict.contains("its mean is off zero"), "{}", r.verdict);
    }
}

#[test]
fn an_effect_only_the_held_out_segment_shows_is_found_on_a_longer_estimation_segment() {
    // Mixed-profile seed 9602 case 3: an input saturation that only the validation segment's
    // commands reach. On the estimation segment (the first 70 %) it gains 0.4 in BIC (nothing
    // selected), on the held-out segment it cuts the error to 0.086 of the nominal's; the
    // residual, white once an AR(1) colour is removed, exempted the model, which was reported
    // complete. It was then called incomplete, the saturation named; now the record is
    // diagnosed again with the first 90 % as the estimation segment, where the saturation is
    // selected (`diagnose/extend.rs`).
    let case = bench_gen::generate_profile("input_saturation", 9602, 3, Profile::Mixed);
    let r = run(&case);
    assert_eq!(r.selected(), "input_saturation", "{}", r.verdict);
    assert!(!r.model_incomplete, "{}", r.verdict);
    assert!(r.notes.iter().any(|n| n.contains("diagnosed again with the first 90 %")), "{:?}", r.notes);
    // Negative control: a recording with nothing missing (same profile and seed) is complete,
    // and not diagnosed again.
    let none = run(&bench_gen::generate_profile("none", 9602, 3, Profile::Mixed));
    assert!(!none.model_incomplete && none.effects.is_empty(), "{}", none.verdict);
    assert!(!none.notes.iter().any(|n| n.contains("diagnosed again with the first 90 %")), "{:?}", none.notes);
}

#[test]
fn a_white_residual_off_zero_keeps_the_selection_going() {
    // An input delay and a sensor offset (seed 9707, digital, case 0, white noise): read as the
    // delay alone (+2276 in BIC), its residual white (Q = 19.8 against 37.6) about a mean off
    // zero, so nothing was said to be left and delay + offset (+5164) was never fitted. A
    // residual white about a non-zero mean is something left: the selection goes on.
    let case = bench_gen::generate_pair(["input_delay", "sensor_offset"], 9707, 0, Profile::Digital).unwrap();
    let r = run(&case);
    assert_eq!(named(&case, &r), 2, "{}", r.verdict);
    assert!(!r.model_incomplete, "{}", r.verdict);
}

#[test]
fn an_effect_chosen_over_a_close_single_is_swapped_for_it() {
    // Coulomb friction and a sensor offset (seed 9711, digital, case 0): alone, a constant force
    // (+1356 in BIC) beat the offset (+1321), so the greedy steps built constant force +
    // Coulomb friction (+3084, residual white and centred) and the true pair was never fitted.
    // With Coulomb friction in, the offset in place of the force gains 212 more.
    let case = bench_gen::generate_pair(["coulomb_friction", "sensor_offset"], 9711, 0, Profile::Digital).unwrap();
    let r = run(&case);
    assert_eq!(named(&case, &r), 2, "{}", r.verdict);
    // Negative control: where the force is the truth beside the friction, it is not swapped
    // for the offset.
    let case = bench_gen::generate_pair(["coulomb_friction", "constant_force"], 9711, 0, Profile::Digital).unwrap();
    let r = run(&case);
    assert!(r.effects.iter().all(|e| e.kind != "sensor_offset"), "{}", r.verdict);
}

#[test]
fn a_single_a_quarter_away_is_swapped_too() {
    // A constant force and an input saturation (fresh seed 9844, digital, case 0): alone, a
    // sensor offset (+390 in BIC) beat the force (+299, 23 % less), so the model was read as
    // the saturation + an offset (+3672, residual white) and the true pair never fitted; with
    // the saturation in, the force in place of the offset gains 194 more (`SWAP_WINDOW` 0.25,
    // was 0.1).
    let case = bench_gen::generate_pair(["constant_force", "input_saturation"], 9844, 0, Profile::Digital).unwrap();
    let r = run(&case);
    assert_eq!(named(&case, &r), 2, "{}", r.verdict);
    assert!(r.effects.iter().all(|e| e.kind != "sensor_offset"), "{}", r.verdict);
}

#[test]
fn two_effects_that_fail_alone_are_searched_together() {
    // A loop backlash and an input saturation (seed 9821, digital, case 0): neither single
    // passed the held-out folds against the nominal model, so nothing was named (flagged
    // incomplete). The pair search now also runs from the nominal model where its residual
    // says something is left.
    let case = bench_gen::generate_pair(["backlash", "input_saturation"], 9821, 0, Profile::Digital).unwrap();
    let r = run(&case);
    assert_eq!(named(&case, &r), 2, "{}", r.verdict);
    // Negative control: a pair found that way still has to pass the held-out folds. A constant
    // force and a sensor offset that cancel at rest (seed 9822, mixed, case 0) show only in the
    // first transient: the pair fits (+733 in BIC, both within 3 % of the truth) but the folds
    // gain 6 %, under the 10 % needed, so nothing is named and the model is called incomplete.
    let case = bench_gen::generate_pair(["constant_force", "sensor_offset"], 9822, 0, Profile::Mixed).unwrap();
    let r = run(&case);
    assert!(r.effects.is_empty(), "{}", r.verdict);
    assert!(r.model_incomplete, "{}", r.verdict);
    assert!(r.ranking.iter().any(|h| h.kinds.len() == 2 && h.cv.as_ref().is_some_and(|c| c.status == "failed")));
}

#[test]
fn a_misfit_whitened_by_the_colour_filter_is_still_searched() {
    // A gap width + Coulomb friction under AR(1) 0.79 noise (fresh seed 9861, digital, case 1):
    // forward selection built an input backlash + gap width whose residual (Q 6284 against
    // 37.6) is white once an AR(1) filter (rho 0.94) is removed, so the pair search did not run
    // and the true pair, 877 better in BIC, was never fitted. The pair search now runs
    // whenever the raw residual is not white.
    let case = bench_gen::generate_pair(["gap_width", "coulomb_friction"], 9861, 1, Profile::Digital).unwrap();
    let r = run(&case);
    assert_eq!(named(&case, &r), 2, "{}", r.verdict);
    assert!(r.effects.iter().all(|e| e.kind != "backlash"), "{}", r.verdict);
    // Negative control: a correctly named single under AR(1) 0.86 noise (singles seed 9801,
    // mixed, case 0) leaves a residual that is white only once filtered, so the pair search
    // runs now (pairs without the friction are ranked), and no pair passes the held-out folds
    // against the single.
    let case = bench_gen::generate_profile("coulomb_friction", 9801, 0, Profile::Mixed);
    let r = run(&case);
    assert_eq!(r.effects.len(), 1, "{}", r.verdict);
    assert_eq!(r.effects[0].kind, "coulomb_friction", "{}", r.verdict);
    let searched =
        |h: &discovery::diagnose::Ranked| h.kinds.len() == 2 && h.kinds.iter().all(|k| k != "coulomb_friction");
    assert!(r.ranking.iter().any(searched), "the pair search did not run");
}

#[test]
fn the_pair_pool_is_not_filled_by_one_physics() {
    // Mixed-profile seed 10711 case 0, a gap width and Coulomb friction on a 4-state plant: the
    // six best singles were Stribeck friction on x4 and x2, an input delay, and
    // direction-dependent, Coulomb and load-dependent friction on x2. Rivals are never paired,
    // so the pair search fitted friction + delay only, and Stribeck friction + an input
    // backlash was selected, 1473 worse in BIC than the true pair. The pool now takes at most
    // two singles that stand for the same physics (`select::forward::POOL_RIVALS`).
    let case = bench_gen::generate_pair(["gap_width", "coulomb_friction"], 10711, 0, Profile::Mixed).unwrap();
    let r = run(&case);
    // Control: the gap width's single is not among the six best singles, so a pool of the
    // six best would not hold it.
    let mut singles: Vec<(&str, f64)> = r
        .ranking
        .iter()
        .filter(|x| x.kinds.len() == 1 && x.status.conclusive())
        .map(|x| (x.label.as_str(), x.delta_bic))
        .collect();
    singles.sort_by(|a, b| b.1.total_cmp(&a.1));
    let gap = singles.iter().position(|s| s.0 == "gap_width").expect("the gap width's single");
    assert!(gap >= discovery::select::forward::PAIR_POOL, "gap width single ranked {gap}: {singles:?}");
    assert_eq!(named(&case, &r), 2, "{}", r.verdict);
}

#[test]
fn a_reading_better_in_bic_replaces_the_one_accepted_first() {
    // Mixed-profile seed 10714 case 0, an input delay and an input saturation: the saturation
    // + an input backlash was accepted first (+3003.3), and the true pair (+3137.7) cut its
    // held-out error by 6.6 %, short of the 10 % an addition needs. A reading of the same size
    // that clears the BIC margin and is no worse on held-out folds now replaces it
    // (`select::forward::ALTERNATIVE_MAX_CV_RATIO`).
    use discovery::select::forward::PASSED_AS_ALTERNATIVE;
    let case = bench_gen::generate_pair(["input_delay", "input_saturation"], 10714, 0, Profile::Mixed).unwrap();
    let r = run(&case);
    assert_eq!(named(&case, &r), 2, "{}", r.verdict);
    // Control: it passed as an alternative only, short of an addition's held-out gain.
    let chosen = r.ranking.iter().find(|x| x.beats_nominal && x.kinds.len() == 2).expect("the selected pair");
    let cv = chosen.cv.as_ref().expect("cross-validated");
    assert_eq!(cv.status, PASSED_AS_ALTERNATIVE, "{}: {cv:?}", chosen.label);
    assert!(cv.ratio > 0.9 && cv.ratio <= 1.0, "{cv:?}");
}

#[test]
fn an_effect_that_gains_nothing_beside_the_others_refitted_is_dropped() {
    // Mixed-profile seed 10801, cogging #3: the cogging single ended in a worse minimum
    // (+2346.5 in BIC); beside an input delay the cogging found the better one (+2773.1) and
    // the pair passed its held-out folds against the single, a delay of 7e-6 s +- 1.1e-5 s
    // riding along. Refitted without the delay from the pair's estimate, the cogging alone
    // gains more: the backward step drops the delay.
    let case = bench_gen::generate_profile("cogging", 10801, 3, Profile::Mixed);
    let r = run(&case);
    assert_eq!(r.selected(), "cogging", "{}", r.verdict);
    let pair = r.ranking.iter().find(|x| x.kinds.len() == 2 && x.kinds.iter().any(|k| k == "input_delay"));
    let pair = pair.expect("the cogging + delay pair is in the ranking");
    // Control: the pair had passed its held-out folds; it is dropped for its passenger.
    assert!(pair.cv.as_ref().is_some_and(|c| c.ratio <= 0.9), "{:?}", pair.cv);
    assert!(pair.evidence.contains("beside the others refitted without it"), "{}", pair.evidence);
    let single = r.ranking.iter().find(|x| x.kinds == ["cogging"]).unwrap();
    assert!(single.delta_bic > pair.delta_bic, "{} against {}", single.delta_bic, pair.delta_bic);
}

#[test]
fn coloured_noise_on_a_none_recording_is_not_placed_outside_the_library() {
    // A digital `none` recording under AR(1) noise: the nominal residual is not white, nothing
    // is selected, and the residual is white once the noise's colour is removed. The verdict
    // must not claim a mismatch outside the library (it did), and says why nothing is missing.
    let case = bench_gen::generate_profile("none", 10925, 0, Profile::Digital);
    assert!(case.truths.is_empty());
    let r = run(&case);
    assert!(!r.nominal_adequate, "control: the nominal residual must not be white ({:?})", r.residual_nominal);
    assert!(r.effects.is_empty(), "{}", r.verdict);
    assert!(!r.model_incomplete, "{}", r.verdict);
    let e = r.residual_explained.as_ref().expect("why the residual is not missing physics");
    assert_eq!(e.reason, "noise_colour");
    assert!(e.q_auto > e.q_auto_threshold && e.q_auto_ar1 <= e.q_auto_threshold, "{e:?}");
    assert!(r.verdict.starts_with("no missing physics found"), "{}", r.verdict);
    assert!(!r.verdict.contains("outside the library"), "{}", r.verdict);
    assert!(r.to_markdown(&[]).contains("## What is left"));
}

#[test]
fn a_white_residual_correlated_with_the_input_on_a_none_recording_is_said_so() {
    // A mixed-profile `none` recording whose nominal residual is white but correlated with the
    // input (a first-order hold standing in for a zero-order-held command): nothing is
    // selected, the model is not called incomplete, and the verdict says why instead of
    // placing a mismatch outside the library.
    let case = bench_gen::generate_profile("none", 10941, 8, Profile::Mixed);
    assert!(case.truths.is_empty());
    let r = run(&case);
    let t = &r.residual_nominal;
    assert!(t.white && !t.uncorrelated, "control: white and correlated with the input ({t:?})");
    assert!(r.effects.is_empty() && !r.model_incomplete, "{}", r.verdict);
    let e = r.residual_explained.as_ref().expect("why the residual is not missing physics");
    assert_eq!(e.reason, "white");
    assert!(
        r.verdict.starts_with("no missing physics found: the nominal residual is correlated with the input"),
        "{}",
        r.verdict
    );
    assert!(r.to_markdown(&[]).contains("## What is left"));
}

#[test]
fn a_mismatch_the_library_misses_is_still_called_missing() {
    // Negative control of the one above: Coulomb friction diagnosed with a library that holds
    // only an input delay leaves a residual that is not noise: nothing explains it away, and
    // the model is incomplete.
    let case = bench_gen::generate_profile("coulomb_friction", 27, 0, Profile::Classic);
    let s = DiagnoseSettings {
        initial_state: Some(discovery::diagnose::InitialState {
            x0: case.nominal.x0.iter().copied().collect(),
            z0: Some(case.nominal.z0.iter().copied().collect()),
        }),
        library: Some(vec!["input_delay".to_string()]),
        ..Default::default()
    };
    let r = diagnose(&case.nominal, &case.recording, &s).unwrap();
    assert!(r.effects.is_empty(), "{}", r.verdict);
    assert!(r.model_incomplete, "{}", r.verdict);
    assert!(r.residual_explained.is_none(), "{:?}", r.residual_explained);
    assert!(r.verdict.contains("something is still missing"), "{}", r.verdict);
    assert!(!r.verdict.contains("not missing physics") && !r.verdict.contains("no missing physics"), "{}", r.verdict);
}
