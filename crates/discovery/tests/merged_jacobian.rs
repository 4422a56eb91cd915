//! The initial-state columns of the fit's finite-difference Jacobian run the perturbed
//! simulation beside the base run and take the base run's residual from the sample where the
//! two merge (`Problem::residual_merged`, `dynamics::extended::merge`): the column must be the
//! whole run's to far below the forward difference's own error, and the merge must happen
//! where the plant forgets its initial state (the control: a plant that does not forget it is
//! run whole).
mod common;
use common::CoulombMass;
use discovery::fit::levenberg_marquardt::MERGE_DECAY;

/// The forward-difference column of initial state `c` (scaled by `scale`, step `h` in scaled
/// units) by the whole run and by the run beside the base run; and whether the latter merged
/// (its tail is the base residual's, to the bit).
fn columns(c: &CoulombMass, level: f64, i: usize, scale: f64, h: f64) -> (Vec<f64>, Vec<f64>, bool) {
    let pb = c.problem();
    let theta = [level];
    let x0 = [0.1, 0.0];
    let mut xp = x0;
    xp[i] += h * scale;
    let r0 = pb.residual_to(&theta, &[], &x0, pb.k_est).unwrap();
    let whole = pb.residual_to(&theta, &[], &xp, pb.k_est).unwrap();
    let x_tol = [MERGE_DECAY * h * scale; 2];
    let beside = pb.residual_merged(&theta, &[], &x0, &xp, pb.k_est, &r0, &x_tol).expect("a free run merges");
    let merged = beside.last() == r0.last() && beside.len() == r0.len();
    let col = |r: &[f64]| r.iter().zip(&r0).map(|(a, b)| (a - b) / h).collect::<Vec<f64>>();
    (col(&whole), col(&beside), merged)
}

#[test]
fn an_initial_state_column_merged_with_the_base_run_is_the_whole_runs() {
    let c = CoulombMass::new(0.25, 3000);
    for i in 0..2 {
        let (whole, beside, merged) = columns(&c, 0.25, i, 0.2, 1e-6);
        assert!(merged, "state {i}: the damped mass forgets its initial state");
        let size = whole.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let diff = whole.iter().zip(&beside).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        eprintln!("state {i}: column max {size:.3e}, merged run differs by {diff:.3e}");
        assert!(size > 1e-6, "the column is not empty");
        assert!(diff <= 1e-6 * size, "state {i}: {diff:e} against a column of {size:e}");
        // before the merge the column is the whole run's to the bit
        assert_eq!(whole[..10], beside[..10]);
    }
}

/// Negative control: without damping (a mass that keeps swinging) the perturbation never
/// decays; the run beside gives up and the column is the whole run's, to the bit.
#[test]
fn an_undamped_plant_is_run_whole() {
    let c = CoulombMass::stepped(0.0, 3000, 0.0, 0.02, 2);
    let (whole, beside, merged) = columns(&c, 0.0, 0, 0.2, 1e-6);
    assert!(!merged, "an undamped mass does not forget its initial state");
    assert_eq!(whole, beside);
}
