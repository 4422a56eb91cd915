//! The friction library of the extended-model simulator (issue 14 item 4): Stribeck friction
//! with a static (breakaway) level, direction-dependent Coulomb friction and a cogging force.
//! Zero parameters reproduce the nominal model bit for bit, the degenerate cases reproduce
//! Coulomb friction, a mass sticks below breakaway and slides above, friction only dissipates
//! and cogging conserves energy up to the discretisation.
//!
//! `load_friction` (issue 28): Coulomb friction whose level grows with the load a transmission
//! carries, `level + k |B_j w + E_j z - sum_{i != j} A_ji x_i|`. A zero coefficient is Coulomb
//! friction bit for bit; a mass held by the actuator against nothing sticks exactly where the
//! load-raised level exceeds the actuator's force (`b w (1 - k) <= level`), and a spring's
//! force counts as load the same way.
#![allow(non_snake_case)]
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

fn run(sys: &System, effects: &[Effect], w: &[f64], dt: f64, x0: &[f64]) -> Vec<[f64; 2]> {
    let out = ExtendedModel::new(sys, effects, dt, 1).unwrap().simulate(w, dt, x0);
    assert!(out.finite);
    out.x.chunks(2).map(|c| [c[0], c[1]]).collect()
}

fn worked(extra: &str) -> System {
    let base =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/worked-example.toml")).unwrap();
    model::parse_str(&format!("{base}\n{extra}")).unwrap()
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(u, v)| (u - v).abs()).fold(0.0, f64::max)
}

/// The worked example (with its play) driven by its sine, 8000 samples of 1 ms.
fn worked_run(sys: &System, extra: &[Effect]) -> Vec<f64> {
    let dt = 1e-3;
    let w: Vec<f64> = (0..8000).map(|k| (k as f64 * dt).sin()).collect();
    let x0 = sys.x0.as_slice().to_vec();
    ExtendedModel::new(sys, extra, dt, 2).unwrap().simulate(&w, dt, &x0).x
}

#[test]
fn zero_parameters_are_the_nominal_bit_for_bit() {
    let sys = worked("");
    let nominal = worked_run(&sys, &[]);
    for e in [
        Effect::StribeckFriction { state: 1, level: 0.0, static_level: 0.0, stribeck_velocity: 0.1, viscous: 0.0 },
        Effect::AsymmetricCoulomb { state: 1, level_positive: 0.0, level_negative: 0.0 },
        Effect::Cogging { state: 1, position_state: 0, amplitude: 0.0, period: 0.3, phase: 1.0 },
    ] {
        let x = worked_run(&sys, std::slice::from_ref(&e));
        assert_eq!(max_diff(&x, &nominal), 0.0, "{e:?} at zero differs");
    }
    // The same through a model file: zero-valued `[[effects]]` tables.
    for t in [
        "kind = \"stribeck_friction\"\nstate = 1\nlevel = 0.0\nstatic_level = 0.0\nstribeck_velocity = 0.1",
        "kind = \"asymmetric_coulomb\"\nstate = 1\nlevel_positive = 0.0\nlevel_negative = 0.0",
        "kind = \"cogging\"\nstate = 1\nposition_state = 0\namplitude = 0.0\nperiod = 0.5",
    ] {
        let s = worked(&format!("[[effects]]\n{t}\n"));
        assert_eq!(max_diff(&worked_run(&s, &[]), &nominal), 0.0, "{t}");
    }
    // Negative control: non-zero values change the trajectory.
    for e in [
        Effect::StribeckFriction { state: 1, level: 0.2, static_level: 0.4, stribeck_velocity: 0.1, viscous: 0.0 },
        Effect::AsymmetricCoulomb { state: 1, level_positive: 0.3, level_negative: 0.0 },
        Effect::Cogging { state: 1, position_state: 0, amplitude: 0.3, period: 0.3, phase: 1.0 },
    ] {
        let x = worked_run(&sys, std::slice::from_ref(&e));
        assert!(max_diff(&x, &nominal) > 1e-3, "{e:?} changed nothing");
    }
}

