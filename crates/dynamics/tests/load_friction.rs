//! `load_friction` (issue 28): Coulomb friction whose level grows with the load a transmission
//! carries, `level + k |B_j w + E_j z - sum_{i != j} A_ji x_i|`. A zero coefficient is Coulomb
//! friction bit for bit; a mass held by the actuator against nothing sticks exactly where the
//! load-raised level exceeds the actuator's force (`b w (1 - k) <= level`), and a spring's
//! force counts as load the same way.
use dynamics::extended::ExtendedModel;
use model::effects::Effect;
use model::System;
use nalgebra::dmatrix;

/// `x' = v`, `v' = -k x - c v + b w` (no play).
fn oscillator(k: f64, c: f64, b: f64) -> System {
    System::builder()
        .A(dmatrix![0.0, 1.0; -k, -c])
        .B(dmatrix![0.0; b])
        .C(dmatrix![1.0, 0.0])
        .E(dmatrix![0.0; 0.0])
        .build()
        .unwrap()
}

fn run(sys: &System, effects: &[Effect], w: &[f64], dt: f64, x0: &[f64], substeps: usize) -> Vec<f64> {
    let out = ExtendedModel::new(sys, effects, dt, substeps).unwrap().simulate(w, dt, x0);
    assert!(out.finite);
    out.x
}

#[test]
fn a_zero_coefficient_is_coulomb_friction_bit_for_bit() {
    let sys = oscillator(4.0, 0.3, 2.0);
    let dt = 1e-3;
    let w: Vec<f64> = (0..6000).map(|k| (1.3 * k as f64 * dt).sin()).collect();
    let coulomb = run(&sys, &[Effect::CoulombFriction { state: 1, level: 0.4 }], &w, dt, &[0.0, 0.0], 2);
    let load0 =
        run(&sys, &[Effect::LoadFriction { state: 1, level: 0.4, load_coefficient: 0.0 }], &w, dt, &[0.0, 0.0], 2);
    assert_eq!(coulomb, load0);
    // Negative control: a nonzero coefficient changes the trajectory.
    let load =
        run(&sys, &[Effect::LoadFriction { state: 1, level: 0.4, load_coefficient: 0.3 }], &w, dt, &[0.0, 0.0], 2);
    let d = coulomb.iter().zip(&load).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(d > 1e-2, "max difference {d}");
}

#[test]
fn the_actuator_is_held_while_its_force_stays_below_the_load_raised_level() {
    // A free mass (no spring) pushed by a constant input w: load b w, level 0.1 + 0.5 b w.
    // It stays at rest iff b w (1 - 0.5) <= 0.1, i.e. w <= 0.2 for b = 1.
    let sys = oscillator(0.0, 0.0, 1.0);
    let eff = [Effect::LoadFriction { state: 1, level: 0.1, load_coefficient: 0.5 }];
    let dt = 1e-3;
    for (w0, moves) in [(0.15, false), (0.19, false), (0.21, true), (0.3, true)] {
        let w = vec![w0; 2000];
        let x = run(&sys, &eff, &w, dt, &[0.0, 0.0], 4);
        let end = x[x.len() - 2];
        assert_eq!(end.abs() > 1e-9, moves, "w = {w0}: end position {end}");
        if moves {
            // Sliding: the acceleration is b w - (0.1 + 0.5 b w) over 2 s (from rest).
            let want = 0.5 * (0.5 * w0 - 0.1) * 2.0f64.powi(2);
            assert!((end / want - 1.0).abs() < 2e-3, "w = {w0}: {end} against {want}");
        }
    }
    // Negative control: plain Coulomb friction of the same level lets w = 0.15 slide.
    let x = run(&sys, &[Effect::CoulombFriction { state: 1, level: 0.1 }], &[0.15; 2000], dt, &[0.0, 0.0], 4);
    assert!(x[x.len() - 2] > 1e-3);
}

#[test]
fn a_spring_pulling_against_the_transmission_is_load_too() {
    // v' = -k x with the mass released at x0, no input: the spring's force k x0 is the
    // load (d = 0, e = -k x0), the level 0.1 + 0.5 k x0, so the mass stays iff
    // k x0 (1 - 0.5) <= 0.1: x0 <= 0.05 for k = 4.
    let sys = oscillator(4.0, 0.0, 1.0);
    let eff = [Effect::LoadFriction { state: 1, level: 0.1, load_coefficient: 0.5 }];
    for (x0, moves) in [(0.045, false), (0.055, true)] {
        let x = run(&sys, &eff, &[0.0; 500], 1e-3, &[x0, 0.0], 4);
        let moved = x.chunks(2).map(|s| (s[0] - x0).abs()).fold(0.0, f64::max);
        assert_eq!(moved > 1e-9, moves, "x0 = {x0}: moved {moved}");
    }
}

#[test]
fn the_load_dependent_level_converges_with_the_sub_steps() {
    // The level is taken at each step's start (first order): the trajectory's change from K
    // to 2K sub-steps shrinks about by half each time.
    let sys = oscillator(4.0, 0.3, 2.0);
    let eff = [Effect::LoadFriction { state: 1, level: 0.2, load_coefficient: 0.4 }];
    let dt = 5e-3;
    let w: Vec<f64> = (0..1200).map(|k| 1.5 * (2.0 * k as f64 * dt).sin()).collect();
    let at = |k| run(&sys, &eff, &w, dt, &[0.0, 0.0], k);
    let (a, b, c) = (at(4), at(8), at(16));
    let diff = |u: &[f64], v: &[f64]| u.iter().zip(v).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max);
    let (d1, d2) = (diff(&a, &b), diff(&b, &c));
    assert!(d2 < 0.7 * d1 && d2 > 0.0, "changes {d1:e} then {d2:e}");
}
