//! The fitter's parallel Jacobian columns and starts (issue 27 item 5, speed) change no number:
//! a fit with `parallel` equals the serial fit bit for bit, and `fit_estimate` (the estimate
//! without the end point's covariance, used by the cross-validation and jackknife folds) equals
//! `fit`'s estimate.
mod common;
use discovery::fit::{self, FitSettings, FitStatus};

#[test]
fn parallel_fit_equals_the_serial_fit_and_the_estimate_alone_equals_the_fit() {
    let level = 0.25;
    let data = common::CoulombMass::new(level, 2000);
    let h = &data.hypothesis;
    // more starts than are iterated: the screening path, then several starts in parallel
    assert!(h.starts.len() > fit::levenberg_marquardt::SCREENED_STARTS);
    let pb = data.problem();
    // a free initial state: three Jacobian columns
    let (x0, xs) = ([0.0, 0.0], [0.2, 0.2]);
    let serial = FitSettings { parallel: false, ..Default::default() };
    let a = fit::fit(&pb, &x0, &xs, None, &serial);
    let b = fit::fit(&pb, &x0, &xs, None, &FitSettings::default());
    assert!(a.status == FitStatus::Converged || a.status == FitStatus::MaxIterations, "{:?}", a.status);
    assert!((a.theta[0] - level).abs() < 0.05 * level, "estimate {} vs truth {level}", a.theta[0]);
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&a.theta), bits(&b.theta));
    assert_eq!(bits(&a.x0), bits(&b.x0));
    assert_eq!(bits(&a.std), bits(&b.std));
    assert_eq!((a.sse.to_bits(), a.status, a.evaluations), (b.sse.to_bits(), b.status, b.evaluations));
    // the estimate alone: the same point, no covariance
    let e = fit::fit_estimate(&pb, &x0, &xs, None, &FitSettings::default());
    assert_eq!(bits(&e.theta), bits(&a.theta));
    assert_eq!(bits(&e.x0), bits(&a.x0));
    assert_eq!(e.sse.to_bits(), a.sse.to_bits());
    assert!(e.std.iter().all(|v| v.is_nan()) && e.evaluations < a.evaluations);
    // control: the comparison sees a change of the fit (one refinement iteration fewer)
    let c = fit::fit(&pb, &x0, &xs, None, &FitSettings { max_iter: 1, ..Default::default() });
    assert_ne!(bits(&c.theta), bits(&a.theta), "a different fit must not compare equal");
}

/// The whole diagnosis with and without rayon: the same verdict, estimates and sigmas, bit for
/// bit (the parallel levels only distribute independent fits and simulations).
#[test]
fn a_diagnosis_reads_the_same_with_and_without_parallelism() {
    let case = discovery::bench_gen::generate_profile("backlash", 5101, 0, discovery::bench_gen::Profile::Digital);
    let s = discovery::DiagnoseSettings {
        initial_state: Some(discovery::InitialState {
            x0: case.nominal.x0.iter().copied().collect(),
            z0: Some(case.nominal.z0.iter().copied().collect()),
        }),
        ..Default::default()
    };
    let run = |parallel: bool| {
        let s = discovery::DiagnoseSettings { parallel, ..s.clone() };
        discovery::diagnose(&case.nominal, &case.recording, &s).expect("the case diagnoses")
    };
    let (a, b) = (run(true), run(false));
    assert_eq!(a.selected(), "backlash");
    assert_eq!(a.selected(), b.selected());
    let numbers = |r: &discovery::Report| -> Vec<u64> {
        r.effects
            .iter()
            .flat_map(|e| e.params.iter().chain(&e.uncertainty).map(|(_, v)| v.to_bits()))
            .chain(r.ranking.iter().map(|h| h.bic.to_bits()))
            .collect()
    };
    assert!(!numbers(&a).is_empty());
    assert_eq!(numbers(&a), numbers(&b));
}
