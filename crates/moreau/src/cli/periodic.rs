//! `moreau periodic FILE [--dt H] [--periods N] [--json]`: the periodic regime (fixed point of
//! the Poincare map), its residual and the (loc) check, the measured convergence exponent with
//! its 95% interval, and the path length of z per period.
use crate::budget::num;
use anyhow::{bail, Context};
use bounds::tube::localisation::{check_localisation, LocalisationSettings};
use dynamics::periodic::linearised::{linearised_periodic, LinearisedSettings};
use dynamics::periodic::poincare::{periodic_regime, PoincareSettings};
use dynamics::rate::lyapunov_exponent::{measure_rate, RateSettings};
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
    let sys = model::load(&a.file).with_context(|| a.file.display().to_string())?;
    let dt = a.dt.unwrap_or(sys.sim.dt);
    if !(dt > 0.0 && dt.is_finite()) {
        bail!("--dt must be positive and finite, got {dt}");
    }
    if a.periods == 0 {
        bail!("--periods must be at least 1, got 0");
    }
    let Some(T) = sys.period() else {
        bail!(
            "`{}` has a non-periodic input (`{}`): the periodic regime needs a T-periodic w",
            a.file.display(),
            sys.input.kind()
        );
    };
    if a.pairs == 0 {
        bail!("--pairs must be at least 1, got 0");
    }
    if a.dt.is_some() {
        crate::budget::step(dt, &sys, None, "--dt")?;
    }
    // rate: `periods` periods of 2 trajectories per pair and a reference; Poincare iteration
    // typically well under 100 periods
    crate::budget::steps(
        "periodic",
        (T / dt).ceil() * (a.periods as f64 * (2 * a.pairs + 1) as f64 + 100.0),
        &format!("{} periods, {} pairs, T = {}, dt = {}", a.periods, a.pairs, num(T), num(dt)),
    )?;
    if !sys.effects.list.is_empty() {
        return run_with_effects(a, &sys, dt);
    }
    let reg = periodic_regime(&sys, &PoincareSettings { dt, ..Default::default() })?;
    let lin = linearised_periodic(&sys, &LinearisedSettings::default())?;
    let loc = check_localisation(&sys, lin.xi0(), &reg.x0, &reg.z0, &LocalisationSettings::default())?;
    let transient = (a.periods / 6).max(1).min(10);
    let rate = measure_rate(
        &sys,
        &RateSettings { dt, periods: a.periods, transient_periods: transient, pairs: a.pairs, ..Default::default() },
        None,
    )?;
    if a.json {
        let v = serde_json::json!({
            "name": sys.name, "period": reg.period, "h": reg.h,
            "periodic_regime": reg, "xi_T0": lin.xi0(), "localisation": loc,
            "rate": { "exponent": rate.exponent, "ci95": [rate.ci_low, rate.ci_high], "pairs": rate.pairs.iter().map(|p| serde_json::json!({"exponent": p.exponent, "ci95": [p.ci_low, p.ci_high], "renormalisations": p.renormalisations, "collapsed": p.collapsed})).collect::<Vec<_>>() },
            "path_length_per_period": rate.path_length_per_period, "limsup_z_speed": rate.limsup_z_speed,
            "osc_eta_T_lower": lin.osc_lower(), "eta_T_dot_inf_sampled": lin.deta_inf_sampled(),
        });
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        let f = |v: &[f64]| v.iter().map(|x| format!("{x:.9}")).collect::<Vec<_>>().join(", ");
        println!("{}", sys.name);
        println!("  period T = {:.9}, step h = {:e} ({} steps per period)", reg.period, reg.h, reg.steps_per_period);
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
        println!(
            "  path length of z per period (min after transient): {:.6};  limsup |z'|: {:.6}",
            rate.path_length_per_period, rate.limsup_z_speed
        );
    }
    Ok(ExitCode::SUCCESS)
}

/// A model with `[[effects]]`: the regime reached by the extended-model simulator after
/// `--periods` periods, with the residual between successive periods (no fixed-point claim, no
/// (loc) check, no rate: those are results about the paper's class).
fn run_with_effects(a: &Args, sys: &model::System, dt: f64) -> anyhow::Result<ExitCode> {
    let kinds: Vec<&str> = sys.effects.list.iter().map(|e| e.kind()).collect();
    let reg = dynamics::extended::regime_by_simulation(sys, dt, a.periods)?;
    let last = reg.residuals.last().copied().unwrap_or(f64::NAN);
    let note = format!(
        "the model has effects outside the paper's class ({}): the regime below is where the extended-model simulator is after {} periods; uniqueness and the convergence rate are not established for it",
        kinds.join(", "),
        reg.periods
    );
    if a.json {
        let v = serde_json::json!({
            "name": sys.name, "period": reg.period, "h": reg.h, "effects": kinds,
            "simulated_regime": reg, "last_period_residual": last, "note": note,
        });
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        let f = |v: &[f64]| v.iter().map(|x| format!("{x:.9}")).collect::<Vec<_>>().join(", ");
        println!("{}", sys.name);
        println!("  period T = {:.9}, step h = {:e} ({} steps per period)", reg.period, reg.h, reg.steps_per_period);
        println!("  note: {note}");
        println!("  state after {} periods: x = [{}], z = [{}]", reg.periods, f(&reg.x0), f(&reg.z0));
        println!("  change over the last period |s(NT) - s((N-1)T)|_inf = {last:.3e}");
        println!(
            "  path length of z over the last period: {:.6};  max |z'|: {:.6}",
            reg.path_length_last_period, reg.max_z_speed_last_period
        );
    }
    Ok(ExitCode::SUCCESS)
}
