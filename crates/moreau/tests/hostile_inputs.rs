//! Hostile inputs (issue 16): every case that once aborted, hung, ran without limit or was
//! silently accepted with a wrong result now ends with exit code 2 and exactly one line on
//! stderr naming the problem and the value (or, for a capped request, a bounded run), never
//! a panic, and leaves nothing beside `--out`. Interruption and concurrency: SIGINT leaves no
//! staging directory or lock, a second sweep into a locked `--out` refuses naming the holder,
//! and `merge` checks shard parameters against the grid. No assertion depends on timing.
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().unwrap()
}

fn moreau_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_moreau")).args(args).current_dir(dir).output().unwrap()
}

/// Exit code 2, one line `error: ...` containing every needle, no panic.
fn assert_refused(o: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "exit code; stderr: {err}");
    assert_eq!(err.lines().count(), 1, "exactly one line on stderr: {err}");
    assert!(err.starts_with("error: "), "{err}");
    assert!(!err.contains("panicked") && !err.contains("backtrace"), "{err}");
    for n in needles {
        assert!(err.contains(n), "expected `{n}` in: {err}");
    }
}

/// Nothing but `expected` in `dir` (no output directory, no staging directory, no lock).
fn assert_only(dir: &Path, expected: &[&str]) {
    let mut names: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    let mut want: Vec<String> = expected.iter().map(|s| s.to_string()).collect();
    want.sort();
    assert_eq!(names, want, "files left in {}", dir.display());
}

/// A temporary directory holding the worked example as `w.toml`.
fn workdir() -> tempfile::TempDir {
    let d = tempfile::tempdir().unwrap();
    std::fs::copy(root().join("examples/worked-example.toml"), d.path().join("w.toml")).unwrap();
    d
}

fn worked() -> String {
    std::fs::read_to_string(root().join("examples/worked-example.toml")).unwrap()
}

/// Writes `text` as `name` into `dir`.
fn put(dir: &Path, name: &str, text: &str) -> String {
    std::fs::write(dir.join(name), text).unwrap();
    name.to_string()
}

fn spec(axis: &str, evaluate: &str) -> String {
    format!("model = \"w.toml\"\n[[axis]]\nparameter = \"input.amplitude\"\n{axis}\n[evaluate]\n{evaluate}\n")
}

#[test]
fn budgets_are_checked_before_any_work() {
    let d = workdir();
    let p = d.path();
    let cases: Vec<(Vec<&str>, Vec<&str>)> = vec![
        (vec!["check", "--cases", "1000000000000", "--only", "pp"], vec!["--cases", "1000000000000", "10000000000"]),
        (vec!["check", "--cases", "100000000", "--only", "pp"], vec!["100000000", "--allow-large"]),
        (vec!["simulate", "w.toml", "--dt", "1e-300", "--out", "out"], vec!["integration steps", "1e-300", "1e15"]),
        (vec!["simulate", "w.toml", "--periods", "1000000000000", "--out", "out"], vec!["integration steps"]),
        (vec!["simulate", "w.toml", "--dt", "1e6", "--out", "out"], vec!["--dt", "T/4", "1000000"]),
        (
            vec!["figure", "trajectory", "w.toml", "--t-end", "1e12", "--out", "out"],
            vec!["integration steps", "1000000000"],
        ),
        (
            vec!["figure", "trajectory", "w.toml", "--dt", "1e-300", "--out", "out"],
            vec!["dt = 1e-300", "integration steps"],
        ),
        (vec!["convergence", "w.toml", "--levels", "60"], vec!["--levels 60", "40"]),
        (vec!["convergence", "w.toml", "--periods", "1000000000"], vec!["integration steps", "--allow-large"]),
        (vec!["periodic", "w.toml", "--periods", "1000000000"], vec!["integration steps", "1000000000 periods"]),
        (vec!["periodic", "w.toml", "--pairs", "0"], vec!["--pairs"]),
        (vec!["check", "--cases", "1e12"], vec!["invalid value '1e12'", "--cases", "see --help"]),
        (vec!["simulate", "w.toml", "--threads", "3", "--out", "out"], vec!["unexpected argument '--threads'"]),
        (vec!["discover-bench", "--cases", "1000000000000"], vec!["--cases", "1000000000000", "hard limit"]),
    ];
    for (args, needles) in &cases {
        let o = moreau_in(p, args);
        assert_refused(&o, needles);
        assert_only(p, &["w.toml"]);
    }
}

