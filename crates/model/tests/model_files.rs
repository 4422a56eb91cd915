//! Model files: the examples parse, round-trip, and every kind of bad input gives an error
//! that names the key and the value.
use model::{parse_str, to_toml_string, ModelError};

const GOOD: &str = r#"
name = "t"
[plant]
A = [[0.0, 1.0], [-2.0, -0.6]]
B = [0.0, 1.0]
C = [[1.0, 0.0]]
E = [[0.0], [1.0]]
[theta]
shape = "interval"
half_width = 0.1
[input]
kind = "sine"
amplitudes = [1.0]
omega = 1.0
[initial]
x0 = [0.05, 0.0]
z0 = [0.0]
"#;

fn err(text: &str) -> String {
    match parse_str(text) {
        Ok(_) => panic!("expected an error for\n{text}"),
        Err(e) => e.to_string(),
    }
}

fn with(replace: &str, by: &str) -> String {
    assert!(GOOD.contains(replace), "fixture does not contain {replace:?}");
    GOOD.replace(replace, by)
}

#[test]
fn good_file_parses_with_expected_dimensions() {
    let s = parse_str(GOOD).unwrap();
    assert_eq!((s.n(), s.m(), s.p()), (2, 1, 1));
    assert!((s.mu() + 0.3).abs() < 1e-12, "mu = {}", s.mu());
    assert!((s.period().unwrap() - std::f64::consts::TAU).abs() < 1e-15);
}

#[test]
fn examples_parse_and_round_trip() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        if !text.contains("[plant]") {
            continue; // sweep specs and other TOML files
        }
        let s = model::load(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let again = parse_str(&to_toml_string(&s)).unwrap();
        assert_eq!(s.A, again.A);
        assert_eq!(s.E, again.E);
        assert_eq!(s.theta, again.theta, "{}", path.display());
        assert_eq!(s.input, again.input);
        // sections written in the file format's order (the examples' order), not alphabetically
        let heads = |t: &str| -> Vec<String> {
            t.lines()
                .filter(|l| l.starts_with('['))
                .map(|l| l.trim_matches(|c| c == '[' || c == ']').to_string())
                .collect()
        };
        let order = ["plant", "theta", "input", "initial", "simulation", "effects", "fit", "signals"];
        let rank = |h: &String| order.iter().position(|o| h.split('.').next() == Some(*o)).unwrap();
        let written = heads(&to_toml_string(&s));
        assert!(written.windows(2).all(|w| rank(&w[0]) <= rank(&w[1])), "{}: {written:?}", path.display());
        assert!(to_toml_string(&s).starts_with("name = "), "{}", path.display());
        n += 1;
    }
    assert!(n >= 4, "expected at least 4 example models, found {n}");
}

#[test]
fn wrong_dimensions_name_the_matrix() {
    let e = err(&with("A = [[0.0, 1.0], [-2.0, -0.6]]", "A = [[0.0, 1.0, 2.0], [-2.0, -0.6, 1.0]]"));
    assert!(e.contains("plant.A") && e.contains("2x3"), "{e}");
    let e = err(&with("E = [[0.0], [1.0]]", "E = [[0.0], [1.0], [2.0]]"));
    assert!(e.contains("plant.E") && e.contains("3x1"), "{e}");
    let e = err(&with("A = [[0.0, 1.0], [-2.0, -0.6]]", "A = [[0.0, 1.0], [-2.0]]"));
    assert!(e.contains("plant.A") && e.contains("row 1"), "{e}");
}

#[test]
fn nan_and_strings_where_numbers_belong() {
    let e = err(&with("[-2.0, -0.6]", "[-2.0, nan]"));
    assert!(e.contains("plant.A[1][1]") && e.contains("NaN"), "{e}");
    let e = err(&with("half_width = 0.1", "half_width = \"wide\""));
    assert!(e.contains("theta.half_width") && e.contains("\"wide\""), "{e}");
    let e = err(&with("omega = 1.0", "omega = inf"));
    assert!(e.contains("input.omega") && e.contains("inf"), "{e}");
}

#[test]
fn bad_sets_are_rejected_with_key_and_value() {
    let ell = |m: &str| {
        GOOD.replace("C = [[1.0, 0.0]]", "C = [[1.0, 0.0], [0.0, 1.0]]")
            .replace("E = [[0.0], [1.0]]", "E = [[0.0, 0.0], [1.0, 0.0]]")
            .replace("shape = \"interval\"\nhalf_width = 0.1", &format!("shape = \"ellipsoid\"\nmatrix = {m}"))
            .replace("z0 = [0.0]", "z0 = [0.05, 0.0]")
    };
    assert!(parse_str(&ell("[[0.01, 0.0], [0.0, 0.02]]")).is_ok());
    let e = err(&ell("[[0.01, 0.0], [0.0, -0.02]]"));
    assert!(e.contains("theta.matrix") && e.contains("positive definite") && e.contains("-2e-2"), "{e}");
    let e = err(&with("shape = \"interval\"", "shape = \"banana\""));
    assert!(e.contains("theta.shape") && e.contains("banana"), "{e}");
    // Theta not containing 0
    let e = err(&with("shape = \"interval\"\nhalf_width = 0.1", "shape = \"interval\"\nlo = 0.1\nhi = 0.3"));
    assert!(e.contains("does not contain 0") && e.contains("1e-1"), "{e}");
    // z0 - C x0 outside Theta
    let e = err(&with("z0 = [0.0]", "z0 = [0.5]"));
    assert!(e.contains("z0 - C x0") && e.contains("0.45"), "{e}");
}

