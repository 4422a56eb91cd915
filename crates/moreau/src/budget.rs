//! Budgets checked before work starts: every command estimates its integration steps, grid
//! points, property cases, stored samples and problem size from its inputs and refuses, in one
//! line naming the value and the limit, before anything is allocated or started. The global
//! flag `--allow-large` lifts the soft limits deliberately; the hard limits (where a larger
//! value would overflow an index or exhaust memory whatever the machine) stay.
//!
//! | budget | soft limit | hard limit |
//! |---|---|---|
//! | integration steps of one command (one sweep point) | [`MAX_STEPS`] = 1e9 | [`HARD_MAX_STEPS`] = 1e15 |
//! | stored trajectory samples | [`MAX_SAMPLES`] = 2e7 | [`HARD_MAX_SAMPLES`] = 1e9 |
//! | cases per property of `moreau check` | [`MAX_CASES`] = 1e7 | [`HARD_MAX_CASES`] = 1e10 |
//! | sweep grid points | [`MAX_SWEEP_POINTS`] = 1e6 | `sweep::spec::MAX_POINTS` = 1e7 |
//! | `discover-bench` cases per class | [`MAX_BENCH_CASES`] = 1000 | 1e6 |
//! | convergence ladder levels | - | [`MAX_LEVELS`] = 40 |
//! | rows of a recording (`diagnose`) | [`MAX_RECORDING_ROWS`] = 1e6 | [`HARD_MAX_RECORDING_ROWS`] = 5e7 |
//! | magnitude of a plant entry (`theta`, `simulate`, ...) | [`MAX_PLANT_ENTRY`] = 1e12 | `model::MAX_MAGNITUDE` = 1e100 |
//! | `theta` state dimension n / backlash dimension p | [`THETA_MAX_N`] / [`THETA_MAX_P`] | - |
//! | numbers of a model / of input samples built in memory (Python) | - | [`MAX_MODEL_NUMBERS`] / [`MAX_SAMPLE_NUMBERS`] |
//! | worker threads | the machine's available parallelism (capped with a note) | |
use anyhow::bail;
use std::sync::atomic::{AtomicBool, Ordering};

/// Integration steps one command (or one sweep point) may take without `--allow-large`
/// (about 10 s to a few minutes of the catching-up scheme in a release build).
pub const MAX_STEPS: f64 = 1e9;
/// Integration steps beyond which nothing runs (step counters and time grids lose meaning).
pub const HARD_MAX_STEPS: f64 = 1e15;
/// Trajectory samples kept in memory without `--allow-large`.
pub const MAX_SAMPLES: f64 = 2e7;
/// Trajectory samples beyond which nothing runs.
pub const HARD_MAX_SAMPLES: f64 = 1e9;
/// Cases per property of `moreau check` without `--allow-large`.
pub const MAX_CASES: u64 = 10_000_000;
/// Cases per property beyond which `moreau check` refuses (the campaign keeps one record
/// per 1,024 cases in memory).
pub const HARD_MAX_CASES: u64 = 10_000_000_000;
/// Grid points of a sweep without `--allow-large` (about 7 h of theta evaluations on 2 cores).
pub const MAX_SWEEP_POINTS: usize = 1_000_000;
/// Cases per class of `moreau discover-bench` without `--allow-large` (9 classes, seconds a
/// case: about half a day).
pub const MAX_BENCH_CASES: usize = 1000;
/// Levels of the step ladder of `moreau convergence` (each halves the step).
pub const MAX_LEVELS: usize = 40;
/// Largest state dimension n for which `theta` (and figures and sweeps that assemble it) run
/// without `--allow-large`: the SDPs and tube quadratures grow like n^4 to n^6.
pub const THETA_MAX_N: usize = 12;
/// Largest backlash dimension p for `theta` without `--allow-large`: the certified maxima over
/// the unit sphere of R^p grow exponentially with p.
pub const THETA_MAX_P: usize = 4;

/// Rows of a recording `diagnose` reads without `--allow-large` (each hypothesis simulates
/// and differentiates the whole recording; 1e7 rows took 3.8 GB before it was stopped).
pub const MAX_RECORDING_ROWS: f64 = 1e6;
/// Rows of a recording beyond which nothing runs.
pub const HARD_MAX_RECORDING_ROWS: f64 = 5e7;

/// Largest magnitude of a plant entry (A, B, C, E) without `--allow-large`: beyond it the
/// plant's time scales span more than double precision resolves beside the input period
/// (1e60 made the matrix exponential lose the slow modes and, before it was guarded, hang).
pub const MAX_PLANT_ENTRY: f64 = 1e12;

static ALLOW_LARGE: AtomicBool = AtomicBool::new(false);

/// Sets the `--allow-large` flag for this process.
pub fn set_allow_large(on: bool) {
    ALLOW_LARGE.store(on, Ordering::Relaxed);
}