#[test]
fn sweep_budgets_are_checked_before_the_grid_is_built() {
    let d = workdir();
    let p = d.path();
    let cases = [
        (spec("range = { from = 1.0, to = 2.0, count = 1000000000000 }", ""), vec!["1000000000000", "10000000"]),
        (
            spec("range = { from = 1.0, to = 2.0, count = 2000000 }", "measure = false"),
            vec!["2000000", "--allow-large"],
        ),
        (spec("values = [1.0]", "periods = 1000000000000"), vec!["periods = 1000000000000", "integration steps"]),
        (spec("values = [1.0]", "pairs = 1000000000000"), vec!["pairs = 1000000000000"]),
        (spec("values = [1.0]", "dt = 1e-300"), vec!["dt = 1e-300", "integration steps"]),
        (spec("values = [1.0]", "dt = 1e6"), vec!["evaluate.dt", "T/4"]),
        ("model = \"w.toml\"\n[[axis]\n".to_string(), vec!["s.toml", "not valid TOML", "line 2"]),
    ];
    for (text, needles) in &cases {
        put(p, "s.toml", text);
        let o = moreau_in(p, &["sweep", "s.toml", "--out", "out", "-q"]);
        assert_refused(&o, needles);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(err.matches("s.toml").count().min(1), err.matches("s.toml").count(), "path once: {err}");
        assert_only(p, &["w.toml", "s.toml"]);
    }
}

#[test]
fn theta_refuses_large_problems_unless_allowed() {
    let d = workdir();
    let p = d.path();
    let n = 200;
    let a: Vec<String> = (0..n)
        .map(|i| format!("[{}]", (0..n).map(|j| if i == j { "-1.0" } else { "0.0" }).collect::<Vec<_>>().join(",")))
        .collect();
    let col = |v: &str| {
        format!("[{}]", (0..n).map(|i| format!("[{}]", if i == 0 { v } else { "0.0" })).collect::<Vec<_>>().join(","))
    };
    let c = format!("[[{}]]", (0..n).map(|j| if j == 0 { "1.0" } else { "0.0" }).collect::<Vec<_>>().join(","));
    let text = format!(
        "[plant]\nA = [{}]\nB = {}\nC = {c}\nE = {}\n[theta]\nshape = \"interval\"\nhalf_width = 0.1\n[input]\nkind = \"sine\"\namplitudes = [1.0]\nomega = 1.0\n",
        a.join(","),
        col("1.0"),
        col("0.5")
    );
    put(p, "big.toml", &text);
    assert_refused(&moreau_in(p, &["theta", "big.toml"]), &["n = 200", "12", "--allow-large"]);
    assert_refused(&moreau_in(p, &["figure", "psi", "big.toml", "--out", "out"]), &["n = 200"]);
    let ball5 = "[plant]\nA = [[-1.0,0,0,0,0],[0,-1.0,0,0,0],[0,0,-1.0,0,0],[0,0,0,-1.0,0],[0,0,0,0,-1.0]]\nB = [1.0,0,0,0,0]\nC = [[1.0,0,0,0,0],[0,1.0,0,0,0],[0,0,1.0,0,0],[0,0,0,1.0,0],[0,0,0,0,1.0]]\nE = [[0.1,0,0,0,0],[0,0.1,0,0,0],[0,0,0.1,0,0],[0,0,0,0.1,0],[0,0,0,0,0.1]]\n[theta]\nshape = \"ball\"\nradius = 0.1\n[input]\nkind = \"sine\"\namplitudes = [1.0]\nomega = 1.0\n";
    put(p, "p5.toml", ball5);
    assert_refused(&moreau_in(p, &["theta", "p5.toml"]), &["p = 5", "4"]);
    assert_only(p, &["w.toml", "big.toml", "p5.toml"]);
}

