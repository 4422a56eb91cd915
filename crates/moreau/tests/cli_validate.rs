//! `moreau validate`: summaries for the examples and one-line errors for bad files.
use std::process::Command;

fn moreau(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_moreau"))
        .args(args)
        .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

#[test]
fn validate_prints_summaries_of_the_examples() {
    let (code, out, err) = moreau(&[
        "validate",
        "examples/worked-example.toml",
        "examples/ellipse-p2.toml",
        "examples/ellipsoid-p3.toml",
        "examples/polytope-p2.toml",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("n = 2, m = 1, p = 1") && out.contains("mu:      -0.300000"), "{out}");
    assert!(out.contains("R:       0.1 (exact)"), "{out}");
    assert!(out.contains("p = 3"), "{out}");
    assert!(out.contains("infinite (not strongly convex)"), "{out}");
}

#[test]
fn bad_files_give_one_line_errors_and_nonzero_exit() {
    let dir = tempfile::tempdir().unwrap();
    let good =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/worked-example.toml")).unwrap();
    let cases = [
        (
            "a23.toml",
            good.replace("A = [[0.0, 1.0], [-2.0, -0.6]]", "A = [[0.0, 1.0, 0.0], [-2.0, -0.6, 0.0]]"),
            "plant.A",
        ),
        ("nan.toml", good.replace("[-2.0, -0.6]", "[-2.0, nan]"), "plant.A[1][1]"),
        ("str.toml", good.replace("half_width = 0.1", "half_width = \"x\""), "theta.half_width"),
        ("shape.toml", good.replace("shape = \"interval\"", "shape = \"banana\""), "banana"),
        ("zero.toml", good.replace("half_width = 0.1", "lo = 0.1\nhi = 0.2"), "does not contain 0"),
    ];
    for (name, text, needle) in cases {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        let (code, _out, err) = moreau(&["validate", p.to_str().unwrap()]);
        assert_ne!(code, 0, "{name} should fail");
        assert!(err.contains(needle), "{name}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{name}: error must be one line: {err}");
        assert!(!err.contains("panicked") && !err.contains("backtrace"), "{name}: {err}");
    }
    let (code, _, err) = moreau(&["validate", "/no/such/model.toml"]);
    assert_ne!(code, 0);
    assert!(err.contains("/no/such/model.toml") && err.lines().count() == 1, "{err}");
    // The operating system's reason is said once, not once per error layer.
    assert_eq!(err.matches("os error").count(), 1, "{err}");
    let (code, _, err) = moreau(&["theta", "/no/such/model.toml"]);
    assert_eq!(code, 2, "{err}");
    assert_eq!(err.matches("os error").count(), 1, "{err}");
}

#[test]
fn negative_numeric_options_reach_their_own_check() {
    // `--dt -1` is a value, not an unknown flag: the error names the option and the value.
    for (args, needle) in [
        (
            &["simulate", "examples/worked-example.toml", "--dt", "-1", "--out", "unused-out"][..],
            "--dt must be positive",
        ),
        (&["periodic", "examples/worked-example.toml", "--dt", "-0.5"][..], "got -0.5"),
        (&["convergence", "examples/worked-example.toml", "--h0", "-0.1"][..], "--h0 must be positive"),
    ] {
        let (code, _, err) = moreau(args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains(needle) && err.trim_end().lines().count() == 1, "{args:?}: {err}");
    }
    let unused = concat!(env!("CARGO_MANIFEST_DIR"), "/../../unused-out");
    assert!(!std::path::Path::new(unused).exists(), "no output directory after a rejected --dt");
}
