//! `moreau diagnose --model M.toml --data R.csv --out DIR`: compare a nominal model with a
//! recording, locate the mismatch, name the missing physics, refit and validate
//! (crate `discovery`). Writes `report.md`, `report.json`, `fitted.toml`, `fit.svg`,
//! `residual.svg`, `zoom-1.svg` .. `zoom-3.svg` (the top located windows; PNG copies of all)
//! into DIR, all together or not at all. With `--data` repeated (several recordings of one
//! machine) or `--validate-on`: the joint diagnosis, `report.md`, `report.json` and
//! `fitted.toml` (no figures). The work is [`crate::commands::diagnose`]; this
//! module parses the arguments and prints the summary.
use crate::commands::diagnose::{
    diagnose, diagnose_recordings, write_joint_outputs, write_outputs_sized, DiagnoseOptions, RecordingSource,
};
use crate::commands::Source;
use crate::output::StagedDir;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Nominal model file (TOML).
    #[arg(long)]
    pub model: PathBuf,
    /// Recording CSV: header `t,w,y` or `t,w1..wm,y1..yp`, optional `z`. Repeat it for
    /// several recordings of one machine (each its own initial state, input and sample time):
    /// one model fitted to all jointly, selected by leave-one-recording-out validation.
    #[arg(long)]
    pub data: Vec<PathBuf>,
    /// A recording of the same machine that the model is judged on, never fitted on
    /// (repeatable): a fitted model that predicts it worse than the nominal is not adopted.
    #[arg(long)]
    pub validate_on: Vec<PathBuf>,
    /// Output directory.
    #[arg(long)]
    pub out: PathBuf,
    /// Fraction of the record used for estimation (the rest validates). Default 0.7; below 0.9, a
    /// record whose missing effect acts only after it is diagnosed again with 0.9 (the report's
    /// first note says so).
    #[arg(allow_negative_numbers = true, long, default_value_t = 0.7)]
    pub estimation_fraction: f64,
    /// Greatest number of effects added by forward selection.
    #[arg(long, default_value_t = 2)]
    pub max_effects: usize,
    /// Input between samples: `zoh` (each sample held until the next, as a digital
    /// controller's command), `foh` (linear interpolation) or `auto` (the hold under which the
    /// nominal model fits better; the report says which and by how much).
    #[arg(long, default_value = "auto", value_parser = ["auto", "zoh", "foh"])]
    pub input_hold: String,
    /// Estimate the initial state even when the model file states `[initial] x0` (by default
    /// a stated x0, and z0, is used as known).
    #[arg(long)]
    pub estimate_x0: bool,
    /// Headline of the verdict: `auto` (RMSE in the output's units, from the model file's
    /// `[signals] y`, when the validation fit % exceeds 99 %, as for a tightly tracking servo
    /// loop; else fit %), `fit` or `rmse`.
    #[arg(long, default_value = "auto", value_parser = ["auto", "fit", "rmse"])]
    pub metric: String,
    /// Keep the nominal parameters that the model file frees (`[fit] free`) at their values:
    /// no grey-box refit.
    #[arg(long)]
    pub no_refit: bool,
    /// A recording longer than twice this many samples is screened on its leading part of this
    /// length (every hypothesis fitted there), then diagnosed whole with the hypotheses the
    /// screening kept; where the whole record finds that model incomplete and the leading
    /// part did not, it is diagnosed again with every hypothesis. `0`: never screen.
    #[arg(long, default_value_t = discovery::diagnose::screen::SCREEN_SAMPLES)]
    pub screen_samples: usize,
    /// Size preset of the figures for papers, in points, as `moreau figure --size`: `column`
    /// (3.5 in, 252 pt wide) or `two-column` (7.16 in, 515 pt), text 8-9 pt, the legends below
    /// the axes; each panel of a stack two thirds of the preset's height (`fit` and `residual`
    /// 252 x 288 at `column`, the zooms 252 x 432). Default: 1200 x 760 and 1100 x 900.
    #[arg(long, value_enum)]
    pub size: Option<crate::figures::canvas::SizePreset>,
}

