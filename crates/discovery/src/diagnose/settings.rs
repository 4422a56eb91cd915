//! Settings of the diagnosis ([`DiagnoseSettings`], checked by its one
//! [`DiagnoseSettings::validate`] at the entry of [`super::diagnose`]) and the choices they
//! offer: the input hold ([`HoldChoice`]), the verdict's headline metric ([`Metric`]) and the
//! model file's initial state ([`InitialState`]).
use crate::fit::FitSettings;
use crate::select::{Plan, SelectSettings};
use crate::{DiscoveryError, Recording};
use dynamics::extended::InputHold;
use model::System;
use serde::Serialize;

/// Settings of the diagnosis.
#[derive(Debug, Clone)]
pub struct DiagnoseSettings {
    /// Fraction of the record used for estimation. Default 0.7. Below
    /// `extend::EXTENDED_FRACTION` (0.9), a record whose missing effect acts only after it is
    /// diagnosed again with 0.9 (`diagnose/extend.rs`).
    pub estimation_fraction: f64,
    /// Largest number of linear sub-steps per sample. Default 64.
    pub max_substeps: usize,
    /// First number of sub-steps tried: `h <= tau_fast / substep_ratio`. Default 10.
    pub substep_ratio: f64,
    /// Sub-steps are doubled until the simulated output changes by at most this fraction of
    /// the noise level (weighted RMS). Default 0.1.
    pub substep_tol: f64,
    /// Input between samples: `Auto` (decided by the nominal fit), `Zoh` or `Foh`.
    pub input_hold: HoldChoice,
    /// The initial state stated by the model file (`None`: not stated, estimated).
    pub initial_state: Option<InitialState>,
    /// Estimate the initial state even when the model file states one. Default false.
    pub estimate_x0: bool,
    /// Contiguous folds of the blocked cross-validation. Default 5.
    pub cv_folds: usize,
    /// Candidates (best BIC first) cross-validated per selection step, until one passes.
    /// Default 3.
    pub max_cv: usize,
    /// LM iterations per fold refit (from the estimation fit). Default 6.
    pub cv_iter: usize,
    /// LM iterations per fold of the jackknife of the selected model's parameters (its
    /// model-error spread over `cv_folds` contiguous folds of the estimation segment, see
    /// [`crate::fit::jackknife`]); 0 leaves the jackknife out. Default 6.
    pub jackknife_iter: usize,
    /// Check the selected model's gain at a finer stepping (an effect whose gain is within the
    /// simulator's stepping error is not reported). Default true; a long record's screening
    /// leaves it to the whole record's diagnosis.
    pub finer_check: bool,
    /// Greatest number of effects added by forward selection. Default 2.
    pub max_effects: usize,
    /// How many of the best single hypotheses are tried as second effects. Default 4.
    pub max_second: usize,
    /// Lags of the residual tests. Default 20.
    pub lags: usize,
    pub fit: FitSettings,
    pub select: SelectSettings,
    /// Run hypotheses in parallel (rayon). Default true.
    pub parallel: bool,
    /// Refit the nominal parameters the model file frees (`[fit] free`). Default true.
    pub refit_nominal: bool,
    /// Records longer than twice this are screened on their leading part of this many samples,
    /// then judged whole with the hypotheses the screening kept ([`super::screen`]); `0` never
    /// screens. Default [`super::screen::SCREEN_SAMPLES`].
    pub screen_samples: usize,
    /// The single hypotheses the diagnosis may use, by label (`coulomb_friction(x2)`) or by
    /// kind (`coulomb_friction`: on every state); `None`: the whole library. The grey-box
    /// refit is kept where the model frees parameters.
    pub library: Option<Vec<String>>,
    /// Set by the screening of a long record for the whole record's diagnosis: the hold its
    /// effects settled on (an `auto` hold then takes it without a second look where the whole
    /// record's nominal agrees with the screening's). `None` otherwise.
    pub screened_hold: Option<super::hold::ScreenedHold>,
    /// Set by the screening of a long record: its single hypotheses' fits, the whole record's
    /// warm starts (as after a change of hold). `None` otherwise.
    pub screened_singles: Option<Vec<crate::select::Ranked>>,
    /// Headline metric of the verdict: `Auto` (RMSE in the output's units when a validation
    /// fit % exceeds 99 %, else fit %), `Fit` or `Rmse`.
    pub metric: Metric,
}

/// Headline metric of the verdict (`--metric`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Metric {
    /// RMSE when a validation fit % exceeds [`SERVO_FIT_PERCENT`] (a tightly tracking loop
    /// saturates fit %), else fit %.
    #[default]
    Auto,
    Fit,
    Rmse,
}

impl Metric {
    /// From `auto`, `fit` or `rmse`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "auto" => Some(Metric::Auto),
            "fit" => Some(Metric::Fit),
            "rmse" => Some(Metric::Rmse),
            _ => None,
        }
    }
}

/// Fit % above which `Metric::Auto` headlines the RMSE.
pub const SERVO_FIT_PERCENT: f64 = 99.0;

