//! `moreau simulate FILE [--periods N] [--dt H] [--integrator catching-up|event] --out DIR`
use crate::commands::simulate::{simulate, Integrator, SimulateOptions, Simulation};
use crate::commands::Source;
use crate::figures::canvas;
use crate::figures::trajectory::simulation_figure;
use crate::output::StagedDir;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, clap::Args)]
#[command(after_help = "Examples:
  moreau simulate examples/worked-example.toml --out out/sim      # trajectory.csv + plots
  moreau simulate examples/lens-p2.toml --periods 5 --dt 1e-4 --out out/lens")]
pub struct Args {
    /// Model file (TOML).
    pub file: PathBuf,
    /// Number of input periods (default: `simulation.periods` of the file). Periodic inputs only.
    #[arg(long)]
    pub periods: Option<usize>,
    /// Time step (default: `simulation.dt`); for periodic inputs `T / ceil(T / dt)` is used.
    #[arg(allow_negative_numbers = true, long)]
    pub dt: Option<f64>,
    #[arg(long, value_enum, default_value = "catching-up")]
    pub integrator: Integrator,
    /// Keep at most this many rows in trajectory.csv (every k-th step). Default 20000.
    #[arg(long, default_value_t = 20_000)]
    pub max_rows: usize,
    /// Output directory (trajectory.csv, trajectory.svg, trajectory.png).
    #[arg(long)]
    pub out: PathBuf,
}

pub fn run(a: &Args) -> anyhow::Result<ExitCode> {
    let o = SimulateOptions {
        periods: a.periods,
        dt: a.dt,
        t_end: None,
        integrator: a.integrator,
        max_rows: Some(a.max_rows),
    };
    let stage = StagedDir::replacing(&a.out)?;
    let Simulation { sys, trajectory: tr, method: what, .. } = simulate(&Source::File(a.file.clone()), &o)?;
    let csv = tr.to_csv(&sys.C);
    let plot = simulation_figure(&sys, &tr, &what);
    let svg = canvas::to_svg(&plot)?;
    std::fs::write(stage.path("trajectory.csv"), csv)?;
    std::fs::write(stage.path("trajectory.svg"), svg)?;
    canvas::write_png(&plot, &stage.path("trajectory.png"))?;
    stage.commit()?;
    println!(
        "{}: {} samples up to t = {:.6} ({what}) -> {}",
        sys.name,
        tr.len(),
        tr.t.last().copied().unwrap_or(0.0),
        a.out.display()
    );
    Ok(ExitCode::SUCCESS)
}
