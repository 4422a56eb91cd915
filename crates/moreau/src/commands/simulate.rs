//! `simulate`: the closed loop from the model's initial state by the catching-up scheme (the
//! extended-model simulator for models with effects) or the event-driven reference. Budgets
//! (all in [`simulate`]): the step against the input ([`crate::budget::step`]), the
//! integration steps ([`crate::budget::steps`]) and the stored samples, `t, w, x, y, z` per
//! kept row ([`crate::budget::samples`]), and for the event-driven reference the events
//! ([`EVENTS_PER_STEP`] per integration step).
use super::Source;
use crate::budget::num;
use anyhow::bail;
use dynamics::integrators::event_driven::{event_driven, EventDrivenSettings};
use dynamics::trajectory::{simulate_model, Trajectory};
use dynamics::DynamicsError;
use model::System;

/// Events the event-driven reference may locate per integration step of the run (at least
/// [`EVENTS_FLOOR_STEPS`] steps counted): a contact that chatters (a smooth set grazed again and
/// again, a diverging state) stops with "too many events" instead of running for minutes; each
/// event costs a bisection of some 40 flows.
pub const EVENTS_PER_STEP: usize = 10;
/// See [`EVENTS_PER_STEP`].
pub const EVENTS_FLOOR_STEPS: usize = 1000;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Integrator {
    /// Moreau's catching-up scheme with the exact linear step (any Theta); models with
    /// `[[effects]]` run on the extended-model simulator.
    #[default]
    CatchingUp,
    /// Event-driven reference (interval, ball, ellipsoid; zero or sine input).
    Event,
}

/// Options of `simulate`: the CLI's `--periods`, `--dt`, `--integrator`, `--max-rows`, and
/// `t_end` (Python only; the CLI takes the final time from `simulation.t_end` of the file).
#[derive(Debug, Clone, Default)]
pub struct SimulateOptions {
    /// Input periods (periodic inputs; default: `simulation.periods`).
    pub periods: Option<usize>,
    /// Step (default: `simulation.dt`); for periodic inputs `T / ceil(T / dt)` is used.
    pub dt: Option<f64>,
    /// Final time instead of `periods` (any input).
    pub t_end: Option<f64>,
    pub integrator: Integrator,
    /// Keep at most this many samples (every k-th step); `None` keeps every step.
    pub max_rows: Option<usize>,
}

/// The result of `simulate`.
pub struct Simulation {
    pub sys: System,
    pub trajectory: Trajectory,
    /// How it was simulated (`catching-up, h = ...`, `event-driven, N events`, ...).
    pub method: String,
    /// The step used.
    pub h: f64,
    /// Steps simulated, and the thinning: every `every`-th step is kept (1: all of them).
    pub steps: usize,
    pub every: usize,
}

/// Validates the options, checks the budgets, simulates.
pub fn simulate(src: &Source, o: &SimulateOptions) -> anyhow::Result<Simulation> {
    let sys = src.system()?;
    let dt = o.dt.unwrap_or(sys.sim.dt);
    let periods = checked_options(o, &sys, dt)?;
    let (t_end, h) = horizon(src, &sys, o, dt, periods)?;
    crate::budget::steps("simulate", (t_end / h).round(), &format!("t_end = {} at dt = {}", num(t_end), num(h)))?;
    let steps = (t_end / h).round().max(1.0) as usize;
    let max_rows = o.max_rows.unwrap_or(steps + 1);
    let rows = (steps as f64).min(max_rows as f64);
    crate::budget::samples(
        "simulate",
        rows * (1 + sys.n() + sys.m() + 2 * sys.p()) as f64,
        "numbers in trajectory.csv, --max-rows",
    )?;
    let every = steps.div_ceil(max_rows).max(1);
    let (trajectory, method) = integrate(src, &sys, o.integrator, h, steps, every)?;
    Ok(Simulation { sys, trajectory, method, h, steps, every })
}

