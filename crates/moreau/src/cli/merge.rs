//! `moreau merge SHARD... --out DIR`: joins the shards of one sweep.
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, clap::Args)]
#[command(after_help = "Examples:
  moreau merge out/shard1 out/shard2 out/shard3 out/shard4 --out out/amplitude")]
pub struct Args {
    /// Shard result files (sweep-shard-K-of-N.json) or directories holding them (every
    /// `*.json` file of a directory is read: each must be a result of the same sweep).
    #[arg(required = true)]
    pub inputs: Vec<PathBuf>,
    /// Output directory: sweep.{csv,json,md,tex}.
    #[arg(long)]
    pub out: PathBuf,
    /// Merge even if points are missing (the tables say how many).
    #[arg(long)]
    pub partial: bool,
    /// Significant digits in the Markdown and LaTeX tables (default: as in the shards).
    #[arg(long)]
    pub digits: Option<usize>,
}

pub fn run(a: &Args) -> anyhow::Result<ExitCode> {
    let (m, files) = crate::sweep::merge::merge_into(&a.inputs, &a.out, a.partial, a.digits)?;
    let failed = m.points.iter().filter(|p| !p.ok()).count();
    eprintln!(
        "merged `{}`: {} of {} points, {} failed; spec hash {}",
        m.name,
        m.points.len(),
        m.total_points,
        failed,
        m.spec_hash
    );
    for f in &files {
        println!("{}", f.display());
    }
    Ok(ExitCode::SUCCESS)
}
