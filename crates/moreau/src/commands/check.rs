//! `check`: the property campaign of the `theorems` crate (every inequality of the paper on
//! random cases), with the counterexample of each violated property written to a file.
//! `negative_control` runs the deliberately wrong variants, each of which must fail. Budget
//! (in [`plan`]): the cases per property ([`crate::budget::cases`]).
use anyhow::Context;
use std::path::PathBuf;
use theorems::{CampaignSettings, Property, PropertyReport, Variant};

/// Options of `check` (the CLI's `--cases`, `--seed`, `--only`, `--negative-control`,
/// `--out`).
#[derive(Debug, Clone, Default)]
pub struct CheckOptions {
    /// Cases per property (default: each property's own).
    pub cases: Option<u64>,
    pub seed: u64,
    /// One property (name or equation label).
    pub only: Option<String>,
    pub negative_control: bool,
    /// Directory for counterexample files; `None` writes none.
    pub out: Option<PathBuf>,
}

/// What a campaign reports while it runs (a progress bar); every method defaults to nothing.
pub trait CheckProgress: Sync {
    /// A property starts.
    fn property(&self, _name: &str) {}
    /// `done` more cases finished.
    fn cases(&self, _done: u64) {}
}

impl CheckProgress for () {}

/// A validated campaign: the selected properties and their settings.
pub struct CheckPlan {
    options: CheckOptions,
    settings: CampaignSettings,
    props: Vec<Box<dyn Property>>,
}

/// Validates the options and the budget, selects the properties.
pub fn plan(o: &CheckOptions) -> anyhow::Result<CheckPlan> {
    if o.cases == Some(0) {
        anyhow::bail!("--cases must be at least 1, got 0");
    }
    if let Some(c) = o.cases {
        crate::budget::cases(c)?;
    }
    let variant = if o.negative_control { Variant::NegativeControl } else { Variant::Claim };
    let settings = CampaignSettings { cases: o.cases, seed: o.seed, only: o.only.clone(), variant };
    let props = theorems::campaign::select(theorems::registry(), o.only.as_deref())?;
    Ok(CheckPlan { options: o.clone(), settings, props })
}

impl CheckPlan {
    /// Cases of the whole campaign (for a progress bar).
    pub fn total_cases(&self) -> u64 {
        self.props.iter().map(|p| self.options.cases.unwrap_or(p.info().default_cases)).sum()
    }

    /// Runs every property, then writes the counterexample files (into `out`, when given).
    pub fn run(self, progress: &dyn CheckProgress) -> anyhow::Result<CheckRun> {
        let mut reports = Vec::new();
        for p in &self.props {
            progress.property(p.info().name);
            reports.push(theorems::run_property(p.as_ref(), &self.settings, &|d| progress.cases(d))?);
        }
        let o = self.options;
        let mut files = Vec::new();
        for r in &reports {
            files.push(match (&r.counterexample, &o.out) {
                (Some(c), Some(dir)) => {
                    let suffix = if o.negative_control { "-negative-control" } else { "" };
                    let path = dir.join(format!("{}{}.{}", r.name, suffix, c.extension));
                    crate::output::write_atomic(&path, c.text.as_bytes())
                        .with_context(|| format!("writing counterexample {}", path.display()))?;
                    Some(path)
                }
                _ => None,
            });
        }
        Ok(CheckRun { seed: o.seed, negative_control: o.negative_control, reports, files })
    }
}

/// The result of `check`: one report per property and its counterexample file.
pub struct CheckRun {
    pub seed: u64,
    pub negative_control: bool,
    pub reports: Vec<PropertyReport>,
    pub files: Vec<Option<PathBuf>>,
}

impl CheckRun {
    /// Whether the command exits with status 1: a violated claim, or a negative control that
    /// held.
    pub fn failed(&self) -> bool {
        if self.negative_control {
            self.reports.iter().any(|r| r.violations == 0)
        } else {
            self.reports.iter().any(|r| r.violations > 0)
        }
    }

    /// The JSON object of `moreau check --json` (`seed`, `variant`, `results`).
    pub fn to_json(&self) -> serde_json::Value {
        let v: Vec<serde_json::Value> =
            self.reports.iter().zip(&self.files).map(|(r, f)| report_json(r, f.as_ref())).collect();
        serde_json::json!({ "seed": self.seed, "variant": if self.negative_control { "negative_control" } else { "claim" }, "results": v })
    }
}

/// One property's entry of the JSON results.
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
