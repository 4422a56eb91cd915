//! Grey-box refit (`[fit] free`), servo-grade metrics and missing inputs (issue 14 items 1,
//! 2, 5 and the grey-box case of item 7).
//!
//! Fast tests run one generated case each. The measurement over many plants is
//! `grey_box_benchmark` (ignored; about 10 s per plant in the test profile):
//! `cargo test -p discovery --test grey_box -- --ignored --nocapture`, seeds from
//! `GREY_BOX_SEEDS` (default `1,2`: the development seeds) and plants per seed from
//! `GREY_BOX_PLANTS` (default 8).
use discovery::bench_gen::servo_loop::{self, mass_and_viscous};
use discovery::{diagnose, DiagnoseSettings, Recording};
use dynamics::extended::{ExtendedModel, InputHold};

/// Diagnoses a servo case; returns the report and the recovered (mass, viscous).
fn run(case: &servo_loop::ServoCase, s: &DiagnoseSettings) -> (discovery::Report, f64, f64) {
    let mut s = s.clone();
    s.initial_state = Some(discovery::InitialState { x0: vec![0.0, 0.0], z0: Some(vec![0.0]) });
    let r = diagnose(&case.nominal, &case.recording, &s).unwrap();
    let fitted = r.fitted_model.as_ref().unwrap();
    let (m, c) = mass_and_viscous(fitted, case.truth.kp, case.truth.kd);
    (r, m, c)
}

#[test]
fn refit_recovers_the_mass_of_a_sampled_pd_loop() {
    // Development seed 1, plant 0.
    let case = servo_loop::generate(1, 0, false);
    let (r, m, c) = run(&case, &DiagnoseSettings::default());
    eprintln!(
        "{}\n{}\nmass {m:.4} (true {:.4}), viscous {c:.4} (true {:.4})",
        case.description, r.verdict, case.truth.mass, case.truth.viscous
    );
    for l in r.ranking.iter().take(6) {
        eprintln!("  {} dBIC {:.1} {}", l.label, l.delta_bic, l.evidence);
    }
    assert!(r.verdict.starts_with("the plant's parameters were off"), "{}", r.verdict);
    assert!(r.effects.is_empty(), "no effect stands in for the wrong plant: {:?}", r.effects);
    assert_eq!(r.nominal_refit.len(), 3);
    assert!((m / case.truth.mass - 1.0).abs() < 0.05, "mass {m} against {}", case.truth.mass);
    // The nominal was 20-40 % off.
    assert!((case.nominal_mass / case.truth.mass - 1.0).abs() >= 0.2);
    // Uncertainties are reported for every refitted parameter.
    assert!(r.nominal_refit.iter().all(|v| v.std.is_finite() && v.std > 0.0), "{:?}", r.nominal_refit);
    // Servo-grade headline: fit % is above 99 %, so the verdict states the RMSE in um.
    assert_eq!(r.headline_metric, "rmse");
    assert!(
        r.verdict.contains("validation RMSE") && r.verdict.contains(" um") && r.verdict.contains("velocity RMSE"),
        "{}",
        r.verdict
    );
    assert!(r.fit_after.rmse[0] < 0.5 * r.fit_before.rmse[0]);
    // The refit is a hypothesis of its own in the ranking.
    assert!(r.ranking.iter().any(|x| x.label == "nominal_refit"));
    let j = serde_json::to_value(&r).unwrap();
    assert!(
        j["nominal_refit"][0]["std"].is_number() && j["nominal_refit"][0]["name"] == "plant.A[1][0]",
        "{}",
        j["nominal_refit"]
    );

    // fitted.toml: loads back with the refitted plant and [fit.result], and reproduces the fit.
    let fitted = r.fitted_model.as_ref().unwrap();
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join(discovery::diagnose::FITTED_INPUT_FILE), fitted.input.samples_csv().unwrap())
        .unwrap();
    std::fs::write(dir.path().join("fitted.toml"), model::to_toml_string(fitted)).unwrap();
    let back = model::load(&dir.path().join("fitted.toml")).unwrap();
    assert_eq!(back.B, fitted.B);
    assert_eq!(back.A, fitted.A);
    assert_eq!(back.fit.result.len(), 3);
    assert_eq!(back.fit.result[2].value, fitted.B[(1, 0)]);
    assert_eq!(back.signals.y_unit(0), "m");
    let w: Vec<f64> = case.recording.w.iter().map(|x| x[0]).collect();
    let dt = case.recording.dt;
    let sim = ExtendedModel::new(&back, &[], dt, r.substeps)
        .unwrap()
        .with_hold(if r.hold.chosen == "zoh" { InputHold::Zoh } else { InputHold::Foh })
        .simulate(&w, dt, back.x0.as_slice());
    let d = sim.y.iter().zip(&r.series.yhat_fitted).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(d < 1e-9, "the reloaded fitted model departs from the fit by {d:e}");
}

