//! Replays the coverage-guided fuzzing corpus (`fuzz/corpus/<target>/`, minimized with
//! `cargo fuzz cmin`) and every finding (`fuzz/regressions/<target>/`) through the target
//! bodies of `moreau::fuzzing`, the same functions the cargo-fuzz targets in `fuzz/` call:
//! each file must return without a panic. The campaign itself (libFuzzer, nightly) is in
//! `fuzz/README.md`; its figures are in BENCHMARKS.md.
use moreau::fuzzing::TARGETS;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

fn fuzz_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fuzz")
}

/// The files of `dir` (none when it does not exist), sorted.
fn files(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|r| r.map(|e| e.unwrap().path()).filter(|p| p.is_file()).collect())
        .unwrap_or_default();
    v.sort();
    v
}

/// Runs `target` on every file of the target's corpus and regressions; returns the files
/// that panicked (with the message) and how many files ran.
fn replay(name: &str, target: impl Fn(&[u8])) -> (Vec<String>, usize) {
    let mut failed = Vec::new();
    let mut ran = 0;
    for sub in ["corpus", "regressions"] {
        for f in files(&fuzz_dir().join(sub).join(name)) {
            let data = std::fs::read(&f).unwrap();
            ran += 1;
            if let Err(e) = catch_unwind(AssertUnwindSafe(|| target(&data))) {
                let msg = e
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_default();
                failed.push(format!("{}: {msg}", f.display()));
            }
        }
    }
    (failed, ran)
}

fn target(name: &str) -> fn(&[u8]) {
    TARGETS.iter().find(|(n, _)| *n == name).unwrap_or_else(|| panic!("no target {name}")).1
}

macro_rules! replay_tests {
    ($($name:ident),* $(,)?) => {
        $(
            #[test]
            fn $name() {
                let (failed, ran) = replay(stringify!($name), target(stringify!($name)));
                assert!(ran > 0, "fuzz/corpus/{} is empty", stringify!($name));
                assert!(failed.is_empty(), "{} of {ran} inputs panicked:\n{}", failed.len(), failed.join("\n"));
            }
        )*
        /// Every target of `moreau::fuzzing::TARGETS` is replayed above and has a cargo-fuzz
        /// target file.
        #[test]
        fn every_target_is_replayed() {
            let replayed = [$(stringify!($name)),*];
            for (name, _) in TARGETS {
                assert!(replayed.contains(name), "target {name} is not replayed");
                let bin = fuzz_dir().join("fuzz_targets").join(format!("{name}.rs"));
                assert!(bin.is_file(), "{} is missing", bin.display());
            }
            assert_eq!(replayed.len(), TARGETS.len());
        }
    };
}

replay_tests!(
    model_file,
    sweep_spec,
    input_csv,
    recording_csv,
    playwidth_config,
    playwidth_log,
    import_json,
    theta,
    simulate,
    diagnose,
    write_output,
);

/// Negative control: a target that panics on one corpus file is reported, with the file.
#[test]
fn a_panicking_target_is_noticed() {
    let (failed, ran) = replay("model_file", |d| {
        if std::str::from_utf8(d).is_ok_and(|t| t.contains("interval")) {
            panic!("boom");
        }
    });
    assert!(ran > 1);
    assert!(!failed.is_empty(), "the replay missed a panic");
    assert!(failed.len() < ran, "only the files with `interval` panic");
    assert!(failed.iter().all(|f| f.ends_with(": boom")), "{failed:?}");
}
