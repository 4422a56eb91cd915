//! `moreau check [--cases N] [--seed S] [--only NAME] [--json] [--negative-control] [--out DIR]`:
//! runs the property campaign of the `theorems` crate (every inequality of the paper on
//! random cases) and prints, per result, the equation label, cases, minimum normalised slack,
//! violations and time. Exit status 1 on any violation; the shrunk counterexample of each
//! violated property is written to `DIR/<name>.toml` (a model file for properties on a
//! system, the set and points for geometric ones).
//!
//! `--negative-control` runs the deliberately wrong variants instead: there every property
//! must produce a counterexample, and the exit status is 1 if one of them does not.
use anyhow::Context;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::PathBuf;
use std::process::ExitCode;
use theorems::{CampaignSettings, PropertyReport, Variant};

#[derive(Debug, clap::Args)]
#[command(after_help = "Examples:
  moreau check                                   # every result of the paper, default cases
  moreau check --only lem1:2 --cases 100000 --seed 7
  moreau check --only psi0 --negative-control    # the control must find counterexamples")]
pub struct Args {
    /// Cases per property (default: each property's own default, thousands for the geometric
    /// lemmas, 2,000 for the simulation-based results).
    #[arg(long)]
    pub cases: Option<u64>,
    /// Master seed; the campaign is deterministic given the seed and the number of cases.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Run only this property (name such as `lemma_a2`, or equation label such as `lem1:2`).
    #[arg(long)]
    pub only: Option<String>,
    /// Print the results as JSON on stdout (no progress bar).
    #[arg(long)]
    pub json: bool,
    /// Run the negative controls (deliberately wrong constants): each must fail.
    #[arg(long)]
    pub negative_control: bool,
    /// Directory for counterexample files (written only when a property is violated).
    #[arg(long, default_value = "moreau-check-counterexamples")]
    pub out: PathBuf,
}

fn fmt_slack(s: f64) -> String {
    if s.is_infinite() {
        "-".into()
    } else {
        format!("{s:+.3e}")
    }
}

pub fn report_json(r: &PropertyReport, file: Option<&PathBuf>) -> serde_json::Value {
    serde_json::json!({
        "name": r.name,
        "label": r.label,
        "title": r.title,
        "variant": match r.variant { Variant::Claim => "claim", Variant::NegativeControl => "negative_control" },
        "cases": r.cases,
        "skipped": r.skipped,
        "min_slack": if r.min_slack.is_finite() { serde_json::json!(r.min_slack) } else { serde_json::Value::Null },
        "violations": r.violations,
        "first_violation": r.first_violation,
        "counterexample_file": file.map(|f| f.display().to_string()),
        "counterexample": r.counterexample.as_ref().map(|c| c.summary.clone()),
        "seconds": r.seconds,
    })
}

pub fn run(a: &Args) -> anyhow::Result<ExitCode> {
    if a.cases == Some(0) {
        anyhow::bail!("--cases must be at least 1, got 0");
    }
    if let Some(c) = a.cases {
        crate::budget::cases(c)?;
    }
    let variant = if a.negative_control { Variant::NegativeControl } else { Variant::Claim };
    let settings = CampaignSettings { cases: a.cases, seed: a.seed, only: a.only.clone(), variant };
    let props = theorems::campaign::select(theorems::registry(), a.only.as_deref())?;
    let total: u64 = props.iter().map(|p| a.cases.unwrap_or(p.info().default_cases)).sum();
    let bar = if a.json {
        ProgressBar::hidden()
    } else {
        ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr())
    };
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} cases, {per_sec}, about {eta} left {msg}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let mut reports = Vec::new();
    for p in &props {
        bar.set_message(p.info().name.to_string());
        let r = theorems::run_property(p.as_ref(), &settings, &|d| bar.inc(d))?;
        reports.push(r);
    }
    bar.finish_and_clear();

    // counterexample files
    let mut files: Vec<Option<PathBuf>> = Vec::new();
    for r in &reports {
        match &r.counterexample {
            Some(c) => {
                let suffix = if a.negative_control { "-negative-control" } else { "" };
                let path = a.out.join(format!("{}{}.{}", r.name, suffix, c.extension));
                crate::output::write_atomic(&path, c.text.as_bytes())
                    .with_context(|| format!("writing counterexample {}", path.display()))?;
                files.push(Some(path));
            }
            None => files.push(None),
        }
    }

    if a.json {
        let v: Vec<serde_json::Value> = reports.iter().zip(&files).map(|(r, f)| report_json(r, f.as_ref())).collect();
        println!(
            "{}",
            serde_json::to_string_pretty(
                &serde_json::json!({ "seed": a.seed, "variant": if a.negative_control { "negative_control" } else { "claim" }, "results": v })
            )?
        );
    } else {
        println!(
            "{:<14} {:<10} {:>9} {:>8} {:>12} {:>10} {:>8}",
            "result", "label", "cases", "skipped", "min slack", "violations", "time"
        );
        for r in &reports {
            println!(
                "{:<14} {:<10} {:>9} {:>8} {:>12} {:>10} {:>7.2}s",
                r.name,
                r.label,
                r.cases,
                r.skipped,
                fmt_slack(r.min_slack),
                r.violations,
                r.seconds
            );
        }
        for (r, f) in reports.iter().zip(&files) {
            if let (Some(c), Some(f)) = (&r.counterexample, f) {
                println!("{} {}: {} -> {}", r.name, r.label, c.summary, f.display());
            }
        }
        if a.negative_control {
            println!("(negative controls: every property must show violations)");
        }
    }
    let bad = if a.negative_control {
        reports.iter().any(|r| r.violations == 0)
    } else {
        reports.iter().any(|r| r.violations > 0)
    };
    Ok(if bad { ExitCode::from(1) } else { ExitCode::SUCCESS })
}
