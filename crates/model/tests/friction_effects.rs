//! The friction library in model files (issue 14 item 4): `stribeck_friction`,
//! `asymmetric_coulomb` and `cogging` load, are validated with errors naming the key and the
//! value, and are written back unchanged (the writer of `fitted.toml`).
use model::effects::Effect;
use model::{parse_str, to_toml_string};

const GOOD: &str = r#"
name = "t"
[plant]
A = [[0.0, 1.0], [-2.0, -0.6]]
B = [0.0, 1.0]
C = [[1.0, 0.0]]
E = [[0.0], [1.0]]
[theta]
shape = "interval"
half_width = 0.1
[input]
kind = "sine"
amplitudes = [1.0]
omega = 1.0
"#;

fn with(effect: &str) -> String {
    format!("{GOOD}\n[[effects]]\n{effect}\n")
}

fn err(effect: &str) -> String {
    match parse_str(&with(effect)) {
        Ok(_) => panic!("expected an error for\n{effect}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn new_effects_load_and_round_trip() {
    let cases = [
        (
            "kind = \"stribeck_friction\"\nstate = 1\nlevel = 0.2\nstatic_level = 0.5\nstribeck_velocity = 0.03\nviscous = 0.1",
            Effect::StribeckFriction { state: 1, level: 0.2, static_level: 0.5, stribeck_velocity: 0.03, viscous: 0.1 },
        ),
        (
            // `viscous` is optional (default 0).
            "kind = \"stribeck_friction\"\nstate = 1\nlevel = 0.2\nstatic_level = 0.2\nstribeck_velocity = 1",
            Effect::StribeckFriction { state: 1, level: 0.2, static_level: 0.2, stribeck_velocity: 1.0, viscous: 0.0 },
        ),
        (
            "kind = \"asymmetric_coulomb\"\nstate = 1\nlevel_positive = 0.3\nlevel_negative = 0.1",
            Effect::AsymmetricCoulomb { state: 1, level_positive: 0.3, level_negative: 0.1 },
        ),
        (
            "kind = \"cogging\"\nstate = 1\nposition_state = 0\namplitude = -0.4\nperiod = 0.25\nphase = 1.5",
            Effect::Cogging { state: 1, position_state: 0, amplitude: -0.4, period: 0.25, phase: 1.5 },
        ),
        (
            "kind = \"load_friction\"\nstate = 1\nlevel = 0.02\nload_coefficient = 0.27",
            Effect::LoadFriction { state: 1, level: 0.02, load_coefficient: 0.27 },
        ),
        (
            // `phase` is optional (default 0).
            "kind = \"cogging\"\nstate = 1\nposition_state = 0\namplitude = 0.4\nperiod = 0.25",
            Effect::Cogging { state: 1, position_state: 0, amplitude: 0.4, period: 0.25, phase: 0.0 },
        ),
    ];
    for (text, want) in cases {
        let sys = parse_str(&with(text)).unwrap_or_else(|e| panic!("{text}: {e}"));
        assert_eq!(sys.effects.list, vec![want.clone()], "{text}");
        // Written back (as `diagnose` writes fitted.toml) and read again: the same effect.
        let again = parse_str(&to_toml_string(&sys)).unwrap();
        assert_eq!(again.effects.list, vec![want], "{text}");
    }
}

#[test]
fn bad_values_name_the_key_and_the_value() {
    let cases = [
        (
            "kind = \"stribeck_friction\"\nstate = 1\nlevel = 0.5\nstatic_level = 0.2\nstribeck_velocity = 0.1",
            &["effects[0].static_level", "0.2", "at least `level` = 0.5"][..],
        ),
        (
            "kind = \"stribeck_friction\"\nstate = 1\nlevel = -0.5\nstatic_level = 0.2\nstribeck_velocity = 0.1",
            &["effects[0].level", "-0.5", "non-negative"],
        ),
        (
            "kind = \"stribeck_friction\"\nstate = 1\nlevel = 0.1\nstatic_level = 0.2\nstribeck_velocity = 0",
            &["effects[0].stribeck_velocity", "value 0", "positive"],
        ),
        (
            "kind = \"stribeck_friction\"\nstate = 1\nlevel = 0.1\nstatic_level = 0.2\nstribeck_velocity = 0.1\nviscous = -1",
            &["effects[0].viscous", "-1", "non-negative"],
        ),
        ("kind = \"stribeck_friction\"\nstate = 1\nlevel = 0.1\nstatic_level = 0.2", &["effects[0].stribeck_velocity", "missing"]),
        (
            "kind = \"stribeck_friction\"\nstate = 1\nlevel = 0.1\nstatic = 0.2\nstribeck_velocity = 0.1",
            &["effects[0].static", "unknown key"],
        ),
        (
            "kind = \"asymmetric_coulomb\"\nstate = 1\nlevel_positive = 0.3\nlevel_negative = -0.1",
            &["effects[0].level_negative", "-0.1", "non-negative"],
        ),
        (
            "kind = \"asymmetric_coulomb\"\nstate = 2\nlevel_positive = 0.3\nlevel_negative = 0.1",
            &["effects[0].state", "2", "state index"],
        ),
        (
            "kind = \"cogging\"\nstate = 1\nposition_state = 0\namplitude = 0.4\nperiod = -0.25",
            &["effects[0].period", "-0.25", "positive"],
        ),
        (
            "kind = \"cogging\"\nstate = 1\nposition_state = 1\namplitude = 0.4\nperiod = 0.25",
            &["effects[0].position_state", "must differ from `state` = 1"],
        ),
        (
            "kind = \"cogging\"\nstate = 1\nposition_state = 5\namplitude = 0.4\nperiod = 0.25",
            &["effects[0].position_state", "5", "state index"],
        ),
        (
            "kind = \"load_friction\"\nstate = 1\nlevel = 0.02\nload_coefficient = -0.1",
            &["effects[0].load_coefficient", "-0.1", "non-negative"],
        ),
        ("kind = \"load_friction\"\nstate = 1\nlevel = 0.02", &["effects[0].load_coefficient", "missing"]),
        ("kind = \"stiction\"\nstate = 1", &["effects[0].kind", "stribeck_friction", "\"stiction\""]),
    ];
    for (text, needles) in cases {
        let e = err(text);
        for n in needles {
            assert!(e.contains(n), "error for\n{text}\nis `{e}`, lacks `{n}`");
        }
    }
}
