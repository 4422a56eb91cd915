//! `moreau diagnose` and `moreau play-width` end to end through the built binary: bad input
//! gives a one-line error naming the problem and the value, a non-zero exit and no output
//! directory; a constant validation output gives an undefined fit % (JSON null) judged by the
//! RMSE; the play width of the committed Robonine log agrees with the authors' value.
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn moreau() -> Command {
    Command::new(env!("CARGO_BIN_EXE_moreau"))
}

fn root(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..").join(rel)
}

/// The worked example (n = 2, m = p = 1, slowest time constant 1 / 0.3 s).
fn model() -> PathBuf {
    root("examples/worked-example.toml")
}

/// `t,w,y` rows, `rows` samples 0.01 s apart, from `f(k) -> (t, w, y)` as text fields.
fn write_csv(dir: &Path, name: &str, header: &str, rows: usize, f: impl Fn(usize) -> String) -> PathBuf {
    let mut s = format!("{header}\n");
    for k in 0..rows {
        s += &f(k);
        s.push('\n');
    }
    let p = dir.join(name);
    std::fs::write(&p, s).unwrap();
    p
}

fn w_of(k: usize) -> f64 {
    let t = k as f64 * 0.01;
    (1.3 * t).sin() + 0.5 * (3.1 * t).sin()
}
fn y_of(k: usize) -> f64 {
    0.3 * (1.3 * k as f64 * 0.01 - 0.4).sin()
}
fn good_row(k: usize) -> String {
    format!("{},{},{}", k as f64 * 0.01, w_of(k), y_of(k))
}

fn diagnose(data: &Path, model: &Path, out: &Path) -> Output {
    moreau().arg("diagnose").arg("--model").arg(model).arg("--data").arg(data).arg("--out").arg(out).output().unwrap()
}

/// Non-zero exit, no panic, exactly one line on stderr containing every needle, no output.
fn assert_rejected(o: &Output, out: &Path, needles: &[&str]) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "accepted; stderr: {err}");
    assert_eq!(o.status.code(), Some(2), "exit code {:?}; stderr: {err}", o.status.code());
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "not one line: {err}");
    for n in needles {
        assert!(err.contains(n), "missing {n:?} in: {err}");
    }
    assert!(!out.exists(), "an output directory was left behind for a rejected input: {}", out.display());
}

