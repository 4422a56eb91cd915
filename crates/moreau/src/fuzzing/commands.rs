//! Targets of whole commands run in-process on small budgets: the bytes are a model file (and
//! for `diagnose` a recording after a line `%%`), written to a fresh temporary directory and
//! read by the command layer as the CLI reads `FILE`.
use super::outputs::REGISTRY;
use super::{split_two, text};
use crate::commands::simulate::{Integrator, SimulateOptions};
use crate::commands::theta::ThetaOptions;
use crate::commands::Source;
use discovery::fit::FitSettings;
use discovery::DiagnoseSettings;
use std::path::PathBuf;

/// Steps of one simulation, at most.
const SIM_STEPS: f64 = 100.0;
/// Rows kept of one simulation.
const SIM_ROWS: usize = 50;

/// The bytes as `model.toml` in a fresh temporary directory (kept alive by the returned guard).
fn model_file(data: &[u8]) -> Option<(tempfile::TempDir, PathBuf)> {
    let dir = super::scratch().ok()?;
    let p = dir.path().join("model.toml");
    std::fs::write(&p, data).ok()?;
    Some((dir, p))
}

/// `moreau theta FILE --no-measure --no-guidance` through the command layer: the size budget,
/// the model reader, the SDPs and the tube (the measured side and the design guidance are
/// whole simulations and optimisations, too slow to fuzz).
pub fn theta(data: &[u8]) {
    let _registry = REGISTRY.lock().unwrap_or_else(|e| e.into_inner());
    let Some((_dir, p)) = model_file(data) else { return };
    let o = ThetaOptions { measure: false, stationary: true, guidance: false, step_check: false };
    let _ = crate::commands::theta::theta(&Source::File(p), &o);
    crate::output::forget_inputs();
}

/// `moreau simulate FILE` through the command layer with a coarse step: one input period
/// (or the model's final time, 1 when unset) in [`SIM_STEPS`] steps, [`SIM_ROWS`] rows kept;
/// an odd-length input runs the event-driven reference instead of the catching-up scheme.
pub fn simulate(data: &[u8]) {
    let Some(t) = text(data) else { return };
    // the model is read once here to choose a step the budget of the fuzzer allows
    let Ok(sys) = model::parse_str(t) else { return };
    let Some((_dir, p)) = model_file(data) else { return };
    let _registry = REGISTRY.lock().unwrap_or_else(|e| e.into_inner());
    let integrator = if data.len() % 2 == 1 { Integrator::Event } else { Integrator::CatchingUp };
    let o = match sys.period() {
        Some(T) => SimulateOptions {
            periods: Some(1),
            dt: Some(T / SIM_STEPS),
            max_rows: Some(SIM_ROWS),
            integrator,
            ..Default::default()
        },
        None => {
            let te = sys.sim.t_end.filter(|t| t.is_finite() && *t > 0.0).unwrap_or(1.0);
            SimulateOptions {
                t_end: Some(te),
                dt: Some(te / SIM_STEPS),
                max_rows: Some(SIM_ROWS),
                integrator,
                ..Default::default()
            }
        }
    };
    let _ = crate::commands::simulate::simulate(&Source::File(p), &o);
    crate::output::forget_inputs();
}

/// `diagnose` of a model (before a line `%%`) against a recording (after it), both read as
/// the command reads its files, with the smallest settings: one added effect, one candidate
/// cross-validated on two folds, no jackknife, at most 4 sub-steps, 2 + 4 LM iterations, one
/// thread. The bytes are a model file, a line `%%`, and a recording CSV.
pub fn diagnose(data: &[u8]) {
    let Some(t) = text(data) else { return };
    let (model_text, rec_text) = split_two(t);
    let Ok(sys) = model::parse_str(model_text) else { return };
    let Ok(rec) = discovery::Recording::parse_checked(rec_text, "fuzz") else { return };
    let stated = crate::commands::Stated::of_text(model_text);
    let settings = DiagnoseSettings {
        max_effects: 1,
        max_second: 0,
        max_cv: 1,
        cv_folds: 2,
        cv_iter: 1,
        jackknife_iter: 0,
        max_substeps: 4,
        parallel: false,
        initial_state: crate::commands::initial_state(stated, &sys),
        fit: FitSettings { max_iter_start: 2, max_iter: 4, ..Default::default() },
        ..Default::default()
    };
    let _ = discovery::diagnose(&sys, &rec, &settings);
}
