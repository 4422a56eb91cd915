//! `moreau theta --json` on every example gives the same numbers as before the layout change
//! (fixtures written by the last `driver` build, commit 0a072e9): every key of a fixture is
//! present with the same value (numbers bit for bit), and every quantity of the fixture's
//! `quantities` list is present with the same value, kind and equation. New keys may appear.
use std::path::PathBuf;
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Keys whose meaning was deliberately left unchanged but whose fixture value is not a number
/// to compare (none at present; kept explicit so a change is a visible decision).
const SKIP: [&str; 1] = ["quantities"];

#[test]
fn theta_json_keys_and_numbers_are_stable() {
    let fixtures = root().join("crates/moreau/tests/fixtures/theta-json");
    let mut checked = 0;
    for entry in std::fs::read_dir(&fixtures).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_stem().unwrap().to_str().unwrap().to_string();
        let before: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        let model = root().join("examples").join(format!("{name}.toml"));
        let out = Command::new(env!("CARGO_BIN_EXE_moreau")).arg("theta").arg(&model).arg("--json").output().unwrap();
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        let after: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        for (k, v) in before.as_object().unwrap() {
            if SKIP.contains(&k.as_str()) {
                continue;
            }
            assert_eq!(after.get(k), Some(v), "{name}: key `{k}` changed");
        }
        let qa = after["quantities"].as_array().unwrap();
        for q in before["quantities"].as_array().unwrap() {
            let key = q["key"].as_str().unwrap();
            let a = qa.iter().find(|x| x["key"] == q["key"]).unwrap_or_else(|| panic!("{name}: quantity {key} gone"));
            for field in ["value", "kind", "label", "symbol"] {
                assert_eq!(a[field], q[field], "{name}: quantity {key}: {field} changed");
            }
        }
        checked += 1;
    }
    assert!(checked >= 6, "only {checked} fixtures");
}
