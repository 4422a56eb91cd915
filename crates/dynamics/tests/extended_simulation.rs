//! The extended-model simulator behind every command for models with `[[effects]]`:
//! effects change the trajectory, and zero-valued effects reproduce the catching-up scheme of
//! the paper's model (to the O(h) difference of the two discretisations).
#![allow(non_snake_case)]
use dynamics::trajectory::{simulate_catching_up, simulate_model, Trajectory};
use dynamics::CatchingUpSettings;

fn worked(extra: &str) -> model::System {
    let base =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/worked-example.toml")).unwrap();
    model::parse_str(&format!("{base}\n{extra}")).unwrap()
}

fn max_y_diff(a: &Trajectory, b: &Trajectory, C: &nalgebra::DMatrix<f64>) -> f64 {
    assert_eq!(a.len(), b.len());
    (0..a.len())
        .flat_map(|i| a.y_at(C, i).into_iter().zip(b.y_at(C, i)).map(|(u, v)| (u - v).abs()).collect::<Vec<_>>())
        .fold(0.0, f64::max)
}

#[test]
fn zero_effects_reproduce_the_catching_up_scheme() {
    let h = 1e-3;
    let steps = 20_000; // about 3 periods
    let nominal = worked("");
    let zero = worked("[[effects]]\nkind = \"constant_force\"\nstate = 1\nforce = 0.0\n");
    let a = simulate_catching_up(&nominal, &CatchingUpSettings { dt: h, ..Default::default() }, steps, 100).unwrap();
    let b = simulate_model(&zero, h, steps, 100).unwrap();
    let d = max_y_diff(&a, &b, &nominal.C);
    assert!(d < 5e-3, "zero effect differs from catching-up by {d}");
    // simulate_model without effects IS the catching-up scheme.
    let c = simulate_model(&nominal, h, steps, 100).unwrap();
    assert_eq!(max_y_diff(&a, &c, &nominal.C), 0.0);
}

#[test]
fn each_effect_changes_the_trajectory() {
    let h = 1e-3;
    let steps = 20_000;
    let nominal = worked("");
    let base = simulate_model(&nominal, h, steps, 100).unwrap();
    for effect in [
        "kind = \"coulomb_friction\"\nstate = 1\nlevel = 0.5",
        "kind = \"sensor_offset\"\noffset = [0.05]",
        "kind = \"input_delay\"\ndelay = 0.3",
        "kind = \"input_saturation\"\nlimit = 0.5",
        "kind = \"gap_width\"\nrelative_change = 2.0",
        "kind = \"backlash_inertia\"\nmass = 0.2\ndamping = 1.0",
    ] {
        let sys = worked(&format!("[[effects]]\n{effect}\n"));
        let tr = simulate_model(&sys, h, steps, 100).unwrap();
        let d = max_y_diff(&base, &tr, &nominal.C);
        assert!(d > 1e-3, "{effect}: y changed by only {d}");
    }
}

#[test]
fn sensor_offset_is_in_the_output_exactly() {
    let sys = worked("[[effects]]\nkind = \"sensor_offset\"\noffset = [0.05]\n");
    let zero = worked("[[effects]]\nkind = \"sensor_offset\"\noffset = [0.0]\n");
    let a = simulate_model(&sys, 1e-3, 5000, 50).unwrap();
    let b = simulate_model(&zero, 1e-3, 5000, 50).unwrap();
    for i in 0..a.len() {
        let (ya, yb) = (a.y_at(&sys.C, i)[0], b.y_at(&sys.C, i)[0]);
        assert!((ya - yb - 0.05).abs() < 1e-12, "row {i}: {ya} vs {yb}");
    }
}

