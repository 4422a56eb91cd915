//! The multi-start phase of a finely stepped fit runs at a coarser stepping
//! (`FitSettings::start_coarsening`, issue 27 item 5); the refinement and the covariance run at
//! the problem's own. The estimate must be the one a start phase at the problem's stepping finds
//! (control: `start_coarsening = 1`), and the truth; a problem stepped too coarsely to coarsen
//! further is fitted bit for bit as before.
mod common;
use common::CoulombMass;
use discovery::fit::{self, FitResult, FitSettings, MIN_START_SUBSTEPS, START_COARSENING};

const LEVEL: f64 = 0.25;

/// A lightly damped mass (damping 0.4) with Coulomb friction, the truth stepped at 256
/// sub-steps per sample of 0.05 s.
fn case() -> CoulombMass {
    let c = CoulombMass::stepped(LEVEL, 1500, 0.4, 0.05, 256);
    assert!(c.hypothesis.starts.len() > 1, "several starts: the start phase is used");
    c
}

/// The friction fitted at `substeps` sub-steps per sample, the initial state free.
fn fit_at(c: &CoulombMass, substeps: usize, s: &FitSettings) -> FitResult {
    fit::fit(&c.problem_at(substeps), &[0.0, 0.0], &[0.2, 0.2], None, s)
}

fn bits(r: &FitResult) -> Vec<u64> {
    r.theta.iter().chain(&r.x0).chain([&r.sse]).map(|x| x.to_bits()).collect()
}

#[test]
fn a_coarser_start_phase_finds_the_estimate_of_the_fine_one() {
    let c = case();
    let fine = START_COARSENING * MIN_START_SUBSTEPS * 2;
    let coarse = fit_at(&c, fine, &FitSettings::default());
    let own = fit_at(&c, fine, &FitSettings { start_coarsening: 1, ..Default::default() });
    let (a, b) = (coarse.theta[0], own.theta[0]);
    eprintln!(
        "level at {fine} sub-steps: coarse start phase {a} +- {}, own {b} +- {}; truth {LEVEL}",
        coarse.std[0], own.std[0]
    );
    // the residual and the covariance are of the fine stepping in both
    assert_eq!(coarse.n_res, own.n_res);
    assert!((a - b).abs() <= 0.1 * own.std[0], "estimates differ by more than a tenth of a sigma: {a} vs {b}");
    assert!((a - LEVEL).abs() <= 0.02 * LEVEL, "estimate {a} vs truth {LEVEL}");
    // control: with no refinement the end point is the start phase's, and the two start
    // phases end apart (the coarse stepping was used)
    let raw = FitSettings { max_iter: 0, ..Default::default() };
    let raw_coarse = fit_at(&c, fine, &raw);
    let raw_own = fit_at(&c, fine, &FitSettings { start_coarsening: 1, ..raw.clone() });
    assert_ne!(bits(&raw_coarse), bits(&raw_own), "the start phase must have run at the coarser stepping");
}

#[test]
fn a_problem_stepped_too_coarsely_is_fitted_as_before() {
    // fewer than START_COARSENING * MIN_START_SUBSTEPS sub-steps: the start phase keeps them
    let c = case();
    let k = START_COARSENING * MIN_START_SUBSTEPS - 1;
    let raw = FitSettings { max_iter: 0, ..Default::default() };
    assert_eq!(bits(&fit_at(&c, k, &raw)), bits(&fit_at(&c, k, &FitSettings { start_coarsening: 1, ..raw.clone() })));
    assert_eq!(
        bits(&fit_at(&c, k, &FitSettings::default())),
        bits(&fit_at(&c, k, &FitSettings { start_coarsening: 1, ..Default::default() }))
    );
}
