//! A constant force and a sensor offset are the same model once the initial state is free
//! (`--estimate-x0`, or a model file that states no `x0`): the force's equilibrium shift is
//! absorbed by the initial state, and the play is translation invariant. The report must then
//! name the other reading as a tie and say why (BENCHMARKS, "Issue 27 on seeds 10993-11005": 15
//! of 32 such recordings named the other reading first). Negative control: with the model
//! file's `x0` known, the same recordings are told apart, the truth selected and the other
//! reading not tied.
use discovery::bench_gen::{self, Profile};
use discovery::{bench, diagnose, DiagnoseSettings, Report};

/// The kinds the report names: the selected effects' and the tied readings'.
fn kinds_named(rep: &Report) -> Vec<String> {
    let kind = |label: &str| label.split('(').next().unwrap_or(label).to_string();
    rep.effects.iter().map(|e| e.kind.clone()).chain(rep.ties.iter().map(|t| kind(t))).collect()
}

#[test]
fn force_and_offset_are_tied_once_the_initial_state_is_free() {
    for (class, other) in [("constant_force", "sensor_offset"), ("sensor_offset", "constant_force")] {
        let case = bench_gen::generate_profile(class, 11, 0, Profile::Classic);
        let stated = bench::with_case_start(&case, &DiagnoseSettings::default());
        let free = DiagnoseSettings { estimate_x0: true, ..stated.clone() };

        let known = diagnose(&case.nominal, &case.recording, &stated).expect("the case diagnoses");
        assert_eq!(known.effects.first().map(|e| e.kind.as_str()), Some(class), "{class}, x0 known: {:?}", known.ties);
        assert!(!kinds_named(&known).iter().any(|k| k == other), "{class}, x0 known, ties {:?}", known.ties);
        assert!(
            known.notes.iter().any(|n| n.contains("told apart here by the known initial state")),
            "{class}, x0 known: {:?}",
            known.notes
        );

        let estimated = diagnose(&case.nominal, &case.recording, &free).expect("the case diagnoses");
        let named = kinds_named(&estimated);
        assert!(
            named.iter().any(|k| k == class) && named.iter().any(|k| k == other),
            "{class}, x0 estimated: selected {}, ties {:?}",
            estimated.selected(),
            estimated.ties
        );
        assert!(
            estimated.notes.iter().any(|n| n.contains("observationally equivalent when the initial state is free")),
            "{class}, x0 estimated: {:?}",
            estimated.notes
        );
    }
}
