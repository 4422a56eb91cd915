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
    let Simulation { sys, trajectory: tr, method: what, steps, every, .. } =
        simulate(&Source::File(a.file.clone()), &o)?;
    let csv = tr.to_csv(&sys.C);
    let plot = simulation_figure(&sys, &tr, &what);
    let svg = canvas::to_svg(&plot)?;
    std::fs::write(stage.path("trajectory.csv"), csv)?;
    std::fs::write(stage.path("trajectory.svg"), svg)?;
    canvas::write_png(&plot, &stage.path("trajectory.png"))?;
    stage.commit()?;
    println!(
        "{}: {} samples up to t = {:.6} ({what}){} -> {}",
        sys.name,
        tr.len(),
        tr.t.last().copied().unwrap_or(0.0),
        thinned(steps, every, a.max_rows),
        a.out.display()
    );
    Ok(ExitCode::SUCCESS)
}

/// What `--max-rows` dropped, for the summary line: `, kept every 8th of 143,000 steps
/// (--max-rows 20000)`, or nothing when every step is kept.
fn thinned(steps: usize, every: usize, max_rows: usize) -> String {
    if every <= 1 {
        return String::new();
    }
    let suffix = match (every % 10, every % 100) {
        (_, 11..=13) => "th",
        (1, _) => "st",
        (2, _) => "nd",
        (3, _) => "rd",
        _ => "th",
    };
    let digits = steps.to_string();
    let mut grouped = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            grouped.push(',');
        }
        grouped.push(c);
    }
    format!(", kept every {every}{suffix} of {grouped} steps (--max-rows {max_rows})")
}

#[cfg(test)]
mod tests {
    use super::thinned;

    #[test]
    fn the_summary_says_what_max_rows_dropped() {
        assert_eq!(thinned(143_000, 8, 20000), ", kept every 8th of 143,000 steps (--max-rows 20000)");
        assert_eq!(thinned(999, 2, 500), ", kept every 2nd of 999 steps (--max-rows 500)");
        assert_eq!(thinned(1_000_000, 21, 50000), ", kept every 21st of 1,000,000 steps (--max-rows 50000)");
        assert_eq!(thinned(5000, 12, 500), ", kept every 12th of 5,000 steps (--max-rows 500)");
        assert_eq!(thinned(5000, 1, 20000), "");
    }
}
