//! `moreau import`: state spaces from MATLAB (.mat v5, written here by a minimal writer) and
//! from JSON give the model file whose theta equals the worked example's; bad files are named.
use std::path::Path;
use std::process::Command;

fn moreau() -> Command {
    Command::new(env!("CARGO_BIN_EXE_moreau"))
}

/// A MATLAB v5 .mat file with real double matrices (uncompressed, little-endian).
fn mat_v5(vars: &[(&str, usize, usize, Vec<f64>)]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut header = b"MATLAB 5.0 MAT-file, written by the moreau import test".to_vec();
    header.resize(116, b' ');
    out.extend(header);
    out.extend([0u8; 8]); // subsystem data offset
    out.extend(0x0100u16.to_le_bytes());
    out.extend(b"IM");
    let pad8 = |v: &mut Vec<u8>| {
        while !v.len().is_multiple_of(8) {
            v.push(0)
        }
    };
    for (name, r, c, col_major) in vars {
        let mut body = Vec::new();
        // array flags: miUINT32, 8 bytes, class mxDOUBLE_CLASS = 6
        body.extend(6u32.to_le_bytes());
        body.extend(8u32.to_le_bytes());
        body.extend(6u32.to_le_bytes());
        body.extend(0u32.to_le_bytes());
        // dimensions: miINT32
        body.extend(5u32.to_le_bytes());
        body.extend(8u32.to_le_bytes());
        body.extend((*r as i32).to_le_bytes());
        body.extend((*c as i32).to_le_bytes());
        // name: miINT8
        body.extend(1u32.to_le_bytes());
        body.extend((name.len() as u32).to_le_bytes());
        body.extend(name.as_bytes());
        pad8(&mut body);
        // real part: miDOUBLE
        body.extend(9u32.to_le_bytes());
        body.extend(((col_major.len() * 8) as u32).to_le_bytes());
        for x in col_major {
            body.extend(x.to_le_bytes());
        }
        pad8(&mut body);
        out.extend(14u32.to_le_bytes()); // miMATRIX
        out.extend((body.len() as u32).to_le_bytes());
        out.extend(body);
    }
    out
}