#[test]
fn inconsistent_model_files_are_rejected_at_load() {
    let d = workdir();
    let p = d.path();
    let good = worked();
    let zero_input =
        good.replace("kind = \"sine\"", "kind = \"zero\"").replace("amplitudes = [1.0]", "").replace("omega = 1.0", "");
    let cases: Vec<(String, Vec<&str>)> = vec![
        (good.replace("dt = 1e-3", "dt = 1e6"), vec!["simulation.dt", "T/4", "1000000"]),
        (format!("{}t_end = -5.0\n", zero_input.replace("periods = 20", "")), vec!["simulation.t_end", "-5"]),
        (
            format!("{}t_end = 0.0\n", zero_input.replace("periods = 20", "")),
            vec!["simulation.t_end", "must be positive"],
        ),
        (format!("{}t_end = 1e-4\n", zero_input.replace("periods = 20", "")), vec!["simulation.dt", "t_end"]),
        (good.replace("[-2.0, -0.6]", "[-2.0, -1e300]"), vec!["plant.A[1][1]", "1e300"]),
        (good.replace("[theta]", "[theta\n"), vec!["m.toml", "TOML syntax error", "line"]),
    ];
    for (text, needles) in &cases {
        put(p, "m.toml", text);
        for cmd in [vec!["validate", "m.toml"], vec!["convergence", "m.toml"]] {
            let o = moreau_in(p, &cmd);
            assert_refused(&o, needles);
            let err = String::from_utf8_lossy(&o.stderr);
            assert!(err.matches("m.toml").count() <= 1, "path printed once: {err}");
        }
    }
    let both = "[plant]\nA = [[-1.0, 0.0], [0.0, -1.0]]\nB = [1.0, 0.0]\nC = [[1.0, 0.0], [0.0, 1.0]]\nE = [[0.1, 0.0], [0.0, 0.1]]\n[theta]\nshape = \"ellipsoid\"\nsemi_axes = [0.1, 0.2]\nmatrix = [[0.01, 0.0], [0.0, 0.04]]\n";
    put(p, "m.toml", both);
    assert_refused(&moreau_in(p, &["validate", "m.toml"]), &["theta.semi_axes", "theta.matrix", "exclude"]);
    let touching = "[plant]\nA = [[-1.0, 0.0], [0.0, -1.0]]\nB = [1.0, 0.0]\nC = [[1.0, 0.0], [0.0, 1.0]]\nE = [[0.1, 0.0], [0.0, 0.1]]\n[theta]\nshape = \"ball_intersection\"\ncentres = [[1.0, 0.0], [-1.0, 0.0]]\nradii = [1.0, 1.0]\n";
    put(p, "m.toml", touching);
    assert_refused(&moreau_in(p, &["simulate", "m.toml", "--out", "out"]), &["empty interior", "balls 0 and 1"]);
    assert_only(p, &["w.toml", "m.toml"]);
}

#[cfg(unix)]
#[test]
fn fifos_and_devices_are_refused_without_blocking() {
    let d = workdir();
    let p = d.path();
    let fifo = p.join("fifo.toml");
    if !Command::new("mkfifo").arg(&fifo).status().map(|s| s.success()).unwrap_or(false) {
        return; // no mkfifo here
    }
    // a writer that would release a reader blocked on the FIFO (were it ever opened), so a
    // regression fails the assertions below instead of hanging the test
    let f2 = fifo.clone();
    let writer = std::thread::spawn(move || drop(std::fs::OpenOptions::new().write(true).open(&f2)));
    let o = moreau_in(p, &["validate", "fifo.toml"]);
    assert_refused(&o, &["fifo.toml", "a FIFO", "regular file"]);
    let o = moreau_in(p, &["sweep", "fifo.toml", "--out", "out"]);
    assert_refused(&o, &["fifo.toml", "a FIFO"]);
    // release the writer thread: opening for reading pairs with its open for writing
    drop(std::fs::File::open(&fifo));
    writer.join().unwrap();
    let o = moreau_in(p, &["validate", "/dev/zero"]);
    assert_refused(&o, &["/dev/zero", "character device"]);
    let o = moreau_in(p, &["diagnose", "--model", "w.toml", "--data", "/dev/zero", "--out", "out"]);
    assert_refused(&o, &["/dev/zero", "character device"]);
    assert_only(p, &["w.toml", "fifo.toml"]);
}

