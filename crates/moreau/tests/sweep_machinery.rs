//! The sweep machinery (specs, axes, tables, resume, shards, merge, bad input) driven by a cheap
//! stand-in evaluator: these tests check the machinery, not the science (the theta evaluator
//! is exercised in `sweep_cli.rs`).
use model::{Input, System};
use moreau::sweep::{
    self, Cell, Column, FnEvaluator, PointError, RunOptions, Shard, SweepError, SweepResult, SweepSpec,
};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

fn worked_example() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/worked-example.toml").canonicalize().unwrap()
}

/// A spec file in `dir` with the given `[[axis]]` blocks (TOML text).
fn spec_in(dir: &Path, axes: &str, extra: &str) -> PathBuf {
    let p = dir.join("spec.toml");
    std::fs::write(
        &p,
        format!("name = \"stand-in sweep\"\nmodel = {:?}\n{axes}\n{extra}", worked_example().display().to_string()),
    )
    .unwrap();
    p
}

fn amplitude(s: &System) -> f64 {
    match &s.input {
        Input::Sine { amplitudes, .. } => amplitudes[0],
        _ => f64::NAN,
    }
}

/// Stand-in: `mu` of `F`, the amplitude, `A[1][0]`, `R` upper, a flag; fails for amplitude > 4.5.
fn stand_in(calls: &AtomicUsize) -> FnEvaluator<impl Fn(&System) -> Result<Vec<Cell>, PointError> + Sync + '_> {
    FnEvaluator {
        fingerprint: "stand-in v1".into(),
        columns: vec![
            Column::number("mu", "$\\mu$"),
            Column::number("amp", "$a$"),
            Column::number("a10", "$A_{21}$"),
            Column::number("R", "$R$"),
            Column::flag("stable", "stable"),
            Column::text("note", "note"),
        ],
        f: move |s: &System| -> Result<Vec<Cell>, PointError> {
            calls.fetch_add(1, Ordering::SeqCst);
            let a = amplitude(s);
            if a > 4.5 {
                return Err(format!("stand-in failure at amplitude {a}").into());
            }
            use geometry::ConvexSet;
            let mu = s.mu();
            Ok(vec![
                Cell::Num(mu),
                Cell::Num(a),
                Cell::Num(s.A[(1, 0)]),
                Cell::Num(s.theta.strong_convexity().upper()),
                Cell::Flag(mu < 0.0),
                Cell::Text(format!("a={a}, x")),
            ])
        },
    }
}

const TWO_AXES: &str = "[[axis]]\nparameter = \"input.amplitude\"\nrange = { from = 0.5, to = 5.0, count = 10 }\n[[axis]]\nparameter = \"plant.A[1][0]\"\nvalues = [-2.0, -1.5, -3.0]\n";

fn read_all(dir: &Path, stem: &str) -> Vec<String> {
    ["json", "csv", "md", "tex"]
        .iter()
        .map(|e| std::fs::read_to_string(dir.join(format!("{stem}.{e}"))).unwrap())
        .collect()
}

fn opts(out: &Path) -> RunOptions {
    RunOptions { out: out.to_path_buf(), ..Default::default() }
}

#[test]
fn grid_order_and_axis_values_reach_the_model() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = SweepSpec::load(&spec_in(tmp.path(), TWO_AXES, "")).unwrap();
    assert_eq!(spec.total_points(), 30);
    // last axis fastest
    assert_eq!(spec.point(0), vec![0.5, -2.0]);
    assert_eq!(spec.point(1), vec![0.5, -1.5]);
    assert_eq!(spec.point(3), vec![1.0, -2.0]);
    let s = spec.system_at(5).unwrap();
    assert_eq!(amplitude(&s), 1.0);
    assert_eq!(s.A[(1, 0)], -3.0);
    assert_eq!(spec.base.A[(1, 0)], -2.0, "the base model is not modified");
}

