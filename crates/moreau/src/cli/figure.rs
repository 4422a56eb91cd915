//! `moreau figure psi|tube|trajectory|sweep INPUT --out DIR`
use crate::figures::{self, trajectory::TrajectorySettings, Figure};
use crate::sweep::SweepResult;
use anyhow::Context;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Kind {
    /// Fig. psi1: psi(gamma) with psi(0), psi(gamma_inf), the limit -lambda and the chord (theta), and the sharper certified bounds (theta_star, the best beyond the paper) as levels. INPUT: model file.
    Psi,
    /// Fig. loop: the orbit eta_T, the tube eta_T + C Xi_inf + Theta, the simulated periodic z. INPUT: model file.
    Tube,
    /// y, z and x against time. INPUT: model file.
    Trajectory,
    /// Columns of a sweep against a swept parameter. INPUT: sweep.json (or its directory).
    Sweep,
}

#[derive(Debug, clap::Args)]
#[command(after_help = "Examples:
  moreau figure psi examples/worked-example.toml --out out/figs     # fig-psi1.{svg,png,tex,csv}
  moreau figure tube examples/ellipse-p2.toml --out out/figs        # fig-loop
  moreau figure sweep out/amplitude --columns theta,measured_rate --out out/figs
  moreau figure psi examples/worked-example.toml --format pgf --no-title --out paper/figs
  moreau figure psi examples/worked-example.toml --size column --format pdf --no-title --out paper/figs")]
pub struct Args {
    /// Which figure.
    #[arg(value_enum)]
    pub kind: Kind,
    /// Model file (psi, tube, trajectory) or sweep result (sweep: sweep.json or its directory).
    pub input: PathBuf,
    /// Output directory (fig-psi1, fig-loop, trajectory-yz/-x or sweep-<columns>, each .svg and .png).
    #[arg(long)]
    pub out: PathBuf,
    /// sweep: numeric columns to draw (default: those of theta, theta_best, measured_rate the
    /// sweep has), all on one y axis.
    #[arg(long, value_delimiter = ',')]
    pub columns: Vec<String>,
    /// sweep: the axis on the horizontal axis (default: the first).
    #[arg(long)]
    pub x: Option<String>,
    /// trajectory: final time (default: the model's periods, or t_end).
    #[arg(allow_negative_numbers = true, long)]
    pub t_end: Option<f64>,
    /// Output formats (comma separated): svg, png, pgf (pgfplots .tex + data .csv), pdf (vector,
    /// font embedded). Default: svg,png,pgf.
    #[arg(long, value_enum, value_delimiter = ',', default_value = "svg,png,pgf")]
    pub format: Vec<figures::Format>,
    /// PNG resolution in dots per inch: the SVG rasterised at scale dpi/96, so text and lines
    /// scale with the image (e.g. `--dpi 300` for print). Default: plotters' bitmap at
    /// --width x --height pixels.
    #[arg(allow_negative_numbers = true, long)]
    pub dpi: Option<f64>,
    /// Size preset for papers, in points (one SVG unit is a point in the PDF): `column` 252 x
    /// 216 (3.5 in wide), `two-column` 515 x 258 (7.16 in); text 8-9 pt, the legend below the
    /// axes. --width and --height override either side.
    #[arg(long, value_enum)]
    pub size: Option<figures::canvas::SizePreset>,
    /// Width of the SVG, PDF (points) and PNG (pixels at 96 dpi). Default 900, or the --size
    /// preset's (the pgf code takes the paper's line width).
    #[arg(long)]
    pub width: Option<u32>,
    /// Height, as --width. Default 600, or the --size preset's.
    #[arg(long)]
    pub height: Option<u32>,
    /// No title above the plot (a paper's caption replaces it).
    #[arg(long)]
    pub no_title: bool,
    /// trajectory: time step (default: the model's dt).
    #[arg(allow_negative_numbers = true, long)]
    pub dt: Option<f64>,
}

pub fn run(a: &Args) -> anyhow::Result<ExitCode> {
    for f in write(a)? {
        println!("{}", f.display());
    }
    Ok(ExitCode::SUCCESS)
}

/// The figures of `a`, written: the files (what `run` prints; the Python package's `figure`).
pub fn write(a: &Args) -> anyhow::Result<Vec<PathBuf>> {
    // options and the output folder are checked before the work
    let (width, height) = checked_options(a)?;
    let figs = match a.kind {
        Kind::Sweep => sweep_figures(a)?,
        Kind::Trajectory => trajectory_figures(a, &model_file(a)?)?,
        Kind::Psi => psi_figures(&model_file(a)?)?,
        Kind::Tube => tube_figures(&model_file(a)?)?,
    };
    let figs: Vec<(String, Figure)> = figs
        .into_iter()
        .map(|(stem, mut f)| {
            f.size = (width, height);
            if a.no_title {
                f.title.clear();
            }
            (stem, f)
        })
        .collect();
    Ok(figures::write_figure_with(&figs, &a.out, &a.format, a.dpi)?)
}

