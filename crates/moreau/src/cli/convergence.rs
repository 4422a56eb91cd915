//! `moreau convergence FILE [--h0 H] [--levels L] [--periods N]`: error of the catching-up
//! scheme against the event-driven reference for a ladder of steps, and the fitted order (a
//! model with `[[effects]]`: the extended-model simulator against its own finest step).
use crate::budget::num;
use anyhow::{bail, Context};
use dynamics::convergence::{convergence_study, ConvergenceSettings};
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
    let sys = model::load(&a.file).with_context(|| a.file.display().to_string())?;
    if !(a.h0 > 0.0 && a.h0.is_finite()) {
        bail!("--h0 must be positive and finite, got {}", a.h0);
    }
    if a.periods == Some(0) {
        bail!("--periods must be at least 1, got 0");
    }
    if a.levels > crate::budget::MAX_LEVELS {
        bail!("--levels {}: more than {} levels (each halves the step)", a.levels, crate::budget::MAX_LEVELS);
    }
    let t_end = match sys.period() {
        Some(T) => a.periods.unwrap_or(sys.sim.periods) as f64 * T,
        None => sys.sim.t_end.unwrap_or(20.0),
    };
    crate::budget::step(a.h0, &sys, Some(t_end), "--h0")?;
    // the ladder: t_end / h0 steps at the coarsest level, doubling per level, plus a reference
    // as fine as the finest level; every level stores t_end / h0 samples
    let n0 = (t_end / a.h0).ceil();
    let levels = a.levels as i32;
    crate::budget::steps(
        "convergence",
        n0 * (2f64.powi(levels) - 1.0 + 2f64.powi(levels)),
        &format!("t_end = {}, h0 = {}, {} levels", num(t_end), num(a.h0), a.levels),
    )?;
    crate::budget::samples(
        "convergence",
        n0 * (a.levels + 1) as f64 * (sys.n() + sys.p()) as f64,
        "numbers stored per level",
    )?;
    // progress: the study runs as one call, so a spinner with the elapsed time and the work
    // it does (indicatif draws nothing when stderr is not a terminal)
    let total_steps = n0 * (2f64.powi(levels) - 1.0 + 2f64.powi(levels));
    let bar = indicatif::ProgressBar::new_spinner();
    bar.set_style(
        indicatif::ProgressStyle::with_template("{spinner} [{elapsed_precise}] {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_spinner()),
    );
    bar.set_message(format!(
        "{} levels from h0 = {} and the reference: {} steps in all",
        a.levels,
        num(a.h0),
        num(total_steps)
    ));
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    let s = convergence_study(&sys, &ConvergenceSettings { h0: a.h0, levels: a.levels, t_end });
    bar.finish_and_clear();
    let s = s?;
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