#[test]
fn a_coasting_backlash_output_converges_at_second_order() {
    // The worked example with a massive backlash output (time constant 1.4 s), 5 s of its sine
    // sampled at 10 ms: the output's change from K to 2K sub-steps per sample. The coasting
    // play is second order in the step away from contact events (issue 27 item 5: the plant
    // sees q change linearly while the output coasts, and a contact hands the output y's
    // velocity); it was first order (a factor 2 per doubling).
    use dynamics::extended::ExtendedModel;
    let sys = worked("");
    let inertia = [model::effects::Effect::BacklashInertia { mass: 1.4, damping: 1.0 }];
    let dt = 0.01;
    let w: Vec<f64> = (0..500).map(|k| 3.0 * (k as f64 * dt).sin()).collect();
    let x0 = sys.x0.as_slice().to_vec();
    let run = |k| ExtendedModel::new(&sys, &inertia, dt, k).unwrap().simulate(&w, dt, &x0).y;
    let rms =
        |a: &[f64], b: &[f64]| (a.iter().zip(b).map(|(u, v)| (u - v).powi(2)).sum::<f64>() / a.len() as f64).sqrt();
    let change: Vec<f64> = [2, 4, 8, 16].iter().map(|&k| rms(&run(k), &run(2 * k))).collect();
    eprintln!("changes K -> 2K for K = 2, 4, 8, 16: {change:?}");
    assert!(change.iter().all(|c| *c > 0.0), "the effect does nothing: {change:?}");
    // Over three doublings a first-order scheme shrinks the change 8 times, a second-order one
    // 64 times.
    assert!(change[0] / change[3] > 25.0, "{change:?}");
}

/// Largest `|(x, z)_a - (x, z)_b|_inf` over the samples the two trajectories share.
fn max_state_diff(a: &Trajectory, b: &Trajectory) -> f64 {
    (0..a.len().min(b.len()))
        .flat_map(|i| {
            a.x_at(i).iter().chain(a.z_at(i)).zip(b.x_at(i).iter().chain(b.z_at(i))).map(|(u, v)| (u - v).abs())
        })
        .fold(0.0, f64::max)
}

/// The extended-model simulator lets the plant see `q = z - y` change over a step where the
/// play is free (`Psi1 E dq`, `dq` from the output's velocity), instead of holding it: away
/// from contact events it is second order in the step. Against the event-driven reference on
/// the worked example its error falls by more than 3 per halving of the step; the paper's
/// catching-up scheme (the negative control) falls by about 2.
#[test]
fn the_extended_simulator_is_second_order_with_a_play() {
    use dynamics::extended::simulate_trajectory;
    use dynamics::integrators::event_driven::{event_driven, EventDrivenSettings};
    let sys = worked("");
    let t_end = 4.0 * sys.period().unwrap();
    let n0 = (t_end / 1e-2).ceil() as usize;
    let h0 = t_end / n0 as f64;
    let (reference, events) =
        event_driven(&sys, &EventDrivenSettings { dt_out: h0, t_end, ..Default::default() }).unwrap();
    assert!(events > 0, "the reference must have contact events");
    let (mut ext, mut cu) = (Vec::new(), Vec::new());
    for l in 0..4 {
        let r = 1usize << l;
        let h = h0 / r as f64;
        ext.push(max_state_diff(&reference, &simulate_trajectory(&sys, h, n0 * r, r).unwrap()));
        let cs = CatchingUpSettings { dt: h, hold: dynamics::InputHold::Foh };
        cu.push(max_state_diff(&reference, &simulate_catching_up(&sys, &cs, n0 * r, r).unwrap()));
    }
    let ratios = |e: &[f64]| e.windows(2).map(|w| w[0] / w[1]).collect::<Vec<_>>();
    let (re, rc) = (ratios(&ext), ratios(&cu));
    eprintln!("extended {ext:?} ratios {re:?}; catching-up {cu:?} ratios {rc:?}");
    assert!(re.iter().all(|&r| r > 3.0), "extended: {ext:?}");
    assert!(rc.iter().all(|&r| r < 2.6), "catching-up (control): {cu:?}");
}
