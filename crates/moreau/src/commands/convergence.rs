//! `convergence`: error of the catching-up scheme against the event-driven reference for a
//! ladder of steps, and the fitted order (a model with `[[effects]]`: the extended-model
//! simulator against its own finest step). Budgets (in [`plan`]): the ladder's levels, the
//! coarsest step against the input ([`crate::budget::step`]), the integration steps and the
//! stored samples.
use super::Source;
use crate::budget::num;
use anyhow::bail;
use dynamics::convergence::{convergence_study, ConvergenceSettings, ConvergenceStudy};
use model::System;

/// Options of `convergence` (the CLI's `--h0`, `--levels`, `--periods`).
#[derive(Debug, Clone, Copy)]
pub struct ConvergenceOptions {
    /// Largest step of the ladder.
    pub h0: f64,
    /// Steps in the ladder (each half the previous).
    pub levels: usize,
    /// Horizon in input periods (default: `simulation.periods`; non-periodic inputs:
    /// `simulation.t_end` or 20).
    pub periods: Option<usize>,
}

/// A validated study: the system, its settings and the integration steps it takes.
pub struct ConvergencePlan {
    pub sys: System,
    pub settings: ConvergenceSettings,
    /// Integration steps of the ladder and the reference (for a progress display).
    pub total_steps: f64,
}

/// Validates the model (F Hurwitz) and the options, and checks the budgets.
pub fn plan(src: &Source, o: &ConvergenceOptions) -> anyhow::Result<ConvergencePlan> {
    let sys = src.system()?;
    // an unstable loop diverges: every level's error grows with the horizon and a slope fitted
    // to them (errors of 1e15 gave "order 0.957") measures nothing
    if let Some(top) = sys.eig_F().first().filter(|l| l.re >= 0.0) {
        let eig = if top.im == 0.0 {
            num(top.re)
        } else {
            format!("{} {} {}i", num(top.re), if top.im < 0.0 { "-" } else { "+" }, num(top.im.abs()))
        };
        bail!(
            "{}: F = A + E C is not Hurwitz (eigenvalue {eig} has real part {} >= 0): the trajectories diverge, so no convergence order can be measured",
            src.label(),
            num(top.re)
        );
    }
    if sys.effects.list.is_empty() && !matches!(sys.input, model::Input::Zero { .. } | model::Input::Sine { .. }) {
        bail!(
            "{}: convergence measures the catching-up scheme against the event-driven reference, which needs an input of kind zero or sine; the model's input is `{}`",
            src.label(),
            sys.input.kind()
        );
    }
    if !(o.h0 > 0.0 && o.h0.is_finite()) {
        bail!("--h0 must be positive and finite, got {}", o.h0);
    }
    if o.periods == Some(0) {
        bail!("--periods must be at least 1, got 0");
    }
    if o.levels > crate::budget::MAX_LEVELS {
        bail!("--levels {}: more than {} levels (each halves the step)", o.levels, crate::budget::MAX_LEVELS);
    }
    let t_end = match sys.period() {
        Some(T) => o.periods.unwrap_or(sys.sim.periods) as f64 * T,
        None => sys.sim.t_end.unwrap_or(20.0),
    };
    crate::budget::step(o.h0, &sys, Some(t_end), "--h0")?;
    // the ladder: t_end / h0 steps at the coarsest level, doubling per level, plus a reference
    // as fine as the finest level; every level stores t_end / h0 samples
    let n0 = (t_end / o.h0).ceil();
    let levels = o.levels as i32;
    crate::budget::steps(
        "convergence",
        n0 * (2f64.powi(levels) - 1.0 + 2f64.powi(levels)),
        &format!("t_end = {}, h0 = {}, {} levels", num(t_end), num(o.h0), o.levels),
    )?;
    crate::budget::samples(
        "convergence",
        n0 * (o.levels + 1) as f64 * (sys.n() + sys.p()) as f64,
        "numbers stored per level",
    )?;
    let total_steps = n0 * (2f64.powi(levels) - 1.0 + 2f64.powi(levels));
    Ok(ConvergencePlan { sys, settings: ConvergenceSettings { h0: o.h0, levels: o.levels, t_end }, total_steps })
}

impl ConvergencePlan {
    /// Runs the study.
    pub fn run(&self) -> anyhow::Result<ConvergenceStudy> {
        Ok(convergence_study(&self.sys, &self.settings)?)
    }
}
