//! `moreau simulate FILE [--periods N] [--dt H] [--integrator catching-up|event] --out DIR`
use crate::output::StagedDir;
use crate::plot::{to_svg_string, write_png, LinePlot, Series};
use anyhow::{bail, Context};
use dynamics::integrators::event_driven::{event_driven, EventDrivenSettings};
use dynamics::trajectory::simulate_model;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Integrator {
    /// Moreau's catching-up scheme with the exact linear step (any Theta); models with
    /// `[[effects]]` run on the extended-model simulator.
    CatchingUp,
    /// Event-driven reference (interval, ball, ellipsoid; zero or sine input).
    Event,
}

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
    let sys = model::load(&a.file).with_context(|| a.file.display().to_string())?;
    let dt = a.dt.unwrap_or(sys.sim.dt);
    if !(dt > 0.0 && dt.is_finite()) {
        bail!("--dt must be positive and finite, got {dt}");
    }
    if a.dt.is_some() {
        crate::budget::step(dt, &sys, sys.sim.t_end.filter(|_| sys.period().is_none()), "--dt")?;
    }
    let periods = a.periods.unwrap_or(sys.sim.periods);
    if periods == 0 {
        bail!("--periods must be at least 1, got 0");
    }
    if a.max_rows < 2 {
        bail!("--max-rows must be at least 2, got {}", a.max_rows);
    }
    let (t_end, h) = match sys.period() {
        Some(T) => {
            crate::budget::steps(
                "simulate",
                periods as f64 * (T / dt).ceil(),
                &format!(
                    "{} periods of T = {} at dt = {}",
                    crate::budget::num(periods as f64),
                    crate::budget::num(T),
                    crate::budget::num(dt)
                ),
            )?;
            let (n, h) = dynamics::periodic::steps_per_period(T, dt)?;
            (periods as f64 * n as f64 * h, h)
        }
        None => {
            if a.periods.is_some() {
                bail!(
                    "--periods needs a periodic input; `{}` has input `{}` (set simulation.t_end instead)",
                    a.file.display(),
                    sys.input.kind()
                );
            }
            (sys.sim.t_end.unwrap_or(100.0), dt)
        }
    };
    crate::budget::steps(
        "simulate",
        (t_end / h).round(),
        &format!("t_end = {} at dt = {}", crate::budget::num(t_end), crate::budget::num(h)),
    )?;
    let steps = (t_end / h).round().max(1.0) as usize;
    let rows = (steps as f64).min(a.max_rows as f64);
    crate::budget::samples(
        "simulate",
        rows * (1 + sys.n() + sys.m() + 2 * sys.p()) as f64,
        "numbers in trajectory.csv, --max-rows",
    )?;
    let every = steps.div_ceil(a.max_rows).max(1);
    let effects: Vec<&str> = sys.effects.list.iter().map(|e| e.kind()).collect();
    let (tr, what) = match a.integrator {
        Integrator::CatchingUp if effects.is_empty() => (
            simulate_model(&sys, h, steps, every)?,
            format!("catching-up, h = {h:e}"),
        ),
        Integrator::CatchingUp => (
            simulate_model(&sys, h, steps, every)?,
            format!("extended model with {}, h = {h:e}", effects.join(", ")),
        ),
        Integrator::Event if !effects.is_empty() => bail!(
            "--integrator event simulates the paper's class only; `{}` has effects ({}): use --integrator catching-up (the extended-model simulator)",
            a.file.display(),
            effects.join(", ")
        ),
        Integrator::Event => {
            let (tr, events) = event_driven(
                &sys,
                &EventDrivenSettings {
                    dt_out: h * every as f64,
                    t_end: (steps / every) as f64 * every as f64 * h,
                    ..Default::default()
                },
            )?;
            (tr, format!("event-driven, {events} events"))
        }
    };
    let csv = tr.to_csv(&sys.C);
    let mut series = Vec::new();
    for j in 0..sys.m() {
        series.push(Series {
            label: format!("w{}", j + 1),
            x: tr.t.clone(),
            y: (0..tr.len()).map(|i| tr.w_at(i)[j]).collect(),
        });
    }
    for j in 0..sys.p() {
        series.push(Series {
            label: format!("y{}", j + 1),
            x: tr.t.clone(),
            y: (0..tr.len()).map(|i| tr.y_at(&sys.C, i)[j]).collect(),
        });
        series.push(Series {
            label: format!("z{}", j + 1),
            x: tr.t.clone(),
            y: (0..tr.len()).map(|i| tr.z_at(i)[j]).collect(),
        });
    }
    let plot = LinePlot {
        title: format!("{} ({what})", sys.name),
        x_label: "t".into(),
        y_label: "w, y, z".into(),
        series,
        windows: vec![],
        size: (0, 0),
    };
    let svg = to_svg_string(&plot)?;
    let stage = StagedDir::new(&a.out)?;
    std::fs::write(stage.path("trajectory.csv"), csv)?;
    std::fs::write(stage.path("trajectory.svg"), svg)?;
    write_png(&plot, &stage.path("trajectory.png"))?;
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
