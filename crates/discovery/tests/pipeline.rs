//! End-to-end tests of the diagnosis: a fixed-seed slice of the concealed-effect benchmark,
//! effects that vanish at zero, stick-slip, bad input, and the fitted-model round trip.
use discovery::bench_gen::{self, CLASSES};
use discovery::{diagnose, DiagnoseSettings, DiscoveryError, Recording};
use dynamics::extended::ExtendedModel;
use model::effects::{Effect, PlayLocation};

#[test]
fn fixed_seed_benchmark_slice() {
    // One case of every class (seed 11). The full benchmark is `moreau discover-bench`.
    let s = DiagnoseSettings::default();
    let mut correct = 0;
    let mut lines = Vec::new();
    for &c in CLASSES.iter() {
        let r = discovery::bench::run_case(c, 11, 0, &s);
        assert!(r.error.is_none(), "{c}: {:?}", r.error);
        if r.correct_or_tied {
            correct += 1;
        }
        if c == "none" {
            assert_eq!(r.predicted, "none", "false alarm on a nominal-only recording: {r:?}");
        } else {
            assert!(r.fit_after >= r.fit_before - 0.5 || r.predicted == "none", "{c}: fit got worse {r:?}");
        }
        lines.push(format!("{c} -> {} (ties {:?}, param error {:?})", r.selected, r.ties, r.param_error));
        if let Some(e) = r.param_error {
            assert!(e <= 0.15, "{c}: parameter error {:.1} % above the 15 % target: {r:?}", 100.0 * e);
        }
    }
    eprintln!("{}", lines.join("\n"));
    assert!(correct >= 8, "only {correct}/9 named correctly:\n{}", lines.join("\n"));
}

#[test]
fn wide_gap_and_coasting_output_are_estimated() {
    // Regressions: seed 1 case 7 hides a play 8.1 times the nominal one (the former fixed
    // bound relative_change <= 4 capped it at 44 % error); seed 1 case 5 hides backlash
    // inertia (a rounding-triggered contact once slowed the coasting, 39 % error).
    let s = DiagnoseSettings::default();
    for (c, i) in [("gap_width", 7), ("backlash_inertia", 5)] {
        let r = discovery::bench::run_case(c, 1, i, &s);
        assert!(r.correct, "{c} #{i}: {r:?}");
        let e = r.param_error.expect("named correctly");
        assert!(e <= 0.15, "{c} #{i}: parameter error {:.1} %: {r:?}", 100.0 * e);
    }
}

#[test]
fn every_effect_at_zero_equals_the_nominal_model() {
    let case = bench_gen::generate("none", 5, 0);
    let sys = &case.nominal;
    let w: Vec<f64> = case.recording.w.iter().map(|r| r[0]).collect();
    let dt = case.recording.dt;
    let x0 = sys.x0.as_slice().to_vec();
    let nominal = ExtendedModel::new(sys, &[], dt, 2).unwrap().simulate(&w, dt, &x0).y;
    let zeros = [
        Effect::Backlash { width: 0.0, location: PlayLocation::Input },
        Effect::GapWidth { relative_change: 0.0 },
        Effect::CoulombFriction { state: 1, level: 0.0 },
        Effect::ConstantForce { state: 1, force: 0.0 },
        Effect::BacklashInertia { mass: 0.0, damping: 1.0 },
        Effect::InputDelay { delay: 0.0 },
        Effect::InputSaturation { limit: 1e9 },
        Effect::SensorOffset { offset: vec![0.0] },
        Effect::StribeckFriction { state: 1, level: 0.0, static_level: 0.0, stribeck_velocity: 0.1, viscous: 0.0 },
        Effect::AsymmetricCoulomb { state: 1, level_positive: 0.0, level_negative: 0.0 },
        Effect::Cogging { state: 1, position_state: 0, amplitude: 0.0, period: 0.2, phase: 0.5 },
    ];
    for e in zeros {
        let y = ExtendedModel::new(sys, std::slice::from_ref(&e), dt, 2).unwrap().simulate(&w, dt, &x0).y;
        let d = y.iter().zip(&nominal).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(d < 1e-12, "{e:?} at zero differs by {d}");
    }
    // Negative control: a non-zero effect must differ.
    let y =
        ExtendedModel::new(sys, &[Effect::SensorOffset { offset: vec![0.01] }], dt, 2).unwrap().simulate(&w, dt, &x0).y;
    assert!((y[0] - nominal[0] - 0.01).abs() < 1e-12);
}

