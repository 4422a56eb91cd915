//! `periodic`: the periodic regime (fixed point of the Poincare map), its residual and the
//! (loc) check, the measured convergence exponent with its 95% interval and the path length
//! of z per period; for a model with `[[effects]]`, the regime the extended-model simulator
//! reaches. Budgets (in [`periodic`]): the step against the period ([`crate::budget::step`])
//! and the integration steps ([`crate::budget::steps`]).
use super::Source;
use crate::budget::num;
use anyhow::bail;
use bounds::tube::localisation::{check_localisation, LocalisationCheck, LocalisationSettings};
use dynamics::extended::SimulatedRegime;
use dynamics::periodic::linearised::{linearised_periodic, LinearisedPeriodic, LinearisedSettings};
use dynamics::periodic::poincare::{periodic_regime, PeriodicRegime, PoincareSettings};
use dynamics::rate::lyapunov_exponent::{measure_rate, MeasuredRate, RateSettings};
use model::System;

/// Options of `periodic` (the CLI's `--dt`, `--periods`, `--pairs`).
#[derive(Debug, Clone, Copy)]
pub struct PeriodicOptions {
    /// Step (default: `simulation.dt`).
    pub dt: Option<f64>,
    /// Periods simulated for the rate measurement.
    pub periods: usize,
    /// Trajectory pairs for the rate.
    pub pairs: usize,
}

impl Default for PeriodicOptions {
    fn default() -> Self {
        Self { dt: None, periods: 60, pairs: 3 }
    }
}

/// The result of `periodic`, made once per command: the size difference between the variants
/// costs nothing.
#[allow(clippy::large_enum_variant)]
pub enum PeriodicRun {
    /// A model of the paper's class: regime, linearisation, (loc) check and measured rate.
    Paper {
        sys: System,
        regime: PeriodicRegime,
        linearised: LinearisedPeriodic,
        localisation: LocalisationCheck,
        rate: MeasuredRate,
    },
    /// A model with effects: where the extended-model simulator is after `periods` periods
    /// (no fixed-point claim, no (loc) check, no rate: those are results about the paper's
    /// class).
    Effects {
        sys: System,
        kinds: Vec<&'static str>,
        regime: SimulatedRegime,
        /// Change over the last period `|s(NT) - s((N-1)T)|_inf`.
        last_residual: f64,
        note: String,
    },
}

impl PeriodicRun {
    /// The JSON object of `moreau periodic --json`.
    pub fn to_json(&self) -> serde_json::Value {
        match self {
            PeriodicRun::Paper { sys, regime: reg, linearised: lin, localisation: loc, rate } => serde_json::json!({
                "name": sys.name, "period": reg.period, "h": reg.h,
                "periodic_regime": reg, "xi_T0": lin.xi0(), "localisation": loc,
                "rate": { "exponent": rate.exponent, "ci95": [rate.ci_low, rate.ci_high], "pairs": rate.pairs.iter().map(|p| serde_json::json!({"exponent": p.exponent, "ci95": [p.ci_low, p.ci_high], "renormalisations": p.renormalisations, "collapsed": p.collapsed})).collect::<Vec<_>>(),
                    "multiplier": rate.multiplier.as_ref().map(|u| serde_json::json!({"exponent": u.exponent, "ci95": [u.ci_low, u.ci_high], "rank": u.rank, "moduli": u.moduli, "complex_pair": u.complex_pair})) },
                "path_length_per_period": rate.path_length_per_period, "limsup_z_speed": rate.limsup_z_speed,
                "osc_eta_T_lower": lin.osc_lower(), "eta_T_dot_inf_sampled": lin.deta_inf_sampled(),
            }),
            PeriodicRun::Effects { sys, kinds, regime: reg, last_residual: last, note } => serde_json::json!({
                "name": sys.name, "period": reg.period, "h": reg.h, "effects": kinds,
                "simulated_regime": reg, "last_period_residual": last, "note": note,
            }),
        }
    }
}

/// Validates the options, checks the budgets, computes.
pub fn periodic(src: &Source, o: &PeriodicOptions) -> anyhow::Result<PeriodicRun> {
    let sys = src.system()?;
    let dt = o.dt.unwrap_or(sys.sim.dt);
    if !(dt > 0.0 && dt.is_finite()) {
        bail!("--dt must be positive and finite, got {dt}");
    }
    if o.periods == 0 {
        bail!("--periods must be at least 1, got 0");
    }
    let Some(T) = sys.period() else {
        bail!(
            "{} has a non-periodic input (`{}`): the periodic regime needs a T-periodic w",
            src.label(),
            sys.input.kind()
        );
    };
    if o.pairs == 0 {
        bail!("--pairs must be at least 1, got 0");
    }
    if o.dt.is_some() {
        crate::budget::step(dt, &sys, None, "--dt")?;
    }
    // rate: `periods` periods of 2 trajectories per pair and a reference; Poincare iteration
    // typically well under 100 periods
    crate::budget::steps(
        "periodic",
        (T / dt).ceil() * (o.periods as f64 * (2 * o.pairs + 1) as f64 + 100.0),
        &format!("{} periods, {} pairs, T = {}, dt = {}", o.periods, o.pairs, num(T), num(dt)),
    )?;
    if !sys.effects.list.is_empty() || sys.controller.is_some() {
        let mut kinds: Vec<&'static str> = sys.effects.list.iter().map(|e| e.kind()).collect();
        if sys.controller.is_some() {
            kinds.push("a digital controller");
        }
        let regime = dynamics::extended::regime_by_simulation(&sys, dt, o.periods)?;
        let last_residual = regime.residuals.last().copied().unwrap_or(f64::NAN);
        let note = format!(
            "the model has effects outside the paper's class ({}): the regime below is where the extended-model simulator is after {} periods; uniqueness and the convergence rate are not established for it",
            kinds.join(", "),
            regime.periods
        );
        return Ok(PeriodicRun::Effects { sys, kinds, regime, last_residual, note });
    }
    let regime = periodic_regime(&sys, &PoincareSettings { dt, ..Default::default() })?;
    let linearised = linearised_periodic(&sys, &LinearisedSettings::default())?;
    let localisation =
        check_localisation(&sys, linearised.xi0(), &regime.x0, &regime.z0, &LocalisationSettings::default())?;
    let transient = (o.periods / 6).clamp(1, 10);
    let rate = measure_rate(
        &sys,
        &RateSettings { dt, periods: o.periods, transient_periods: transient, pairs: o.pairs, ..Default::default() },
        None,
    )?;
    Ok(PeriodicRun::Paper { sys, regime, linearised, localisation, rate })
}
