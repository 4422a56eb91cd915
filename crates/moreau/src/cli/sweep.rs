//! `moreau sweep SPEC --out DIR [--shard K/N] [--threads N] [--digits D]`
use crate::commands::sweep::{sweep, SweepOptions, SweepRun};
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

pub fn run(a: &Args) -> anyhow::Result<ExitCode> {
    let o = SweepOptions {
        spec: a.spec.clone(),
        out: a.out.clone(),
        shard: a.shard.clone(),
        threads: a.threads,
        digits: a.digits,
        overwrite: a.overwrite,
        fresh: a.fresh,
        retry_failed: a.retry_failed,
        progress: !a.quiet,
    };
    let SweepRun { name, summary: s, .. } = sweep(&o)?;
    eprintln!(
        "sweep `{}`: {} points in scope, {} resumed, {} computed, {} failed; spec hash {}",
        name, s.in_scope, s.resumed, s.computed, s.failed, s.result.spec_hash
    );
    for f in &s.files {
        println!("{}", f.display());
    }
    Ok(if s.failed == 0 { ExitCode::SUCCESS } else { ExitCode::from(1) })
}