pub fn run(a: &Args) -> anyhow::Result<ExitCode> {
    if a.data.is_empty() {
        anyhow::bail!(
            "--data: no recording given{} (usage: moreau diagnose --model M.toml --data R.csv [--data R2.csv ...] [--validate-on V.csv ...] --out DIR)",
            if a.validate_on.is_empty() { "" } else { "; --validate-on only judges the fitted model, at least one --data is fitted on" }
        );
    }
    if a.size.is_some() && (a.data.len() > 1 || !a.validate_on.is_empty()) {
        anyhow::bail!(
            "--size: the joint diagnosis (--data repeated or --validate-on) writes no figures; leave --size out"
        );
    }
    let o = DiagnoseOptions {
        estimation_fraction: a.estimation_fraction,
        max_effects: a.max_effects,
        input_hold: discovery::HoldChoice::parse(&a.input_hold).unwrap_or_default(),
        estimate_x0: a.estimate_x0,
        metric: discovery::diagnose::Metric::parse(&a.metric).unwrap_or_default(),
        refit_nominal: !a.no_refit,
        screen_samples: a.screen_samples,
    };
    let staged = StagedDir::replacing(&a.out)?;
    if a.data.len() > 1 || !a.validate_on.is_empty() {
        return run_joint(a, &o, staged);
    }
    let run = diagnose(&Source::File(a.model.clone()), &RecordingSource::File(a.data[0].clone()), &o)?;
    let (r, secs) = (&run.report, run.seconds);
    write_outputs_sized(r, staged, a.size)?;
    println!("{}", r.verdict);
    println!(
        "input hold {}{}; {} sub-step(s) per sample (remaining discretisation error {:.2e} output standard deviations; noise level {}); initial state {}",
        r.hold.chosen,
        match (r.hold.requested, r.hold.delta_bic) {
            (discovery::HoldChoice::Auto, Some(d)) => format!(" (auto: better by {d:.1} in BIC{})", if r.hold.decisive { "" } else { ", not decisive" }),
            _ => " (as requested)".to_string(),
        },
        r.substeps,
        r.discretisation.error_rms,
        r.noise_level.iter().map(|v| format!("{v:.2e}")).collect::<Vec<_>>().join(", "),
        r.initial_state.source
    );
    let pct = |v: &[Option<f64>]| {
        v.iter().map(|x| x.map_or("undefined".to_string(), |x| format!("{x:.1}"))).collect::<Vec<_>>().join(", ")
    };
    if r.headline_metric == "rmse" {
        println!("{}", r.headline);
    } else {
        let rmse = |v: &[f64]| v.iter().map(|x| format!("{x:.3e}")).collect::<Vec<_>>().join(", ");
        println!(
            "validation fit % (nominal -> fitted): {} -> {}; RMSE {} -> {}",
            pct(&r.fit_before.fit_percent),
            pct(&r.fit_after.fit_percent),
            rmse(&r.fit_before.rmse),
            rmse(&r.fit_after.rmse)
        );
    }
    for v in &r.nominal_refit {
        print_refitted(&v.name, v.nominal, v.value, v.std);
    }
    if !r.fit_before.constant_outputs.is_empty() {
        println!("fit % undefined: the validation output is constant; judge by the RMSE");
    }
    for e in &r.effects {
        // "width = 0.553 +- 0.012" per parameter, the uncertainty where the fit gives one
        let params: Vec<String> = e
            .params
            .iter()
            .map(|(name, v)| match e.uncertainty.iter().find(|(n, _)| n == name) {
                Some((_, s)) => format!("{name} = {} +- {}", sig4(*v), sig4(*s)),
                None => format!("{name} = {}", sig4(*v)),
            })
            .collect();
        println!("  {}: {}", e.label, params.join(", "));
    }
    println!("{} hypotheses ranked in {secs:.2} s; report in {}", r.ranking.len(), a.out.display());
    Ok(ExitCode::SUCCESS)
}

/// Several recordings (`--data` repeated, or `--validate-on`): the joint diagnosis.
fn run_joint(a: &Args, o: &DiagnoseOptions, staged: StagedDir) -> anyhow::Result<ExitCode> {
    let files = |v: &[PathBuf]| v.iter().map(|p| RecordingSource::File(p.clone())).collect::<Vec<_>>();
    let run = diagnose_recordings(&Source::File(a.model.clone()), &files(&a.data), &files(&a.validate_on), o)?;
    let r = &run.report;
    write_joint_outputs(r, staged)?;
    println!("{}", r.verdict);
    for v in &r.nominal_refit {
        print_refitted(&v.name, v.nominal, v.value, v.std);
    }
    for e in &r.effects {
        let params: Vec<String> = e
            .params
            .iter()
            .zip(&e.uncertainty)
            .map(|((name, v), (_, s))| format!("{name} = {} +- {}", sig4(*v), sig4(*s)))
            .collect();
        println!("  {}: {}", e.label, params.join(", "));
    }
    for o in r.own_fits.iter().filter(|o| !o.worsens.is_empty()) {
        println!("  {} fitted on {} alone {}", o.label, o.recording, o.note);
    }
    println!("{} recording(s) diagnosed in {:.2} s; report in {}", r.recordings.len(), run.seconds, a.out.display());
    Ok(ExitCode::SUCCESS)
}

/// `  M: 4.2 -> 4.76 +- 0.01 (refitted plant parameter)`.
fn print_refitted(name: &str, nominal: f64, value: f64, std: f64) {
    println!("  {name}: {} -> {} +- {} (refitted plant parameter)", sig4(nominal), sig4(value), sig4(std));
}

/// 4 significant digits, as the sweep tables write numbers.
fn sig4(v: f64) -> String {
    crate::sweep::table::sig(v, 4, false)
}
