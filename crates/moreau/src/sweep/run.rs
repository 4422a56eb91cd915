//! Running a sweep: parallel evaluation (rayon), a progress bar with ETA (indicatif), a
//! checkpoint file so that an interrupted run resumes where it stopped, and atomic table
//! output (tables appear complete or not at all; a good table is never overwritten by a
//! partial one).
use super::eval::{Cell, Evaluator};
use super::shard::Shard;
use super::spec::SweepSpec;
use super::table::{AxisInfo, PointRecord, SweepResult};
use super::SweepError;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Options of one run.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Output directory (created if absent).
    pub out: PathBuf,
    /// Only this shard's points. Default: all points.
    pub shard: Option<Shard>,
    /// Worker threads. Default: rayon's default (all cores, or `RAYON_NUM_THREADS`).
    pub threads: Option<usize>,
    /// Show a progress bar on stderr.
    pub progress: bool,
    /// Replace results of a different spec in `out` instead of refusing.
    pub overwrite: bool,
    /// Recompute every point, ignoring earlier results of the same spec (e.g. after a change
    /// of the code: the spec hash covers the inputs and settings, not the program).
    pub fresh: bool,
    /// Recompute points whose earlier evaluation failed (their `status` is an error).
    pub retry_failed: bool,
    /// Significant digits of Markdown / LaTeX (default: the spec's `[table] digits`).
    pub digits: Option<usize>,
}

/// What a run did.
#[derive(Debug, Clone)]
pub struct RunSummary {
    /// Points of this run's scope (the shard, or all).
    pub in_scope: usize,
    /// Points found in earlier output and not recomputed.
    pub resumed: usize,
    pub computed: usize,
    /// Points whose evaluation failed (recorded with their error in `status`).
    pub failed: usize,
    pub files: Vec<PathBuf>,
    pub result: SweepResult,
}

/// File stem of a run's outputs: `sweep`, or `sweep-shard-K-of-N`.
pub fn stem(shard: Option<Shard>) -> String {
    shard.map(|s| s.stem()).unwrap_or_else(|| "sweep".into())
}

fn checkpoint_path(out: &Path, stem: &str) -> PathBuf {
    out.join(format!(".{stem}.checkpoint.jsonl"))
}

/// Writes the four tables `stem.{json,csv,md,tex}` into `out`, all or none.
pub fn write_tables(result: &SweepResult, out: &Path, stem: &str, digits: usize) -> Result<Vec<PathBuf>, SweepError> {
    let werr =
        |path: &Path, e: &dyn std::fmt::Display| SweepError::Write { path: path.to_path_buf(), reason: e.to_string() };
    let staged = crate::output::StagedDir::new(out).map_err(|e| werr(out, &e))?;
    let files = [
        (format!("{stem}.json"), result.to_json_string()),
        (format!("{stem}.csv"), result.to_csv()),
        (format!("{stem}.md"), result.to_markdown(digits)),
        (format!("{stem}.tex"), result.to_latex(digits)),
    ];
    for (name, text) in &files {
        let p = staged.path(name);
        std::fs::write(&p, text).map_err(|e| werr(&p, &e))?;
    }
    staged.commit().map_err(|e| werr(out, &e))?;
    Ok(files.iter().map(|(n, _)| out.join(n)).collect())
}

/// Header (no points) of the result of `spec` under `evaluator`.
pub fn result_header(spec: &SweepSpec, evaluator: &dyn Evaluator, shard: Option<Shard>, digits: usize) -> SweepResult {
    let mut table = spec.table.clone();
    table.digits = digits;
    SweepResult {
        name: spec.name.clone(),
        spec_hash: spec.hash(&evaluator.fingerprint()),
        model: spec.model.clone(),
        evaluator: evaluator.fingerprint(),
        axes: spec
            .axes
            .iter()
            .map(|a| AxisInfo { name: a.parameter.name(), label: a.label.clone(), values: a.values.clone() })
            .collect(),
        columns: evaluator.columns(),
        total_points: spec.total_points(),
        shard,
        table,
        points: vec![],
    }
}

