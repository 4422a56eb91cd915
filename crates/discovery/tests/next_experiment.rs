//! The model a diagnosis returns predicts the machine's next experiment
//! (`bench::next_experiment`): the same machine recorded again with a new input and new noise,
//! replayed by the fitted model as it is. Mixed seed 11006, Coulomb friction case 0 (level
//! 23.57 on the velocity state, a sine-segment input next): the returned model predicts the
//! next recording at the noise floor (measured 1.002 times it), where the nominal is 2.5 times
//! above it. Negative controls: the same model with its friction level doubled predicts it
//! 2.4 times above the floor, and without `BENCH_NEXT` a case has no next experiment and the same first
//! recording.
use discovery::bench::{self, next_experiment};
use discovery::bench_gen::{self, Profile};
use discovery::{diagnose, DiagnoseSettings, HoldChoice};
use model::effects::Effect;

#[test]
fn the_returned_model_predicts_the_next_experiment_at_the_noise_floor() {
    let case = bench_gen::generate_with_next("coulomb_friction", 11006, 0, Profile::Mixed);
    let next = case.next.as_ref().expect("a next experiment");
    // The same machine recorded again: same sampling and length, another input.
    assert_eq!(
        (next.recording.t0, next.recording.dt, next.recording.len()),
        (case.recording.t0, case.recording.dt, case.recording.len())
    );
    assert_ne!(next.recording.w, case.recording.w);
    let s = bench::with_case_start(&case, &DiagnoseSettings::default());
    let rep = diagnose(&case.nominal, &case.recording, &s).expect("the case diagnoses");
    assert_eq!(rep.selected(), "coulomb_friction", "{}", rep.verdict);
    let score = next_experiment::score(&case, &rep, &s).expect("scored").expect("predicted");
    eprintln!("{score}");
    assert!(score.over_floor() < 1.05, "{score}");
    assert!(score.rmse_nominal > 2.0 * score.rmse_truth, "{score}");
    assert!(score.explained() > 0.95, "{score}");
    // Negative control: the friction level doubled predicts the next recording far worse.
    let mut wrong = rep.fitted_model.clone().expect("a fitted model");
    for e in wrong.effects.list.iter_mut() {
        if let Effect::CoulombFriction { level, .. } = e {
            *level *= 2.0;
        }
    }
    let hold = HoldChoice::parse(rep.hold.chosen).expect("a hold");
    let r = next_experiment::prediction_rmse(&wrong, &next.recording, hold, &s).expect("predicted");
    eprintln!("doubled friction: RMSE {r:.4e}");
    assert!(r > 1.5 * score.rmse_truth, "doubled friction: RMSE {r} against the floor {}", score.rmse_truth);
}

#[test]
fn without_bench_next_a_case_has_no_next_experiment_and_the_same_first_recording() {
    if bench_gen::next_requested() {
        return; // BENCH_NEXT=1 in the environment: the plain generator records one too
    }
    let plain = bench_gen::generate_profile("coulomb_friction", 11006, 0, Profile::Mixed);
    let with = bench_gen::generate_with_next("coulomb_friction", 11006, 0, Profile::Mixed);
    assert!(plain.next.is_none());
    assert_eq!(plain.recording.w, with.recording.w);
    assert_eq!(plain.recording.y, with.recording.y);
    assert_eq!(plain.truths, with.truths);
}