#[test]
fn csv_inputs_and_recordings_are_checked() {
    let d = workdir();
    let p = d.path();
    let csv_model = |period: &str| {
        worked()
            .replace("kind = \"sine\"", &format!("kind = \"csv\"\nfile = \"w.csv\"\n{period}"))
            .replace("amplitudes = [1.0]\n", "")
            .replace("omega = 1.0\n", "")
    };
    put(p, "m.toml", &csv_model(""));
    put(p, "w.csv", "t,w1,w1\n0,0,0\n1,1,1\n");
    assert_refused(&moreau_in(p, &["validate", "m.toml"]), &["w.csv", "duplicate column `w1`"]);
    let samples: String = (0..=100).map(|k| format!("{},{}\n", k as f64 * 0.1, (k as f64 * 0.1).sin())).collect();
    put(p, "w.csv", &format!("t,w\n{samples}"));
    put(p, "m.toml", &csv_model("period = 5.0\n"));
    assert_refused(&moreau_in(p, &["validate", "m.toml"]), &["input.period", "shorter than the data", "10"]);
    // recordings for diagnose
    let rows: Vec<String> =
        (0..400).map(|k| format!("{},{},{}", k as f64 * 0.01, (k as f64 * 0.01).sin(), 0.0)).collect();
    let rec = |header: &str, rows: &[String]| format!("{header}\n{}\n", rows.join("\n"));
    let dup: Vec<String> = rows.iter().map(|r| format!("{r},0.0")).collect();
    let mut reversed = rows.clone();
    reversed.reverse();
    let mut huge = rows.clone();
    huge[5] = "0.05,1e300,0.0".into();
    let far: Vec<String> =
        (0..400).map(|k| format!("{:e},{},0.0", 1e300 + k as f64 * 1e290, (k as f64).sin())).collect();
    let cases = [
        (rec("t,w,y,y", &dup), vec!["r.csv", "duplicate column `y`", "columns 3 and 4"]),
        (rec("t,w,y", &reversed), vec!["r.csv", "row 3", "increase"]),
        (rec("t,w,y", &huge), vec!["r.csv", "1e300", "row 7"]),
        (rec("t,w,y", &far), vec!["r.csv", "1e300"]),
    ];
    for (text, needles) in &cases {
        put(p, "r.csv", text);
        let o = moreau_in(p, &["diagnose", "--model", "w.toml", "--data", "r.csv", "--out", "out"]);
        assert_refused(&o, needles);
    }
    assert_only(p, &["w.toml", "m.toml", "w.csv", "r.csv"]);
}

#[test]
fn play_width_rejects_reversed_logs_and_bad_configs() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path();
    let log = std::fs::read_to_string(root().join("data/robonine-backlash/logs/motor_telemetry_single.csv")).unwrap();
    let mut lines: Vec<&str> = log.lines().collect();
    let header = lines.remove(0);
    lines.reverse();
    put(p, "rev.csv", &format!("{header}\n{}\n", lines.join("\n")));
    let cfg = root().join("data/robonine-backlash/analysis_config_m5.json");
    let o = moreau_in(p, &["play-width", "--data", "rev.csv", "--config", cfg.to_str().unwrap()]);
    assert_refused(&o, &["rev.csv", "timestamp", "time order"]);
    let bad_cfg =
        std::fs::read_to_string(&cfg).unwrap().replacen("\"relaxed_tolerance\": 4", "\"relaxed_tolerance\": -4", 1);
    put(p, "cfg.json", &bad_cfg);
    let data = root().join("data/robonine-backlash/logs/motor_telemetry_single.csv");
    let o = moreau_in(p, &["play-width", "--data", data.to_str().unwrap(), "--config", "cfg.json"]);
    assert_refused(&o, &["cfg.json", "relaxed_tolerance", "-4"]);
    let ragged = format!("{header}\n{}\n2025-11-09T09:27:03.748Z,1\n", log.lines().nth(1).unwrap());
    put(p, "ragged.csv", &ragged);
    let o = moreau_in(p, &["play-width", "--data", "ragged.csv", "--config", cfg.to_str().unwrap()]);
    assert_refused(&o, &["ragged.csv", "row 3 has 2 fields"]);
}