#[test]
fn theta_scale_omega_and_half_width_axes() {
    use geometry::ConvexSet;
    let tmp = tempfile::tempdir().unwrap();
    let axes = "[[axis]]\nparameter = \"theta.scale\"\nvalues = [0.5, 2.0]\n[[axis]]\nparameter = \"input.omega\"\nvalues = [2.0]\n";
    let spec = SweepSpec::load(&spec_in(tmp.path(), axes, "")).unwrap();
    let s = spec.system_at(1).unwrap();
    assert!((s.theta.strong_convexity().upper() - 0.2).abs() < 1e-12, "R of 2 x [-0.1, 0.1]");
    assert!((s.period().unwrap() - std::f64::consts::PI).abs() < 1e-12);
    let axes = "[[axis]]\nparameter = \"theta.R\"\nvalues = [0.3]\n";
    let s = SweepSpec::load(&spec_in(tmp.path(), axes, "")).unwrap().system_at(0).unwrap();
    assert!((s.theta.strong_convexity().upper() - 0.3).abs() < 1e-12);
    let axes = "[[axis]]\nparameter = \"theta.half_width\"\nvalues = [0.25]\n";
    let s = SweepSpec::load(&spec_in(tmp.path(), axes, "")).unwrap().system_at(0).unwrap();
    assert!(s.theta.contains(&[0.25], 1e-12) && !s.theta.contains(&[0.26], 1e-12));
}

#[test]
fn tables_do_not_depend_on_the_thread_count() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = SweepSpec::load(&spec_in(tmp.path(), TWO_AXES, "")).unwrap();
    let calls = AtomicUsize::new(0);
    let ev = stand_in(&calls);
    let (o1, o2) = (tmp.path().join("t1"), tmp.path().join("t2"));
    let s1 = sweep::run(&spec, &ev, &RunOptions { threads: Some(1), ..opts(&o1) }).unwrap();
    let s2 = sweep::run(&spec, &ev, &RunOptions { threads: Some(2), ..opts(&o2) }).unwrap();
    assert_eq!((s1.computed, s1.failed), (30, 3), "amplitude 5.0 fails for 3 values of A[1][0]");
    assert_eq!(s2.computed, 30);
    assert_eq!(read_all(&o1, "sweep"), read_all(&o2, "sweep"));
    // the JSON round-trips exactly and the CSV holds every value
    let r = SweepResult::read(&o1.join("sweep.json")).unwrap();
    assert_eq!(r, s1.result);
    assert!(r.points[3].ok() && !r.points[29].ok() && r.points[29].status.contains("stand-in failure"));
    let csv = std::fs::read_to_string(o1.join("sweep.csv")).unwrap();
    assert_eq!(csv.lines().count(), 31);
    assert!(csv
        .lines()
        .next()
        .unwrap()
        .starts_with("index,input.amplitude,plant.A[1][0],mu,amp,a10,R,stable,note,status"));
    assert!(csv.contains("\"a=0.5, x\""), "text with a comma is quoted");
    let tex = std::fs::read_to_string(o1.join("sweep.tex")).unwrap();
    assert!(
        tex.contains("\\toprule")
            && tex.contains("\\midrule")
            && tex.contains("\\bottomrule")
            && tex.contains("$A_{21}$")
    );
    assert_eq!(tex.matches("\\\\\n").count(), 31, "header + 30 rows");
}

#[test]
fn digits_option_changes_only_markdown_and_latex() {
    let tmp = tempfile::tempdir().unwrap();
    let spec =
        SweepSpec::load(&spec_in(tmp.path(), "[[axis]]\nparameter = \"plant.A[1][0]\"\nvalues = [-2.123456789]\n", ""))
            .unwrap();
    let calls = AtomicUsize::new(0);
    let ev = stand_in(&calls);
    let (o3, o6) = (tmp.path().join("d3"), tmp.path().join("d6"));
    sweep::run(&spec, &ev, &RunOptions { digits: Some(3), ..opts(&o3) }).unwrap();
    sweep::run(&spec, &ev, &RunOptions { digits: Some(6), ..opts(&o6) }).unwrap();
    let (a, b) = (read_all(&o3, "sweep"), read_all(&o6, "sweep"));
    assert_eq!(a[1], b[1], "CSV is exact whatever --digits");
    assert!(a[3].contains("\n-2.12 &") && b[3].contains("\n-2.12346 &"), "{}", a[3]);
    assert!(a[2].contains("| -2.12 |") && b[2].contains("| -2.12346 |"));
    assert!(matches!(
        sweep::run(&spec, &ev, &RunOptions { digits: Some(0), ..opts(&tmp.path().join("d0")) }),
        Err(SweepError::BadDigits { digits: 0, source_key: "--digits" })
    ));
}

