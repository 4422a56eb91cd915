//! Targets of the readers: each feeds the bytes to one parser the CLI uses for a file.
use super::text;
use discovery::play_width::{robonine, PlayWidthSettings};
use discovery::recording::{check_text, TimeColumn};
use std::path::{Path, PathBuf};

/// A model file ([`model::parse_str`]; `csv` inputs relative to the current directory).
pub fn model_file(data: &[u8]) {
    let Some(t) = text(data) else { return };
    let _ = model::parse_str(t);
}

/// A sweep spec, located in `examples/sweeps/` so that the seeds' base models resolve.
pub fn sweep_spec(data: &[u8]) {
    let Some(t) = text(data) else { return };
    let at = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/sweeps/fuzz.toml");
    let _ = crate::sweep::spec::SweepSpec::parse(t, &at);
}

/// An input CSV (`[input] kind = "csv"`), read from a temporary file as the model reader does.
pub fn input_csv(data: &[u8]) {
    let Ok(dir) = super::scratch() else { return };
    let p = dir.path().join("w.csv");
    if std::fs::write(&p, data).is_err() {
        return;
    }
    let _ = model::Input::from_csv(&p, None, model::input::InputHold::Foh);
}

/// A recording CSV through the checked reader of `diagnose`.
pub fn recording_csv(data: &[u8]) {
    let Some(t) = text(data) else { return };
    let _ = discovery::Recording::parse_checked(t, "fuzz");
}

/// The play-width stand config: the reader, then the CLI's range checks.
pub fn playwidth_config(data: &[u8]) {
    let Some(t) = text(data) else { return };
    if let Ok(c) = robonine::StandConfig::from_json_str(t) {
        let _ = crate::cli::play_width::check_config(&c);
    }
}

/// The stand config the log target analyses against (the seed of `fuzz/corpus/playwidth_config`).
const STAND: &str = r#"{"home_position": 2000, "report_motor_ids": [5], "actuated_motors": [
 {"motor_id": 3, "label": "left", "relaxed_target": 1700, "relaxed_tolerance": 4, "stretched_target": 2100, "stretched_tolerance": 100},
 {"motor_id": 4, "label": "right", "relaxed_target": 2300, "relaxed_tolerance": 4, "stretched_target": 1900, "stretched_tolerance": 100}]}"#;

/// A play-width telemetry log: the CLI's text checks, then the whole analysis (segments,
/// per-cycle differences, uncertainty) against [`STAND`].
pub fn playwidth_log(data: &[u8]) {
    let Some(t) = text(data) else { return };
    if check_text(t, "log", TimeColumn::Iso8601("timestamp")).is_err() {
        return;
    }
    let Ok(cfg) = robonine::StandConfig::from_json_str(STAND) else { return };
    let s = PlayWidthSettings { min_segment_samples: 2, skip_samples: 0, resolution: 1.0, ..Default::default() };
    let _ = robonine::analyse(t, "log", &cfg, &s);
}

/// `moreau import` of a JSON state space: the reader, then the model builder with the flags
/// the file leaves open (`--e-from-b 0` without `E`, `--interval 0.1` or `--ball 0.1`
/// without `theta`, `--sine 1,..,1` without `input`), then the model file text.
pub fn import_json(data: &[u8]) {
    use crate::cli::import::{build, read_json, Args};
    let Some(t) = text(data) else { return };
    let Ok(ss) = read_json(t) else { return };
    let p = ss.C.as_ref().map_or(1, |c| c.nrows());
    let m = ss.B.as_ref().map_or(1, |b| b.ncols());
    let no_theta = !ss.rest.contains_key("theta");
    let a = Args {
        file: PathBuf::from("fuzz.json"),
        out: PathBuf::from("fuzz.toml"),
        e_from_b: ss.E.is_none().then_some(0),
        interval: (no_theta && p == 1).then_some(0.1),
        ball: (no_theta && p != 1).then_some(0.1),
        sine: (!ss.rest.contains_key("input")).then(|| vec![1.0; m]),
        omega: 1.0,
        name: None,
    };
    if let Ok(sys) = build(ss, &a) {
        let _ = model::to_toml_string(&sys);
    }
}