#[test]
fn bad_recordings_are_rejected_with_a_named_one_line_error() {
    let d = tempfile::tempdir().unwrap();
    let dir = d.path();
    let n = 3000;
    let cases: Vec<(PathBuf, Vec<&str>)> = vec![
        // Missing column: the header has no y.
        (
            write_csv(dir, "missing.csv", "t,w", n, |k| format!("{},{}", k as f64 * 0.01, w_of(k))),
            vec!["lacks column `y`", "[\"t\", \"w\"]"],
        ),
        // NaN in the input column at data row 101 (file row 102).
        (
            write_csv(dir, "nan.csv", "t,w,y", n, |k| {
                if k == 100 {
                    format!("{},NaN,{}", k as f64 * 0.01, y_of(k))
                } else {
                    good_row(k)
                }
            }),
            vec!["row 102", "column `w`", "\"NaN\"", "not a finite number"],
        ),
        // Non-increasing time: row 202 goes back to t = 1.5.
        (
            write_csv(dir, "time.csv", "t,w,y", n, |k| {
                if k == 200 {
                    format!("1.5,{},{}", w_of(k), y_of(k))
                } else {
                    good_row(k)
                }
            }),
            vec!["time must increase strictly", "row 202", "t = 1.5", "after t = 1.99"],
        ),
        // Constant input.
        (
            write_csv(dir, "constw.csv", "t,w,y", n, |k| format!("{},2.5,{}", k as f64 * 0.01, y_of(k))),
            vec!["input column `w` is constant", "2.5"],
        ),
        // Shorter than the slowest time constant (0.99 s against 3 x 3.33 s).
        (
            write_csv(dir, "short.csv", "t,w,y", 100, good_row),
            vec!["shorter than 3 x the model's slowest time constant", "0.99", "3.33"],
        ),
        // Dimensions: two outputs for a p = 1 model, two inputs for an m = 1 model.
        (
            write_csv(dir, "p2.csv", "t,w,y1,y2", n, |k| format!("{},0", good_row(k))),
            vec!["model and recording disagree", "outputs p = 1", "has 2"],
        ),
        (
            write_csv(dir, "m2.csv", "t,w1,w2,y", n, |k| {
                format!("{},{},{},{}", k as f64 * 0.01, w_of(k), w_of(k + 7), y_of(k))
            }),
            vec!["model and recording disagree", "inputs m = 1", "has 2"],
        ),
        // A sampling gap of 1000 s in 0.01 s sampling.
        (
            write_csv(dir, "gap.csv", "t,w,y", n, |k| {
                let t = k as f64 * 0.01 + if k >= 1500 { 1000.0 } else { 0.0 };
                format!("{t},{},{}", w_of(k), y_of(k))
            }),
            vec!["sampling gap", "row 1502", "split the recording"],
        ),
        // A row with a field missing.
        (
            write_csv(dir, "ragged.csv", "t,w,y", n, |k| {
                if k == 10 {
                    format!("{},{}", k as f64 * 0.01, w_of(k))
                } else {
                    good_row(k)
                }
            }),
            vec!["row 12", "has 2 fields", "header has 3"],
        ),
    ];
    for (csv, needles) in &cases {
        let out = dir.join(format!("out-{}", csv.file_stem().unwrap().to_string_lossy()));
        assert_rejected(&diagnose(csv, &model(), &out), &out, needles);
    }
    // Missing files, data and model.
    let out = dir.join("out-nofile");
    assert_rejected(&diagnose(&dir.join("absent.csv"), &model(), &out), &out, &["cannot read recording", "absent.csv"]);
    let good = write_csv(dir, "good.csv", "t,w,y", n, good_row);
    assert_rejected(&diagnose(&good, &dir.join("absent.toml"), &out), &out, &["absent.toml"]);
    // Negative control: the well-formed recording is accepted and the report is complete.
    let out = dir.join("out-good");
    let o = diagnose(&good, &model(), &out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in ["report.md", "report.json", "fitted.toml", "residual.svg", "fit.svg"] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert!(j["fit_before"]["fit_percent"][0].is_f64(), "{}", j["fit_before"]);
    assert_eq!(j["fit_before"]["constant_outputs"], serde_json::json!([]));
}

#[test]
fn constant_validation_output_reports_undefined_fit_and_rmse() {
    // The output moves on the estimation segment (first 70 %) and rests exactly at 0.3 on the
    // validation segment: fit % = 100 (1 - |e| / |y - mean y|) has a zero denominator there.
    let d = tempfile::tempdir().unwrap();
    let csv = write_csv(d.path(), "rest.csv", "t,w,y", 3000, |k| {
        format!("{},{},{}", k as f64 * 0.01, w_of(k), if k < 2000 { y_of(k) } else { 0.3 })
    });
    let out = d.path().join("out");
    let o = diagnose(&csv, &model(), &out);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(stdout.contains("fit % undefined"), "{stdout}");
    let text = std::fs::read_to_string(out.join("report.json")).unwrap();
    assert!(!text.contains("e16") && !text.contains("NaN"), "absurd figure in report.json");
    let j: serde_json::Value = serde_json::from_str(&text).unwrap();
    for seg in ["fit_before", "fit_after"] {
        assert!(j[seg]["fit_percent"][0].is_null(), "{seg}: {}", j[seg]);
        assert_eq!(j[seg]["constant_outputs"], serde_json::json!([0]));
        assert!(j[seg]["rmse"][0].as_f64().is_some_and(|r| r.is_finite() && r > 0.0), "{}", j[seg]);
    }
    assert!(j["notes"].as_array().unwrap().iter().any(|n| n.as_str().unwrap().contains("judged by the RMSE")));
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("undefined (constant output)"), "report.md does not say so");
}

fn robonine(rel: &str) -> PathBuf {
    root(&format!("data/robonine-backlash/{rel}"))
}

#[test]
fn play_width_of_the_single_sts3215_matches_the_authors() {
    // The authors report 7.03 counts (0.62 deg) unloaded and 14.78 counts loaded for the single
    // STS3215 (paper table "Combined backlash test results"). Our width must lie within 3
    // reported standard uncertainties of theirs, the uncertainty must be a sensible fraction
    // of the width (not inflated to make the check pass), and loaded != unloaded.
    let d = tempfile::tempdir().unwrap();
    let json = d.path().join("pw.json");
    let o = moreau()
        .arg("play-width")
        .arg("--data")
        .arg(robonine("logs/motor_telemetry_single.csv"))
        .arg("--config")
        .arg(robonine("analysis_config_m5.json"))
        .arg("--json")
        .arg(&json)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("unloaded") && stdout.contains("loaded"), "{stdout}");
    let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let r = &j.as_array().unwrap()[0];
    assert_eq!(r["motor_id"], 5);
    let get = |s: &str, k: &str| r[s][k].as_f64().unwrap();
    let (u, su) = (get("unloaded", "width"), get("unloaded", "std_uncertainty"));
    let (l, sl) = (get("loaded", "width"), get("loaded", "std_uncertainty"));
    assert!(su > 0.0 && su < 0.15 * u, "unloaded uncertainty {su} for width {u}");
    assert!((u - 7.03).abs() <= 3.0 * su, "unloaded {u} +- {su} vs the authors' 7.03 counts");
    assert!((l - 14.78).abs() <= 3.0 * sl, "loaded {l} +- {sl} vs the authors' 14.78 counts");
    // Negative control: the loaded reading is not the play (it is many sigma away from 7.03).
    assert!((l - 7.03).abs() > 3.0 * sl, "the check cannot tell loaded from unloaded");
}

