//! The worked example of NOTES.md (a = 1 and a = 5) through `bounds::assemble`, and the
//! bad-input cases of `assemble` (non-Hurwitz F, no period, polytope with R infinite).
#![allow(non_snake_case)]
use bounds::BoundsError;
use bounds::{assemble, ThetaSettings};

fn load(name: &str) -> model::System {
    model::load(std::path::Path::new(&format!("{}/../../examples/{name}", env!("CARGO_MANIFEST_DIR")))).unwrap()
}

#[test]
fn worked_example_theta_is_negative_verified_and_above_the_measured_rate() {
    for (file, expect) in [("worked-example.toml", -0.02), ("worked-example-a5.toml", -0.04)] {
        let sys = load(file);
        let r = assemble(&sys, &ThetaSettings::default()).unwrap();
        assert!(
            r.theta < 0.0 && r.theta_verified && r.convergence_guaranteed,
            "{file}: theta {} verified {}",
            r.theta,
            r.theta_verified
        );
        // NOTES.md: an independent computation gives about -0.02 (a = 1) and -0.04 (a = 5).
        assert!((r.theta - expect).abs() < 0.01, "{file}: theta {}", r.theta);
        // Structure of eq. (theta): a convex combination of psi(0) and psi(gamma_inf) > -lambda.
        assert!(r.psi_inf > -r.lambda && r.psi_inf <= r.psi_0);
        assert!(r.theta <= r.psi_0 && r.theta >= r.psi_inf);
        assert!(r.kappa <= 1.0 / std::f64::consts::PI + 1e-9, "kappa {} > 1/pi for a sine", r.kappa);
        assert!((r.alpha.lower).abs() < 1e-12 && r.alpha.verified); // C E = 0
        assert!((r.mu + 0.3).abs() < 1e-12);
        assert!(r.lambda > 0.0 && r.lambda < 0.3);
        // Reality: the bound holds.
        let m = r.measured.as_ref().expect("measured side");
        assert!(m.rate <= r.theta, "{file}: measured {} > theta {}", m.rate, r.theta);
        assert!(m.path_length_per_period >= r.path_bound && m.path_length_per_period >= r.path1_bound * (1.0 - 1e-3));
        assert!(m.path_length_per_period >= r.path2.value * (1.0 - 1e-3));
        assert!(m.limsup_zdot <= r.zdot_bound, "{file}: limsup |z'| {} > (zinf) {}", m.limsup_zdot, r.zdot_bound);
        assert!(r.path1_bound >= r.path_bound - 1e-12);
        // Stationary set: the input is large, R(T) is empty (proven for p = 1).
        let st = r.stationary.as_ref().unwrap();
        assert_eq!(st.empty, Some(true));
        assert!(st.verified && st.phi.first_singular.is_none());
        // JSON has the stable keys.
        let j = r.to_json();
        for k in [
            "mu",
            "alpha",
            "lambda",
            "beta",
            "osc",
            "d",
            "eta_dot_inf",
            "d_ftheta",
            "gamma_1",
            "gamma_inf",
            "psi_0",
            "psi_inf",
            "theta",
            "theta_verified",
            "measured_rate",
            "path_bound",
            "path1_bound",
            "path_measured",
            "stationary_set_empty",
        ] {
            assert!(j.get(k).is_some_and(|v| !v.is_null()), "{file}: key {k} missing or null");
        }
    }
}

#[test]
fn theta_is_monotone_in_its_parts_negative_control() {
    // If the lower-bounded gamma_1 were replaced by a larger value, theta would drop: theta is
    // NOT a valid bound with an overestimated gamma_1 (the safe direction matters).
    let sys = load("worked-example.toml");
    let r = assemble(&sys, &ThetaSettings::bound_only()).unwrap();
    let psi = r.psi();
    assert!((psi.theta(r.gamma_1, r.gamma_inf) - r.theta).abs() < 1e-15);
    assert!(psi.theta(r.gamma_1 * 1.5, r.gamma_inf) < r.theta);
    assert!(psi.theta(r.gamma_1, r.gamma_inf * 1.5) > r.theta);
    // The output tube: C Xi_inf for p = 1 is an interval symmetric about 0; d = its width + 0.2.
    let tube = bounds::tube::OutputTube::new(&sys, &ThetaSettings::bound_only().tube).unwrap();
    let (a, b) = (tube.tube_support(&[1.0]), tube.tube_support(&[-1.0]));
    assert!((a.upper - b.upper).abs() < 1e-12);
    assert!((2.0 * a.upper + 0.2 - r.d).abs() < 1e-9, "{} vs {}", 2.0 * a.upper + 0.2, r.d);
}

#[test]
fn bad_inputs_give_named_errors_or_reported_cases() {
    let sys = load("worked-example.toml");
    // Non-Hurwitz F: A + E C with a negative damping.
    let mut bad = sys.clone();
    bad.A[(1, 1)] = 0.6;
    match assemble(&bad, &ThetaSettings::bound_only()) {
        Err(BoundsError::NotHurwitz { mu }) => assert!(mu > 0.0),
        other => panic!("expected NotHurwitz, got {other:?}"),
    }
    // No period.
    let zero = sys.with_input(model::Input::Zero { m: 1 });
    assert!(matches!(assemble(&zero, &ThetaSettings::bound_only()), Err(BoundsError::NoPeriod { kind: "zero" })));
    // Polytope: R infinite, gamma = 0, theta = psi(0) (reported, not an error).
    let poly = load("polytope-p2.toml");
    let r = assemble(&poly, &ThetaSettings::bound_only()).unwrap();
    assert!(r.R.is_infinite() && r.gamma_1 == 0.0 && r.gamma_inf == 0.0);
    assert_eq!(r.theta, r.psi_0);
    assert!(r.theta > 0.0 && !r.convergence_guaranteed, "alpha = 0 gives psi(0) > 0");
    assert!(r.theta_profile == r.theta_star && r.profile_intervals == 0, "no profile without strong convexity");
    assert!(!r.theta_engaged_verified && r.engaged_cells == 0, "no floors without strong convexity");
    assert!(r.notes.iter().any(|n| n.contains("not strongly convex")));
}