#[test]
fn degenerate_laws_are_coulomb_friction() {
    let sys = worked("");
    let coulomb = worked_run(&sys, &[Effect::CoulombFriction { state: 1, level: 0.3 }]);
    // Static level equal to the sliding level: Coulomb, bit for bit (stribeck_velocity unused).
    let st =
        Effect::StribeckFriction { state: 1, level: 0.3, static_level: 0.3, stribeck_velocity: 0.05, viscous: 0.0 };
    assert_eq!(max_diff(&worked_run(&sys, &[st]), &coulomb), 0.0);
    // Equal levels per direction: Coulomb, bit for bit.
    let asym = Effect::AsymmetricCoulomb { state: 1, level_positive: 0.3, level_negative: 0.3 };
    assert_eq!(max_diff(&worked_run(&sys, &[asym]), &coulomb), 0.0);
    // Unequal levels: Coulomb at the mean level plus a constant force of half the difference
    // (the stick band [-S_-, S_+] and both sliding forces coincide), up to rounding.
    let asym = Effect::AsymmetricCoulomb { state: 1, level_positive: 0.5, level_negative: 0.1 };
    let equiv = [Effect::CoulombFriction { state: 1, level: 0.3 }, Effect::ConstantForce { state: 1, force: -0.2 }];
    let (a, b) = (worked_run(&sys, &[asym]), worked_run(&sys, &equiv));
    assert!(max_diff(&a, &b) < 1e-9, "asymmetric vs Coulomb + force: {}", max_diff(&a, &b));
    assert!(max_diff(&a, &coulomb) > 1e-2, "negative control: the asymmetry must show");
}

#[test]
fn a_mass_sticks_below_breakaway_and_slides_above() {
    // x' = v, v' = -0.1 v + w (a damped mass) with Fc = 1, Fs = 2, vs = 0.1, pushed by w.
    let sys = oscillator(0.0, 0.1, 1.0);
    let dt = 1e-3;
    let st = Effect::StribeckFriction { state: 1, level: 1.0, static_level: 2.0, stribeck_velocity: 0.1, viscous: 0.0 };
    let push = |f: f64| vec![f; 3000];
    // Between the Coulomb and the static level: stuck for good, exactly.
    let x = run(&sys, std::slice::from_ref(&st), &push(1.5), dt, &[0.0, 0.0]);
    assert!(x.iter().all(|s| s[0] == 0.0 && s[1] == 0.0), "moved below breakaway: {:?}", x.last());
    // Negative control: Coulomb friction at the sliding level lets the same push slide.
    let x = run(&sys, &[Effect::CoulombFriction { state: 1, level: 1.0 }], &push(1.5), dt, &[0.0, 0.0]);
    assert!(x.last().unwrap()[1] > 1.0);
    // Above the static level: slides, and far beyond the Stribeck velocity the friction is
    // the Coulomb level: v' = w - Fc - 0.1 v.
    let x = run(&sys, std::slice::from_ref(&st), &push(2.5), dt, &[0.0, 0.0]);
    let n = x.len();
    let acc = (x[n - 1][1] - x[n - 101][1]) / (100.0 * dt);
    let v = x[n - 51][1];
    assert!(v > 1.0, "v = {v}");
    assert!((acc - (2.5 - 1.0 - 0.1 * v)).abs() < 1e-3, "acceleration {acc} at v = {v}");
    // A slow ramp w = 0.5 t breaks away when it reaches the static level (t = 4 s) and not
    // before.
    let w: Vec<f64> = (0..6000).map(|k| 0.5 * k as f64 * dt).collect();
    let x = run(&sys, std::slice::from_ref(&st), &w, dt, &[0.0, 0.0]);
    let first = x.iter().position(|s| s[1] != 0.0).expect("breaks away");
    assert!((first as f64 * dt - 4.0).abs() <= 2.0 * dt, "broke away at t = {}", first as f64 * dt);
    // Direction-dependent levels: a push of 1.5 holds against 2 upwards, not against 1 down.
    let asym = Effect::AsymmetricCoulomb { state: 1, level_positive: 2.0, level_negative: 1.0 };
    let x = run(&sys, std::slice::from_ref(&asym), &push(1.5), dt, &[0.0, 0.0]);
    assert!(x.iter().all(|s| s[1] == 0.0));
    let x = run(&sys, &[asym], &push(-1.5), dt, &[0.0, 0.0]);
    assert!(x.last().unwrap()[1] < -1.0);
    // A viscous increment adds c_v v while sliding.
    let stv =
        Effect::StribeckFriction { state: 1, level: 1.0, static_level: 2.0, stribeck_velocity: 0.1, viscous: 0.4 };
    let x = run(&sys, &[stv], &push(2.5), dt, &[0.0, 0.0]);
    let acc = (x[n - 1][1] - x[n - 101][1]) / (100.0 * dt);
    let v = x[n - 51][1];
    assert!((acc - (2.5 - 1.0 - 0.5 * v)).abs() < 1e-3, "acceleration {acc} at v = {v}");
}