#[test]
fn resume_skips_points_already_in_the_output() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = SweepSpec::load(&spec_in(tmp.path(), TWO_AXES, "")).unwrap();
    let calls = AtomicUsize::new(0);
    let ev = stand_in(&calls);
    let full = tmp.path().join("full");
    sweep::run(&spec, &ev, &opts(&full)).unwrap();
    let reference = read_all(&full, "sweep");
    assert_eq!(calls.swap(0, Ordering::SeqCst), 30);
    // a second run over a complete output computes nothing and rewrites the same tables
    let again = sweep::run(&spec, &ev, &opts(&full)).unwrap();
    assert_eq!((again.resumed, again.computed, calls.load(Ordering::SeqCst)), (30, 0, 0));
    assert_eq!(read_all(&full, "sweep"), reference);
    // an interrupted run: checkpoint with 12 points and a line cut short, no tables yet
    let cut = tmp.path().join("cut");
    std::fs::create_dir_all(&cut).unwrap();
    let r = SweepResult::read(&full.join("sweep.json")).unwrap();
    let mut cp = format!("{}\n", r.header_json());
    for p in r.points.iter().filter(|p| p.index % 5 != 2).take(12) {
        cp.push_str(&format!("{}\n", p.to_json()));
    }
    let partial_line = r.points[2].to_json().to_string();
    cp.push_str(&partial_line[..partial_line.len() / 2]);
    std::fs::write(cut.join(".sweep.checkpoint.jsonl"), cp).unwrap();
    let resumed = sweep::run(&spec, &ev, &opts(&cut)).unwrap();
    assert_eq!((resumed.resumed, resumed.computed, calls.load(Ordering::SeqCst)), (12, 18, 18));
    assert_eq!(read_all(&cut, "sweep"), reference, "resumed tables equal a fresh run");
    assert!(!cut.join(".sweep.checkpoint.jsonl").exists(), "the checkpoint is removed once the tables are written");
    // --retry-failed recomputes exactly the 3 failed points; --fresh recomputes everything
    calls.store(0, Ordering::SeqCst);
    let retry = sweep::run(&spec, &ev, &RunOptions { retry_failed: true, ..opts(&cut) }).unwrap();
    assert_eq!((retry.resumed, retry.computed, retry.failed, calls.load(Ordering::SeqCst)), (27, 3, 3, 3));
    calls.store(0, Ordering::SeqCst);
    let fresh = sweep::run(&spec, &ev, &RunOptions { fresh: true, ..opts(&cut) }).unwrap();
    assert_eq!((fresh.resumed, fresh.computed, calls.load(Ordering::SeqCst)), (0, 30, 30));
    assert_eq!(read_all(&cut, "sweep"), reference);
}

#[test]
fn shards_merge_to_the_full_table() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = SweepSpec::load(&spec_in(tmp.path(), TWO_AXES, "")).unwrap();
    let calls = AtomicUsize::new(0);
    let ev = stand_in(&calls);
    let full = tmp.path().join("full");
    sweep::run(&spec, &ev, &opts(&full)).unwrap();
    calls.store(0, Ordering::SeqCst);
    let shards = tmp.path().join("shards");
    let mut sizes = vec![];
    for k in 0..4 {
        let s =
            sweep::run(&spec, &ev, &RunOptions { shard: Some(Shard::new(k, 4).unwrap()), ..opts(&shards) }).unwrap();
        assert!(s.result.points.iter().all(|p| p.index % 4 == k));
        sizes.push(s.computed);
        assert!(shards.join(format!("sweep-shard-{k}-of-4.json")).exists());
    }
    assert_eq!(sizes, vec![8, 8, 7, 7]);
    assert_eq!(calls.load(Ordering::SeqCst), 30, "every point computed exactly once over the shards");
    // merging three shards is incomplete
    let three: Vec<PathBuf> = (0..3).map(|k| shards.join(format!("sweep-shard-{k}-of-4.json"))).collect();
    let err = sweep::merge::merge_into(&three, &tmp.path().join("m3"), false, None).unwrap_err();
    assert!(matches!(err, SweepError::MergeIncomplete { missing: 7, total: 30, first: 3 }), "{err}");
    assert!(!tmp.path().join("m3").join("sweep.csv").exists());
    let (p, _) = sweep::merge::merge_into(&three, &tmp.path().join("m3"), true, None).unwrap();
    assert_eq!(p.points.len(), 23);
    // the whole directory merges to exactly the tables of the unsharded run
    let merged = tmp.path().join("merged");
    sweep::merge::merge_into(std::slice::from_ref(&shards), &merged, false, None).unwrap();
    assert_eq!(read_all(&merged, "sweep"), read_all(&full, "sweep"));
}

