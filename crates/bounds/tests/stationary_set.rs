//! Theorem 1: Phi(t), its first singular time, and the set R(T) of T-stationary initial
//! conditions (empty / nonempty, confirmed by simulation), with negative controls.
#![allow(non_snake_case)]
use bounds::stationary::{confirm_at_rest, phi, rest_set, scan_phi, RestSetSettings};
use nalgebra::DMatrix;

fn load(name: &str) -> model::System {
    model::load(std::path::Path::new(&format!("{}/../../examples/{name}", env!("CARGO_MANIFEST_DIR")))).unwrap()
}

fn small_input(mut sys: model::System, a: f64) -> model::System {
    if let model::Input::Sine { amplitudes, .. } = &mut sys.input {
        amplitudes.iter_mut().for_each(|x| *x *= a);
    }
    // start at rest at the origin so that only the (small) input moves y
    sys.x0.fill(0.0);
    sys.z0.fill(0.0);
    sys
}

#[test]
fn phi_matches_its_closed_form_for_a_diagonal_system() {
    // A = -1 (n = 1), C = E = 1: Phi(t) = 1 - (1 - e^{-t}).
    let A = DMatrix::from_element(1, 1, -1.0);
    let I = DMatrix::from_element(1, 1, 1.0);
    for t in [0.0f64, 0.5, 2.0] {
        assert!((phi(&A, &I, &I, t)[(0, 0)] - (-t).exp()).abs() < 1e-13);
    }
    // A lightly damped oscillator with E = [0, 0.8]: the step response overshoots 1, so
    // Phi(t) = 1 - C int e^{sA} E becomes singular although F = A + E C is Hurwitz.
    let A = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -1.0, -0.1]);
    let C = DMatrix::from_row_slice(1, 2, &[1.0, 0.0]);
    let E = DMatrix::from_row_slice(2, 1, &[0.0, 0.8]);
    let F = &A + &E * &C;
    assert!(lmi::hurwitz_mu(&F).is_ok());
    let s = scan_phi(&A, &C, &E, std::f64::consts::TAU, 400, 1e-10);
    let t = s.first_singular.expect("Phi becomes singular");
    assert!(t > 0.5 && t < std::f64::consts::PI, "t = {t}");
    assert!(phi(&A, &C, &E, t)[(0, 0)].abs() < 1e-9);
    // Negative control: with E = [0, 0.3] the step response stays below 1: no singular time.
    let E3 = DMatrix::from_row_slice(2, 1, &[0.0, 0.3]);
    assert!(scan_phi(&A, &C, &E3, std::f64::consts::TAU, 400, 1e-10).first_singular.is_none());
}

#[test]
fn small_inputs_have_stationary_points_confirmed_by_simulation() {
    for (file, a) in [("worked-example.toml", 0.01), ("ellipse-p2.toml", 0.005)] {
        let sys = small_input(load(file), a);
        let r = rest_set(&sys, &RestSetSettings::default()).unwrap();
        assert_eq!(r.empty, Some(false), "{file}: {r:?}");
        assert!(r.verified && r.max_drift.unwrap() <= 1e-9, "{file}: {r:?}");
        let z = r.point.clone().unwrap();
        // Negative control: a point outside R(T) (shifted by 3 gap widths) moves.
        let far: Vec<f64> = z.iter().map(|v| v + 0.3).collect();
        assert!(confirm_at_rest(&sys, &far, 1e-3).unwrap() > 1e-3, "{file}");
    }
}

#[test]
fn large_inputs_have_empty_stationary_sets_and_singular_phi_is_reported_not_fatal() {
    let r = rest_set(&load("ellipse-p2.toml"), &RestSetSettings::default()).unwrap();
    assert_eq!(r.empty, Some(true));
    assert!(r.slack > 0.0 && r.point.is_none());
    // Singular Phi: the oscillator of the test above as a model.
    let mut sys = load("worked-example.toml");
    sys.A = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -1.0, -0.1]);
    sys.E = DMatrix::from_row_slice(2, 1, &[0.0, 0.8]);
    let r = rest_set(&sys, &RestSetSettings::default()).unwrap();
    assert!(r.phi.first_singular.is_some());
    assert!(r.empty.is_some());
}
