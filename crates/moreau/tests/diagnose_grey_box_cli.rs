//! `moreau diagnose` with a grey-box model file (`[fit] free`, `[signals]`) through the built
//! binary: the nominal-only refit is the verdict for a sampled PD loop with a wrong mass, the
//! headline is the RMSE in the output's units, `fitted.toml` records the refit and runs under
//! `moreau simulate`; a bad `[fit]` name is a one-line error naming key and value.
use discovery::bench_gen::servo_loop;
use std::process::Command;

fn moreau() -> Command {
    Command::new(env!("CARGO_BIN_EXE_moreau"))
}

#[test]
fn grey_box_refit_through_the_cli() {
    let dir = tempfile::tempdir().unwrap();
    let case = servo_loop::generate(1, 1, false);
    let model = dir.path().join("servo.toml");
    std::fs::write(&model, model::to_toml_string(&case.nominal)).unwrap();
    let data = dir.path().join("servo.csv");
    std::fs::write(&data, case.recording.to_csv_string()).unwrap();
    let out = dir.path().join("out");
    let o = moreau()
        .arg("diagnose")
        .arg("--model")
        .arg(&model)
        .arg("--data")
        .arg(&data)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}\n{stdout}", String::from_utf8_lossy(&o.stderr));
    let first = stdout.lines().next().unwrap();
    assert!(first.starts_with("the plant's parameters were off"), "{stdout}");
    assert!(first.contains("validation RMSE") && first.contains(" um") && first.contains("um/s"), "{first}");
    assert!(stdout.contains("plant.B[1][0]") && stdout.contains("refitted plant parameter"), "{stdout}");
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("## Plant parameters (grey-box refit)") && md.contains("| plant.A[1][1] |"), "{md}");
    let fitted = std::fs::read_to_string(out.join("fitted.toml")).unwrap();
    assert!(fitted.contains("[fit.result.\"plant.B[1][0]\"]") && fitted.contains("[signals]"), "{fitted}");
    let back = model::load(&out.join("fitted.toml")).unwrap();
    let (m, _) = servo_loop::mass_and_viscous(&back, case.truth.kp, case.truth.kd);
    assert!((m / case.truth.mass - 1.0).abs() < 0.05, "mass {m} against {}", case.truth.mass);
    let sim = dir.path().join("sim");
    let o = moreau().arg("simulate").arg(out.join("fitted.toml")).arg("--out").arg(&sim).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(sim.join("trajectory.csv").exists());

    // --metric fit: the classic headline; --no-refit: the nominal stands.
    let out2 = dir.path().join("out2");
    let o = moreau()
        .args(["diagnose", "--metric", "fit", "--no-refit", "--model"])
        .arg(&model)
        .arg("--data")
        .arg(&data)
        .arg("--out")
        .arg(&out2)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!stdout.contains("plant's parameters were off") && stdout.contains("validation fit %"), "{stdout}");
}

#[test]
fn a_bad_fit_table_is_a_one_line_error() {
    let dir = tempfile::tempdir().unwrap();
    let case = servo_loop::generate(1, 1, false);
    let text = model::to_toml_string(&case.nominal).replace("plant.A[1][1]", "plant.A[1][7]");
    let model = dir.path().join("bad.toml");
    std::fs::write(&model, text).unwrap();
    let data = dir.path().join("servo.csv");
    std::fs::write(&data, case.recording.to_csv_string()).unwrap();
    let out = dir.path().join("out");
    let o = moreau()
        .arg("diagnose")
        .arg("--model")
        .arg(&model)
        .arg("--data")
        .arg(&data)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("fit.free[1]") && err.contains("plant.A[1][7]") && err.contains("2x2"), "{err}");
    assert!(!out.exists());
}
