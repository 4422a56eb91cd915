//! `sweep`: theta, its parts and the measured rate over a grid of parameters (a TOML spec),
//! parallel and resumable, one shard of a job array with `shard`; writes the table as CSV,
//! JSON, Markdown and LaTeX. Budgets (in [`check_budget`]): grid points, theta's problem size
//! and the integration steps per point.
use crate::sweep::theta_eval::ThetaEvaluator;
use crate::sweep::{RunOptions, RunSummary, Shard, SweepSpec};
use anyhow::Context;
use std::path::PathBuf;

/// Options of `sweep` (the CLI's arguments).
#[derive(Debug, Clone)]
pub struct SweepOptions {
    /// Sweep specification (TOML).
    pub spec: PathBuf,
    /// Output directory.
    pub out: PathBuf,
    /// Shard `K/N` of a job array.
    pub shard: Option<String>,
    /// Worker threads (default: all cores).
    pub threads: Option<usize>,
    /// Significant digits of the Markdown and LaTeX tables.
    pub digits: Option<usize>,
    /// Replace results of a different spec found in `out`.
    pub overwrite: bool,
    /// Recompute every point.
    pub fresh: bool,
    /// Recompute points whose earlier evaluation failed.
    pub retry_failed: bool,
    /// Draw a progress bar on stderr.
    pub progress: bool,
}

/// The result of `sweep`: the spec's name, the shard and the run's summary.
pub struct SweepRun {
    pub name: String,
    pub shard: Option<Shard>,
    pub summary: RunSummary,
}

/// Work of a sweep estimated before any point is evaluated: grid points, theta's problem size
/// and, per point, the steps of the measured side (`[evaluate] dt, periods, pairs`) at the
/// longest input period of the grid; `dt` against the shortest one.
pub fn check_budget(spec: &SweepSpec, ev: &ThetaEvaluator) -> anyhow::Result<()> {
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

/// Validates the options, loads the spec, checks the budget, runs.
pub fn sweep(o: &SweepOptions) -> anyhow::Result<SweepRun> {
    let shard = o.shard.as_deref().map(Shard::parse).transpose()?;
    let threads = o.threads.map(crate::budget::threads).transpose()?;
    let spec = SweepSpec::load(&o.spec).with_context(|| o.spec.display().to_string())?;
    let evaluator = ThetaEvaluator::from_table(&spec.evaluate, &spec.path)?;
    check_budget(&spec, &evaluator)?;
    let opts = RunOptions {
        out: o.out.clone(),
        shard,
        threads,
        progress: o.progress,
        overwrite: o.overwrite,
        fresh: o.fresh,
        retry_failed: o.retry_failed,
        digits: o.digits,
    };
    let summary = crate::sweep::run(&spec, &evaluator, &opts)?;
    Ok(SweepRun { name: spec.name.clone(), shard, summary })
}