#[test]
fn a_correct_nominal_is_not_refitted_into_another_verdict() {
    // Concealed-effect cases whose nominal is exact, now with freed parameters: the verdict
    // must not change (none stays none, Coulomb friction stays Coulomb friction).
    for (class, idx) in [("none", 0), ("coulomb_friction", 0)] {
        let case = discovery::bench_gen::generate(class, 11, idx);
        let mut sys = case.nominal.clone();
        use model::model_file::{FreeParam, PlantMatrix};
        sys.fit.free = vec![FreeParam::entry(PlantMatrix::A, 1, 0), FreeParam::entry(PlantMatrix::A, 1, 1)];
        let s = DiagnoseSettings {
            initial_state: Some(discovery::InitialState {
                x0: case.nominal.x0.iter().copied().collect(),
                z0: Some(case.nominal.z0.iter().copied().collect()),
            }),
            ..Default::default()
        };
        let fixed = diagnose(&case.nominal, &case.recording, &s).unwrap();
        let freed = diagnose(&sys, &case.recording, &s).unwrap();
        eprintln!("{class}: fixed: {}\n  freed: {}", fixed.verdict, freed.verdict);
        assert_eq!(freed.selected(), fixed.selected(), "{class}: {} vs {}", freed.verdict, fixed.verdict);
        assert!(freed.nominal_refit.is_empty(), "{class}: refitted a correct nominal: {:?}", freed.nominal_refit);
        assert!(freed.ranking.iter().any(|x| x.label == "nominal_refit") || freed.nominal_adequate);
    }
}