#[test]
fn coulomb_friction_sticks_and_slips() {
    // x' = v, v' = -x - 0.2 v + w: a constant push of 0.5 against friction 1.0 never moves it;
    // a push of 2.0 does.
    let text = "name = \"mass\"\n[plant]\nA = [[0.0, 1.0], [-1.0, -0.2]]\nB = [0.0, 1.0]\nC = [[1.0, 0.0]]\nE = [0.0, 0.0]\n[input]\nkind = \"zero\"\nm = 1\n[initial]\nx0 = [0.0, 0.0]\nz0 = [0.0]\n";
    let sys = model::parse_str(text)
        .or_else(|_| {
            model::parse_str(
                &text.replace("kind = \"zero\"\nm = 1", "kind = \"sine\"\namplitudes = [0.0]\nomega = 1.0"),
            )
        })
        .unwrap();
    let fric = [Effect::CoulombFriction { state: 1, level: 1.0 }];
    let ext = ExtendedModel::new(&sys, &fric, 0.01, 1).unwrap();
    let stuck = ext.simulate(&vec![0.5; 500], 0.01, &[0.0, 0.0]).y;
    assert!(stuck.iter().all(|v| v.abs() < 1e-12), "moved under a sub-threshold force");
    let slips = ext.simulate(&vec![2.0; 500], 0.01, &[0.0, 0.0]).y;
    // Equilibrium with kinetic friction: x -> 2 - 1 = 1 (it sticks somewhere in [1, 3]).
    assert!(slips[499] > 0.9, "did not slip: {}", slips[499]);
}

fn small_csv(rows: usize, f: impl Fn(f64) -> (f64, f64)) -> String {
    let mut s = "t,w,y\n".to_string();
    for k in 0..rows {
        let t = k as f64 * 0.05;
        let (w, y) = f(t);
        s += &format!("{t},{w},{y}\n");
    }
    s
}

#[test]
fn bad_input_gives_named_errors() {
    let case = bench_gen::generate("none", 5, 0);
    let sys = &case.nominal;
    // Too short for the slowest time constant.
    let rec = Recording::parse_str(&small_csv(60, |t| (t.sin(), t.cos())), "short.csv").unwrap();
    let e = diagnose(sys, &rec, &DiagnoseSettings::default()).unwrap_err();
    assert!(matches!(e, DiscoveryError::TooShort { .. }), "{e}");
    // Dimensions disagree.
    let text = "t,w1,w2,y\n".to_string()
        + &(0..100)
            .map(|k| format!("{},{},{},{}\n", k as f64 * 0.1, (k as f64).sin(), (k as f64).cos(), k))
            .collect::<String>();
    let rec = Recording::parse_str(&text, "two-inputs.csv").unwrap();
    let e = diagnose(sys, &rec, &DiagnoseSettings::default()).unwrap_err();
    assert!(e.to_string().contains("inputs m"), "{e}");
    // Bad settings.
    let e = diagnose(sys, &case.recording, &DiagnoseSettings { estimation_fraction: 1.5, ..Default::default() })
        .unwrap_err();
    assert!(e.to_string().contains("estimation_fraction"), "{e}");
}