#[test]
fn threads_are_capped_at_the_machine() {
    let d = workdir();
    let p = d.path();
    put(p, "s.toml", &spec("values = [1.0]", "measure = false"));
    let o = moreau_in(p, &["sweep", "s.toml", "--out", "out", "-q", "--threads", "100000"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{err}");
    assert!(err.contains("--threads 100000 capped at"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_only(p, &["w.toml", "s.toml", "out"]);
    assert_only(&p.join("out"), &["sweep.csv", "sweep.json", "sweep.md", "sweep.tex"]);
}

#[test]
fn a_locked_out_refuses_a_second_sweep_naming_the_holder() {
    let d = workdir();
    let p = d.path();
    put(p, "s.toml", &spec("values = [1.0]", "measure = false"));
    std::fs::create_dir(p.join("out")).unwrap();
    let lock_path = p.join("out/.sweep.lock");
    let lock = std::fs::File::create(&lock_path).unwrap();
    lock.try_lock().unwrap();
    std::fs::write(&lock_path, "pid 4242").unwrap();
    let o = moreau_in(p, &["sweep", "s.toml", "--out", "out", "-q"]);
    assert_refused(&o, &["out is in use by another sweep", "pid 4242", ".sweep.lock"]);
    assert_only(&p.join("out"), &[".sweep.lock"]);
    drop(lock);
    // the holder gone (its lock released), the next run goes ahead and removes the lock file
    let o = moreau_in(p, &["sweep", "s.toml", "--out", "out", "-q"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_only(&p.join("out"), &["sweep.csv", "sweep.json", "sweep.md", "sweep.tex"]);
}

#[test]
fn merge_checks_shard_parameters_against_the_grid() {
    let d = workdir();
    let p = d.path();
    put(p, "s.toml", &spec("values = [1.0, 2.0]", "measure = false"));
    let o = moreau_in(p, &["sweep", "s.toml", "--out", "shards", "-q", "--shard", "0/1"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let f = p.join("shards/sweep-shard-0-of-1.json");
    let text = std::fs::read_to_string(&f).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["points"][1]["params"][0] = serde_json::json!(7.5);
    std::fs::write(&f, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    let o = moreau_in(p, &["merge", "shards", "--out", "merged"]);
    assert_refused(&o, &["sweep-shard-0-of-1.json", "point 1", "7.5", "grid"]);
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["total_points"] = serde_json::json!(1_000_000_000_000_000u64);
    std::fs::write(&f, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    let o = moreau_in(p, &["merge", "shards", "--out", "merged"]);
    assert_refused(&o, &["total_points 1000000000000000", "product 2"]);
    assert_only(p, &["w.toml", "s.toml", "shards"]);
}

#[cfg(unix)]
#[test]
fn an_interrupted_sweep_leaves_no_staging_and_no_lock_and_resumes() {
    let d = workdir();
    let p = d.path();
    // a staging directory of a run that died (its process id does not exist)
    std::fs::create_dir(p.join(".moreau-staging-4000000000-abcdef")).unwrap();
    put(p, "s.toml", &spec("range = { from = 1.0, to = 3.0, count = 5000 }", ""));
    let mut child = Command::new(env!("CARGO_BIN_EXE_moreau"))
        .args(["sweep", "s.toml", "--out", "out", "-q"])
        .current_dir(p)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // wait until points are being computed (checkpoint lines), then interrupt
    let cp = p.join("out/.sweep.checkpoint.jsonl");
    loop {
        let lines = std::fs::read_to_string(&cp).map(|t| t.lines().count()).unwrap_or(0);
        if lines >= 3 {
            break;
        }
        if let Some(st) = child.try_wait().unwrap() {
            panic!("the sweep ended before it could be interrupted: {st}");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let ok = Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap().success();
    assert!(ok);
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("interrupted") && !err.contains("panicked"), "{err}");
    // the stale staging directory was removed at the start; nothing else beside --out
    assert_only(p, &["w.toml", "s.toml", "out"]);
    // inside --out only the checkpoint, from which the next run resumes
    assert_only(&p.join("out"), &[".sweep.checkpoint.jsonl"]);
}

/// Issue 31 items 1, 2, 6: an output never replaces an input or a device, a symlink is followed
/// (the link stays), and a closed standard output ends the run quietly.
#[test]
fn outputs_never_replace_inputs_devices_or_links() {
    let d = workdir();
    let p = d.path();
    let model = worked();
    // the model file as `--out` (also through a symlink): refused before any work, unchanged
    std::os::unix::fs::symlink("w.toml", p.join("alias.json")).unwrap();
    for out in ["w.toml", "alias.json"] {
        let o = moreau_in(p, &["theta", "w.toml", "--no-measure", "--out", out]);
        assert_refused(&o, &["refusing to overwrite", "w.toml"]);
        assert_eq!(std::fs::read_to_string(p.join("w.toml")).unwrap(), model);
    }
    // import's input as its output
    let ss = r#"{"A": [[-1.0]], "B": [[1.0]], "C": [[1.0]], "E": [[0.5]]}"#;
    put(p, "ss.json", ss);
    let o = moreau_in(p, &["import", "ss.json", "--out", "ss.json", "--interval", "0.1"]);
    assert_refused(&o, &["refusing to overwrite", "ss.json"]);
    assert_eq!(std::fs::read_to_string(p.join("ss.json")).unwrap(), ss);
    // a character device is written through and stays a device
    let o = moreau_in(p, &["theta", "w.toml", "--no-measure", "--out", "/dev/null"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(std::os::unix::fs::FileTypeExt::is_char_device(
        &std::fs::symlink_metadata("/dev/null").unwrap().file_type()
    ));
    // a directory is refused by name
    std::fs::create_dir(p.join("dir.json")).unwrap();
    let o = moreau_in(p, &["theta", "w.toml", "--no-measure", "--out", "dir.json"]);
    assert_refused(&o, &["dir.json", "is a directory"]);
    // a symlink to another file: the file gets the report, the link stays
    put(p, "real.json", "old");
    std::os::unix::fs::symlink("real.json", p.join("link.json")).unwrap();
    let o = moreau_in(p, &["theta", "w.toml", "--no-measure", "--out", "link.json"]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(std::fs::symlink_metadata(p.join("link.json")).unwrap().file_type().is_symlink());
    assert!(std::fs::read_to_string(p.join("real.json")).unwrap().contains("\"theta\""));
    assert_only(p, &["w.toml", "alias.json", "ss.json", "dir.json", "real.json", "link.json"]);
}

#[test]
fn a_closed_stdout_ends_quietly() {
    let d = workdir();
    // The reader is gone before the command starts, as with `| head -c 0` once `head` has
    // exited: closing it after the spawn raced the command's few lines into the pipe's buffer
    // (exit 0 on a fast start, seen once in CI).
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let child = Command::new(env!("CARGO_BIN_EXE_moreau"))
        .args(["validate", "w.toml", "w.toml", "w.toml"])
        .current_dir(d.path())
        .stdout(writer)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let o = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!err.contains("panicked") && !err.contains("Broken pipe"), "{err}");
    assert_eq!(o.status.code(), Some(141), "128 + SIGPIPE; stderr: {err}");
}

// ---------------------------------------------------------------------------------------------
// Issue 31 item 7: inputs that were silently accepted or answered with contradictory messages.
// Each case below was accepted (or misleading) before its fix.

/// The worked example with `from` replaced by `to` (the replacement must happen).
fn worked_with(from: &str, to: &str) -> String {
    let w = worked();
    assert!(w.contains(from), "{from}");
    w.replacen(from, to, 1)
}

/// `convergence` on a non-Hurwitz loop printed a "fitted order 0.957" from errors of 9e15;
/// on a csv input it said "needs ... zero, sine, square or csv; got csv".
#[test]
fn convergence_refuses_unstable_loops_and_names_the_inputs_it_takes() {
    let d = workdir();
    let p = d.path();
    put(p, "u.toml", &worked_with("[-2.0, -0.6]", "[-2.0, 0.6]"));
    let o = moreau_in(p, &["convergence", "u.toml", "--levels", "2", "--periods", "1"]);
    assert_refused(&o, &["u.toml", "not Hurwitz", "eigenvalue 0.3 + 0.953939i", "real part 0.3"]);
    assert!(o.stdout.is_empty(), "no table, no fitted order");
    put(p, "w.csv", "t,w\n0,0\n1,1\n2,0\n");
    put(
        p,
        "c.toml",
        &worked_with("kind = \"sine\"\namplitudes = [1.0]\nomega = 1.0", "kind = \"csv\"\nfile = \"w.csv\""),
    );
    let o = moreau_in(p, &["convergence", "c.toml"]);
    assert_refused(&o, &["c.toml", "needs an input of kind zero or sine", "input is `csv`"]);
    // the same text from the integrator itself (simulate --integrator event)
    let o = moreau_in(p, &["simulate", "c.toml", "--integrator", "event", "--out", "sim"]);
    assert_refused(&o, &["zero or sine", "got csv"]);
    // control: the stable worked example still gives its table
    let o = moreau_in(p, &["convergence", "w.toml", "--levels", "2", "--periods", "1"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("fitted order"));
}

/// A CSV input stated `period = 1e12` for 6.28 s of data (accepted by `theta`), a header
/// `t,wfoo` was read as `t,w`, and a polytope with an empty interior was accepted.
#[test]
fn csv_periods_headers_and_degenerate_polytopes_are_refused() {
    let d = workdir();
    let p = d.path();
    let samples: String = (0..=100).map(|k| format!("{},{}\n", k as f64 * 0.0628, (k as f64 * 0.0628).sin())).collect();
    put(p, "w.csv", &format!("t,w\n{samples}"));
    let csv_input = |period: &str| {
        worked_with(
            "kind = \"sine\"\namplitudes = [1.0]\nomega = 1.0",
            &format!("kind = \"csv\"\nfile = \"w.csv\"\n{period}"),
        )
    };
    put(p, "m.toml", &csv_input("period = 1e12"));
    let o = moreau_in(p, &["theta", "m.toml", "--no-measure"]);
    assert_refused(&o, &["m.toml", "input.period", "1000000000000", "span 6.28"]);
    put(p, "w2.csv", &format!("t,wfoo\n{samples}"));
    put(p, "h.toml", &csv_input("").replace("w.csv", "w2.csv"));
    let o = moreau_in(p, &["validate", "h.toml"]);
    assert_refused(&o, &["w2.csv", "header `t,wfoo`", "`t,w` or `t,w1`"]);
    let poly = std::fs::read_to_string(root().join("examples/polytope-p2.toml")).unwrap();
    let start = poly.find("[theta]").unwrap();
    let end = poly.find("[input]").unwrap();
    let flat = format!(
        "{}[theta]\nshape = \"box\"\nlower = [0.0, -0.1]\nupper = [0.0, 0.1]\n\n{}",
        &poly[..start],
        &poly[end..]
    );
    put(p, "flat.toml", &flat);
    let o = moreau_in(p, &["validate", "flat.toml"]);
    assert_refused(&o, &["flat.toml", "empty interior", "width across half-space 0"]);
    // control: the hexagon itself
    put(p, "hex.toml", &poly);
    assert!(moreau_in(p, &["validate", "hex.toml"]).status.success());
}

/// The stand config accepted `home_tolerance = -5`, `min_segment_samples = 0` and unknown keys.
#[test]
fn play_width_configs_refuse_bad_ranges_and_unknown_keys() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path();
    let data = root().join("data/robonine-backlash/logs/motor_telemetry_single.csv");
    let cfg = std::fs::read_to_string(root().join("data/robonine-backlash/analysis_config_m5.json")).unwrap();
    for (from, to, needles) in [
        ("\"home_tolerance\": 5", "\"home_tolerance\": -5", vec!["cfg.json", "home_tolerance -5"]),
        ("\"min_segment_samples\": 10", "\"min_segment_samples\": 0", vec!["cfg.json", "min_segment_samples 0"]),
        ("\"home_tolerance\": 5", "\"home_tolerance\": 5, \"colour\": 1", vec!["cfg.json", "unknown field `colour`"]),
    ] {
        assert!(cfg.contains(from));
        put(p, "cfg.json", &cfg.replacen(from, to, 1));
        let o = moreau_in(p, &["play-width", "--data", data.to_str().unwrap(), "--config", "cfg.json"]);
        assert_refused(&o, &needles);
    }
}

/// `merge DIR` read only `sweep*.json` and left a conflicting `extra.json` out unseen.
#[test]
fn merge_of_a_folder_refuses_a_conflicting_extra_json() {
    let d = workdir();
    let p = d.path();
    put(p, "s.toml", &spec("values = [1.0, 2.0]", "measure = false"));
    for k in ["0/2", "1/2"] {
        let o = moreau_in(p, &["sweep", "s.toml", "--out", "shards", "-q", "--shard", k]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let o = moreau_in(p, &["merge", "shards", "--out", "merged"]);
    assert!(o.status.success(), "control: {}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(p.join("shards/sweep-shard-0-of-2.json")).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["points"][0]["values"][0] = serde_json::json!(123.0);
    put(&p.join("shards"), "extra.json", &serde_json::to_string(&v).unwrap());
    let o = moreau_in(p, &["merge", "shards", "--out", "merged2"]);
    assert_refused(&o, &["point 0 differs", "extra.json", "sweep-shard-0-of-2.json"]);
    put(&p.join("shards"), "extra.json", "{\"note\": 1}");
    let o = moreau_in(p, &["merge", "shards", "--out", "merged2"]);
    assert_refused(&o, &["extra.json", "not a moreau sweep result"]);
    assert!(!p.join("merged2").exists());
}

/// The benchmark's environment variables: a typo is refused before any case runs, not read as
/// the default and reported as if the condition had been set.
#[test]
fn discover_bench_refuses_a_benchmark_variable_it_cannot_read() {
    let d = workdir();
    let p = d.path();
    let run = |k: &str, v: &str| {
        Command::new(env!("CARGO_BIN_EXE_moreau"))
            .args(["discover-bench", "--cases", "1", "--classes", "none"])
            .env(k, v)
            .current_dir(p)
            .output()
            .unwrap()
    };
    for (k, v, needle) in [
        ("BENCH_SIGNAL", "chrip", "chirp or steps"),
        ("BENCH_NOISE_DB", "loud", "finite level in dB"),
        ("BENCH_NOISE_DB", "NaN", "finite level in dB"),
        ("BENCH_LENGTH", "-2", "positive factor"),
        ("BENCH_TRUTH", "fine", "expected coarse"),
    ] {
        let o = run(k, v);
        assert_refused(&o, &[k, v, needle]);
        assert!(o.stdout.is_empty());
    }
}

/// `discover-bench --json <unwritable>` failed only after the benchmark; `--allow-large` was
/// advised when it had been given.
#[test]
fn outputs_are_checked_before_the_work_and_messages_do_not_contradict() {
    let d = workdir();
    let p = d.path();
    put(p, "file.txt", "x");
    std::fs::create_dir(p.join("dir.json")).unwrap();
    for (out, needle) in [("file.txt/out.json", "file.txt is not a directory"), ("dir.json", "is a directory")] {
        let o = moreau_in(p, &["discover-bench", "--cases", "1", "--classes", "none", "--json", out]);
        // one line on stderr: no case was run (each prints a progress line) and no table
        assert_refused(&o, &[out, needle]);
        assert!(o.stdout.is_empty());
    }
    put(p, "s.toml", &spec("range = { from = 1.0, to = 2.0, count = 20000000 }", "measure = false"));
    let o = moreau_in(p, &["sweep", "s.toml", "--out", "out", "-q", "--allow-large"]);
    assert_refused(&o, &["20000000", "limit 10000000", "the hard limit"]);
    assert!(!String::from_utf8_lossy(&o.stderr).contains("pass --allow-large"));
    let o = moreau_in(p, &["sweep", "s.toml", "--out", "out", "-q"]);
    assert_refused(&o, &["20000000", "limit 1000000;", "pass --allow-large"]);
}

/// `import` wrote models that `validate` refused: a fast sine (`--omega 1e4` with the default
/// step 1e-3) and a `csv` input named relative to the working directory.
#[test]
fn import_writes_only_models_that_validate_accepts() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path();
    std::fs::create_dir(p.join("js")).unwrap();
    let ss = r#"{"A": [[0.0, 1.0], [-2.0, -0.6]], "B": [[0.0], [1.0]], "C": [[1.0, 0.0]], "E": [[0.0], [1.0]]"#;
    put(p, "ss.json", &format!("{ss}}}"));
    let o = moreau_in(
        p,
        &["import", "ss.json", "--out", "fast.toml", "--interval", "0.1", "--sine", "1", "--omega", "1e4"],
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = moreau_in(p, &["validate", "fast.toml"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    put(&p.join("js"), "w.csv", "t,w\n0,0\n1,1\n2,0\n");
    put(
        &p.join("js"),
        "ss.json",
        &format!(
            r#"{ss}, "theta": {{"shape": "interval", "half_width": 0.1}}, "input": {{"kind": "csv", "file": "w.csv"}}}}"#
        ),
    );
    for out in ["m.toml", "js/m.toml", "new/m.toml"] {
        let o = moreau_in(p, &["import", "js/ss.json", "--out", out]);
        assert!(o.status.success(), "{out}: {}", String::from_utf8_lossy(&o.stderr));
        let o = moreau_in(p, &["validate", out]);
        assert!(o.status.success(), "{out}: {}", String::from_utf8_lossy(&o.stderr));
    }
    // a model larger than a model file may be is refused, and nothing is written
    let n = 1300;
    let row = |i: usize| {
        format!("[{}]", (0..n).map(|j| if i == j { "-1.0" } else { "0.123456789012" }).collect::<Vec<_>>().join(","))
    };
    let a: Vec<String> = (0..n).map(row).collect();
    let col = vec!["[1.0]"; n].join(",");
    let c = format!("[[1.0{}]]", ",0.0".repeat(n - 1));
    put(p, "big.json", &format!(r#"{{"A": [{}], "B": [{col}], "C": {c}, "E": [{col}]}}"#, a.join(",")));
    let o = moreau_in(p, &["import", "big.json", "--out", "big.toml", "--interval", "0.1", "--sine", "1"]);
    assert_refused(&o, &["big.json", "bytes, more than the 16777216 a model file may have"]);
    assert!(!p.join("big.toml").exists());
}

/// Issue 31 item 5 (a coverage-guided fuzzing finding of the `simulate` target): the
/// event-driven reference on a diverging 6-state plant whose ellipsoidal contact (p = 3)
/// chatters ran for over a minute (the event limit was 10^7 whatever the run); it now stops at
/// 10 events per step of the run with a one-line error naming the limit and the way out.
#[test]
fn a_chattering_event_driven_run_stops_at_its_event_budget() {
    let d = workdir();
    let f = put(d.path(), "chatter.toml", include_str!("../../../fuzz/regressions/simulate/event-driven-chatter-p3"));
    let args = ["simulate", &f, "--periods", "1", "--dt", "0.2094", "--max-rows", "50", "--integrator", "event"];
    let o = moreau_in(d.path(), &[&args[..], &["--out", "o"]].concat());
    assert_refused(&o, &["more than 10000 events", "--integrator catching-up"]);
    assert_only(d.path(), &["chatter.toml", "w.toml"]);
    // control: the worked example is simulated by the same reference within its budget
    let o = moreau_in(d.path(), &["simulate", "w.toml", "--periods", "2", "--integrator", "event", "--out", "ok"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}