#[test]
fn play_width_bad_input_is_a_one_line_error() {
    let d = tempfile::tempdir().unwrap();
    let json = d.path().join("pw.json");
    let run = |data: &Path, cfg: &Path| {
        moreau()
            .arg("play-width")
            .arg("--data")
            .arg(data)
            .arg("--config")
            .arg(cfg)
            .arg("--json")
            .arg(&json)
            .output()
            .unwrap()
    };
    let missing = d.path().join("absent.csv");
    for (o, needles) in [
        (run(&missing, &robonine("analysis_config_m5.json")), vec!["cannot read", "absent.csv"]),
        (
            run(&robonine("logs/motor_telemetry_single.csv"), &d.path().join("absent.json")),
            vec!["cannot read", "absent.json"],
        ),
    ] {
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(!err.contains("panicked") && err.trim().lines().count() == 1, "{err}");
        for n in needles {
            assert!(err.contains(n), "missing {n:?} in {err}");
        }
        assert!(!json.exists(), "a JSON file was written for a rejected input");
    }
}

/// Texts of an SVG (`<text>` contents, trimmed).
fn svg_texts(path: &Path) -> Vec<String> {
    let s = std::fs::read_to_string(path).unwrap();
    s.split("<text")
        .skip(1)
        .filter_map(|t| t.split_once('>').and_then(|(_, r)| r.split_once("</text>")))
        .map(|(a, _)| a.trim().to_string())
        .collect()
}

#[test]
fn bam_report_localises_against_a_null_and_zooms_on_the_windows_with_units() {
    // The BAM servo log (units `[signals] y = "rad"` in the model file).
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("out");
    let o = diagnose(
        &root("data/bam-servo/xl330-kp100-sin_time_square.csv"),
        &root("examples/real/bam-xl330-kp100.toml"),
        &out,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    let loc = &j["localisation"];
    assert_eq!(loc["null"]["level"], serde_json::json!(0.05), "{loc}");
    let dt = j["dt"].as_f64().unwrap();
    // the windows' width is the residual's correlation length, not a tenth of tau_slow
    let corr = loc["scales"]["correlation_length_s"].as_f64().unwrap();
    assert!(corr > 3.0 * dt && corr < 2.0, "{loc}");
    assert!(loc["scales"]["low_speed_band"][0].as_f64().unwrap() > 0.0, "{loc}");
    for key in ["regimes", "velocity_regimes"] {
        let rs = j[key].as_array().unwrap();
        assert!(rs.iter().any(|r| r["regime"] == "reversal"), "{key}");
        for r in rs {
            let (p, q, e) = (
                r["p_value"].as_f64().unwrap(),
                r["null_q95_enrichment"].as_f64().unwrap(),
                r["enrichment"].as_f64().unwrap(),
            );
            assert!((0.0..=1.0).contains(&p) && q > 0.0, "{r}");
            // enriched only when the observed enrichment is above the null's bulk
            if r["enriched"].as_bool().unwrap() {
                assert!(e > 1.0 && p <= 0.05, "{r}");
            }
        }
    }
    let windows = j["windows"].as_array().unwrap().len() + j["velocity_windows"].as_array().unwrap().len();
    assert!(windows > 0);
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("null 95 %") && md.contains("velocity residual") && md.contains("zoom-1.svg"), "{md}");
    // figures: zoomed panels on the top windows, units on the axes, Okabe-Ito colours, no
    // "-0.0" ticks
    for f in ["fit", "residual", "zoom-1"] {
        assert!(out.join(format!("{f}.png")).is_file(), "{f}.png");
        let texts = svg_texts(&out.join(format!("{f}.svg")));
        assert!(texts.iter().any(|t| t == "residual y − ŷ (rad)"), "{f}: {texts:?}");
        // no negative zero, and minus signs are U+2212, not hyphens
        let minus = ['-', '\u{2212}'];
        assert!(
            !texts.iter().any(|t| t.trim_start_matches(minus).trim_matches(|c| c == '0' || c == '.').is_empty()
                && t.starts_with(minus)),
            "{f}: {texts:?}"
        );
        assert!(texts.iter().any(|t| t.starts_with('\u{2212}')), "{f}: a negative tick label: {texts:?}");
        assert!(!texts.iter().any(|t| t.starts_with('-') && t[1..].parse::<f64>().is_ok()), "{f}: {texts:?}");
        let svg = std::fs::read_to_string(out.join(format!("{f}.svg"))).unwrap();
        assert!(svg.contains("#0072B2") && svg.contains("#E69F00"), "{f}: Okabe-Ito blue and orange");
    }
    let zoom = svg_texts(&out.join("zoom-1.svg"));
    assert!(zoom.iter().any(|t| t.starts_with("Window 1: t = ")), "{zoom:?}");
    assert!(zoom.iter().any(|t| t == "velocity residual (rad/s)"), "{zoom:?}");
}