#[test]
fn stribeck_friction_makes_a_dragged_mass_stick_and_slip() {
    // A mass dragged through a spring whose end moves at V = 0.1: x'' = 10 (V t - x) - v - f.
    // Coulomb friction settles to steady sliding; a Stribeck curve steeper than the damping
    // at V (slope 1.47 > 1) makes it stick and slip periodically.
    let sys = oscillator(10.0, 1.0, 10.0);
    let dt = 1e-3;
    let w: Vec<f64> = (0..40_000).map(|k| 0.1 * k as f64 * dt).collect();
    let stuck = |e: Effect| {
        let x = run(&sys, &[e], &w, dt, &[0.0, 0.0]);
        x[20_000..].iter().filter(|s| s[1] == 0.0).count()
    };
    let st =
        Effect::StribeckFriction { state: 1, level: 1.0, static_level: 2.0, stribeck_velocity: 0.05, viscous: 0.0 };
    let n_st = stuck(st);
    let n_c = stuck(Effect::CoulombFriction { state: 1, level: 1.0 });
    assert!(n_st > 1000, "Stribeck: stuck in only {n_st} of 20000 samples");
    assert_eq!(n_c, 0, "Coulomb: stuck in {n_c} samples of the second half");
}

#[test]
fn friction_only_dissipates_and_cogging_conserves_energy() {
    // Undamped oscillator x'' = -x from x = 2: energy 0.5 (x^2 + v^2).
    let sys = oscillator(1.0, 0.0, 1.0);
    let dt = 1e-3;
    let w = vec![0.0; 30_000];
    let energy = |s: &[f64; 2]| 0.5 * (s[0] * s[0] + s[1] * s[1]);
    for e in [
        Effect::StribeckFriction { state: 1, level: 0.1, static_level: 0.3, stribeck_velocity: 0.2, viscous: 0.05 },
        Effect::AsymmetricCoulomb { state: 1, level_positive: 0.3, level_negative: 0.1 },
    ] {
        let x = run(&sys, std::slice::from_ref(&e), &w, dt, &[2.0, 0.0]);
        // Never above its past minimum by more than the O(h^2) of the held friction force
        // acting on the position within a step (|x| L h^2 / 2 <= 3e-7 here).
        let mut low = energy(&x[0]);
        let mut worst = 0.0f64;
        for s in &x[1..] {
            worst = worst.max(energy(s) - low);
            low = low.min(energy(s));
        }
        assert!(worst <= 3e-7, "{e:?}: energy rose by {worst:e} above its past minimum");
        // It comes to rest where the spring force is within the static band.
        let last = x.last().unwrap();
        assert_eq!(last[1], 0.0, "{e:?} still moving");
        let (s_up, s_down) = match e {
            Effect::StribeckFriction { static_level, .. } => (static_level, static_level),
            Effect::AsymmetricCoulomb { level_positive, level_negative, .. } => (level_positive, level_negative),
            _ => unreachable!(),
        };
        assert!(-last[0] <= s_up + 1e-12 && last[0] <= s_down + 1e-12, "{e:?}: rests at x = {}", last[0]);
        assert!(energy(last) < 0.5 * energy(&x[0]));
    }
    // Cogging is conservative: 0.5 (x^2 + v^2) + (A / k) cos(k x + phase) stays constant up to
    // the discretisation (midpoint position, force held over the step).
    let (A, P, ph) = (0.3, 0.7, 0.4);
    let kw = std::f64::consts::TAU / P;
    let cog = Effect::Cogging { state: 1, position_state: 0, amplitude: A, period: P, phase: ph };
    let total = |s: &[f64; 2]| energy(s) + A / kw * (kw * s[0] + ph).cos();
    let x = run(&sys, &[cog], &w, dt, &[2.0, 0.0]);
    let drift = x.iter().map(|s| (total(s) - total(&x[0])).abs()).fold(0.0, f64::max);
    assert!(drift < 1e-4 * total(&x[0]), "cogging energy drift {drift}");
    // Negative control: the cogging force does work (kinetic + spring energy alone varies).
    let var = x.iter().map(|s| (energy(s) - energy(&x[0])).abs()).fold(0.0, f64::max);
    assert!(var > 1e-2, "{var}");
}

