//! `moreau periodic FILE [--dt H] [--periods N] [--json]`: the periodic regime (fixed point of
//! the Poincare map), its residual and the (loc) check, the measured convergence exponent with
//! its 95% interval, and the path length of z per period.
use crate::commands::periodic::{periodic, PeriodicOptions, PeriodicRun};
use crate::commands::Source;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, clap::Args)]
#[command(after_help = "Examples:
  moreau periodic examples/worked-example.toml
  moreau periodic examples/ellipse-p2.toml --periods 100 --pairs 4 --json")]
pub struct Args {
    /// Model file (TOML) with a periodic input.
    pub file: PathBuf,
    /// Time step (default: `simulation.dt`).
    #[arg(allow_negative_numbers = true, long)]
    pub dt: Option<f64>,
    /// Periods simulated for the rate measurement (default 60; the first 10 are transient).
    #[arg(long, default_value_t = 60)]
    pub periods: usize,
    /// Number of trajectory pairs for the rate.
    #[arg(long, default_value_t = 3)]
    pub pairs: usize,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: &Args) -> anyhow::Result<ExitCode> {
    let o = PeriodicOptions { dt: a.dt, periods: a.periods, pairs: a.pairs };
    let run = periodic(&Source::File(a.file.clone()), &o)?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&run.to_json())?);
        return Ok(ExitCode::SUCCESS);
    }
    let f = |v: &[f64]| v.iter().map(|x| format!("{x:.9}")).collect::<Vec<_>>().join(", ");
    match &run {
        PeriodicRun::Paper { sys, regime: reg, linearised: lin, localisation: loc, rate } => {
            println!("{}", sys.name);
            println!(
                "  period T = {:.9}, step h = {:e} ({} steps per period)",
                reg.period, reg.h, reg.steps_per_period
            );
            println!("  periodic regime: x(0) = [{}], z(0) = [{}]", f(&reg.x0), f(&reg.z0));
            println!(
                "    fixed-point iteration: {:?} after {} periods, residual |P(s) - s|_inf = {:.3e}",
                reg.status, reg.iterations, reg.residual
            );
            println!(
                "    (loc): {} (worst margin {:.3e} over {} directions, q in Theta: {})",
                if loc.inside { "inside" } else { "OUTSIDE" },
                loc.worst_margin,
                loc.directions,
                loc.q_in_theta
            );
            println!(
                "  linearised: xi_T(0) = [{}], osc(eta_T) >= {:.6}, max sampled |eta_T'| = {:.6}",
                f(lin.xi0()),
                lin.osc_lower(),
                lin.deta_inf_sampled()
            );
            println!(
                "  measured exponent (1/2) limsup (1/t) ln V: {:.5}  95% CI [{:.5}, {:.5}]  ({} pairs, periods {}..{})",
                rate.exponent,
                rate.ci_low,
                rate.ci_high,
                rate.pairs.len(),
                rate.transient_periods,
                rate.periods
            );
            if let Some(u) = &rate.multiplier {
                println!(
                    "  measured dominant multiplier ln rho / T: {:.6}  95% CI [{:.6}, {:.6}]  ({}, {} modes fitted)",
                    u.exponent,
                    u.ci_low,
                    u.ci_high,
                    if u.complex_pair { "a complex pair" } else { "real" },
                    u.rank
                );
            }
            println!(
                "  path length of z per period (min after transient): {:.6};  limsup |z'|: {:.6}",
                rate.path_length_per_period, rate.limsup_z_speed
            );
        }
        PeriodicRun::Effects { sys, regime: reg, last_residual: last, note, .. } => {
            println!("{}", sys.name);
            println!(
                "  period T = {:.9}, step h = {:e} ({} steps per period)",
                reg.period, reg.h, reg.steps_per_period
            );
            println!("  note: {note}");
            println!("  state after {} periods: x = [{}], z = [{}]", reg.periods, f(&reg.x0), f(&reg.z0));
            println!("  change over the last period |s(NT) - s((N-1)T)|_inf = {last:.3e}");
            println!(
                "  path length of z over the last period: {:.6};  max |z'|: {:.6}",
                reg.path_length_last_period, reg.max_z_speed_last_period
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}