/// `moreau diagnose` with several `--data` and `--validate-on` arguments.
fn diagnose_several(args: &[&Path], out: &Path) -> Output {
    let mut c = moreau();
    c.arg("diagnose").arg("--model").arg(model()).arg("--out").arg(out);
    for a in args {
        c.arg(a);
    }
    c.output().unwrap()
}

#[test]
fn several_recordings_bad_input_is_a_one_line_error() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = d.join("out");
    let a = write_csv(d, "a.csv", "t,w,y", 2000, good_row);
    let flag = |s: &'static str| Path::new(s);
    // --validate-on without --data
    let o = diagnose_several(&[flag("--validate-on"), &a], &out);
    assert_rejected(&o, &out, &["--data: no recording given", "--validate-on only judges"]);
    let o = diagnose_several(&[], &out);
    assert_rejected(&o, &out, &["--data: no recording given"]);
    // a missing recording among several
    let missing = d.join("missing.csv");
    let o = diagnose_several(&[flag("--data"), &a, flag("--data"), &missing], &out);
    assert_rejected(&o, &out, &["missing.csv"]);
    let o = diagnose_several(&[flag("--data"), &a, flag("--validate-on"), &missing], &out);
    assert_rejected(&o, &out, &["missing.csv"]);
    // recordings with different signal columns
    let two = write_csv(d, "two.csv", "t,w1,w2,y", 2000, |k| {
        format!("{},{},{},{}", k as f64 * 0.01, w_of(k), 0.5 * w_of(k), y_of(k))
    });
    let o = diagnose_several(&[flag("--data"), &a, flag("--data"), &two], &out);
    assert_rejected(&o, &out, &["a.csv", "two.csv", "inputs", "2"]);
    let extra = write_csv(d, "extra.csv", "t,w,y,current", 2000, |k| {
        format!("{},{},{},{}", k as f64 * 0.01, w_of(k), y_of(k), 0.1)
    });
    let o = diagnose_several(&[flag("--data"), &a, flag("--validate-on"), &extra], &out);
    assert_rejected(&o, &out, &["extra.csv", "current"]);
}

#[test]
fn size_presets_put_the_figures_at_column_width_and_the_joint_diagnosis_rejects_them() {
    // `--size column|two-column`: every figure the preset's width, each stack panel two thirds
    // of its height (moreau::figures::diagnosis::stack_size); the layouts are checked in
    // tests/figure_layout.rs
    let d = tempfile::tempdir().unwrap();
    for (preset, w, h2, h3) in [("column", 252, 288, 432), ("two-column", 515, 344, 516)] {
        let out = d.path().join(preset);
        let o = moreau()
            .arg("diagnose")
            .arg("--model")
            .arg(root("examples/real/bam-xl330-kp100.toml"))
            .arg("--data")
            .arg(root("data/bam-servo/xl330-kp100-sin_sin.csv"))
            .args(["--size", preset, "--out"])
            .arg(&out)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        for (f, h) in [("fit", h2), ("residual", h2), ("zoom-1", h3)] {
            let svg = std::fs::read_to_string(out.join(format!("{f}.svg"))).unwrap();
            assert!(svg.contains(&format!("width=\"{w}\" height=\"{h}\"")), "{preset} {f}: {}", &svg[..300]);
            assert!(out.join(format!("{f}.png")).is_file());
        }
    }
    // the joint diagnosis writes no figures: --size is an error, not silently ignored
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let a = write_csv(dir.path(), "a.csv", "t,w,y", 2000, good_row);
    let b = write_csv(dir.path(), "b.csv", "t,w,y", 2000, good_row);
    let p = |s: &'static str| Path::new(s);
    let o = diagnose_several(&[p("--data"), &a, p("--data"), &b, p("--size"), p("column")], &out);
    assert_rejected(&o, &out, &["--size", "joint diagnosis", "no figures"]);
}