/// Whether `--allow-large` was given.
pub fn allow_large() -> bool {
    ALLOW_LARGE.load(Ordering::Relaxed)
}

/// A number for a message: integers as they are, other values in short scientific notation.
pub fn num(x: f64) -> String {
    if x.is_finite() && x.fract() == 0.0 && x.abs() < 1e15 {
        return format!("{x}");
    }
    if x != 0.0 && (1e-3..1e6).contains(&x.abs()) {
        return format!("{}", (x * 1e6).round() / 1e6);
    }
    let s = format!("{x:.4e}");
    match s.split_once('e') {
        Some((m, e)) if m.contains('.') => format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.')),
        _ => s,
    }
}

/// Refuses `value` above `soft` (unless `--allow-large`) or above `hard` (always).
/// `what` names the quantity, `detail` how it was estimated.
pub fn check(what: &str, value: f64, soft: f64, hard: f64, detail: &str) -> anyhow::Result<()> {
    let detail = if detail.is_empty() { String::new() } else { format!(" ({detail})") };
    if value.is_nan() || value > hard {
        bail!("{what}: {}{detail} exceeds the hard limit {}", num(value), num(hard));
    }
    if value > soft && !allow_large() {
        bail!("{what}: {}{detail} exceeds the limit {}; pass --allow-large to run it anyway", num(value), num(soft));
    }
    Ok(())
}

/// Integration steps of one command or sweep point.
pub fn steps(command: &str, steps: f64, detail: &str) -> anyhow::Result<()> {
    check(&format!("{command}: integration steps"), steps, MAX_STEPS, HARD_MAX_STEPS, detail)
}

/// Trajectory samples held in memory.
pub fn samples(command: &str, samples: f64, detail: &str) -> anyhow::Result<()> {
    check(&format!("{command}: stored samples"), samples, MAX_SAMPLES, HARD_MAX_SAMPLES, detail)
}

/// Cases per property of `moreau check`.
pub fn cases(cases: u64) -> anyhow::Result<()> {
    check("check: --cases", cases as f64, MAX_CASES as f64, HARD_MAX_CASES as f64, "per property")
}

/// Rows of a recording (data lines of its CSV text, counted before it is parsed).
pub fn recording_rows(source: &str, text: &str) -> anyhow::Result<()> {
    let lines = text.lines().filter(|l| !l.trim().is_empty()).count();
    let rows = lines.saturating_sub(1) as f64;
    check(&format!("diagnose: recording {source}: rows"), rows, MAX_RECORDING_ROWS, HARD_MAX_RECORDING_ROWS, "")
}

/// Magnitudes of the plant's entries against [`MAX_PLANT_ENTRY`]; the message names the
/// largest entry.
pub fn plant_entries(sys: &model::System) -> anyhow::Result<()> {
    let mut largest = (0.0f64, "A", 0, 0);
    for (name, m) in [("A", &sys.A), ("B", &sys.B), ("C", &sys.C), ("E", &sys.E)] {
        for i in 0..m.nrows() {
            for j in 0..m.ncols() {
                if m[(i, j)].abs() > largest.0 {
                    largest = (m[(i, j)].abs(), name, i, j);
                }
            }
        }
    }
    let (value, name, i, j) = largest;
    let what = format!("plant entry {name}[{i}][{j}]: magnitude");
    check(
        &what,
        value,
        MAX_PLANT_ENTRY,
        model::MAX_MAGNITUDE,
        "time scales this far apart are not resolved in double precision; rescale the units",
    )
}

/// Problem size of `theta` (state dimension `n`, backlash dimension `p`).
pub fn theta_size(command: &str, n: usize, p: usize) -> anyhow::Result<()> {
    if allow_large() {
        return Ok(());
    }
    if n > THETA_MAX_N {
        bail!(
            "{command}: state dimension n = {n} exceeds the limit {THETA_MAX_N} for the theta bound (SDPs and tube quadratures grow like n^4 to n^6); pass --allow-large to run it anyway"
        );
    }
    if p > THETA_MAX_P {
        bail!(
            "{command}: backlash dimension p = {p} exceeds the limit {THETA_MAX_P} for the theta bound (certified maxima over the unit sphere of R^p grow exponentially with p); pass --allow-large to run it anyway"
        );
    }
    Ok(())
}

/// The size check of [`theta_size`] for a model file (the file is loaded once more; errors of
/// the file itself are left to the command).
pub fn theta_size_of_file(command: &str, path: &std::path::Path) -> anyhow::Result<()> {
    match model::load(path) {
        Ok(sys) => theta_size(command, sys.n(), sys.p()),
        Err(_) => Ok(()),
    }
}

