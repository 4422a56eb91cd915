//! What the commands write, end to end (the mechanisms are unit-tested in `src/output.rs`): a
//! folder output of `simulate` or `diagnose` replaces the previous run's files and keeps the
//! user's, a held folder is refused naming the holder, `/dev/stdout` and a FIFO are written
//! through, a full standard output is one error line, and the work budgets for plant entries
//! refuse in one line naming the limit and the override. No assertion depends on timing.
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().unwrap()
}

fn moreau_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_moreau")).args(args).current_dir(dir).output().unwrap()
}

fn worked(dir: &Path) {
    std::fs::copy(root().join("examples/worked-example.toml"), dir.join("w.toml")).unwrap();
}

fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    v.sort();
    v
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn a_folder_output_replaces_the_previous_runs_files_and_keeps_the_users() {
    let d = tempfile::tempdir().unwrap();
    worked(d.path());
    let out = d.path().join("sim");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    // a file the previous run wrote (listed in its manifest) that this run does not write
    std::fs::write(out.join("zoom-3.svg"), "stale").unwrap();
    std::fs::write(out.join(".moreau-outputs"), "trajectory.csv\nzoom-3.svg\n").unwrap();
    let o = moreau_in(d.path(), &["simulate", "w.toml", "--periods", "1", "--out", "sim"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(names(&out), [".moreau-outputs", "notes.txt", "trajectory.csv", "trajectory.png", "trajectory.svg"]);
    assert_eq!(std::fs::read_to_string(out.join("notes.txt")).unwrap(), "mine");
    let manifest = std::fs::read_to_string(out.join(".moreau-outputs")).unwrap();
    assert_eq!(manifest, "trajectory.csv\ntrajectory.png\ntrajectory.svg\n");
}

#[test]
fn a_held_folder_is_refused_naming_the_holder_and_freed_after() {
    let d = tempfile::tempdir().unwrap();
    worked(d.path());
    let out = d.path().join("sim");
    std::fs::create_dir(&out).unwrap();
    // this test process holds the folder's lock, as a running `diagnose` would
    let lock = std::fs::File::create(out.join(".moreau.lock")).unwrap();
    lock.try_lock().unwrap();
    std::fs::write(out.join(".moreau.lock"), "pid 4242").unwrap();
    let o = moreau_in(d.path(), &["simulate", "w.toml", "--periods", "1", "--out", "sim"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("in use by another moreau run (pid 4242"), "{}", stderr(&o));
    assert_eq!(names(&out), [".moreau.lock"], "a refused run writes nothing");
    // negative control: released, the same run goes through and removes the lock file
    drop(lock);
    std::fs::remove_file(out.join(".moreau.lock")).unwrap();
    let o = moreau_in(d.path(), &["simulate", "w.toml", "--periods", "1", "--out", "sim"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!out.join(".moreau.lock").exists());
}

#[test]
fn dev_stdout_is_written_through_and_a_full_stdout_is_one_error_line() {
    let d = tempfile::tempdir().unwrap();
    worked(d.path());
    // stdout redirected to a file: the report and the JSON both land in it, the file stays
    let captured = d.path().join("captured.out");
    let f = std::fs::File::create(&captured).unwrap();
    let ino = std::os::unix::fs::MetadataExt::ino(&std::fs::metadata(&captured).unwrap());
    let o = Command::new(env!("CARGO_BIN_EXE_moreau"))
        .args(["theta", "w.toml", "--no-measure", "--no-stationary", "--no-guidance", "--out", "/dev/stdout"])
        .current_dir(d.path())
        .stdout(Stdio::from(f))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&captured).unwrap();
    assert!(text.contains("theta") && text.contains("\"theta_best_verified\""), "{text}");
    let now = std::os::unix::fs::MetadataExt::ino(&std::fs::metadata(&captured).unwrap());
    assert_eq!(ino, now, "the redirected file must not be replaced");
    // standard output on /dev/full
    let full = std::fs::OpenOptions::new().write(true).open("/dev/full").unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_moreau"))
        .args(["validate", "w.toml"])
        .current_dir(d.path())
        .stdout(Stdio::from(full))
        .output()
        .unwrap();
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.starts_with("error: cannot write to standard output") && !err.contains("panicked"), "{err}");
}

#[test]
fn a_fifo_output_without_a_reader_is_refused_and_one_with_a_reader_gets_the_file() {
    let d = tempfile::tempdir().unwrap();
    worked(d.path());
    let fifo = d.path().join("out.fifo");
    assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    let o = moreau_in(
        d.path(),
        &["theta", "w.toml", "--no-measure", "--no-stationary", "--no-guidance", "--out", "out.fifo"],
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("FIFO with no reader"), "{}", stderr(&o));
    // negative control: with a reader the JSON goes through the FIFO, which stays a FIFO
    let path = fifo.clone();
    let reader = std::thread::spawn(move || std::fs::read_to_string(path).unwrap());
    let o = moreau_in(
        d.path(),
        &["theta", "w.toml", "--no-measure", "--no-stationary", "--no-guidance", "--out", "out.fifo"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let json = reader.join().unwrap();
    assert!(json.trim_start().starts_with('{') && json.contains("\"theta\""), "{json}");
    assert!(std::os::unix::fs::FileTypeExt::is_fifo(&std::fs::symlink_metadata(&fifo).unwrap().file_type()));
}

#[test]
fn huge_plant_entries_need_allow_large() {
    let d = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(root().join("examples/worked-example.toml"))
        .unwrap()
        .replace("A = [[0.0, 1.0], [-2.0, -0.6]]", "A = [[0.0, 1.0], [-2e60, -0.6]]");
    std::fs::write(d.path().join("big.toml"), text).unwrap();
    for cmd in [&["theta", "big.toml"][..], &["simulate", "big.toml", "--out", "o"][..], &["periodic", "big.toml"][..]]
    {
        let o = moreau_in(d.path(), cmd);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{cmd:?}: {err}");
        assert!(err.contains("plant entry A[1][0]") && err.contains("--allow-large"), "{cmd:?}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
    }
    // with the override the simulation runs to its end (no longer an endless matrix exponential)
    let o = moreau_in(d.path(), &["--allow-large", "simulate", "big.toml", "--periods", "1", "--out", "o"]);
    assert!(o.status.success(), "{}", stderr(&o));
    // negative control: an ordinary plant is not refused
    worked(d.path());
    assert!(moreau_in(d.path(), &["validate", "w.toml"]).status.success());
}

#[test]
fn simulate_says_when_max_rows_thins_the_trajectory() {
    let d = tempfile::tempdir().unwrap();
    worked(d.path());
    // 1 period of 2 pi at dt ~ 1e-3: 6284 steps, thinned to every 7th by --max-rows 1000
    let o = moreau_in(d.path(), &["simulate", "w.toml", "--periods", "1", "--max-rows", "1000", "--out", "sim"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let line = String::from_utf8(o.stdout).unwrap();
    assert!(line.contains("), kept every 7th of 6,284 steps (--max-rows 1000) -> sim"), "{line}");
    let rows = std::fs::read_to_string(d.path().join("sim/trajectory.csv")).unwrap().lines().count() - 1;
    assert!(line.starts_with(&format!("worked example (NOTES.md), a = 1: {rows} samples")), "{line}");
    // diagnose reads simulate's own time stamps as a regular grid: the short last step (the end
    // of the simulation off the thinned grid) is left out, nothing is resampled
    let rec = discovery::recording::Recording::load(&d.path().join("sim/trajectory.csv")).unwrap();
    assert!(!rec.resampled && rec.rows_in_file == rows && rec.len() == rows - 1, "{} of {rows}", rec.len());
    // negative control: every step kept, nothing said
    let o = moreau_in(d.path(), &["simulate", "w.toml", "--periods", "1", "--out", "sim"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let line = String::from_utf8(o.stdout).unwrap();
    assert!(!line.contains("kept every") && line.contains("6285 samples"), "{line}");
}
