//! `moreau check [--cases N] [--seed S] [--only NAME] [--json] [--negative-control] [--out DIR]`:
//! runs the property campaign of the `theorems` crate (every inequality of the paper on
//! random cases) and prints, per result, the equation label, cases, minimum normalised slack,
//! violations and time. Exit status 1 on any violation; the shrunk counterexample of each
//! violated property is written to `DIR/<name>.toml` (a model file for properties on a
//! system, the set and points for geometric ones).
//!
//! `--negative-control` runs the deliberately wrong variants instead: there every property
//! must produce a counterexample, and the exit status is 1 if one of them does not.
use crate::commands::check::{self, CheckOptions, CheckProgress};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::PathBuf;
use std::process::ExitCode;

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

/// The progress bar of a campaign.
struct Bar(ProgressBar);

impl CheckProgress for Bar {
    fn property(&self, name: &str) {
        self.0.set_message(name.to_string());
    }
    fn cases(&self, done: u64) {
        self.0.inc(done);
    }
}

pub fn run(a: &Args) -> anyhow::Result<ExitCode> {
    let o = CheckOptions {
        cases: a.cases,
        seed: a.seed,
        only: a.only.clone(),
        negative_control: a.negative_control,
        out: Some(a.out.clone()),
    };
    let plan = check::plan(&o)?;
    let bar = if a.json {
        ProgressBar::hidden()
    } else {
        ProgressBar::with_draw_target(Some(plan.total_cases()), ProgressDrawTarget::stderr())
    };
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} [{elapsed_precise}] {bar:30} {pos}/{len} cases, {per_sec}, about {eta} left {msg}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let bar = Bar(bar);
    let run = plan.run(&bar)?;
    bar.0.finish_and_clear();
    if a.json {
        println!("{}", serde_json::to_string_pretty(&run.to_json())?);
    } else {
        println!(
            "{:<14} {:<10} {:>9} {:>8} {:>12} {:>10} {:>8}",
            "result", "label", "cases", "skipped", "min slack", "violations", "time"
        );
        for r in &run.reports {
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
        for (r, f) in run.reports.iter().zip(&run.files) {
            if let (Some(c), Some(f)) = (&r.counterexample, f) {
                println!("{} {}: {} -> {}", r.name, r.label, c.summary, f.display());
            }
        }
        if a.negative_control {
            println!("(negative controls: every property must show violations)");
        }
    }
    Ok(if run.failed() { ExitCode::from(1) } else { ExitCode::SUCCESS })
}
