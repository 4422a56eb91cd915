//! `load_friction` in the diagnosis (issue 28): a servo whose transmission's friction grows
//! with the load it carries (the BAM XL330's gearbox) is diagnosed as such, its load
//! coefficient recovered, and a plain Coulomb friction is not read as load-dependent.
//!
//! The truth is simulated with the extended model itself at 256 sub-steps per sample (the
//! load-dependent level is taken at each sub-step's start, first order); a check asserts that
//! halving the truth's step moves its output by less than a twentieth of the noise.
use discovery::{diagnose, DiagnoseSettings, Recording};
use dynamics::extended::ExtendedModel;
use model::effects::Effect;
use rand::{Rng, SeedableRng};

/// A position servo: `theta'' = -a theta - c theta' + b (w - theta)` written as the BAM
/// model file writes it (the actuator `b (w - z)` through `B` and `E`, gravity-like
/// stiffness `a` in `A`, no play).
const SERVO: &str = r#"
name = "servo with a gearbox"
[plant]
A = [[0, 1], [-5, -1.5]]
B = [0, 20]
C = [[1, 0]]
E = [0, -20]
[theta]
shape = "point"
[input]
kind = "zero"
[initial]
x0 = [0.0, 0.0]
z0 = [0.0]
"#;

const DT: f64 = 0.005;
const NOISE: f64 = 1e-3;

fn reference(t: f64) -> f64 {
    let tau = std::f64::consts::TAU;
    0.5 * (tau * 0.35 * t).sin() + 0.25 * (tau * 0.9 * t + 1.0).sin() + 0.1 * (tau * 2.3 * t + 2.0).sin()
}

/// The servo with `truth` simulated over 8 s at `substeps` per sample (noise-free output).
fn truth_output(truth: &Effect, substeps: usize) -> (Vec<f64>, Vec<f64>) {
    let sys = model::parse_str(SERVO).unwrap();
    let w: Vec<f64> = (0..1600).map(|k| reference(k as f64 * DT)).collect();
    let out =
        ExtendedModel::new(&sys, std::slice::from_ref(truth), DT, substeps).unwrap().simulate(&w, DT, &[0.0, 0.0]);
    assert!(out.finite);
    (w, out.y)
}

fn recording(truth: &Effect, seed: u64) -> Recording {
    let (w, y) = truth_output(truth, 256);
    let (_, y_half) = truth_output(truth, 512);
    let moved = y.iter().zip(&y_half).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(moved < NOISE / 20.0, "the truth is not converged: halving its step moves y by {moved:e}");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut gauss = || {
        let (u, v): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    };
    let t: Vec<f64> = (0..w.len()).map(|k| k as f64 * DT).collect();
    let y: Vec<Vec<f64>> = y.iter().map(|v| vec![v + NOISE * gauss()]).collect();
    Recording::from_samples("servo.csv", &t, w.iter().map(|v| vec![*v]).collect(), y, None)
}

fn selected(truth: &Effect, seed: u64) -> Vec<Effect> {
    let sys = model::parse_str(SERVO).unwrap();
    let r = diagnose(&sys, &recording(truth, seed), &DiagnoseSettings::default()).unwrap();
    eprintln!("{}", r.verdict);
    r.fitted_model.map(|m| m.effects.list).unwrap_or_default()
}

#[test]
fn a_gearbox_whose_friction_grows_with_its_load_is_named_and_measured() {
    let truth = Effect::LoadFriction { state: 1, level: 1.0, load_coefficient: 0.3 };
    let found = selected(&truth, 28);
    let k = found
        .iter()
        .find_map(|e| match e {
            Effect::LoadFriction { load_coefficient, .. } => Some(*load_coefficient),
            _ => None,
        })
        .unwrap_or_else(|| panic!("load_friction not named: {found:?}"));
    eprintln!("load coefficient {k} (truth 0.3)");
    assert!((k / 0.3 - 1.0).abs() < 0.15, "load coefficient {k} against 0.3 ({found:?})");
    // Negative control: plain Coulomb friction of a similar size is named as Coulomb
    // friction, not as a load-dependent law.
    let coulomb = Effect::CoulombFriction { state: 1, level: 2.0 };
    let found = selected(&coulomb, 29);
    assert!(!found.iter().any(|e| matches!(e, Effect::LoadFriction { .. })), "{found:?}");
    assert!(found.iter().any(|e| matches!(e, Effect::CoulombFriction { .. })), "{found:?}");
}
