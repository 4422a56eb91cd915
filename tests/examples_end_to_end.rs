//! Every model shipped in `examples/` through the whole chain, crate by crate:
//! `model` (parse and validate) -> `geometry` (R of Theta) -> `driver` (theta with `lmi`'s
//! certificate) -> `dynamics` (an independent measurement of the convergence exponent, with a
//! different seed, a finer step and the Euclidean norm instead of the certificate's `Pi`).
//!
//! What README promises for the examples is checked here: where theta < 0 is verified, the
//! independently measured exponent lies below it; the (zinf) bound lies above the measured
//! limsup |z'|; the path bounds (path), (path1) lie below the measured path length per period;
//! for the polytope (R infinite) the report does not claim convergence.
use dynamics::rate::lyapunov_exponent::{measure_rate, RateSettings};
use geometry::ConvexSet;
use std::path::{Path, PathBuf};

fn examples() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    v.sort();
    v
}

#[test]
fn every_example_loads_and_its_theta_holds_against_an_independent_measurement() {
    let files = examples();
    assert!(files.len() >= 5, "examples/ holds the worked example, p = 2, p = 3, polytope, lens: {files:?}");
    let mut verified_negative = 0;
    for f in &files {
        let sys = model::load(f).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        let name = f.file_name().unwrap().to_string_lossy().to_string();
        assert!(sys.mu() < 0.0, "{name}: F must be Hurwitz");
        let r = bounds::assemble(&sys, &bounds::ThetaSettings::bound_only()).unwrap_or_else(|e| panic!("{name}: {e}"));
        // geometry and driver agree on R (driver reports the safe upper value)
        let r_geom = sys.theta.strong_convexity().upper();
        assert!(r.R == r_geom || (r.R - r_geom).abs() <= 1e-12 * r_geom, "{name}: R {} vs {}", r.R, r_geom);
        // structure of eq. (theta): between psi(gamma_inf) and psi(0), above -lambda
        assert!(r.theta <= r.psi_0 + 1e-15 && r.theta >= r.psi_inf - 1e-15, "{name}");
        assert!(r.psi_inf > -r.lambda && r.lambda > 0.0 && r.lambda < -r.mu, "{name}");
        // independent measurement: 3 pairs, dt = 5e-4, 50 periods, another seed
        let rate = measure_rate(
            &sys,
            &RateSettings { dt: 5e-4, periods: 50, transient_periods: 10, pairs: 3, seed: 2026, ..Default::default() },
            None,
        )
        .unwrap();
        if r.R.is_infinite() {
            assert!(!r.convergence_guaranteed || r.psi_0 < 0.0, "{name}: R = inf, theta = psi(0) = {}", r.psi_0);
            continue;
        }
        assert!(
            r.zdot_bound >= rate.limsup_z_speed,
            "{name}: (zinf) {} < measured {}",
            r.zdot_bound,
            rate.limsup_z_speed
        );
        assert!(
            r.path_bound <= rate.path_length_per_period && r.path1_bound <= rate.path_length_per_period * (1.0 + 1e-3),
            "{name}: (path) {}, (path1) {} vs measured {}",
            r.path_bound,
            r.path1_bound,
            rate.path_length_per_period
        );
        if r.theta_verified && r.theta < 0.0 {
            verified_negative += 1;
            assert!(
                rate.ci_high <= r.theta,
                "{name}: measured exponent CI up to {} above theta {}",
                rate.ci_high,
                r.theta
            );
        }
    }
    // the worked example (a = 1, 5), the ellipse, the ellipsoid and the lens are certified
    assert!(verified_negative >= 5, "only {verified_negative} examples with verified theta < 0");
}
