//! `eta_T` in closed form for a multisine input (bounds::orbit::multisine, issue 29 item 2):
//! the sum of phasor orbits against an independent fine-grid solution of the linearised system,
//! `osc` from below and `||eta_T'||_inf` from above against a much finer sampling (negative
//! control: the samples' own maximum, without the Lipschitz slack, misses the supremum on a
//! coarse grid), a single harmonic equal to the sine's closed form, and the theta certificate
//! on the worked example against a simulation of the same input.
use bounds::orbit::{EtaOrbit, OrbitSettings};
use dynamics::periodic::linearised::{linearised_periodic, LinearisedSettings};
use model::input::Harmonic;
use model::Input;

const MULTISINE: &str =
    "kind = \"multisine\"\nharmonics = [1, 3, 5]\nweights = [1.0, 0.3, 0.1]\nphases = [0.0, 0.4, 1.0]";

fn worked(input: &str) -> model::System {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/worked-example.toml")).unwrap();
    model::parse_str(&text.replace("kind = \"sine\"", input)).unwrap()
}

#[test]
fn multisine_orbit_is_verified_and_encloses_a_fine_grid_solution() {
    for phase in [0.0, 0.9] {
        let mut sys = worked(MULTISINE);
        if let Input::Multisine { phase: p, .. } = &mut sys.input {
            *p = phase;
        }
        let o = EtaOrbit::new(&sys, &OrbitSettings::default()).unwrap();
        assert!(o.verified && o.rel_margin < 1e-9, "{} margin {}", o.method, o.rel_margin);
        assert!(o.method.contains("multisine"), "{}", o.method);
        // an independent solution: the first-order-hold grid map, 64 sub-steps per sample
        let lp = linearised_periodic(&sys, &LinearisedSettings { samples: 2000, substeps: 64 }).unwrap();
        let err = o.eta.iter().zip(&lp.eta).map(|(a, b)| (a[0] - b[0]).abs()).fold(0.0, f64::max);
        assert!(err < 1e-4, "phase {phase}: closed form vs grid differ by {err:e}");
        // a finer sampling of the same closed form: osc below, sup |eta'| above, and close
        let fine = EtaOrbit::new(&sys, &OrbitSettings { samples: 16_000 }).unwrap();
        assert!(o.osc <= fine.osc_sampled() * (1.0 + 1e-9), "{} > {}", o.osc, fine.osc_sampled());
        assert!(o.eta_dot_inf >= fine.eta_dot_sampled(), "{} < {}", o.eta_dot_inf, fine.eta_dot_sampled());
        assert!(o.eta_dot_inf <= 1.01 * fine.eta_dot_sampled(), "{} vs {}", o.eta_dot_inf, fine.eta_dot_sampled());
        assert!(o.osc >= 0.999 * fine.osc_sampled(), "{} vs {}", o.osc, fine.osc_sampled());
    }
}

#[test]
fn the_lipschitz_slack_is_what_makes_a_coarse_grid_an_upper_bound() {
    let sys = worked(MULTISINE);
    let coarse = EtaOrbit::new(&sys, &OrbitSettings { samples: 24 }).unwrap();
    let fine = EtaOrbit::new(&sys, &OrbitSettings { samples: 8_000 }).unwrap();
    let sup = fine.eta_dot_sampled();
    assert!(coarse.verified);
    assert!(coarse.eta_dot_inf >= sup, "{} < {sup}", coarse.eta_dot_inf);
    // negative control: the coarse samples' own maximum is below the supremum
    assert!(coarse.eta_dot_sampled() < sup, "{} >= {sup}", coarse.eta_dot_sampled());
}

#[test]
fn one_harmonic_is_the_sine() {
    let sine = EtaOrbit::new(&worked("kind = \"sine\"\nphase = 0.3"), &OrbitSettings::default()).unwrap();
    let mut sys = worked("kind = \"sine\"");
    sys.input = Input::Multisine {
        amplitudes: vec![1.0],
        omega: 1.0,
        phase: 0.1,
        harmonics: vec![Harmonic { k: 1, weight: 1.0, phase: 0.2 }],
    };
    let one = EtaOrbit::new(&sys, &OrbitSettings::default()).unwrap();
    assert!(one.verified && sine.verified);
    let err = one.eta.iter().zip(&sine.eta).map(|(a, b)| (a[0] - b[0]).abs()).fold(0.0, f64::max);
    assert!(err < 1e-12, "{err:e}");
    // the sine's exact osc and ||eta'|| lie within the samples' bounds
    assert!(one.osc <= sine.osc * (1.0 + 1e-9) && one.osc >= 0.999 * sine.osc, "{} vs {}", one.osc, sine.osc);
    assert!(one.eta_dot_inf >= sine.eta_dot_inf * (1.0 - 1e-9), "{} vs {}", one.eta_dot_inf, sine.eta_dot_inf);
}

#[test]
fn the_worked_example_under_a_multisine_is_certified_and_not_violated() {
    let sys = worked(MULTISINE);
    let measure = dynamics::rate::lyapunov_exponent::RateSettings {
        periods: 20,
        transient_periods: 10,
        pairs: 2,
        ..Default::default()
    };
    let settings = bounds::ThetaSettings { stationary: None, measure: Some(measure), ..Default::default() };
    let r = bounds::assemble(&sys, &settings).unwrap();
    assert!(r.theta_verified && r.theta < 0.0, "theta {} verified {}", r.theta, r.theta_verified);
    assert!(r.theta_best_verified && r.theta_best <= r.theta);
    let m = r.measured.clone().unwrap();
    // a certified bound is an upper bound of the exponent: never below what the simulation shows
    assert!(
        r.theta_best >= m.ci_low,
        "theta_best {} below the measured {} (ci_low {})",
        r.theta_best,
        m.rate,
        m.ci_low
    );
    // negative control: a gap the multisine does not move certifies nothing
    let mut wide = sys.clone();
    wide.theta = geometry::Shape::Interval(geometry::Interval::symmetric(3.0).unwrap());
    wide.z0 = &wide.C * &wide.x0;
    let r = bounds::assemble(&wide, &bounds::ThetaSettings::bound_only()).unwrap();
    assert!(!(r.theta_verified && r.theta < 0.0), "theta {} with a gap of 6", r.theta);
}
