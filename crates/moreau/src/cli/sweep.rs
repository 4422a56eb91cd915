//! `moreau sweep SPEC --out DIR [--shard K/N] [--threads N] [--digits D]`
use crate::sweep::theta_eval::ThetaEvaluator;
use crate::sweep::{RunOptions, Shard, SweepSpec};
use anyhow::Context;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, clap::Args)]
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

pub fn run(a: &Args) -> anyhow::Result<ExitCode> {
    let shard = a.shard.as_deref().map(Shard::parse).transpose()?;
    if let Some(t) = a.threads {
        anyhow::ensure!(t >= 1, "--threads {t}: need at least 1");
    }
    let spec = SweepSpec::load(&a.spec).with_context(|| format!("sweep spec {}", a.spec.display()))?;
    let evaluator = ThetaEvaluator::from_table(&spec.evaluate, &spec.path)?;
    let opts = RunOptions {
        out: a.out.clone(),
        shard,
        threads: a.threads,
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