#[test]
fn assemble_is_deterministic_and_thread_safe() {
    fn assert_send_sync<T: Send + Sync>() {}
    assert_send_sync::<bounds::ThetaReport>();
    let sys = load("ellipse-p2.toml");
    let s = ThetaSettings::bound_only();
    let reference = assemble(&sys, &s).unwrap();
    let results: Vec<f64> = std::thread::scope(|sc| {
        let hs: Vec<_> = (0..3).map(|_| sc.spawn(|| assemble(&sys, &s).unwrap().theta)).collect();
        hs.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for t in results {
        assert_eq!(t.to_bits(), reference.theta.to_bits());
    }
    // psi as a function and the tube support function are usable from the report.
    let psi = reference.psi();
    assert!(psi.eval(0.0) == reference.psi_0 && psi.limit() == -reference.lambda);
    let tube = bounds::tube::OutputTube::new(&sys, &s.tube).unwrap();
    let up = tube.support_upper(&[1.0, 0.0]);
    assert!(up > tube.tube_support(&[1.0, 0.0]).upper);
}

#[test]
fn theta_star_is_sharper_and_verified_on_the_worked_example() {
    let sys = load("worked-example.toml");
    let r = assemble(&sys, &ThetaSettings::bound_only()).unwrap();
    assert!((r.theta + 0.017232).abs() < 1e-5, "paper's theta unchanged: {}", r.theta);
    assert!(r.theta_star <= -0.095 && r.theta_star_verified, "theta* = {}", r.theta_star);
    assert!(r.gamma_1_star >= r.gamma_1 && r.kappa_star <= 1.0);
    // theta_profile (time-resolved chord, beyond the paper): at least as sharp as theta*, and
    // the best verified bound.
    assert!(r.theta_profile_verified && r.theta_profile <= r.theta_star, "{} vs {}", r.theta_profile, r.theta_star);
    assert!(r.theta_profile <= -0.11, "theta_profile = {}", r.theta_profile);
    // theta_engaged (speed floors where the backlash is engaged, p = 1; issue 15's target for a
    // bound beyond the paper is <= -0.15, measured -0.325): the best verified bound.
    assert!(r.theta_engaged_verified && r.theta_engaged <= r.theta_profile);
    assert!(r.theta_engaged <= -0.15 && r.engaged_cells > 0, "theta_engaged = {}", r.theta_engaged);
    assert_eq!((r.theta_best_method, r.theta_best), ("theta_engaged", r.theta_engaged));
    // Negative control: an overestimated path (d ignored) gives a smaller, invalid theta*.
    let psi = bounds::Psi { alpha: r.alpha.lower, lambda: r.lambda_star, beta: r.beta_star };
    let too_long = (r.osc * 2.0) / (r.period * r.R);
    assert!(psi.theta(too_long, r.gamma_inf) < r.theta_star);
}

/// psi(0) >= 0 for every admissible Pi (proofs-notes/psi0.md): the tool's psi(0), evaluated at
/// b_hat >= beta and alpha_lower <= alpha and rounded up, is never negative on the examples.
#[test]
fn psi_at_zero_is_never_negative_on_the_examples() {
    for name in ["worked-example.toml", "worked-example-a5.toml", "ellipse-p2.toml", "lens-p2.toml", "polytope-p2.toml"]
    {
        let r = assemble(&load(name), &ThetaSettings::bound_only()).unwrap();
        assert!(r.psi_0 >= 0.0, "{name}: psi(0) = {}", r.psi_0);
        for &(l, b, _) in &r.curve {
            let psi = bounds::Psi { alpha: r.alpha.lower, lambda: l, beta: b };
            assert!(psi.at_zero() >= 0.0, "{name}: psi(0) = {} at lambda = {l}", psi.at_zero());
        }
    }
}

/// theta_engaged for balls and ellipsoids in R^2 and R^3 (proofs-notes/theta-engaged-balls.md):
/// on the ellipse and ellipsoid examples the contact floors engage, `theta_engaged` is verified
/// and at most `theta_profile`; on the lens (an intersection of discs, no curvature bound) it
/// is not computed. Before the contact floors no p >= 2 system had an engaged cell.
#[test]
fn contact_floors_engage_on_the_p2_and_p3_examples() {
    let s = ThetaSettings::bound_only();
    for name in ["ellipse-p2.toml", "ellipsoid-p3.toml"] {
        let r = assemble(&load(name), &s).unwrap();
        eprintln!(
            "{name}: theta_profile {} theta_engaged {} ({} of {} cells engaged) verified {}",
            r.theta_profile, r.theta_engaged, r.engaged_cells, r.profile_cells, r.theta_engaged_verified
        );
        assert!(r.engaged_cells > 0, "{name}: no engaged cell");
        assert_eq!(r.theta_engaged_verified, r.theta_profile_verified, "{name}");
        assert!(r.theta_engaged <= r.theta_profile, "{name}");
    }
    let lens = assemble(&load("lens-p2.toml"), &s).unwrap();
    assert!(lens.engaged_cells == 0 && !lens.theta_engaged_verified);
}
