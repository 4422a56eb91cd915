use super::*;

#[test]
fn ellipse_support_max_is_the_major_semi_axis_and_bound_is_tight() {
    // g = support of the ellipse with semi-axes 3, 1 rotated by 0.3: max = 3.
    let (c, s) = (0.3f64.cos(), 0.3f64.sin());
    let g = |v: &[f64]| {
        let (x, y) = (c * v[0] + s * v[1], -s * v[0] + c * v[1]);
        (9.0 * x * x + y * y).sqrt()
    };
    let b = sublinear_sphere_max(2, g, 3.0, &SphereMaxSettings { tol_abs: 1e-12, tol_rel: 1e-10, max_evals: 10_000 });
    assert!(b.lower <= 3.0 + 1e-12 && b.upper >= 3.0 - 1e-12, "{b:?}");
    assert!(b.width() < 1e-9, "{b:?}");
}

#[test]
fn ellipsoid_support_max_in_3d() {
    // support of the ellipsoid with semi-axes (1, 2, 0.5) rotated: max = 2.
    let R = nalgebra::Rotation3::from_euler_angles(0.3, -0.7, 1.1);
    let g = |v: &[f64]| {
        let w = R.inverse() * nalgebra::Vector3::new(v[0], v[1], v[2]);
        (w[0] * w[0] + 4.0 * w[1] * w[1] + 0.25 * w[2] * w[2]).sqrt()
    };
    let b = sublinear_sphere_max(3, g, 2.0, &SphereMaxSettings { tol_abs: 1e-10, tol_rel: 1e-8, max_evals: 20_000 });
    assert!(b.lower <= 2.0 + 1e-12 && b.upper >= 2.0 - 1e-12, "{b:?}");
    assert!(b.width() < 1e-7, "{b:?}");
}

#[test]
fn negative_control_non_sublinear_function_can_break_the_bound() {
    // The arc bound relies on sublinearity: a narrow bump (not convex) between two grid
    // angles is missed, so the "upper bound" is below the true maximum.
    let bump = |v: &[f64]| {
        let a = v[1].atan2(v[0]);
        1.0 + 10.0 * (-((a - 0.05) / 1e-3).powi(2)).exp()
    };
    let b = sublinear_sphere_max(2, bump, 1.0, &SphereMaxSettings { tol_abs: 1e-6, tol_rel: 1e-6, max_evals: 1000 });
    // true maximum 11 at angle 0.05: the "upper bound" misses it
    assert!(b.upper < 10.0, "the harness must be able to see a violated hypothesis: {b:?}");
    // and the arc bound itself is exact at the end points for a linear function
    assert!((arc_bound(1.0, 1.0, 0.1) - 1.0 / (0.05f64).cos()).abs() < 1e-12);
}
