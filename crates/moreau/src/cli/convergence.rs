//! `moreau convergence FILE [--h0 H] [--levels L] [--periods N]`: error of the catching-up
//! scheme against the event-driven reference for a ladder of steps, and the fitted order (a
//! model with `[[effects]]`: the extended-model simulator against its own finest step).
use crate::budget::num;
use crate::commands::convergence::{plan, ConvergenceOptions};
use crate::commands::Source;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, clap::Args)]
#[command(after_help = "Examples:
  moreau convergence examples/worked-example.toml --levels 6")]
pub struct Args {
    /// Model file (TOML); Theta an interval, ball or ellipsoid; zero or sine input.
    pub file: PathBuf,
    /// Largest step of the ladder.
    #[arg(allow_negative_numbers = true, long, default_value_t = 1e-2)]
    pub h0: f64,
    /// Number of steps in the ladder (each half the previous).
    #[arg(long, default_value_t = 6)]
    pub levels: usize,
    /// Horizon in input periods (default: `simulation.periods`; non-periodic: `simulation.t_end` or 20).
    #[arg(long)]
    pub periods: Option<usize>,
}

pub fn run(a: &Args) -> anyhow::Result<ExitCode> {
    let o = ConvergenceOptions { h0: a.h0, levels: a.levels, periods: a.periods };
    let plan = plan(&Source::File(a.file.clone()), &o)?;
    // progress: the study runs as one call, so a spinner with the elapsed time and the work
    // it does (indicatif draws nothing when stderr is not a terminal)
    let bar = indicatif::ProgressBar::new_spinner();
    bar.set_style(
        indicatif::ProgressStyle::with_template("{spinner} [{elapsed_precise}] {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner()),
    );
    bar.set_message(format!(
        "{} levels from h0 = {} and the reference: {} steps in all",
        a.levels,
        num(a.h0),
        num(plan.total_steps)
    ));
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    let s = plan.run();
    bar.finish_and_clear();
    let s = s?;
    let sys = &plan.sys;
    if sys.effects.list.is_empty() {
        println!("{}: catching-up vs event-driven reference over [0, {:.6}] ({} events)", sys.name, s.t_end, s.events);
    } else {
        let kinds: Vec<&str> = sys.effects.list.iter().map(|e| e.kind()).collect();
        println!(
            "{}: extended-model simulator (effects: {}) vs itself at step h_min/2 over [0, {:.6}] (no event-driven reference exists for effects)",
            sys.name,
            kinds.join(", "),
            s.t_end
        );
    }
    println!("  {:>12}  {:>12}  {:>8}", "h", "max error", "ratio");
    for i in 0..s.h.len() {
        let r = if i > 0 { format!("{:.3}", s.error[i - 1] / s.error[i]) } else { String::new() };
        println!("  {:>12.4e}  {:>12.4e}  {:>8}", s.h[i], s.error[i], r);
    }
    println!("  fitted order (slope of ln error vs ln h): {:.3}", s.order);
    Ok(ExitCode::SUCCESS)
}