#[test]
fn merge_refuses_shards_of_different_specs_and_conflicts() {
    let tmp = tempfile::tempdir().unwrap();
    let calls = AtomicUsize::new(0);
    let ev = stand_in(&calls);
    let d1 = tmp.path().join("one");
    let d2 = tmp.path().join("two");
    std::fs::create_dir_all(&d1).unwrap();
    std::fs::create_dir_all(&d2).unwrap();
    let s1 = SweepSpec::load(&spec_in(&d1, TWO_AXES, "")).unwrap();
    let s2 = SweepSpec::load(&spec_in(&d2, &TWO_AXES.replace("-3.0", "-3.5"), "")).unwrap();
    assert_ne!(s1.hash("stand-in v1"), s2.hash("stand-in v1"));
    assert_ne!(s1.hash("stand-in v1"), s1.hash("stand-in v2"), "the evaluator is part of the hash");
    let out = tmp.path().join("out");
    sweep::run(&s1, &ev, &RunOptions { shard: Some(Shard::new(0, 2).unwrap()), ..opts(&out.join("a")) }).unwrap();
    sweep::run(&s2, &ev, &RunOptions { shard: Some(Shard::new(1, 2).unwrap()), ..opts(&out.join("b")) }).unwrap();
    let files = vec![out.join("a/sweep-shard-0-of-2.json"), out.join("b/sweep-shard-1-of-2.json")];
    let good = tmp.path().join("good");
    sweep::run(&s1, &ev, &opts(&good)).unwrap();
    let before = read_all(&good, "sweep");
    let err = sweep::merge::merge_into(&files, &good, true, None).unwrap_err();
    assert!(matches!(err, SweepError::MergeSpecMismatch { .. }), "{err}");
    assert_eq!(read_all(&good, "sweep"), before, "a failed merge leaves the good table alone");
    // a tampered duplicate point conflicts
    let full = SweepResult::read(&good.join("sweep.json")).unwrap();
    let mut bad = full.clone();
    bad.points[4].cells[0] = Cell::Num(123.0);
    std::fs::write(tmp.path().join("bad.json"), bad.to_json_string()).unwrap();
    let err = sweep::merge::merge_into(
        &[good.join("sweep.json"), tmp.path().join("bad.json")],
        &tmp.path().join("m"),
        false,
        None,
    )
    .unwrap_err();
    assert!(matches!(err, SweepError::MergeConflict { index: 4, .. }), "{err}");
    // not a sweep result
    std::fs::write(tmp.path().join("junk.json"), "{\"a\": 1}").unwrap();
    assert!(matches!(
        sweep::merge::merge_into(&[tmp.path().join("junk.json")], &tmp.path().join("m"), false, None),
        Err(SweepError::BadResultFile { .. })
    ));
}

#[test]
fn output_of_another_spec_is_not_overwritten() {
    let tmp = tempfile::tempdir().unwrap();
    let calls = AtomicUsize::new(0);
    let ev = stand_in(&calls);
    let s1 = SweepSpec::load(&spec_in(tmp.path(), TWO_AXES, "")).unwrap();
    let out = tmp.path().join("out");
    sweep::run(&s1, &ev, &opts(&out)).unwrap();
    let before = read_all(&out, "sweep");
    let s2 = SweepSpec::load(&spec_in(tmp.path(), "[[axis]]\nparameter = \"input.omega\"\nvalues = [1.0, 2.0]\n", ""))
        .unwrap();
    let err = sweep::run(&s2, &ev, &opts(&out)).unwrap_err();
    assert!(matches!(err, SweepError::OtherSpec { .. }), "{err}");
    assert!(err.to_string().contains("--overwrite"));
    assert_eq!(read_all(&out, "sweep"), before);
    let s = sweep::run(&s2, &ev, &RunOptions { overwrite: true, ..opts(&out) }).unwrap();
    assert_eq!(s.computed, 2);
    assert_eq!(SweepResult::read(&out.join("sweep.json")).unwrap().points.len(), 2);
}