/// Worker threads: at least 1, at most the machine's available parallelism (a larger request
/// is capped, with a note on stderr).
pub fn threads(requested: usize) -> anyhow::Result<usize> {
    if requested == 0 {
        bail!("--threads 0: need at least 1");
    }
    let cores = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    if requested > cores {
        eprintln!("note: --threads {requested} capped at {cores} (the machine's available parallelism)");
        return Ok(cores);
    }
    Ok(requested)
}

/// The step `dt` against the input period and final time ([`model::check_step`]) as a CLI error.
pub fn step(dt: f64, sys: &model::System, t_end: Option<f64>, key: &str) -> anyhow::Result<()> {
    model::check_step(dt, sys.period(), t_end, key)?;
    Ok(())
}

/// Numbers (matrix and vector entries) of a model built in memory (the Python package's
/// `System`, `Polytope`, ...): as many as the largest model file the CLI reads holds
/// ([`model::files::MAX_MODEL_BYTES`], 16 MiB) at 16 bytes a number. A 3000 x 3000 `A` (9e6
/// numbers, gigabytes once converted) is refused before it is converted. No `--allow-large`
/// lifts it, as none lifts the model-file limit.
pub const MAX_MODEL_NUMBERS: u64 = model::files::MAX_MODEL_BYTES / 16;
/// Numbers of an input given as sample arrays (`t` and `w`): as many as the largest input
/// CSV ([`model::files::MAX_CSV_BYTES`], 512 MiB) holds at 16 bytes a number.
pub const MAX_SAMPLE_NUMBERS: u64 = model::files::MAX_CSV_BYTES / 16;

/// Refuses a model of more than [`MAX_MODEL_NUMBERS`] numbers (`detail`: which arrays).
pub fn model_numbers(numbers: u64, detail: &str) -> anyhow::Result<()> {
    numbers_of_a_file("model", numbers, detail, "model file", model::files::MAX_MODEL_BYTES)
}

/// Refuses input samples of more than [`MAX_SAMPLE_NUMBERS`] numbers (`detail`: which arrays).
pub fn sample_numbers(numbers: u64, detail: &str) -> anyhow::Result<()> {
    numbers_of_a_file("input samples", numbers, detail, "input CSV", model::files::MAX_CSV_BYTES)
}

/// Refuses more numbers than the largest `file` (of `bytes`) holds at 16 bytes a number.
fn numbers_of_a_file(what: &str, numbers: u64, detail: &str, file: &str, bytes: u64) -> anyhow::Result<()> {
    let limit = bytes / 16;
    if numbers > limit {
        bail!(
            "{what}: {numbers} numbers ({detail}) exceed the limit {limit}, what the largest {file} ({} MiB) holds at 16 bytes a number",
            bytes >> 20
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_name_value_and_limit() {
        let e = steps("simulate", 1e12, "t_end 1e9 / dt 1e-3").unwrap_err().to_string();
        assert!(e.contains("1000000000000") && e.contains("limit 1000000000;") && e.contains("--allow-large"), "{e}");
        assert_eq!(num(1.2566370614359173e302), "1.2566e302");
        assert_eq!(num(0.001), "0.001");
        let e = steps("simulate", 1e300, "").unwrap_err().to_string();
        assert!(e.contains("hard limit"), "{e}");
        assert!(steps("simulate", 1e6, "").is_ok());
        assert!(cases(1_000_000).is_ok());
        assert!(cases(1_000_000_000_000).is_err());
        assert!(theta_size("theta", 200, 1).unwrap_err().to_string().contains("n = 200"));
        assert!(threads(0).is_err());
        // recordings: rows counted before parsing (header and blank lines not counted)
        let rows = |k: usize| format!("t,w,y\n{}\n", "0,0,0\n".repeat(k));
        assert!(recording_rows("r.csv", &rows(1_000_000)).is_ok());
        let e = recording_rows("r.csv", &rows(1_000_001)).unwrap_err().to_string();
        assert!(e.contains("rows: 1000001") && e.contains("--allow-large"), "{e}");
        assert!(threads(100_000).unwrap() >= 1);
    }
}

#[cfg(test)]
mod model_size_tests {
    use super::*;

    #[test]
    fn model_and_sample_numbers_name_value_and_limit() {
        assert_eq!(MAX_MODEL_NUMBERS, 1_048_576);
        assert!(model_numbers(MAX_MODEL_NUMBERS, "A").is_ok());
        let e = model_numbers(9_000_000, "`plant.A` of shape (3000, 3000)").unwrap_err().to_string();
        assert!(e.contains("9000000 numbers (`plant.A` of shape (3000, 3000))") && e.contains("limit 1048576"), "{e}");
        assert!(sample_numbers(MAX_SAMPLE_NUMBERS, "t").is_ok());
        assert!(sample_numbers(MAX_SAMPLE_NUMBERS + 1, "t").unwrap_err().to_string().contains("input samples"));
    }
}
