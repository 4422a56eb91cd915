//! A model with `[[effects]]` is outside the paper's class: `assemble` computes the nominal
//! bound but never verifies it, and says which effects are to blame. Negative control: the
//! same model without the effects is verified.
use bounds::{assemble, ThetaSettings};

fn with_effects(extra: &str) -> model::System {
    let base =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/worked-example.toml")).unwrap();
    model::parse_str(&format!("{base}\n{extra}")).unwrap()
}

#[test]
fn theta_with_effects_is_never_verified() {
    let nominal = with_effects("");
    let r0 = assemble(&nominal, &ThetaSettings::bound_only()).unwrap();
    assert!(r0.theta_verified && r0.convergence_guaranteed, "negative control: the nominal model is certified");
    assert!(r0.effects.is_empty());
    for (effect, kind) in [
        ("kind = \"coulomb_friction\"\nstate = 1\nlevel = 5.0", "coulomb_friction"),
        ("kind = \"gap_width\"\nrelative_change = 9.0", "gap_width"),
        ("kind = \"backlash_inertia\"\nmass = 0.1\ndamping = 1.0", "backlash_inertia"),
        ("kind = \"input_saturation\"\nlimit = 0.5", "input_saturation"),
    ] {
        let sys = with_effects(&format!("[[effects]]\n{effect}\n"));
        let r = assemble(&sys, &ThetaSettings::bound_only()).unwrap();
        assert!(!r.theta_verified, "{kind}: theta must not be verified");
        assert!(!r.convergence_guaranteed, "{kind}");
        assert_eq!(r.effects, vec![kind.to_string()]);
        assert!(r.notes.iter().any(|n| n.contains(kind) && n.contains("outside the paper's class")), "{:?}", r.notes);
        // The nominal numbers are unchanged: the bound is the nominal model's.
        assert_eq!(r.theta, r0.theta, "{kind}");
        let j = r.to_json();
        assert_eq!(j["theta_verified"], serde_json::json!(false));
        assert_eq!(j["effects"], serde_json::json!([kind]));
    }
}