#[test]
fn fitted_model_round_trips_through_the_model_file() {
    let case = bench_gen::generate("sensor_offset", 11, 0);
    let r = diagnose(&case.nominal, &case.recording, &DiagnoseSettings::default()).unwrap();
    let m = r.fitted_model.as_ref().unwrap();
    assert!(!m.effects.list.is_empty(), "{}", r.verdict);
    let text = model::to_toml_string(m);
    // The fitted model carries the recording's input as a CSV input beside it.
    let dir = tempfile::tempdir().unwrap();
    assert!(text.contains(discovery::diagnose::FITTED_INPUT_FILE), "{text}");
    std::fs::write(dir.path().join(discovery::diagnose::FITTED_INPUT_FILE), m.input.samples_csv().unwrap()).unwrap();
    std::fs::write(dir.path().join("fitted.toml"), &text).unwrap();
    let back = model::load(&dir.path().join("fitted.toml")).unwrap();
    assert_eq!(back.effects, m.effects);
    assert_eq!(back.input.samples_csv(), m.input.samples_csv());
    assert_eq!(back.sim, m.sim);
    // The JSON report has the documented keys.
    let j = serde_json::to_value(&r).unwrap();
    for k in ["fit_before", "fit_after", "effects", "windows", "ranking"] {
        assert!(j.get(k).is_some(), "report.json lacks {k}");
    }
    assert!(j["effects"][0].get("uncertainty").is_some());
}

#[test]
fn backlash_inertia_coasts_as_the_closed_form() {
    // x' = -x + w, w = 1, y = x, play half-width r = 0.1 not fed back (E = 0): z stays at 0
    // until y - z = r at t_c = ln(1/0.9), is then pushed with y' = 0.9 and, since y decelerates
    // faster (rate 1) than the coasting output (rate 1/tau, tau = 1.05), leaves y at once and
    // coasts: z(t) = 0.9 tau (1 - e^{-(t - t_c)/tau}), always within r of y.
    let text = "name = \"coast\"\n[plant]\nA = [[-1.0]]\nB = [[1.0]]\nC = [[1.0]]\nE = [[0.0]]\n[theta]\nshape = \"interval\"\nhalf_width = 0.1\n[input]\nkind = \"sine\"\namplitudes = [1.0]\nomega = 1.0\n[initial]\nx0 = [0.0]\nz0 = [0.0]\n";
    let sys = model::parse_str(text).unwrap();
    let (dt, ns, tau) = (0.002, 5000, 1.05);
    let w = vec![1.0; ns];
    let tc = (1.0f64 / 0.9).ln();
    let exact = |t: f64| if t <= tc { 0.0 } else { 0.9 * tau * (1.0 - (-(t - tc) / tau).exp()) };
    let run = |tau: f64| {
        let e = [Effect::BacklashInertia { mass: tau, damping: 1.0 }];
        ExtendedModel::new(&sys, &e, dt, 4).unwrap().simulate(&w, dt, &[0.0]).z
    };
    let z = run(tau);
    let err = (0..ns).map(|k| (z[k] - exact(k as f64 * dt)).abs()).fold(0.0, f64::max);
    assert!(err < 5e-3, "coasting output off the closed form by {err}");
    // Negative control: a massless output ends at y - r = 0.9 - e^{-10}, 0.045 below.
    let z0 = run(0.0);
    let err0 = (z0[ns - 1] - exact((ns - 1) as f64 * dt)).abs();
    assert!(err0 > 0.04, "massless output indistinguishable from the coasting one ({err0})");
}

#[test]
fn max_effects_zero_adds_no_effect() {
    // `--max-effects 0` judged a model as it is (e.g. a model fitted on another recording):
    // it used to bound only the forward additions, and the best single effect was still added.
    let case = bench_gen::generate("coulomb_friction", 11, 0);
    let added = diagnose(&case.nominal, &case.recording, &DiagnoseSettings::default()).unwrap();
    assert_ne!(added.selected(), "none", "control: the concealed friction is named by default: {}", added.verdict);
    let s = DiagnoseSettings { max_effects: 0, ..Default::default() };
    let r = diagnose(&case.nominal, &case.recording, &s).unwrap();
    assert_eq!(r.selected(), "none", "{}", r.verdict);
}
