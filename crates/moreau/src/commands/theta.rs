//! `theta`: the paper's bound theta (eq. (theta)) of a model, its report and, when nothing is
//! certified, the design guidance. Budget: theta's problem size ([`crate::budget::theta_size`]).
use super::Source;
use crate::guidance::Guidance;
use anyhow::Context;
use bounds::beyond_paper::floquet::{self, FloquetEnclosure, FloquetSettings};
use bounds::{assemble_memo, Memo, ThetaReport, ThetaSettings};
use model::System;

/// Options of `theta` (the CLI's `--no-measure`, `--no-stationary`, `--no-guidance`,
/// `--step-check`).
#[derive(Debug, Clone, Copy)]
pub struct ThetaOptions {
    /// Simulate the measured side (rate, path length, limsup |z'|).
    pub measure: bool,
    /// Decide the stationary set of Theorem 1.
    pub stationary: bool,
    /// Design guidance when nothing is certified (and the model has no effects).
    pub guidance: bool,
    /// Measure at the step, its half and its quarter (and the quarter at a 100 times smaller
    /// separation) and widen the measured intervals by the changes
    /// (`dynamics::rate::lyapunov_exponent::RateSettings::step_check`).
    pub step_check: bool,
}

impl Default for ThetaOptions {
    fn default() -> Self {
        Self { measure: true, stationary: true, guidance: true, step_check: false }
    }
}

/// The result of `theta`: the system, its report, the guidance (when computed) and the verified
/// Floquet enclosure of the regime (p = 1, interval, sine input; computed with the measured
/// side, since its phase structure is read from a simulation; issue 30,
/// proofs-notes/floquet-enclosure.md).
pub struct ThetaRun {
    pub sys: System,
    pub report: ThetaReport,
    pub guidance: Option<Guidance>,
    pub floquet: Option<FloquetEnclosure>,
}

impl ThetaRun {
    /// The JSON object of `moreau theta --json`: the report, plus `guidance` when computed.
    pub fn to_json(&self) -> anyhow::Result<serde_json::Value> {
        let mut obj = self.report.to_json();
        if let (Some(g), Some(m)) = (&self.guidance, obj.as_object_mut()) {
            m.insert("guidance".into(), serde_json::to_value(g)?);
        }
        if let (Some(f), Some(m)) = (&self.floquet, obj.as_object_mut()) {
            let ends = f.floquet_exponent;
            let value =
                if ends.iter().all(|v| v.is_finite()) { serde_json::json!(ends) } else { serde_json::Value::Null };
            m.insert("floquet_exponent".into(), value);
            m.insert("floquet_exponent_verified".into(), serde_json::json!(f.verified));
            m.insert("floquet_reason".into(), serde_json::json!(f.reason));
        }
        Ok(obj)
    }
}

/// The problem-size budget of `theta`, then the model, then the bound (errors of a model file
/// carry its path).
pub fn theta(src: &Source, o: &ThetaOptions) -> anyhow::Result<ThetaRun> {
    let sys = match src {
        Source::File(p) => {
            crate::budget::theta_size_of_file("theta", p)?;
            super::load(p)?
        }
        Source::Built(s, _) => {
            crate::budget::theta_size("theta", s.n(), s.p())?;
            (**s).clone()
        }
    };
    if let Some(c) = &sys.controller {
        anyhow::bail!(
            "{}: theta certifies the continuous loop of the paper; this model closes its loop by a digital [controller] ({}, period {}): `simulate` and `diagnose` run it",
            src.label(),
            c.kind(),
            c.period
        );
    }
    let mut settings = ThetaSettings::default();
    if !o.measure {
        settings.measure = None;
    }
    if let Some(m) = settings.measure.as_mut() {
        m.step_check = o.step_check;
    }
    if !o.stationary {
        settings.stationary = None;
    }
    // the guidance's bound computations share the report's memo (same F, E, C: its beta SDPs
    // and engaged history, bounds::Memo)
    let mut memo = Memo::new();
    let report = match src {
        Source::File(p) => assemble_memo(&sys, &settings, &mut memo).with_context(|| p.display().to_string())?,
        Source::Built(..) => assemble_memo(&sys, &settings, &mut memo)?,
    };
    let guidance = (o.guidance && !report.convergence_guaranteed && report.effects.is_empty())
        .then(|| crate::guidance::guidance(&sys, &report, &Default::default(), &mut memo));
    let floquet =
        (o.measure && floquet::applies(&sys)).then(|| floquet::floquet_enclosure(&sys, &FloquetSettings::default()));
    Ok(ThetaRun { sys, report, guidance, floquet })
}
