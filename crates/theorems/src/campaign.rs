//! The campaign runner shared by `cargo test -p theorems` and `moreau check`.
//!
//! Deterministic given the seed: the cases of a property are split into chunks of a size
//! that depends only on the number of cases; chunk `k` of property `name` draws from a ChaCha
//! generator seeded with `splitmix(seed, name, k)`, so the result does not depend on the
//! number of threads (chunks run in parallel with rayon and are merged in order).
use crate::properties::{self, ChunkResult, Counterexample, Property, Variant};
pub use crate::seeding::chunk_rng;
use rayon::prelude::*;
use std::time::Instant;

/// Errors of the campaign runner.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum CampaignError {
    #[error("unknown property '{name}' (known: {known})")]
    UnknownProperty { name: String, known: String },
    #[error("--cases must be at least 1, got {cases}")]
    ZeroCases { cases: u64 },
}

/// Campaign settings.
#[derive(Debug, Clone)]
pub struct CampaignSettings {
    /// Cases per property; `None` uses each property's `default_cases`.
    pub cases: Option<u64>,
    /// Master seed. Default `0`.
    pub seed: u64,
    /// Run only the property with this name (or label, e.g. `lem1:2`).
    pub only: Option<String>,
    /// Claim or negative control. Default: the claim.
    pub variant: Variant,
}

impl Default for CampaignSettings {
    fn default() -> Self {
        Self { cases: None, seed: 0, only: None, variant: Variant::Claim }
    }
}

/// Report of one property.
#[derive(Debug, Clone)]
pub struct PropertyReport {
    pub name: &'static str,
    pub label: &'static str,
    pub title: &'static str,
    pub variant: Variant,
    /// Cases generated (checked + skipped).
    pub cases: u64,
    /// Cases outside the hypotheses (not checked).
    pub skipped: u64,
    /// Minimum normalised slack over the checked cases (`+inf` if none checked).
    pub min_slack: f64,
    pub violations: u64,
    /// Global index of the first violated case.
    pub first_violation: Option<u64>,
    /// Its shrunk counterexample.
    pub counterexample: Option<Counterexample>,
    pub seconds: f64,
}

/// Every property of the paper that this crate checks, in the paper's order.
pub fn registry() -> Vec<Box<dyn Property>> {
    vec![
        Box::new(properties::pp::property()),
        Box::new(properties::zy::property()),
        Box::new(properties::lemma2::property()),
        Box::new(properties::lemma_a1::property()),
        Box::new(properties::lemma_a2::property()),
        Box::new(properties::rr::property()),
        Box::new(properties::lemma_b::property()),
        Box::new(properties::theorem1::property()),
        Box::new(properties::theorem2::property_path()),
        Box::new(properties::theorem2::property_zinf()),
        Box::new(properties::qzdot::property()),
        Box::new(properties::psi0::property()),
    ]
}

/// Selects properties by name or label (`lemma_a2`, `(lem1:2)` or `lem1:2`).
pub fn select(all: Vec<Box<dyn Property>>, only: Option<&str>) -> Result<Vec<Box<dyn Property>>, CampaignError> {
    let Some(want) = only else { return Ok(all) };
    let w = want.trim().trim_start_matches('(').trim_end_matches(')').to_ascii_lowercase();
    let known: Vec<String> = all.iter().map(|p| p.info().name.to_string()).collect();
    let sel: Vec<Box<dyn Property>> = all
        .into_iter()
        .filter(|p| {
            let i = p.info();
            i.name.eq_ignore_ascii_case(&w)
                || i.label.trim_start_matches('(').trim_end_matches(')').eq_ignore_ascii_case(&w)
        })
        .collect();
    if sel.is_empty() {
        return Err(CampaignError::UnknownProperty { name: want.to_string(), known: known.join(", ") });
    }
    Ok(sel)
}

/// Chunk size for `cases` cases: at most 1024, at least 1, about 16 chunks for small runs.
pub fn chunk_size(cases: u64) -> u64 {
    cases.div_ceil(16).clamp(1, 1024)
}

/// Runs one property; `progress(k)` is called with the number of cases finished since the
/// previous call (from several threads).
pub fn run_property(
    prop: &dyn Property,
    settings: &CampaignSettings,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<PropertyReport, CampaignError> {
    let info = prop.info();
    let cases = settings.cases.unwrap_or(info.default_cases);
    if cases == 0 {
        return Err(CampaignError::ZeroCases { cases });
    }
    let cs = chunk_size(cases);
    let chunks = cases.div_ceil(cs);
    let start = Instant::now();
    let results: Vec<ChunkResult> = (0..chunks)
        .into_par_iter()
        .map(|k| {
            let n = cs.min(cases - k * cs);
            let mut rng = chunk_rng(settings.seed, info.name, k);
            prop.run_cases(&mut rng, n, settings.variant, &mut |d| progress(d))
        })
        .collect();
    let mut rep = PropertyReport {
        name: info.name,
        label: info.label,
        title: info.title,
        variant: settings.variant,
        cases: 0,
        skipped: 0,
        min_slack: f64::INFINITY,
        violations: 0,
        first_violation: None,
        counterexample: None,
        seconds: 0.0,
    };
    for (k, r) in results.into_iter().enumerate() {
        rep.cases += r.cases;
        rep.skipped += r.skipped;
        rep.min_slack = rep.min_slack.min(r.min_slack);
        rep.violations += r.violations;
        if rep.first_violation.is_none() {
            if let Some(i) = r.first_violation {
                rep.first_violation = Some(k as u64 * cs + i);
                rep.counterexample = r.counterexample;
            }
        }
    }
    rep.seconds = start.elapsed().as_secs_f64();
    Ok(rep)
}

/// Runs the selected properties in order.
pub fn run(
    settings: &CampaignSettings,
    progress: &(dyn Fn(&str, u64) + Sync),
) -> Result<Vec<PropertyReport>, CampaignError> {
    let props = select(registry(), settings.only.as_deref())?;
    props.iter().map(|p| run_property(p.as_ref(), settings, &|d| progress(p.info().name, d))).collect()
}
