//! Does the diagnosed model describe the machine? The model fitted on a case's recording
//! predicts the machine's next experiment ([`bench_gen::NextExperiment`]: the same machine, a
//! new input and new noise) as it is, the way a user replays `fitted.toml` on a new
//! recording (`moreau diagnose --model fitted.toml --data next.csv --no-refit --max-effects 0`):
//! no effect added, no parameter refitted, the hold the first diagnosis chose, the initial
//! state the model states. Scored against the nominal model's prediction and the noise floor.
use crate::bench_gen::{self, NextExperiment};
use crate::diagnose::{diagnose, DiagnoseSettings, HoldChoice, InitialState};
use crate::metrics::rmse;
use crate::{DiscoveryError, Recording, Report};
use model::System;
use serde::Serialize;

/// RMSE over the whole next recording of three predictions of it.
#[derive(Debug, Clone, Serialize)]
pub struct NextScore {
    /// The next experiment's input family.
    pub input: &'static str,
    /// The nominal model (the case's model file).
    pub rmse_nominal: f64,
    /// The model the diagnosis of the first recording returned (`fitted.toml`).
    pub rmse_fitted: f64,
    /// The machine's own clean output: the measurement noise alone, the floor.
    pub rmse_truth: f64,
}

impl NextScore {
    /// The share of the nominal's mean-square error above the noise floor that the fitted
    /// model removes: 1 predicts as the machine does, 0 as the nominal, below 0 worse. `NaN`
    /// where the nominal is at the floor (nothing to remove: a `none` case).
    pub fn explained(&self) -> f64 {
        let excess = |r: f64| r * r - self.rmse_truth * self.rmse_truth;
        let nominal = excess(self.rmse_nominal);
        if nominal <= 0.0 {
            return f64::NAN;
        }
        1.0 - excess(self.rmse_fitted) / nominal
    }

    /// The fitted model's RMSE over the noise floor (1: as close as the noise allows).
    pub fn over_floor(&self) -> f64 {
        self.rmse_fitted / self.rmse_truth
    }
}

impl std::fmt::Display for NextScore {
    /// One line: the three RMSEs, the returned model's over the floor, the excess explained.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "next experiment ({}): RMSE nominal {:.4e}, returned {:.4e}, noise floor {:.4e}; returned / floor {:.3}, excess explained {:.3}",
            self.input,
            self.rmse_nominal,
            self.rmse_fitted,
            self.rmse_truth,
            self.over_floor(),
            self.explained()
        )
    }
}

/// Scores the first recording's diagnosis `rep` of `case` on its next experiment (`None`
/// where the case has none); `s` the settings the first diagnosis ran with.
pub fn score(case: &bench_gen::Case, rep: &Report, s: &DiagnoseSettings) -> Option<Result<NextScore, DiscoveryError>> {
    let next = case.next.as_ref()?;
    let hold = HoldChoice::parse(rep.hold.chosen).unwrap_or_default();
    let fitted = rep.fitted_model.as_ref().unwrap_or(&case.nominal);
    Some(score_models(&case.nominal, fitted, next, hold, s))
}

fn score_models(
    nominal: &System,
    fitted: &System,
    next: &NextExperiment,
    hold: HoldChoice,
    s: &DiagnoseSettings,
) -> Result<NextScore, DiscoveryError> {
    let y: Vec<f64> = next.recording.y.iter().flatten().copied().collect();
    Ok(NextScore {
        input: next.input,
        rmse_nominal: prediction_rmse(nominal, &next.recording, hold, s)?,
        rmse_fitted: prediction_rmse(fitted, &next.recording, hold, s)?,
        rmse_truth: rmse(&next.clean, &y),
    })
}

/// The RMSE over `rec` of the output `sys` predicts for it as it is, under `hold`, from the
/// initial state `sys` states: the nominal simulation of a diagnosis that may add nothing and
/// refit nothing (`s` otherwise).
pub fn prediction_rmse(
    sys: &System,
    rec: &Recording,
    hold: HoldChoice,
    s: &DiagnoseSettings,
) -> Result<f64, DiscoveryError> {
    let s = DiagnoseSettings {
        max_effects: 0,
        refit_nominal: false,
        input_hold: hold,
        initial_state: Some(InitialState {
            x0: sys.x0.iter().copied().collect(),
            z0: Some(sys.z0.iter().copied().collect()),
        }),
        estimate_x0: false,
        jackknife_iter: 0,
        ..s.clone()
    };
    let y: Vec<f64> = rec.y.iter().flatten().copied().collect();
    Ok(rmse(&diagnose(sys, rec, &s)?.series.yhat_nominal, &y))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn explained_share_runs_from_the_nominal_to_the_floor() {
        let at =
            |fitted: f64| NextScore { input: "multisine", rmse_nominal: 5.0, rmse_fitted: fitted, rmse_truth: 3.0 };
        assert_eq!(at(3.0).explained(), 1.0);
        assert_eq!(at(5.0).explained(), 0.0);
        // worse than the nominal: negative
        assert!(at(6.0).explained() < 0.0);
        assert_eq!(at(4.5).over_floor(), 1.5);
        // nothing to explain where the nominal is at the floor
        let none = NextScore { input: "multisine", rmse_nominal: 3.0, rmse_fitted: 3.0, rmse_truth: 3.0 };
        assert!(none.explained().is_nan());
    }
}
