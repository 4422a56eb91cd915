//! Long records screened on their leading part (`diagnose::screen`): the whole record judged with
//! what the screening kept gives the unscreened diagnosis's answer; an effect that acts only
//! after the leading part is not hidden (negative control: the narrowed model is found
//! incomplete and the whole library runs again).
use discovery::bench_gen::long_record::{long_recording, LongNoise};
use discovery::{diagnose, DiagnoseSettings, Recording};
use dynamics::extended::ExtendedModel;
use model::effects::Effect;
use rand::{Rng, SeedableRng};

fn settings(screen_samples: usize) -> DiagnoseSettings {
    DiagnoseSettings { screen_samples, ..Default::default() }
}

#[test]
fn a_screened_long_record_gives_the_unscreened_answer() {
    let (sys, rec) = long_recording(2_400, LongNoise::White);
    let whole = diagnose(&sys, &rec, &settings(0)).unwrap();
    let screened = diagnose(&sys, &rec, &settings(1_000)).unwrap();
    assert!(whole.screening.is_none(), "screen_samples 0 never screens");
    let sc = screened.screening.as_ref().expect("a record longer than screen_samples is screened");
    assert_eq!(sc.samples, 1_000);
    assert!(!sc.full_library, "{sc:?}");
    assert!(sc.kept.iter().any(|k| k == "coulomb_friction(x2)"), "{sc:?}");
    assert!(screened.notes[0].contains("screened on its first 1000"), "{}", screened.notes[0]);
    // every number is the whole record's
    assert_eq!(screened.samples, 2_400);
    assert_eq!(screened.selected(), whole.selected());
    assert_eq!(whole.selected(), "coulomb_friction");
    let (a, b) = (screened.effects[0].params[0].1, whole.effects[0].params[0].1);
    let sigma = whole.effects[0].uncertainty[0].1;
    assert!((a - b).abs() <= 0.1 * sigma, "level {a} vs unscreened {b} +- {sigma}");
    // a short record is not screened, nor any record under the largest setting (no overflow)
    let short = diagnose(&sys, &rec.leading(900), &settings(1_000)).unwrap();
    assert!(short.screening.is_none());
    let huge = diagnose(&sys, &rec.leading(900), &settings(usize::MAX)).unwrap();
    assert!(huge.screening.is_none());
}

#[test]
fn an_effect_acting_after_the_leading_part_is_not_hidden_by_the_screening() {
    // An input saturation the small input of the first 1000 samples never reaches.
    let (sys, base) = long_recording(2_400, LongNoise::White);
    let dt = base.dt;
    let w: Vec<f64> = (0..base.len())
        .map(|k| {
            let t = k as f64 * dt;
            let a = if k < 1_200 { 0.3 } else { 1.2 };
            a * ((0.97 * t).sin() + 0.4 * (2.3 * t + 1.0).sin())
        })
        .collect();
    let truth = [Effect::InputSaturation { limit: 0.8 }];
    let out = ExtendedModel::new(&sys, &truth, dt, 8).unwrap().simulate(&w, dt, sys.x0.as_slice());
    let yr =
        out.y.iter().copied().fold(f64::NEG_INFINITY, f64::max) - out.y.iter().copied().fold(f64::INFINITY, f64::min);
    // seeded white noise, uniform, 0.3 % of the range
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let y: Vec<Vec<f64>> = out.y.iter().map(|v| vec![v + 0.003 * yr * (rng.random::<f64>() - 0.5)]).collect();
    let t: Vec<f64> = (0..w.len()).map(|k| k as f64 * dt).collect();
    let rec = Recording::from_samples("late saturation", &t, w.iter().map(|v| vec![*v]).collect(), y, None);
    let r = diagnose(&sys, &rec, &settings(1_000)).unwrap();
    let sc = r.screening.as_ref().expect("screened");
    eprintln!("{sc:?}\n{}", r.verdict);
    assert_eq!(sc.selected, "none", "the first part has nothing missing: {sc:?}");
    assert!(sc.full_library, "the whole record must be diagnosed again with every hypothesis: {sc:?}");
    assert_eq!(r.selected(), "input_saturation", "{}", r.verdict);
}