fn theta_json(model: &Path) -> serde_json::Value {
    let out = moreau()
        .args(["theta", "--json", "--no-measure", "--no-stationary", "--no-guidance"])
        .arg(model)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

fn worked_example_theta() -> serde_json::Value {
    theta_json(Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/worked-example.toml")))
}

#[test]
fn mat_and_json_imports_reproduce_the_worked_example() {
    let dir = tempfile::tempdir().unwrap();
    // A = [[0, 1], [-2, -0.6]] column-major; B = E = [0, 1]^T; C = [1, 0]; D = 0
    let mat = dir.path().join("ss.mat");
    std::fs::write(
        &mat,
        mat_v5(&[
            ("A", 2, 2, vec![0.0, -2.0, 1.0, -0.6]),
            ("B", 2, 1, vec![0.0, 1.0]),
            ("C", 1, 2, vec![1.0, 0.0]),
            ("D", 1, 1, vec![0.0]),
        ]),
    )
    .unwrap();
    let out_mat = dir.path().join("from-mat.toml");
    let o = moreau()
        .args(["import"])
        .arg(&mat)
        .args(["--e-from-b", "0", "--interval", "0.1", "--sine", "1.0", "--omega", "1.0", "--out"])
        .arg(&out_mat)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    let json = dir.path().join("ss.json");
    std::fs::write(
        &json,
        r#"{"A": [[0, 1], [-2, -0.6]], "B": [0, 1], "C": [[1, 0]], "E": [[0], [1]],
            "theta": {"shape": "interval", "half_width": 0.1},
            "input": {"kind": "sine", "amplitudes": [1.0], "omega": 1.0}}"#,
    )
    .unwrap();
    let out_json = dir.path().join("from-json.toml");
    let o = moreau().args(["import"]).arg(&json).arg("--out").arg(&out_json).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    let reference = worked_example_theta();
    for f in [&out_mat, &out_json] {
        let j = theta_json(f);
        for key in ["theta", "theta_star", "theta_profile", "beta", "d", "osc"] {
            assert_eq!(j[key], reference[key], "{}: {key}", f.display());
        }
    }
}

#[test]
fn bad_state_space_files_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let cases: Vec<(&str, Vec<u8>, &[&str], &str)> = vec![
        (
            "d.mat",
            mat_v5(&[("A", 1, 1, vec![-1.0]), ("B", 1, 1, vec![1.0]), ("C", 1, 1, vec![1.0]), ("D", 1, 1, vec![0.5])]),
            &["--e-from-b", "0", "--interval", "0.1", "--sine", "1"],
            "D has a nonzero entry 0.5",
        ),
        (
            "noe.json",
            br#"{"A": [[-1]], "B": [[1]], "C": [[1]]}"#.to_vec(),
            &["--interval", "0.1", "--sine", "1"],
            "no E",
        ),
        (
            "ragged.json",
            br#"{"A": [[-1, 0], [0]], "B": [[1]], "C": [[1]], "E": [[1]]}"#.to_vec(),
            &["--interval", "0.1", "--sine", "1"],
            "row 1 has 1 entries",
        ),
        (
            "garbage.mat",
            b"not a mat file at all".to_vec(),
            &["--e-from-b", "0", "--interval", "0.1", "--sine", "1"],
            "not a readable MATLAB v5 .mat file",
        ),
        ("ss.txt", b"A = 1".to_vec(), &["--interval", "0.1"], "unknown extension"),
    ];
    for (name, bytes, args, needle) in cases {
        let p = dir.path().join(name);
        std::fs::write(&p, bytes).unwrap();
        let out = dir.path().join(format!("{name}.toml"));
        let o = moreau().arg("import").arg(&p).args(args).arg("--out").arg(&out).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{name}: {err}");
        assert!(err.contains(needle) && err.lines().count() == 1, "{name}: {err}");
        assert!(!err.contains("panicked") && !out.exists(), "{name}");
    }
}

/// `moreau import FILE --interval 0.1 --sine 1.0 --out OUT`.
fn import_sine(file: &Path, out: &Path) -> std::process::Output {
    moreau().arg("import").arg(file).args(["--interval", "0.1", "--sine", "1.0", "--out"]).arg(out).output().unwrap()
}

/// Issue 31 (hostile probe c0634, c0656): a .mat whose declared size does not match its data
/// panicked in the matrix constructor; a 10 MB JSON value was echoed whole into the error.
#[test]
fn damaged_mat_files_and_huge_json_values_are_one_line_errors() {
    let dir = tempfile::tempdir().unwrap();
    let mat = dir.path().join("ss.mat");
    std::fs::write(&mat, mat_v5(&[("A", i32::MAX as usize, i32::MAX as usize, vec![1.0])])).unwrap();
    let out = import_sine(&mat, &dir.path().join("m.toml"));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("damaged"), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!err.contains("panicked"), "{err}");
    // negative control: the same writer with a consistent size imports
    let one = |name, x| (name, 1, 1, vec![x]);
    std::fs::write(&mat, mat_v5(&[one("A", -1.0), one("B", 1.0), one("C", 1.0), one("E", 0.5)])).unwrap();
    let ok = import_sine(&mat, &dir.path().join("m.toml"));
    assert!(ok.status.success(), "{}", String::from_utf8_lossy(&ok.stderr));
    let json = dir.path().join("ss.json");
    let huge = "v".repeat(10 << 20);
    std::fs::write(&json, format!(r#"{{"A": [[-1.0]], "B": [[1.0]], "C": [[1.0]], "E": "{huge}"}}"#)).unwrap();
    let out = import_sine(&json, &dir.path().join("j.toml"));
    assert!(!out.status.success());
    assert!(out.stderr.len() < 1000, "{} bytes of error", out.stderr.len());
    assert!(String::from_utf8_lossy(&out.stderr).contains("bytes in all"));
}
