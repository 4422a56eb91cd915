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
