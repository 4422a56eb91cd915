//! `moreau sweep SPEC --out DIR [--shard K/N] [--threads N] [--digits D]`
use crate::sweep::theta_eval::ThetaEvaluator;
use crate::sweep::{RunOptions, Shard, SweepSpec};
use anyhow::Context;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, clap::Args)]
#[command(after_help = "Examples:
  moreau sweep examples/sweeps/amplitude.toml --out out/amplitude
  moreau sweep examples/sweeps/amplitude.toml --out out/shard1 --shard 1/4   # one task of a job array
  moreau merge out/shard* --out out/amplitude                                  # then join the shards

Spec file reference (every key, axis, range, column, output file, limit): docs/sweep-spec.md")]
pub struct Args {
    /// Sweep specification (TOML): base model, axes, [evaluate], [table].
    pub spec: PathBuf,
    /// Output directory: sweep.{csv,json,md,tex} (or sweep-shard-K-of-N.* with --shard).
    /// Points already there (same spec) are not recomputed.
    #[arg(long)]
    pub out: PathBuf,
    /// Compute only shard K of N (K = 0..N-1, round robin over the points); join with `moreau merge`.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<String>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Significant digits in the Markdown and LaTeX tables (default: the spec's, else 4).
    #[arg(long)]
    pub digits: Option<usize>,
    /// Replace results of a different spec found in --out instead of refusing.
    #[arg(long)]
    pub overwrite: bool,
    /// Recompute every point, ignoring earlier results of the same spec in --out (after a
    /// change of the program: the spec hash covers inputs and settings, not the code).
    #[arg(long)]
    pub fresh: bool,
    /// Recompute points whose earlier evaluation failed.
    #[arg(long)]
    pub retry_failed: bool,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Work of a sweep estimated before any point is evaluated: grid points, theta's problem size
/// and, per point, the steps of the measured side (`[evaluate] dt, periods, pairs`) at the
/// longest input period of the grid; `dt` against the shortest one.
fn check_budget(spec: &SweepSpec, ev: &ThetaEvaluator) -> anyhow::Result<()> {
    let points = spec.axes.iter().fold(1f64, |acc, a| acc * a.values.len() as f64);
    crate::budget::check(
        "sweep: grid points",
        points,
        crate::budget::MAX_SWEEP_POINTS as f64,
        crate::sweep::spec::MAX_POINTS as f64,
        "",
    )?;
    crate::budget::theta_size("sweep", spec.base.n(), spec.base.p())?;
    let Some(rate) = &ev.settings.measure else { return Ok(()) };
    let Some(base_T) = spec.base.period() else { return Ok(()) };
    let omegas: Vec<f64> = spec
        .axes
        .iter()
        .filter(|a| a.parameter == crate::sweep::axis::Parameter::InputOmega)
        .flat_map(|a| a.values.iter().copied())
        .collect();
    let periods: Vec<f64> =
        if omegas.is_empty() { vec![base_T] } else { omegas.iter().map(|w| std::f64::consts::TAU / w).collect() };
    let t_min = periods.iter().copied().fold(f64::INFINITY, f64::min);
    let t_max = periods.iter().copied().fold(0.0, f64::max);
    model::check_step(rate.dt, Some(t_min), None, "evaluate.dt").with_context(|| spec.path.display().to_string())?;
    crate::budget::steps(
        "sweep: per point",
        (t_max / rate.dt).ceil() * rate.periods as f64 * (2 * rate.pairs) as f64,
        &format!(
            "[evaluate] periods = {}, pairs = {}, dt = {}, T up to {}",
            rate.periods,
            rate.pairs,
            crate::budget::num(rate.dt),
            crate::budget::num(t_max)
        ),
    )
}

pub fn run(a: &Args) -> anyhow::Result<ExitCode> {
    let shard = a.shard.as_deref().map(Shard::parse).transpose()?;
    let threads = a.threads.map(crate::budget::threads).transpose()?;
    let spec = SweepSpec::load(&a.spec).with_context(|| a.spec.display().to_string())?;
    let evaluator = ThetaEvaluator::from_table(&spec.evaluate, &spec.path)?;
    check_budget(&spec, &evaluator)?;
    let opts = RunOptions {
        out: a.out.clone(),
        shard,
        threads,
        progress: !a.quiet,
        overwrite: a.overwrite,
        fresh: a.fresh,
        retry_failed: a.retry_failed,
        digits: a.digits,
    };
    let s = crate::sweep::run(&spec, &evaluator, &opts)?;
    eprintln!(
        "sweep `{}`: {} points in scope, {} resumed, {} computed, {} failed; spec hash {}",
        spec.name, s.in_scope, s.resumed, s.computed, s.failed, s.result.spec_hash
    );
    for f in &s.files {
        println!("{}", f.display());
    }
    Ok(if s.failed == 0 { ExitCode::SUCCESS } else { ExitCode::from(1) })
}