/// Points of an earlier run of the same spec in `out` (final file and checkpoint).
fn previous_points(
    header: &SweepResult,
    out: &Path,
    stem: &str,
    overwrite: bool,
) -> Result<BTreeMap<usize, PointRecord>, SweepError> {
    let mut done = BTreeMap::new();
    let final_path = out.join(format!("{stem}.json"));
    if final_path.exists() {
        match SweepResult::read(&final_path) {
            Ok(r) if r.spec_hash == header.spec_hash => {
                for p in r.points {
                    done.insert(p.index, p);
                }
            }
            Ok(r) if !overwrite => {
                return Err(SweepError::OtherSpec {
                    path: final_path,
                    found: r.spec_hash,
                    expected: header.spec_hash.clone(),
                })
            }
            Err(e) if !overwrite => return Err(e),
            _ => {}
        }
    }
    let cp = checkpoint_path(out, stem);
    if cp.exists() {
        let f = std::fs::File::open(&cp).map_err(|source| SweepError::Io { path: cp.clone(), source })?;
        let mut lines = std::io::BufReader::new(f).lines();
        let head = lines.next().and_then(|l| l.ok()).and_then(|l| serde_json::from_str::<serde_json::Value>(&l).ok());
        let hash = head.as_ref().and_then(|h| h.get("spec_hash")).and_then(|h| h.as_str()).map(String::from);
        match hash {
            Some(h) if h == header.spec_hash => {
                // a line cut short by an interrupted run fails to parse and is recomputed
                for l in lines.map_while(Result::ok) {
                    if let Some(p) = serde_json::from_str::<serde_json::Value>(&l)
                        .ok()
                        .and_then(|v| PointRecord::from_json(&v, &header.columns, header.axes.len()))
                    {
                        if p.index < header.total_points {
                            done.insert(p.index, p);
                        }
                    }
                }
            }
            Some(h) if !overwrite => {
                return Err(SweepError::OtherSpec { path: cp, found: h, expected: header.spec_hash.clone() })
            }
            _ => {}
        }
    }
    Ok(done)
}

/// Evaluates one point, turning errors and panics into a failed record.
fn evaluate_point(spec: &SweepSpec, evaluator: &dyn Evaluator, index: usize, ncols: usize) -> PointRecord {
    let params = spec.point(index);
    let failed =
        |status: String| PointRecord { index, params: params.clone(), cells: vec![Cell::Empty; ncols], status };
    let sys = match spec.system_at(index) {
        Ok(s) => s,
        Err(e) => return failed(format!("error: {e}")),
    };
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| evaluator.evaluate(&sys))) {
        Ok(Ok(cells)) if cells.len() == ncols => PointRecord { index, params, cells, status: "ok".into() },
        Ok(Ok(cells)) => failed(format!("error: the evaluator returned {} values for {ncols} columns", cells.len())),
        Ok(Err(e)) => failed(format!("error: {e}")),
        Err(p) => {
            let msg = p
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| p.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            failed(format!("error: panic in the evaluator: {msg}"))
        }
    }
}

/// Runs (or resumes) `spec` with `evaluator`; writes `stem.{json,csv,md,tex}` into `opts.out`.
pub fn run(spec: &SweepSpec, evaluator: &dyn Evaluator, opts: &RunOptions) -> Result<RunSummary, SweepError> {
    let digits = opts.digits.unwrap_or(spec.table.digits);
    if !(1..=17).contains(&digits) {
        return Err(SweepError::BadDigits { digits: digits as i64, source_key: "--digits" });
    }
    let mut header = result_header(spec, evaluator, opts.shard, digits);
    if let Some(name) = header.unknown_table_columns().into_iter().next() {
        return Err(SweepError::UnknownColumn {
            name,
            known: header.columns.iter().map(|c| c.name.as_str()).collect::<Vec<_>>().join(", "),
        });
    }
    let stem = stem(opts.shard);
    let _lock = crate::output::DirLock::acquire(&opts.out, &stem, "sweep")?;
    // staging directories of interrupted runs beside `--out`
    crate::output::remove_stale_staging(
        opts.out.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new(".")),
    );
    let Plan { mut done, in_scope, todo } = plan(&header, opts, &stem)?;
    let resumed = in_scope - todo.len();
    let cp = checkpoint_path(&opts.out, &stem);
    let cp_file = Mutex::new(open_checkpoint(&header, opts, &stem, &cp)?);
    let new = evaluate_all(spec, evaluator, opts, &todo, header.columns.len(), &cp_file)?;
    let computed = new.len();
    for p in new {
        done.insert(p.index, p);
    }
    header.points = done.into_values().collect();
    let failed = header.points.iter().filter(|p| !p.ok()).count();
    let files = write_tables(&header, &opts.out, &stem, digits)?;
    drop(cp_file);
    let _ = std::fs::remove_file(&cp);
    Ok(RunSummary { in_scope, resumed, computed, failed, files, result: header })
}