#[test]
fn a_recorded_column_left_out_of_the_model_is_reported_missing() {
    // x' = -x + w + 0.8 u: the model knows w, the CSV also has u (a pulse train) and an
    // unrelated column; the model lacks u.
    let text = "name = \"first order\"\n[plant]\nA = [[0.0, 1.0], [-4.0, -1.2]]\nB = [[0.0], [4.0]]\nC = [[1.0, 0.0]]\nE = [[0.0], [0.0]]\n[initial]\nx0 = [0.0, 0.0]\n";
    let sys = model::parse_str(text).unwrap();
    let dt = 0.01;
    let n = 3000;
    let w: Vec<f64> = (0..n).map(|k| (0.7 * k as f64 * dt).sin() + 0.5 * (1.9 * k as f64 * dt).sin()).collect();
    let u: Vec<f64> = (0..n).map(|k| if (k / 150) % 3 == 1 { 1.0 } else { 0.0 }).collect();
    let unrelated: Vec<f64> = (0..n).map(|k| (3.3 * k as f64 * dt).cos() * (0.05 * k as f64 * dt).sin()).collect();
    let mut truth = sys.clone();
    truth.B = nalgebra::DMatrix::from_row_slice(2, 2, &[0.0, 0.0, 4.0, 3.2]);
    truth.input = model::Input::Zero { m: 2 };
    let wu: Vec<f64> = (0..n).flat_map(|k| [w[k], u[k]]).collect();
    let y = ExtendedModel::new(&truth, &[], dt, 4).unwrap().simulate(&wu, dt, &[0.0, 0.0]).y;
    let mut csv = "t,w,y,pulse,unrelated,sample\n".to_string();
    let mut rng = 12345u64;
    for k in 0..n {
        rng = rng.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let noise = ((rng >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 2e-3;
        csv += &format!("{},{},{},{},{},{}\n", k as f64 * dt, w[k], y[k] + noise, u[k], unrelated[k], k);
    }
    let rec = Recording::parse_str(&csv, "missing.csv").unwrap();
    assert_eq!(rec.extra.iter().map(|e| e.0.as_str()).collect::<Vec<_>>(), ["pulse", "unrelated", "sample"]);
    let s = DiagnoseSettings {
        initial_state: Some(discovery::InitialState { x0: vec![0.0, 0.0], z0: None }),
        ..Default::default()
    };
    let r = diagnose(&sys, &rec, &s).unwrap();
    eprintln!("{}\n{:?}", r.verdict, r.missing_inputs);
    assert!(r.verdict.starts_with("input pulse is missing from the model"), "{}", r.verdict);
    assert!(r.effects.is_empty(), "{:?}", r.effects);
    let chk = |c: &str| r.missing_inputs.iter().find(|m| m.column == c);
    assert!(chk("pulse").unwrap().missing);
    // Negative controls: the unrelated column is not reported, the counter is skipped.
    assert!(!chk("unrelated").unwrap().missing);
    assert!(chk("sample").is_none());
    // And without the column, an effect stands in (the situation the check prevents).
    let csv2: String =
        csv.lines().map(|l| l.split(',').take(3).collect::<Vec<_>>().join(",")).collect::<Vec<_>>().join("\n");
    let r2 = diagnose(&sys, &Recording::parse_str(&csv2, "without.csv").unwrap(), &s).unwrap();
    eprintln!("without the column: {}", r2.verdict);
    assert!(!r2.verdict.contains("is missing from the model"));
}

/// Over `GREY_BOX_PLANTS` plants of each seed in `GREY_BOX_SEEDS`: mass recovered within 5 %,
/// verdict "the plant's parameters were off".
#[test]
#[ignore]
fn grey_box_benchmark() {
    let seeds: Vec<u64> = std::env::var("GREY_BOX_SEEDS")
        .unwrap_or_else(|_| "1,2".into())
        .split(',')
        .map(|x| x.trim().parse().unwrap())
        .collect();
    let plants: usize = std::env::var("GREY_BOX_PLANTS").ok().and_then(|v| v.parse().ok()).unwrap_or(8);
    let s = DiagnoseSettings::default();
    let (mut ok_mass, mut ok_verdict, mut total) = (0, 0, 0);
    let mut worst: f64 = 0.0;
    for &seed in &seeds {
        for i in 0..plants {
            let case = servo_loop::generate(seed, i, false);
            let t0 = std::time::Instant::now();
            let (r, m, c) = run(&case, &s);
            let em = m / case.truth.mass - 1.0;
            let ec = c / case.truth.viscous - 1.0;
            total += 1;
            ok_mass += (em.abs() <= 0.05) as usize;
            ok_verdict += r.verdict.starts_with("the plant's parameters were off") as usize;
            worst = worst.max(em.abs());
            println!(
                "seed {seed} plant {i}: mass error {:+.2} % (nominal {:+.1} %), viscous error {:+.1} % (nominal {:+.1} %), RMSE {:.2e} -> {:.2e} m, {:.1} s | {} | {}",
                100.0 * em,
                100.0 * (case.nominal_mass / case.truth.mass - 1.0),
                100.0 * ec,
                100.0 * (case.nominal_viscous / case.truth.viscous - 1.0),
                r.fit_before.rmse[0],
                r.fit_after.rmse[0],
                t0.elapsed().as_secs_f64(),
                case.description,
                r.verdict
            );
        }
    }
    println!("seeds {seeds:?}: mass within 5 %: {ok_mass}/{total} (worst {:.2} %), verdict 'plant parameters off': {ok_verdict}/{total}", 100.0 * worst);
    assert_eq!(ok_mass, total);
}

#[test]
fn an_input_effect_on_one_of_two_inputs_gets_its_own_parameter() {
    // Two inputs in different units: a reference in mm (peak ~14, never clipped) and a
    // voltage (peak ~9) that the drive clips at 70 % of its peak. One limit for both inputs
    // cannot say this (it would clip the reference first); a per-input saturation can.
    let text = "name = \"two inputs\"\n[plant]\nA = [[0.0, 1.0], [-4.0, -1.2]]\nB = [[0.0, 0.0], [0.4, 0.3]]\nC = [[1.0, 0.0]]\nE = [[0.0], [0.0]]\n[initial]\nx0 = [0.0, 0.0]\n[signals]\nw = [\"m\", \"V\"]\n";
    let sys = model::parse_str(text).unwrap();
    let dt = 0.01;
    let n = 4000;
    let w1: Vec<f64> =
        (0..n).map(|k| 10.0 * (0.5 * k as f64 * dt).sin() + 4.0 * (1.7 * k as f64 * dt + 1.0).sin()).collect();
    let w2: Vec<f64> = (0..n).map(|k| 6.0 * (0.9 * k as f64 * dt).sin() + 3.3 * (2.3 * k as f64 * dt).cos()).collect();
    let peak = w2.iter().fold(0.0f64, |a, b| a.max(b.abs()));
    let limit = 0.7 * peak;
    // The plant sees the clipped voltage, held over each sample (zero-order hold).
    let wu: Vec<f64> = (0..n).flat_map(|k| [w1[k], w2[k].clamp(-limit, limit)]).collect();
    let y = ExtendedModel::new(&sys, &[], dt, 8).unwrap().with_hold(InputHold::Zoh).simulate(&wu, dt, &[0.0, 0.0]).y;
    let mut csv = "t,w1,w2,y\n".to_string();
    let mut rng = 777u64;
    for k in 0..n {
        rng = rng.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        let noise = ((rng >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 2e-3;
        csv += &format!("{},{},{},{}\n", k as f64 * dt, w1[k], w2[k], y[k] + noise);
    }
    let rec = Recording::parse_str(&csv, "two-inputs.csv").unwrap();
    let s = DiagnoseSettings {
        initial_state: Some(discovery::InitialState { x0: vec![0.0, 0.0], z0: None }),
        input_hold: discovery::HoldChoice::Fixed(dynamics::extended::InputHold::Zoh),
        ..Default::default()
    };
    let r = diagnose(&sys, &rec, &s).unwrap();
    eprintln!("{}", r.verdict);
    for l in r.ranking.iter().take(6) {
        eprintln!("  {} {:?} dBIC {:.1} {}", l.label, l.params, l.delta_bic, l.evidence);
    }
    assert_eq!(r.effects.len(), 1, "{}", r.verdict);
    assert_eq!(r.effects[0].label, "input_saturation(w2)", "{}", r.verdict);
    let est = r.effects[0].params[0].1;
    assert!((est / limit - 1.0).abs() < 0.05, "limit {est} against {limit}");
    // The global saturation (one limit for both inputs) was a candidate and lost.
    let global = r.ranking.iter().find(|x| x.label == "input_saturation").unwrap();
    let own = r.ranking.iter().find(|x| x.label == "input_saturation(w2)").unwrap();
    assert!(own.bic < global.bic - 10.0, "per-input {} vs global {}", own.bic, global.bic);
    // fitted.toml carries the clipped voltage in its input file, no global saturation.
    let fitted = r.fitted_model.as_ref().unwrap();
    assert!(fitted.effects.list.is_empty(), "{:?}", fitted.effects);
    let model::Input::Samples { w, .. } = &fitted.input else { panic!("samples input") };
    assert!(w.iter().all(|r| r[1].abs() <= est + 1e-12) && w.iter().any(|r| r[0].abs() > 10.0));
}

/// The shipped BAM XL330 logs with the grey-box model (`examples/real/bam-xl330-kp100-greybox.toml`:
/// loop gain and damping freed with physical bounds): both logs name friction that grows with
/// the gearbox's load (`load_friction`, issue 28) with a load coefficient of the upstream
/// identification's size (0.12 in its M3, 0.27 in its M6; here 0.43 and 0.17: `sin_time_square`
/// also refits the loop's entries, and the load is computed from them), the validation fit
/// improves by more than 50 points, and the RMSE headline is in mrad.
/// (Before `load_friction`, both logs refitted the documented loop gain 40 % down and took
/// input saturation: a stand-in that did not carry from one log to the other.)
#[test]
fn bam_logs_name_the_gearbox_load_friction() {
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let sys = model::load(&root.join("examples/real/bam-xl330-kp100-greybox.toml")).unwrap();
    let mut coefficients = Vec::new();
    for log in ["xl330-kp100-sin_sin.csv", "xl330-kp100-sin_time_square.csv"] {
        let rec = Recording::load(&root.join("data/bam-servo").join(log)).unwrap();
        let s = DiagnoseSettings {
            initial_state: Some(discovery::InitialState { x0: vec![0.0, 0.0], z0: Some(vec![0.0]) }),
            metric: discovery::diagnose::Metric::Rmse,
            ..Default::default()
        };
        let r = diagnose(&sys, &rec, &s).unwrap();
        eprintln!("{log}: {}", r.verdict);
        let Some(load) = r.effects.iter().find(|e| e.label == "load_friction(x2)") else {
            panic!("{log}: no load_friction in {}", r.verdict)
        };
        coefficients.push(load.params.iter().find(|p| p.0 == "load_coefficient").unwrap().1);
        assert!(r.headline.contains("mrad") && r.headline_metric == "rmse", "{}", r.headline);
        assert!(r.fit_after.fit_percent[0].unwrap() > r.fit_before.fit_percent[0].unwrap() + 50.0, "{}", r.verdict);
    }
    eprintln!("load coefficients {coefficients:?}");
    assert!(coefficients.iter().all(|k| (0.05..=0.6).contains(k)), "{coefficients:?}");
}

/// Issue 14's acceptance case: a friction-dominated sampled (1 kHz) position loop whose nominal
/// model leaves the Coulomb friction out (Fc = 5 % and 15 % of the peak reference force). The
/// diagnosis must name friction on the velocity state and, the loop tracking to better than
/// 99 %, head its verdict with the RMSE in the output's unit (m, shown in um/nm/mm).
/// Ignored (about 10 s per plant in the test profile):
/// `cargo test -p discovery --test grey_box -- --ignored friction_dominated --nocapture`.
/// Seed 78 was run once with the final code: 8/8 named friction, 8/8 RMSE headlines.
#[test]
#[ignore]
fn friction_dominated_sampled_loop_names_friction_with_an_rmse_headline() {
    let (mut named, mut total) = (0, 0);
    for fr in [0.05, 0.15] {
        for idx in 0..2 {
            let c = servo_loop::generate_with_friction(77, idx, true, fr);
            assert!(c.truth.coulomb > 0.0);
            let r = diagnose(&c.nominal, &c.recording, &DiagnoseSettings::default()).unwrap();
            let v = &r.verdict;
            eprintln!("Fc = {:.3} N: {}", c.truth.coulomb, v);
            let friction = v.contains("friction(x2)") || v.contains("asymmetric_coulomb(x2)");
            let units = [" um", " nm", " mm"].iter().any(|u| v.contains(u));
            assert!(v.contains("validation RMSE") && units, "no RMSE headline in units: {v}");
            total += 1;
            named += friction as usize;
        }
    }
    assert_eq!(named, total, "friction named on {named} of {total} friction-dominated loops");
    // Control: the same loops without friction are not given one.
    let c = servo_loop::generate_with_friction(77, 0, true, 0.0);
    let r = diagnose(&c.nominal, &c.recording, &DiagnoseSettings::default()).unwrap();
    assert!(!r.verdict.contains("friction(x2)"), "friction claimed without friction: {}", r.verdict);
}