#[test]
fn unknown_keys_and_missing_sections() {
    let e = err(&with("omega = 1.0", "omega = 1.0\nomgea = 2.0"));
    assert!(e.contains("input.omgea"), "{e}");
    let e = err("name = \"x\"\n");
    assert!(e.contains("plant"), "{e}");
    let e = err("[plant\nA = 1");
    assert!(e.contains("TOML syntax"), "{e}");
}

#[test]
fn missing_file_and_bad_csv_inputs() {
    let e = model::load(std::path::Path::new("/nonexistent/model.toml")).unwrap_err();
    assert!(matches!(e, ModelError::Io { .. }) && e.to_string().contains("/nonexistent/model.toml"), "{e}");
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, csv: &str| {
        std::fs::write(dir.path().join(name), csv).unwrap();
        let text =
            with("kind = \"sine\"\namplitudes = [1.0]\nomega = 1.0", &format!("kind = \"csv\"\nfile = \"{name}\""));
        std::fs::write(dir.path().join("m.toml"), text).unwrap();
        model::load(&dir.path().join("m.toml"))
    };
    assert!(write("ok.csv", "t,w\n0,0\n1,1\n2,0\n").is_ok());
    let e = write("unsorted.csv", "t,w\n0,0\n2,1\n1,0\n").unwrap_err().to_string();
    assert!(e.contains("row 4") && e.contains("t = 1") && e.contains("t = 2"), "{e}");
    let e = write("dup.csv", "t,w\n0,0\n1,1\n1,0\n").unwrap_err().to_string();
    assert!(e.contains("increase strictly"), "{e}");
    let e = write("nan.csv", "t,w\n0,0\n1,NaN\n").unwrap_err().to_string();
    assert!(e.contains("row 3") && e.contains("`w`") && e.contains("NaN"), "{e}");
    let e = write("hdr.csv", "time,w\n0,0\n1,1\n").unwrap_err().to_string();
    assert!(e.contains("header"), "{e}");
}

#[test]
fn a_multisine_input_parses_round_trips_and_its_errors_name_key_and_value() {
    let ms = "kind = \"multisine\"\nharmonics = [1, 3]\nweights = [1.0, 0.25]\nphases = [0.0, 1.5]";
    let s = parse_str(&with("kind = \"sine\"", ms)).unwrap();
    let model::Input::Multisine { harmonics, amplitudes, omega, .. } = &s.input else { panic!("{:?}", s.input) };
    assert_eq!((harmonics.len(), harmonics[1].k, harmonics[1].weight, harmonics[1].phase), (2, 3, 0.25, 1.5));
    assert_eq!((amplitudes.clone(), *omega), (vec![1.0], 1.0));
    assert_eq!(parse_str(&to_toml_string(&s)).unwrap().input, s.input);
    // weights and phases default to 1 and 0
    let s = parse_str(&with("kind = \"sine\"", "kind = \"multisine\"\nharmonics = [2]")).unwrap();
    let model::Input::Multisine { harmonics, .. } = &s.input else { panic!() };
    assert_eq!((harmonics[0].weight, harmonics[0].phase), (1.0, 0.0));
    for (bad, words) in [
        ("harmonics = [1, 2.5]", &["input.harmonics[1]", "2.5", "whole multiple"][..]),
        ("harmonics = [0]", &["input.harmonics[0]", "whole multiple"][..]),
        ("harmonics = [2, 2]", &["input.harmonics", "once"][..]),
        ("harmonics = [1, 2]\nweights = [1.0]", &["input.weights", "one per harmonic (2)"][..]),
        ("harmonics = [1]\nphases = [\"x\"]", &["input.phases[0]"][..]),
        ("harmonics = [1]\nweights = [0.0]", &["input.weights", "non-zero"][..]),
        ("weights = [1.0]", &["input.harmonics"][..]),
        ("harmonics = [1]\nharmonic = 2", &["input.harmonic"][..]),
    ] {
        let e = err(&with("kind = \"sine\"", &format!("kind = \"multisine\"\n{bad}")));
        assert!(words.iter().all(|w| e.contains(w)), "{bad}: {e}");
    }
    let e = err(&with("kind = \"sine\"", "kind = \"multisin\""));
    assert!(e.contains("multisine"), "{e}");
}

#[test]
fn a_csv_input_takes_a_hold_and_a_wrong_one_is_named() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("w.csv"), "t,w\n0,0\n1,1\n2,0\n").unwrap();
    let load = |extra: &str| {
        let text = with(
            "kind = \"sine\"\namplitudes = [1.0]\nomega = 1.0",
            &format!("kind = \"csv\"\nfile = \"w.csv\"\nperiod = 3.0{extra}"),
        );
        std::fs::write(dir.path().join("m.toml"), text).unwrap();
        model::load(&dir.path().join("m.toml"))
    };
    let hold = |s: &model::System| match &s.input {
        model::Input::Samples { hold, .. } => *hold,
        other => panic!("{other:?}"),
    };
    use model::input::InputHold;
    let foh = load("").unwrap();
    assert_eq!((hold(&foh), foh.input.at(0.5)), (InputHold::Foh, vec![0.5]));
    let zoh = load("\nhold = \"zoh\"").unwrap();
    assert_eq!((hold(&zoh), zoh.input.at(0.5), zoh.input.at(1.5)), (InputHold::Zoh, vec![0.0], vec![1.0]));
    assert!(to_toml_string(&zoh).contains("hold = \"zoh\"") && !to_toml_string(&foh).contains("hold"));
    let e = load("\nhold = \"cubic\"").unwrap_err().to_string();
    assert!(e.contains("input.hold") && e.contains("\"cubic\"") && e.contains("zoh"), "{e}");
}
