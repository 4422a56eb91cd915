//! Design guidance of `moreau theta` (crates/moreau/src/guidance.rs) on the worked example with
//! a too-small input: the smallest certifying amplitude it reports is certified by an
//! independent bound computation, the factor just below is not (negative control), the
//! blocking term is the path (kappa), and the amplitude sensitivity has the right sign.
use bounds::{assemble, ThetaSettings};
use model::Input;
use moreau::guidance::{guidance, GuidanceSettings};

fn worked_example_with_amplitude(a: f64) -> model::System {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/worked-example.toml");
    let mut sys = model::load(std::path::Path::new(path)).unwrap();
    if let Input::Sine { amplitudes, .. } = &mut sys.input {
        amplitudes[0] = a;
    }
    sys
}

#[test]
fn smallest_certifying_amplitude_is_certified_and_the_factor_below_is_not() {
    let sys = worked_example_with_amplitude(0.2);
    let rep = assemble(&sys, &ThetaSettings::bound_only()).unwrap();
    assert!(!rep.convergence_guaranteed, "amplitude 0.2 is not certified: {}", rep.theta_best);
    let g = guidance(&sys, &rep, &GuidanceSettings::default(), &mut bounds::Memo::new());
    assert!(g.blocking.contains("kappa"), "{}", g.blocking);
    assert!(g.kappa_star < g.kappa_needed);
    let amp = g.sensitivities.iter().find(|s| s.parameter == "input.amplitude").unwrap();
    assert!(amp.derivative < 0.0, "more amplitude, more motion, smaller bound: {}", amp.derivative);
    assert!(g.large_amplitude_limit.unwrap() < 0.0);
    let a = g.amplitude.clone().expect("an amplitude certifies");
    assert!(a.factor > a.below && a.factor / a.below < 1.01, "{} {}", a.factor, a.below);
    let check = |f: f64| {
        let r = assemble(&worked_example_with_amplitude(0.2 * f), &ThetaSettings::bound_only()).unwrap();
        r.theta_best_verified && r.theta_best < 0.0
    };
    assert!(check(a.factor), "the reported factor {} certifies", a.factor);
    // Negative control: the bracket's lower end does not.
    assert!(!check(a.below), "the factor below {} must not certify", a.below);
    eprintln!("{}", g.render());
}

#[test]
fn polytope_guidance_says_no_certificate_exists() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/polytope-p2.toml");
    let sys = model::load(std::path::Path::new(path)).unwrap();
    let rep = assemble(&sys, &ThetaSettings::bound_only()).unwrap();
    let g =
        guidance(&sys, &rep, &GuidanceSettings { bisection_steps: 2, ..Default::default() }, &mut bounds::Memo::new());
    assert!(g.blocking.contains("not strongly convex") && g.amplitude.is_none(), "{}", g.blocking);
}