/// The flat state trajectory at `substeps` per sample (`load_friction`).
fn run_sub(sys: &System, effects: &[Effect], w: &[f64], dt: f64, x0: &[f64], substeps: usize) -> Vec<f64> {
    let out = ExtendedModel::new(sys, effects, dt, substeps).unwrap().simulate(w, dt, x0);
    assert!(out.finite);
    out.x
}

#[test]
fn a_zero_coefficient_is_coulomb_friction_bit_for_bit() {
    let sys = oscillator(4.0, 0.3, 2.0);
    let dt = 1e-3;
    let w: Vec<f64> = (0..6000).map(|k| (1.3 * k as f64 * dt).sin()).collect();
    let coulomb = run_sub(&sys, &[Effect::CoulombFriction { state: 1, level: 0.4 }], &w, dt, &[0.0, 0.0], 2);
    let load0 =
        run_sub(&sys, &[Effect::LoadFriction { state: 1, level: 0.4, load_coefficient: 0.0 }], &w, dt, &[0.0, 0.0], 2);
    assert_eq!(coulomb, load0);
    // Negative control: a nonzero coefficient changes the trajectory.
    let load =
        run_sub(&sys, &[Effect::LoadFriction { state: 1, level: 0.4, load_coefficient: 0.3 }], &w, dt, &[0.0, 0.0], 2);
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
        let x = run_sub(&sys, &eff, &w, dt, &[0.0, 0.0], 4);
        let end = x[x.len() - 2];
        assert_eq!(end.abs() > 1e-9, moves, "w = {w0}: end position {end}");
        if moves {
            // Sliding: the acceleration is b w - (0.1 + 0.5 b w) over 2 s (from rest).
            let want = 0.5 * (0.5 * w0 - 0.1) * 2.0f64.powi(2);
            assert!((end / want - 1.0).abs() < 2e-3, "w = {w0}: {end} against {want}");
        }
    }
    // Negative control: plain Coulomb friction of the same level lets w = 0.15 slide.
    let x = run_sub(&sys, &[Effect::CoulombFriction { state: 1, level: 0.1 }], &[0.15; 2000], dt, &[0.0, 0.0], 4);
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
        let x = run_sub(&sys, &eff, &[0.0; 500], 1e-3, &[x0, 0.0], 4);
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
    let at = |k| run_sub(&sys, &eff, &w, dt, &[0.0, 0.0], k);
    let (a, b, c) = (at(4), at(8), at(16));
    let diff = |u: &[f64], v: &[f64]| u.iter().zip(v).map(|(p, q)| (p - q).abs()).fold(0.0, f64::max);
    let (d1, d2) = (diff(&a, &b), diff(&b, &c));
    assert!(d2 < 0.7 * d1 && d2 > 0.0, "changes {d1:e} then {d2:e}");
}