/// The options checked against each other and the model (`dt` the step asked for): the number
/// of input periods.
fn checked_options(o: &SimulateOptions, sys: &System, dt: f64) -> anyhow::Result<usize> {
    if !(dt > 0.0 && dt.is_finite()) {
        bail!("--dt must be positive and finite, got {dt}");
    }
    if let Some(te) = o.t_end {
        if !(te > 0.0 && te.is_finite()) {
            bail!("t_end must be positive and finite, got {te}");
        }
        if o.periods.is_some() {
            bail!("give t_end or periods, not both");
        }
    }
    if o.dt.is_some() {
        let t_end = o.t_end.or(sys.sim.t_end).filter(|_| sys.period().is_none() || o.t_end.is_some());
        crate::budget::step(dt, sys, t_end, "--dt")?;
    }
    let periods = o.periods.unwrap_or(sys.sim.periods);
    if periods == 0 {
        bail!("--periods must be at least 1, got 0");
    }
    if let Some(r) = o.max_rows.filter(|&r| r < 2) {
        bail!("--max-rows must be at least 2, got {r}");
    }
    Ok(periods)
}

/// The final time and the step: whole periods of a periodic input at `T / ceil(T / dt)`
/// (within the step budget), else `t_end` (the option's, the file's, or 100) at `dt`.
fn horizon(src: &Source, sys: &System, o: &SimulateOptions, dt: f64, periods: usize) -> anyhow::Result<(f64, f64)> {
    Ok(match (sys.period(), o.t_end) {
        (Some(T), None) => {
            crate::budget::steps(
                "simulate",
                periods as f64 * (T / dt).ceil(),
                &format!("{} periods of T = {} at dt = {}", num(periods as f64), num(T), num(dt)),
            )?;
            let (n, h) = dynamics::periodic::steps_per_period(T, dt)?;
            (periods as f64 * n as f64 * h, h)
        }
        (Some(T), Some(te)) => {
            let (_, h) = dynamics::periodic::steps_per_period(T, dt)?;
            (te, h)
        }
        (None, te) => {
            if o.periods.is_some() {
                bail!(
                    "--periods needs a periodic input; {} has input `{}` (set simulation.t_end instead)",
                    src.label(),
                    sys.input.kind()
                );
            }
            (te.or(sys.sim.t_end).unwrap_or(100.0), dt)
        }
    })
}

/// `steps` steps of `h`, every `every`-th kept, by the chosen integrator: the trajectory and
/// how it was simulated.
fn integrate(
    src: &Source,
    sys: &System,
    integrator: Integrator,
    h: f64,
    steps: usize,
    every: usize,
) -> anyhow::Result<(Trajectory, String)> {
    let mut effects: Vec<&str> = sys.effects.list.iter().map(|e| e.kind()).collect();
    if sys.controller.is_some() {
        effects.push("a digital controller");
    }
    Ok(match integrator {
        Integrator::CatchingUp if effects.is_empty() => {
            (simulate_model(sys, h, steps, every)?, format!("catching-up, h = {h:e}"))
        }
        Integrator::CatchingUp => (
            simulate_model(sys, h, steps, every)?,
            format!("extended model with {}, h = {h:e}", effects.join(", ")),
        ),
        Integrator::Event if !effects.is_empty() => bail!(
            "--integrator event simulates the paper's class only; {} has effects ({}): use --integrator catching-up (the extended-model simulator)",
            src.label(),
            effects.join(", ")
        ),
        Integrator::Event => {
            let max_events = EVENTS_PER_STEP * steps.max(EVENTS_FLOOR_STEPS);
            let settings = EventDrivenSettings {
                dt_out: h * every as f64,
                t_end: (steps / every) as f64 * every as f64 * h,
                max_events,
                ..Default::default()
            };
            let (tr, events) = event_driven(sys, &settings).map_err(|e| match e {
                DynamicsError::TooManyEvents { t, .. } => anyhow::anyhow!(
                    "event-driven reference: more than {max_events} events before t = {} ({EVENTS_PER_STEP} per step of the run): the contact chatters or the state diverges; use --integrator catching-up",
                    num(t)
                ),
                e => e.into(),
            })?;
            (tr, format!("event-driven, {events} events"))
        }
    })
}
