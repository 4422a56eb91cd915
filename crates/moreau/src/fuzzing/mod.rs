//! Bodies of the coverage-guided fuzz targets (cargo-fuzz project `fuzz/`, one target file per
//! function of [`TARGETS`]). They live here, not in `fuzz/`, so that the default test suite
//! replays the committed corpus and regressions through the same code
//! (`crates/moreau/tests/fuzz_corpus_replay.rs`).
//!
//! Every target takes arbitrary bytes and returns nothing: it calls the real reader or command
//! and discards `Ok` and `Err` alike. A panic (or an abort, a hang, an allocation beyond
//! libFuzzer's limit) is a finding. Some targets also check an invariant and panic when it
//! is broken (the output writer: a symlink, FIFO or directory target is never replaced).
//!
//! | target | what it runs |
//! |---|---|
//! | `model_file` | [`model::parse_str`] |
//! | `sweep_spec` | [`crate::sweep::spec::SweepSpec::parse`] (base model relative to `examples/sweeps/`) |
//! | `input_csv` | [`model::Input::from_csv`] on a temporary file |
//! | `recording_csv` | [`discovery::Recording::parse_checked`] |
//! | `playwidth_config` | `StandConfig::from_json_str` and the CLI's config checks |
//! | `playwidth_log` | the CLI's log check and `robonine::analyse` against a fixed stand config |
//! | `import_json` | `moreau import`'s JSON reader and model builder (`--e-from-b 0 --interval 0.1 --sine 1`) |
//! | `theta` | the command layer's `theta` on a model file (no measured side, no guidance) |
//! | `simulate` | the command layer's `simulate`, at most 200 steps and 50 rows |
//! | `diagnose` | a model and a recording (split at a line `%%`) through `discovery::diagnose` with the smallest settings |
//! | `write_output` | [`crate::output::write_atomic`] on a hostile target in a fresh temporary directory |
mod commands;
mod outputs;
mod parsers;

pub use commands::{diagnose, simulate, theta};
pub use outputs::write_output;
pub use parsers::{import_json, input_csv, model_file, playwidth_config, playwidth_log, recording_csv, sweep_spec};

/// A target body: arbitrary bytes in, nothing out.
pub type Target = fn(&[u8]);

/// Every target by name (the name of its `fuzz/fuzz_targets/<name>.rs` and of its corpus
/// folder `fuzz/corpus/<name>/`).
pub const TARGETS: &[(&str, Target)] = &[
    ("model_file", model_file),
    ("sweep_spec", sweep_spec),
    ("input_csv", input_csv),
    ("recording_csv", recording_csv),
    ("playwidth_config", playwidth_config),
    ("playwidth_log", playwidth_log),
    ("import_json", import_json),
    ("theta", theta),
    ("simulate", simulate),
    ("diagnose", diagnose),
    ("write_output", write_output),
];

/// The bytes as text, or `None` when they are not UTF-8 (every reader here takes text; the
/// file readers refuse other bytes before parsing).
fn text(data: &[u8]) -> Option<&str> {
    std::str::from_utf8(data).ok()
}

/// The text before and after the first line that is exactly `%%` (two-file targets).
fn split_two(text: &str) -> (&str, &str) {
    for sep in ["\n%%\n", "\n%%\r\n"] {
        if let Some(i) = text.find(sep) {
            return (&text[..i + 1], &text[i + sep.len()..]);
        }
    }
    (text, "")
}

/// A fresh temporary directory, in memory (`/dev/shm`) where there is one: a directory on
/// disk costs about 1 ms to make and remove here, 5x the parse it serves.
fn scratch() -> std::io::Result<tempfile::TempDir> {
    let shm = std::path::Path::new("/dev/shm");
    if shm.is_dir() {
        if let Ok(d) = tempfile::tempdir_in(shm) {
            return Ok(d);
        }
    }
    tempfile::tempdir()
}