/// The figure's size (pixels at 96 dpi) from --size, --width, --height, with the other options
/// checked and the output folder writable.
fn checked_options(a: &Args) -> anyhow::Result<(u32, u32)> {
    let preset = a.size.map_or((900, 600), |s| s.size());
    let (width, height) = (a.width.unwrap_or(preset.0), a.height.unwrap_or(preset.1));
    anyhow::ensure!(
        (200..=8000).contains(&width) && (150..=8000).contains(&height),
        "--width {width} --height {height}: must be within 200..8000 x 150..8000 pixels"
    );
    if let Some(dpi) = a.dpi {
        figures::canvas::png_size((width, height), dpi).map_err(anyhow::Error::msg)?;
    }
    crate::output::register_input(&a.input);
    crate::output::check_directory_writable(&a.out)?;
    for (name, v) in [("--t-end", a.t_end), ("--dt", a.dt)] {
        if let Some(v) = v {
            anyhow::ensure!(v > 0.0 && v.is_finite(), "{name} {v}: must be positive and finite");
        }
    }
    Ok((width, height))
}

/// `figure sweep`: the chosen columns (default theta, theta_best and the measured exponent,
/// those the sweep has) of a sweep result.
fn sweep_figures(a: &Args) -> anyhow::Result<Vec<(String, Figure)>> {
    let path = if a.input.is_dir() { a.input.join("sweep.json") } else { a.input.clone() };
    let r = SweepResult::read(&path)?;
    let cols: Vec<&str> = if a.columns.is_empty() {
        ["theta", "theta_best", "measured_rate"]
            .into_iter()
            .filter(|c| r.columns.iter().any(|k| k.name == *c))
            .collect()
    } else {
        a.columns.iter().map(String::as_str).collect()
    };
    let f = figures::sweep::sweep_figure(&r, a.x.as_deref(), &cols)?;
    Ok(vec![(format!("sweep-{}", cols.join("-")), f)])
}

/// The model file of `figure trajectory|psi|tube`, within theta's size limits for psi and tube.
fn model_file(a: &Args) -> anyhow::Result<model::System> {
    let sys = model::load(&a.input).with_context(|| a.input.display().to_string())?;
    if matches!(a.kind, Kind::Psi | Kind::Tube) {
        crate::budget::theta_size("figure", sys.n(), sys.p())?;
    }
    Ok(sys)
}

/// `figure psi` (Fig. psi1), with theta and its verdict on stderr.
fn psi_figures(sys: &model::System) -> anyhow::Result<Vec<(String, Figure)>> {
    let r = bounds::assemble(sys, &bounds::ThetaSettings::bound_only())?;
    eprintln!(
        "theta = {:.6} ({}), psi(0) = {:.6}, psi(gamma_inf) = {:.6}, -lambda = {:.6}",
        r.theta,
        match (r.theta_verified, r.theta < 0.0) {
            (true, true) => "verified: certifies convergence",
            (true, false) => "a valid bound, no convergence guaranteed",
            (false, _) => "not verified",
        },
        r.psi_0,
        r.psi_inf,
        -r.lambda
    );
    Ok(vec![("fig-psi1".into(), figures::psi::from_report(&r))])
}

/// `figure tube` (Fig. loop): the orbit, the tube and the simulated periodic z.
fn tube_figures(sys: &model::System) -> anyhow::Result<Vec<(String, Figure)>> {
    let settings = bounds::ThetaSettings::bound_only();
    let orbit = bounds::orbit::EtaOrbit::new(sys, &settings.orbit)?;
    let tube = bounds::tube::OutputTube::new(sys, &settings.tube)?;
    let z = figures::tube::periodic_z(sys, 2000)?;
    Ok(vec![("fig-loop".into(), figures::tube::tube_figure(sys, &orbit, &tube, &z))])
}

/// `figure trajectory`: y and z, and x, against time, within the step budget.
fn trajectory_figures(a: &Args, sys: &model::System) -> anyhow::Result<Vec<(String, Figure)>> {
    let dt = a.dt.unwrap_or(sys.sim.dt);
    let t_end = a.t_end.unwrap_or_else(|| match sys.period() {
        Some(T) => T * sys.sim.periods as f64,
        None => sys.sim.t_end.unwrap_or(100.0),
    });
    if a.dt.is_some() {
        crate::budget::step(dt, sys, Some(t_end), "--dt")?;
    } else if a.t_end.is_some() && dt > t_end {
        crate::budget::step(dt, sys, Some(t_end), "--t-end")?;
    }
    crate::budget::steps(
        "figure trajectory",
        (t_end / dt).ceil(),
        &format!("t_end = {} at dt = {}", crate::budget::num(t_end), crate::budget::num(dt)),
    )?;
    let (yz, x) = figures::trajectory::trajectory_figures(
        sys,
        &TrajectorySettings { t_end: a.t_end, dt: a.dt, ..Default::default() },
    )?;
    Ok(vec![("trajectory-yz".into(), yz), ("trajectory-x".into(), x)])
}
