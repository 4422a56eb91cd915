//! `moreau theta` end to end: readable report, JSON keys, bad input exit codes.
use std::process::Command;

fn moreau() -> Command {
    Command::new(env!("CARGO_BIN_EXE_moreau"))
}
fn example(name: &str) -> String {
    format!("{}/../../examples/{name}", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn readable_report_and_json() {
    let out = moreau().args(["theta", &example("worked-example.toml"), "--no-measure"]).output().unwrap();
    assert!(out.status.success());
    let s = String::from_utf8(out.stdout).unwrap();
    for needle in [
        "(theta)",
        "(ginf)",
        "(g1)",
        "(d),(Xinfsupp)",
        "(mho),(osc)",
        "(path1)",
        "(path2)",
        "(stat1)",
        "Verdict: convergence CERTIFIED; theta_best = theta_engaged = ",
        "theta*",
        "theta_profile",
        "theta_engaged",
        // the paper's printed equation numbers next to the source labels
        "(84)",
    ] {
        assert!(s.contains(needle), "missing {needle} in\n{s}");
    }
    // the verdict leads: before the table's header row
    let verdict = s.find("Verdict: ").unwrap();
    let table = s.find("\nsymbol ").expect("the table's header row");
    assert!(verdict < table, "the verdict must come before the table:\n{s}");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("theta.json");
    let out = moreau()
        .args(["theta", &example("worked-example.toml"), "--json", "--no-measure", "--out"])
        .arg(&path)
        .output()
        .unwrap();
    assert!(out.status.success());
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let f: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    assert_eq!(j, f);
    assert!(j["theta"].as_f64().unwrap() < 0.0 && j["theta_verified"].as_bool().unwrap());
    assert!(j["measured_rate"].is_null()); // skipped
    assert_eq!(j["stationary_set_empty"], serde_json::Value::Bool(true));
}

#[test]
fn bad_input_one_line_error_nonzero_exit() {
    let dir = tempfile::tempdir().unwrap();
    let src = std::fs::read_to_string(example("worked-example.toml")).unwrap();
    // Non-Hurwitz F (negative damping), and an input without a period.
    let unstable = src.replace("[-2.0, -0.6]", "[-2.0, 0.6]");
    let zero = src.replace("kind = \"sine\"\namplitudes = [1.0]\nomega = 1.0", "kind = \"zero\"");
    for (name, text, needle) in [("unstable.toml", unstable, "not Hurwitz"), ("zero.toml", zero, "no period")] {
        assert_ne!(text, src, "{name}: the replacement must change the file");
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        let out = moreau().arg("theta").arg(&p).output().unwrap();
        assert!(!out.status.success(), "{name}");
        let err = String::from_utf8(out.stderr).unwrap();
        assert!(
            err.starts_with("error: ") && err.trim_end().lines().count() == 1 && err.contains(needle),
            "{name}: {err}"
        );
    }
    // Polytope: an answer exists (theta = psi(0) > 0): exit 0.
    let out =
        moreau().args(["theta", &example("polytope-p2.toml"), "--no-measure", "--no-stationary"]).output().unwrap();
    assert!(out.status.success());
    assert!(String::from_utf8(out.stdout).unwrap().contains("not strongly convex"));
}

#[test]
fn explain_prints_a_glossary_row_for_every_quantity() {
    let out = moreau()
        .args(["theta", &example("worked-example.toml"), "--no-measure", "--no-stationary", "--explain"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let s = String::from_utf8(out.stdout).unwrap();
    let glossary = s.split("What the rows mean").nth(1).expect("glossary printed");
    assert!(glossary.contains("- theta (84) [(theta)]: "), "{glossary}");
    assert!(glossary.contains("psi(0)") && glossary.contains("Always >= 0"));
    // one row per reported quantity
    let rows = glossary.lines().filter(|l| l.starts_with("- ")).count();
    let table_rows = s
        .split("What the rows mean")
        .next()
        .unwrap()
        .lines()
        .filter(|l| l.contains(" yes ") || l.contains(" no "))
        .count();
    assert!(rows >= 20 && rows >= table_rows, "{rows} glossary rows for {table_rows} table rows");
}

#[test]
fn brief_prints_only_the_verdict_block_in_100_columns() {
    for (file, head) in [
        ("worked-example.toml", "Verdict: convergence CERTIFIED; theta_best = theta_engaged = "),
        ("polytope-p2.toml", "Verdict: NOTHING certified; theta_best = theta = "),
    ] {
        let out = moreau().args(["theta", &example(file), "--brief", "--no-stationary"]).output().unwrap();
        assert!(out.status.success(), "{file}: {}", String::from_utf8_lossy(&out.stderr));
        let s = String::from_utf8(out.stdout).unwrap();
        assert!(s.starts_with(head), "{file}:\n{s}");
        let lines: Vec<&str> = s.lines().collect();
        assert!((2..=8).contains(&lines.len()), "{file}: {} lines:\n{s}", lines.len());
        assert!(lines.iter().all(|l| l.chars().count() <= 100), "{file}: a line over 100 columns:\n{s}");
        // no table, no guidance
        assert!(!s.contains("symbol ") && !s.contains("(ginf)"), "{file}:\n{s}");
    }
    // the measured side is part of the block
    let out = moreau().args(["theta", &example("worked-example.toml"), "--brief"]).output().unwrap();
    let s = String::from_utf8(out.stdout).unwrap();
    assert!(s.contains("\nReality: measured exponent "), "{s}");
    // --brief is readable text only
    let out = moreau().args(["theta", &example("worked-example.toml"), "--brief", "--json"]).output().unwrap();
    assert!(!out.status.success());
}