/// What a run does: the points already done (kept from an earlier run unless `--fresh`, the
/// failed ones dropped with `--retry-failed`), how many points the run's shard holds, and the
/// indices still to evaluate.
struct Plan {
    done: BTreeMap<usize, PointRecord>,
    in_scope: usize,
    todo: Vec<usize>,
}

fn plan(header: &SweepResult, opts: &RunOptions, stem: &str) -> Result<Plan, SweepError> {
    let mut done = previous_points(header, &opts.out, stem, opts.overwrite)?;
    if opts.fresh {
        done.clear();
    }
    if opts.retry_failed {
        done.retain(|_, p| p.ok());
    }
    let in_scope: Vec<usize> = (0..header.total_points).filter(|&i| opts.shard.is_none_or(|s| s.contains(i))).collect();
    done.retain(|i, _| opts.shard.is_none_or(|s| s.contains(*i)));
    let todo: Vec<usize> = in_scope.iter().copied().filter(|i| !done.contains_key(i)).collect();
    Ok(Plan { done, in_scope: in_scope.len(), todo })
}

/// The checkpoint `cp`, open for appending: a header line, then one line per finished point
/// (an earlier run's file of the same sweep is continued). Every line goes out in one write, so
/// a line is whole or (cut by an interruption) unparsable, never mixed with another.
fn open_checkpoint(
    header: &SweepResult,
    opts: &RunOptions,
    stem: &str,
    cp: &Path,
) -> Result<std::fs::File, SweepError> {
    std::fs::create_dir_all(&opts.out)
        .map_err(|e| SweepError::Write { path: opts.out.clone(), reason: e.to_string() })?;
    let cperr = |e: std::io::Error| SweepError::Write { path: cp.to_path_buf(), reason: e.to_string() };
    // `plan` read the files already; without --overwrite it refused any of another sweep, so
    // they are this sweep's and need no second reading
    let exists_same =
        !opts.fresh && cp.exists() && (!opts.overwrite || previous_points(header, &opts.out, stem, false).is_ok());
    if !exists_same {
        std::fs::write(cp, format!("{}\n", header.header_json())).map_err(cperr)?;
    }
    let mut f = std::fs::OpenOptions::new().append(true).open(cp).map_err(cperr)?;
    let _ = f.flush();
    Ok(f)
}

/// The points `todo`, in parallel (on `--threads` threads where given), each written to the
/// checkpoint as it finishes, with a progress bar where asked.
fn evaluate_all(
    spec: &SweepSpec,
    evaluator: &dyn Evaluator,
    opts: &RunOptions,
    todo: &[usize],
    ncols: usize,
    cp_file: &Mutex<std::fs::File>,
) -> Result<Vec<PointRecord>, SweepError> {
    let pb = progress_bar(opts.progress, todo.len());
    let work = || -> Vec<PointRecord> {
        todo.par_iter()
            .map(|&i| {
                let rec = evaluate_point(spec, evaluator, i, ncols);
                let line = format!("{}\n", rec.to_json());
                if let Ok(mut f) = cp_file.lock() {
                    let _ = f.write_all(line.as_bytes());
                    let _ = f.flush();
                }
                pb.inc(1);
                rec
            })
            .collect()
    };
    let new = match opts.threads {
        Some(t) => rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()
            .map_err(|e| SweepError::ThreadPool { threads: t, reason: e.to_string() })?
            .install(work),
        None => work(),
    };
    pb.finish_and_clear();
    Ok(new)
}

/// A bar of `n` points with the elapsed time and the ETA, or a hidden one.
fn progress_bar(shown: bool, n: usize) -> indicatif::ProgressBar {
    if !shown {
        return indicatif::ProgressBar::hidden();
    }
    let pb = indicatif::ProgressBar::new(n as u64);
    pb.set_style(
        indicatif::ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} points, ETA {eta}")
            .expect("template")
            .progress_chars("=> "),
    );
    pb
}