impl Default for DiagnoseSettings {
    fn default() -> Self {
        Self {
            estimation_fraction: 0.7,
            max_substeps: 64,
            substep_ratio: 10.0,
            substep_tol: 0.1,
            input_hold: HoldChoice::Auto,
            initial_state: None,
            estimate_x0: false,
            cv_folds: 5,
            max_cv: 3,
            cv_iter: 6,
            jackknife_iter: 6,
            finer_check: true,
            max_effects: 2,
            max_second: 4,
            lags: 20,
            fit: FitSettings::default(),
            select: SelectSettings::default(),
            parallel: true,
            refit_nominal: true,
            screen_samples: super::screen::SCREEN_SAMPLES,
            library: None,
            screened_hold: None,
            screened_singles: None,
            metric: Metric::Auto,
        }
    }
}

impl DiagnoseSettings {
    /// Samples of the estimation segment of a record of `n` samples: the first
    /// `estimation_fraction` of them.
    pub fn estimation_samples(&self, n: usize) -> usize {
        ((n as f64) * self.estimation_fraction).round() as usize
    }

    /// Checks the settings and their agreement with the model `sys` and the recording `rec`:
    /// the estimation fraction in `[0.2, 0.95]`, at least 2 folds, the recording's inputs and
    /// outputs those of the model, a stated initial state of the model's dimensions.
    pub fn validate(&self, sys: &System, rec: &Recording) -> Result<(), DiscoveryError> {
        if !(0.2..=0.95).contains(&self.estimation_fraction) {
            return Err(DiscoveryError::BadSetting {
                field: "estimation_fraction",
                value: self.estimation_fraction,
                reason: "must lie in [0.2, 0.95]",
            });
        }
        if self.cv_folds < 2 {
            return Err(DiscoveryError::BadSetting {
                field: "cv_folds",
                value: self.cv_folds as f64,
                reason: "at least 2 folds are needed",
            });
        }
        let (m, p) = (rec.m(), rec.p());
        if sys.m() != m {
            return Err(DiscoveryError::DimensionMismatch {
                what: "inputs m",
                model: sys.m(),
                recording: m,
                columns: "w columns".into(),
            });
        }
        if sys.p() != p {
            return Err(DiscoveryError::DimensionMismatch {
                what: "outputs p",
                model: sys.p(),
                recording: p,
                columns: "y columns".into(),
            });
        }
        if let Some(is) = &self.initial_state {
            if is.x0.len() != sys.n() {
                return Err(DiscoveryError::BadSetting {
                    field: "initial_state.x0 length",
                    value: is.x0.len() as f64,
                    reason: "must equal the model's n",
                });
            }
            if is.z0.as_ref().is_some_and(|z| z.len() != p) {
                return Err(DiscoveryError::BadSetting {
                    field: "initial_state.z0 length",
                    value: is.z0.as_ref().map_or(0, |z| z.len()) as f64,
                    reason: "must equal the model's p",
                });
            }
        }
        Ok(())
    }

    /// These settings with the fits' own parallelism (`fit.parallel`: Jacobian columns and
    /// starts) off where `parallel` is; `None` where that changes nothing.
    pub(crate) fn serial_fits(&self) -> Option<Self> {
        (!self.parallel && self.fit.parallel)
            .then(|| Self { fit: FitSettings { parallel: false, ..self.fit.clone() }, ..self.clone() })
    }

    /// The settings of fitting, cross-validation and forward selection.
    pub fn plan(&self) -> Plan<'_> {
        Plan {
            fit: &self.fit,
            select: &self.select,
            cv_folds: self.cv_folds,
            cv_iter: self.cv_iter,
            max_cv: self.max_cv,
            max_effects: self.max_effects,
            max_second: self.max_second,
            parallel: self.parallel,
            library: self.library.as_deref(),
            whiteness: None,
        }
    }
}

/// The hold requested for the input between samples (`--input-hold`): decided from the data,
/// or one of the simulator's holds ([`InputHold`], declared once in `dynamics`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum HoldChoice {
    /// Decided from the data: the hold under which the nominal model fits better.
    #[default]
    Auto,
    /// This hold, as requested.
    Fixed(InputHold),
}

impl HoldChoice {
    /// From `auto`, `zoh` or `foh`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "auto" => Some(HoldChoice::Auto),
            _ => [InputHold::Zoh, InputHold::Foh].into_iter().find(|h| h.name() == s).map(HoldChoice::Fixed),
        }
    }
    /// `auto`, `zoh` or `foh` (the `--input-hold` value).
    pub fn name(&self) -> &'static str {
        match self {
            HoldChoice::Auto => "auto",
            HoldChoice::Fixed(h) => h.name(),
        }
    }
}

impl Serialize for HoldChoice {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.name())
    }
}

/// An initial state stated by the model file.
#[derive(Debug, Clone, PartialEq)]
pub struct InitialState {
    pub x0: Vec<f64>,
    /// Backlash output `z0` when stated (else at rest in the play, `z0 = C x0`).
    pub z0: Option<Vec<f64>>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn serial_diagnosis_makes_its_fits_serial_too() {
        let s = DiagnoseSettings { parallel: false, ..Default::default() };
        let serial = s.serial_fits().expect("parallel = false must reach the fits");
        assert!(!serial.fit.parallel && !serial.parallel);
        // the default (parallel) and an already serial fit change nothing
        assert!(DiagnoseSettings::default().serial_fits().is_none());
        assert!(serial.serial_fits().is_none());
    }
}
