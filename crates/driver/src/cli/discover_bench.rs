//! `moreau discover-bench --cases N --seed S`: the concealed-effect benchmark of `discovery`
//! (N cases of each of the 9 classes: none and the 8 effects), printing the confusion matrix,
//! the false-alarm rate on `none` and the parameter errors.
use anyhow::Context;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Cases per class.
    #[arg(long, default_value_t = 8)]
    pub cases: usize,
    /// Seed of the generator.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Also write every case's result as JSON here.
    #[arg(long)]
    pub json: Option<PathBuf>,
}

pub fn run(a: &Args) -> anyhow::Result<ExitCode> {
    if a.cases == 0 {
        anyhow::bail!("--cases must be at least 1 (got 0)");
    }
    let r = discovery::bench::run(a.cases, a.seed, &Default::default(), |c| {
        eprintln!("{:>18} #{:<3} -> {:<34} {} ({:.1} s)", c.class, c.index, c.selected, c.error.as_deref().unwrap_or(""), c.seconds);
    });
    println!("{}", r.to_text());
    if let Some(p) = &a.json {
        crate::output::write_atomic(p, serde_json::to_string_pretty(&r)?.as_bytes()).with_context(|| format!("writing {}", p.display()))?;
    }
    Ok(ExitCode::SUCCESS)
}
