//! `moreau diagnose` with a grey-box model file (`[fit] free`, `[signals]`) through the built
//! binary: the nominal-only refit is the verdict for a sampled PD loop with a wrong mass, the
//! headline is the RMSE in the output's units, `fitted.toml` records the refit and runs under
//! `moreau simulate`; a bad `[fit]` name is a one-line error naming key and value.
use discovery::bench_gen::servo_loop;
use std::path::Path;
use std::process::{Command, Output};

fn moreau() -> Command {
    Command::new(env!("CARGO_BIN_EXE_moreau"))
}

/// `moreau diagnose [extra] --model MODEL --data DATA --out OUT`.
fn diagnose(extra: &[&str], model: &Path, data: &Path, out: &Path) -> Output {
    moreau()
        .arg("diagnose")
        .args(extra)
        .arg("--model")
        .arg(model)
        .arg("--data")
        .arg(data)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap()
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
    let o = diagnose(&[], &model, &data, &out);
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
    let o = diagnose(&["--metric", "fit", "--no-refit"], &model, &data, &out2);
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
    let o = diagnose(&[], &model, &data, &out);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("fit.free[1]") && err.contains("plant.A[1][7]") && err.contains("2x2"), "{err}");
    assert!(!out.exists());
}

/// The servo loop of [`grey_box_refit_through_the_cli`] written as a machine is described:
/// mass `M`, viscous friction `c` and the controller's gains in `[parameters]`, the matrix
/// entries as expressions of them, `[fit] free = ["M", "c"]`. The refit moves the physical
/// parameters (the gains stay the controller's), `fitted.toml` keeps the expressions and
/// carries the fitted `M` and `c` with their sigma, and a sweep runs over `parameters.M`.
#[test]
fn physical_parameters_are_refitted_as_such() {
    let dir = tempfile::tempdir().unwrap();
    let case = servo_loop::generate(1, 1, false);
    let text = format!(
        "name = \"PD loop on a carriage\"\n[parameters]\nM = {m}\nc = {c}\nkp = {kp}\nkd = {kd}\n\
         [plant]\nA = [[0, 1], [\"-kp/M\", \"-(c + kd)/M\"]]\nB = [0, \"kp/M\"]\nC = [[1, 0]]\nE = [0, 0]\n\
         [input]\nkind = \"zero\"\n[fit]\nfree = [\"M\", \"c\"]\n[signals]\ny = \"m\"\nw = \"m\"\nt = \"s\"\nreference = \"w\"\n",
        m = case.nominal_mass,
        c = case.nominal_viscous,
        kp = case.truth.kp,
        kd = case.truth.kd,
    );
    let model = dir.path().join("servo.toml");
    std::fs::write(&model, &text).unwrap();
    let data = dir.path().join("servo.csv");
    std::fs::write(&data, case.recording.to_csv_string()).unwrap();
    let out = dir.path().join("out");
    let o = diagnose(&[], &model, &data, &out);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}\n{stdout}", String::from_utf8_lossy(&o.stderr));
    assert!(stdout.lines().next().unwrap().starts_with("the plant's parameters were off"), "{stdout}");
    assert!(stdout.contains("  M: ") && stdout.contains("  c: "), "{stdout}");
    let fitted = std::fs::read_to_string(out.join("fitted.toml")).unwrap();
    assert!(fitted.contains("\"-kp/M\"") && fitted.contains("[fit.result.M]"), "{fitted}");
    let back = model::load(&out.join("fitted.toml")).unwrap();
    let m = back.parameters.value("M").unwrap();
    assert!(
        (m / case.truth.mass - 1.0).abs() < 0.05,
        "mass {m} against {} (nominal {})",
        case.truth.mass,
        case.nominal_mass
    );
    assert_eq!(back.parameters.value("kp"), Some(case.truth.kp), "the controller's gain is not refitted");
    // the entries moved together: the mass read from B agrees with the one in [parameters]
    let (m_b, _) = servo_loop::mass_and_viscous(&back, case.truth.kp, case.truth.kd);
    assert!((m_b / m - 1.0).abs() < 1e-12, "{m_b} vs {m}");
    // the fit's correlation is written with each value, the same number under both names
    let corr = |a: &str, b: &str| -> f64 {
        let rec = back.fit.result.iter().find(|r| r.name == a).unwrap_or_else(|| panic!("{a}: {fitted}"));
        rec.correlation.iter().find(|(n, _)| n == b).unwrap_or_else(|| panic!("{a} ~ {b}: {fitted}")).1
    };
    let (r_mc, r_cm) = (corr("M", "c"), corr("c", "M"));
    assert!(r_mc.abs() <= 1.0 && r_mc != 0.0 && (r_mc - r_cm).abs() < 1e-12, "{r_mc} {r_cm}");

    // a sweep over the mass of a cart behind a play: mu = -c / (2 M) while the poles are complex
    let cart = "[parameters]\nM = 2.0\nc = 1.2\nk = 8.0\nks = 4.0\n[plant]\nA = [[0, 1], [\"-k/M\", \"-c/M\"]]\n\
                B = [0, \"1/M\"]\nC = [[1, 0]]\nE = [0, \"ks/M\"]\n[theta]\nshape = \"interval\"\nhalf_width = 0.05\n\
                [input]\nkind = \"sine\"\namplitudes = [4.0]\nomega = 1.5\n";
    std::fs::write(dir.path().join("cart.toml"), cart).unwrap();
    let spec = dir.path().join("mass.toml");
    std::fs::write(&spec, "model = \"cart.toml\"\n[[axis]]\nparameter = \"parameters.M\"\nvalues = [1.0, 2.0]\n[evaluate]\nmeasure = false\n").unwrap();
    let o = moreau().arg("sweep").arg(&spec).arg("--out").arg(dir.path().join("sw")).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(dir.path().join("sw/sweep.csv")).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    assert_eq!(header[1], "parameters.M", "{csv}");
    let mu = header.iter().position(|h| *h == "mu").unwrap();
    let mus: Vec<f64> = csv.lines().skip(1).map(|l| l.split(',').nth(mu).unwrap().parse().unwrap()).collect();
    assert!((mus[0] + 0.6).abs() < 1e-9 && (mus[1] + 0.3).abs() < 1e-9, "{mus:?}");
    // negative control: a parameter the model lacks is refused by name
    std::fs::write(&spec, "model = \"servo.toml\"\n[[axis]]\nparameter = \"parameters.mass\"\nvalues = [1.0]\n")
        .unwrap();
    let o = moreau().arg("sweep").arg(&spec).arg("--out").arg(dir.path().join("sw2")).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("parameters.mass") && err.contains("M, c, kd, kp"), "{err}");
}