fn load_err(axes: &str, extra: &str) -> SweepError {
    let tmp = tempfile::tempdir().unwrap();
    SweepSpec::load(&spec_in(tmp.path(), axes, extra)).unwrap_err()
}

#[test]
fn bad_specs_give_clear_errors() {
    let e = load_err("[[axis]]\nparameter = \"plant.Q[0][0]\"\nvalues = [1.0]\n", "");
    assert!(matches!(&e, SweepError::UnknownParameter { name } if name == "plant.Q[0][0]"), "{e}");
    let e = load_err("[[axis]]\nparameter = \"input.gain\"\nvalues = [1.0]\n", "");
    assert!(e.to_string().contains("`input.gain`: unknown parameter"), "{e}");
    let e = load_err("[[axis]]\nparameter = \"plant.A[2][0]\"\nvalues = [1.0]\n", "");
    assert!(matches!(e, SweepError::IndexOutOfRange { i: 2, j: 0, rows: 2, cols: 2, .. }), "{e}");
    let e = load_err("[[axis]]\nparameter = \"input.amplitude\"\nrange = { from = 1.0, to = 2.0, count = 0 }\n", "");
    assert!(matches!(e, SweepError::EmptyRange { .. }), "{e}");
    let e = load_err("[[axis]]\nparameter = \"input.amplitude\"\nrange = { from = 2.0, to = 1.0, step = 0.5 }\n", "");
    assert!(matches!(e, SweepError::EmptyRange { .. }), "{e}");
    let e = load_err("[[axis]]\nparameter = \"input.amplitude\"\nvalues = []\n", "");
    assert!(matches!(e, SweepError::EmptyValues { .. }), "{e}");
    let e = load_err("", "");
    assert!(matches!(e, SweepError::NoAxes), "{e}");
    let e = load_err("[[axis]]\nparameter = \"input.omega\"\nvalues = [1.0]\n[[axis]]\nparameter = \"input.omega\"\nvalues = [2.0]\n", "");
    assert!(matches!(e, SweepError::DuplicateAxis { .. }), "{e}");
    let e = load_err("[[axis]]\nparameter = \"input.omega\"\nvalues = [0.0]\n", "");
    assert!(matches!(e, SweepError::NotApplicable { .. }), "{e}");
    let e = load_err("[[axis]]\nparameter = \"input.omega\"\nvalues = [1.0]\nstep = 2\n", "");
    assert!(matches!(e, SweepError::UnknownKey { .. }), "{e}");
    let e = load_err("[[axis]]\nparameter = \"input.omega\"\nvalues = [1.0]\n", "[table]\ndigits = 40\n");
    assert!(matches!(e, SweepError::BadDigits { digits: 40, .. }), "{e}");
    assert_eq!(e.to_string(), "[table] digits = 40 is out of range: use 1 to 17");
    // an entry making the model invalid is caught at load time (E must stay finite etc.)
    let e = load_err("[[axis]]\nparameter = \"theta.scale\"\nvalues = [-1.0]\n", "");
    assert!(matches!(e, SweepError::NotApplicable { .. }), "{e}");
    assert!(matches!(Shard::parse("4/4"), Err(SweepError::BadShard { .. })));
}

#[test]
fn unknown_table_column_is_refused_before_any_work() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = SweepSpec::load(&spec_in(
        tmp.path(),
        "[[axis]]\nparameter = \"input.omega\"\nvalues = [1.0]\n",
        "[table]\ncolumns = [\"mu\", \"nonsense\"]\n",
    ))
    .unwrap();
    let calls = AtomicUsize::new(0);
    let err = sweep::run(&spec, &stand_in(&calls), &opts(&tmp.path().join("o"))).unwrap_err();
    assert!(matches!(&err, SweepError::UnknownColumn { name, .. } if name == "nonsense"), "{err}");
    assert_eq!(calls.load(Ordering::SeqCst), 0);
}
