//! `diagnose`: compare a nominal model with a recording, locate the mismatch, name the missing
//! physics, refit and validate (crate `discovery`); [`write_outputs`] writes `report.md`,
//! `report.json`, `fitted.toml` and the figures ([`crate::figures::diagnosis`]) into a
//! directory, all together or not at all. The recording goes through the checked reader
//! ([`discovery::Recording::load`], [`discovery::Recording::parse_checked`]). Several
//! recordings of one machine: [`diagnose_recordings`] and [`write_joint_outputs`].
use super::{Source, Stated};
use crate::figures::canvas;
use crate::output::StagedDir;
use anyhow::Context;
use discovery::diagnose::JointReport;
use discovery::diagnose::Metric;
use discovery::recording::TimeColumn;
use discovery::{DiagnoseSettings, HoldChoice, Recording, Report};
use std::path::PathBuf;

/// A recording: a CSV file or CSV text (built in Python from a DataFrame or an array;
/// `source` names it in messages).
pub enum RecordingSource {
    File(PathBuf),
    Text { text: String, source: String },
}

/// Options of `diagnose` (the CLI's `--estimation-fraction`, `--max-effects`,
/// `--input-hold`, `--estimate-x0`, `--metric`, `--no-refit`, `--screen-samples`).
#[derive(Debug, Clone)]
pub struct DiagnoseOptions {
    /// Fraction of the record used for estimation (the rest validates). Default 0.7.
    pub estimation_fraction: f64,
    /// Greatest number of effects added by forward selection. Default 2.
    pub max_effects: usize,
    pub input_hold: HoldChoice,
    /// Estimate the initial state even when the model states `[initial] x0`.
    pub estimate_x0: bool,
    pub metric: Metric,
    /// Refit the nominal parameters the model file frees (`[fit] free`). Default true.
    pub refit_nominal: bool,
    /// Records longer than twice this are screened on their leading part of this many samples
    /// (`0`: never; see [`discovery::diagnose::screen`]). Default
    /// [`discovery::diagnose::screen::SCREEN_SAMPLES`].
    pub screen_samples: usize,
}

impl Default for DiagnoseOptions {
    fn default() -> Self {
        Self {
            estimation_fraction: 0.7,
            max_effects: 2,
            input_hold: HoldChoice::Auto,
            estimate_x0: false,
            metric: Metric::Auto,
            refit_nominal: true,
            screen_samples: discovery::diagnose::screen::SCREEN_SAMPLES,
        }
    }
}

/// The result of `diagnose`: the report and the seconds the diagnosis itself took.
pub struct DiagnoseRun {
    pub report: Report,
    pub seconds: f64,
}

/// Reads the model (with which initial values it states) and the recording, diagnoses.
pub fn diagnose(model_src: &Source, rec: &RecordingSource, o: &DiagnoseOptions) -> anyhow::Result<DiagnoseRun> {
    let (sys, settings) = model_and_settings(model_src, o)?;
    let rec = read_recording(rec)?;
    let start = std::time::Instant::now();
    let report = discovery::diagnose(&sys, &rec, &settings)?;
    Ok(DiagnoseRun { report, seconds: start.elapsed().as_secs_f64() })
}

/// The result of `diagnose` on several recordings: the joint report and the seconds it took.
pub struct JointRun {
    pub report: JointReport,
    pub seconds: f64,
}

/// Reads the model and the recordings, diagnoses them jointly (`recs` fitted on, `validate_on`
/// judged only; see [`discovery::diagnose::joint`]).
pub fn diagnose_recordings(
    model_src: &Source,
    recs: &[RecordingSource],
    validate_on: &[RecordingSource],
    o: &DiagnoseOptions,
) -> anyhow::Result<JointRun> {
    if recs.is_empty() {
        anyhow::bail!("no recording to fit on: give at least one --data (--validate-on only judges)");
    }
    let (sys, settings) = model_and_settings(model_src, o)?;
    let fit: Vec<Recording> = recs.iter().map(read_recording).collect::<anyhow::Result<_>>()?;
    let val: Vec<Recording> = validate_on.iter().map(read_recording).collect::<anyhow::Result<_>>()?;
    let start = std::time::Instant::now();
    let report = discovery::diagnose_recordings(&sys, &fit, &val, &settings)?;
    Ok(JointRun { report, seconds: start.elapsed().as_secs_f64() })
}

