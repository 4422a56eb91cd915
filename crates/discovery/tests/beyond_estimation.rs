//! An effect that acts only beyond the estimation segment (`diagnose/extend.rs`): an input
//! saturation whose limit only commands after 76 % of the record exceed (mixed seed 11008,
//! saturation case 2: limit 0.785; its estimation fit is stuck at zero gradient, yet it cuts
//! the held-out error to 0.109). The diagnosis with the default 70 % estimation segment calls
//! the model incomplete and names the effect; the second diagnosis, with 90 %, selects it, and
//! its limit must lie within 2 reported sigma of the truth.
//! Negative controls: a saturation that acts within the first 70 % (case 0) and a recording with
//! nothing concealed (`none`, case 0) take the ordinary path: no second diagnosis.
use discovery::bench_gen::{self, Profile};
use discovery::{bench, diagnose, DiagnoseSettings, Report};
use model::effects::Effect;

const NOTE: &str = "acts only beyond the estimation segment";

fn diagnosed(class: &'static str, index: usize) -> (Report, Vec<Effect>) {
    let case = bench_gen::generate_profile(class, 11008, index, Profile::Mixed);
    let s = bench::with_case_start(&case, &DiagnoseSettings::default());
    (diagnose(&case.nominal, &case.recording, &s).expect("the case diagnoses"), case.truths)
}

#[test]
fn a_saturation_only_the_last_commands_reach_is_selected_on_a_longer_estimation_segment() {
    let (rep, truths) = diagnosed("input_saturation", 2);
    let Some(Effect::InputSaturation { limit }) = truths.first() else { panic!("a saturation case: {truths:?}") };
    assert_eq!(rep.selected(), "input_saturation", "notes {:?}", rep.notes);
    assert!(rep.notes.iter().any(|n| n.contains(NOTE)), "{:?}", rep.notes);
    let fitted = &rep.effects[0];
    let est = fitted.params[0].1;
    let sigma = fitted.uncertainty[0].1;
    assert!((est - limit).abs() <= 2.0 * sigma, "limit {est} +- {sigma} against the truth {limit}");
    assert!(!rep.model_incomplete, "{:?}", rep.remaining);
}

#[test]
fn effects_the_estimation_segment_sees_take_the_ordinary_path() {
    let (rep, _) = diagnosed("input_saturation", 0);
    assert_eq!(rep.selected(), "input_saturation");
    assert!(!rep.notes.iter().any(|n| n.contains(NOTE)), "{:?}", rep.notes);
    let (rep, _) = diagnosed("none", 0);
    assert_eq!(rep.selected(), "none");
    assert!(!rep.notes.iter().any(|n| n.contains(NOTE)), "{:?}", rep.notes);
}