/// The model and the diagnosis settings (the initial values the model file states).
fn model_and_settings(model_src: &Source, o: &DiagnoseOptions) -> anyhow::Result<(model::System, DiagnoseSettings)> {
    let (sys, stated) = match model_src {
        Source::File(p) => {
            let sys = super::load(p).with_context(|| format!("model {}", p.display()))?;
            (sys, None)
        }
        Source::Built(_, stated) => (model_src.system()?, Some(*stated)),
    };
    let stated = match (stated, model_src) {
        (Some(s), _) => s,
        (None, Source::File(p)) => {
            let text = std::fs::read_to_string(p).with_context(|| format!("model {}", p.display()))?;
            Stated::of_text(&text)
        }
        (None, Source::Built(..)) => Stated::default(),
    };
    let settings = DiagnoseSettings {
        estimation_fraction: o.estimation_fraction,
        max_effects: o.max_effects,
        input_hold: o.input_hold,
        initial_state: super::initial_state(stated, &sys),
        estimate_x0: o.estimate_x0,
        metric: o.metric,
        refit_nominal: o.refit_nominal,
        screen_samples: o.screen_samples,
        ..Default::default()
    };
    Ok((sys, settings))
}

/// A recording through the checked reader and the row budget.
fn read_recording(rec: &RecordingSource) -> anyhow::Result<Recording> {
    Ok(match rec {
        RecordingSource::File(p) => {
            let text = discovery::recording::read_checked(p, "recording", TimeColumn::Numeric("t"))?;
            let source = p.display().to_string();
            crate::budget::recording_rows(&source, &text)?;
            Recording::parse_str(&text, &source)?
        }
        RecordingSource::Text { text, source } => {
            crate::budget::recording_rows(source, text)?;
            Recording::parse_checked(text, source)?
        }
    })
}

/// Writes every output of a report into the output directory `st` (made with
/// [`StagedDir::replacing`] before the work, so the directory is locked during the run),
/// all files together; the previous run's files there are replaced.
pub fn write_outputs(r: &Report, st: StagedDir) -> anyhow::Result<()> {
    write_outputs_sized(r, st, None)
}

/// [`write_outputs`] with the figures at the width of a paper's column (`moreau diagnose
/// --size`, [`crate::figures::diagnosis::figures_sized`]); `None`: their own sizes.
pub fn write_outputs_sized(r: &Report, st: StagedDir, size: Option<canvas::SizePreset>) -> anyhow::Result<()> {
    let figs = crate::figures::diagnosis::figures_sized(r, size);
    let mut captions = Vec::new();
    for (name, fig) in &figs {
        let svg = canvas::to_svg(fig).with_context(|| format!("figure {name}"))?;
        std::fs::write(st.path(&format!("{name}.svg")), svg)?;
        canvas::write_png(fig, &st.path(&format!("{name}.png"))).with_context(|| format!("figure {name}"))?;
        captions.push((format!("{name}.svg"), fig.title.clone()));
    }
    let caps: Vec<(&str, &str)> = captions.iter().map(|(a, b)| (a.as_str(), b.as_str())).collect();
    std::fs::write(st.path("report.md"), r.to_markdown(&caps))?;
    std::fs::write(st.path("report.json"), serde_json::to_string_pretty(r)?)?;
    if let Some(m) = &r.fitted_model {
        write_fitted(m, &st)?;
    }
    st.commit()
}

/// Writes the outputs of a joint diagnosis (`report.md`, `report.json`, `fitted.toml` and its
/// input file) into `st`, all together.
pub fn write_joint_outputs(r: &JointReport, st: StagedDir) -> anyhow::Result<()> {
    std::fs::write(st.path("report.md"), r.to_markdown())?;
    std::fs::write(st.path("report.json"), serde_json::to_string_pretty(r)?)?;
    if let Some(m) = &r.fitted_model {
        write_fitted(m, &st)?;
    }
    st.commit()
}

/// `fitted.toml` and its input file, read back.
fn write_fitted(m: &model::System, st: &StagedDir) -> anyhow::Result<()> {
    let text = model::to_toml_string(m);
    if let (model::Input::Samples { path, .. }, Some(csv)) = (&m.input, m.input.samples_csv()) {
        std::fs::write(st.path(path), csv)?;
    }
    std::fs::write(st.path("fitted.toml"), text)?;
    model::load(&st.path("fitted.toml")).context("the fitted model does not read back (internal error)")?;
    Ok(())
}
