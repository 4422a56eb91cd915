//! `R` of eq. (R) from verified bounds (issue 15, item 3): ellipsoids from a proven eigenvalue
//! enclosure of the shape matrix, intervals and balls rounded upward; negative controls show that
//! a wrong eigenvalue claim is rejected and flips `is_verified_upper`.
use geometry::strong_convexity::{proves_lambda_min_at_least, symmetric_eigen_enclosure};
use geometry::{BallIntersection, ConvexSet, Ellipsoid, Interval, StrongConvexity};
use nalgebra::DMatrix;
use rounding::{add_up, div_up, sqrt_down, sqrt_up};

/// `Q diag(l) Q^T` for a rotation by `phi` (the product is rounded; what is verified is the
/// rounded matrix).
fn rotated(l0: f64, l1: f64, phi: f64) -> DMatrix<f64> {
    let (c, s) = (phi.cos(), phi.sin());
    let q = DMatrix::from_row_slice(2, 2, &[c, -s, s, c]);
    let d = DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(&[l0, l1]));
    let m = &q * d * q.transpose();
    (&m + m.transpose()) * 0.5
}

#[test]
fn directed_rounding_helpers_bracket_the_exact_values() {
    // 0.3 - (-0.1): the exact sum of the two doubles is below fl = 0.4, which is kept.
    assert_eq!(add_up(0.3, 0.1), 0.4);
    // 1 + 2^-60 rounds to 1 but the exact value is larger: moved up.
    assert!(add_up(1.0, 2f64.powi(-60)) > 1.0);
    assert_eq!(add_up(0.1, 0.1), 0.2);
    assert_eq!(div_up(4.0, 1.0), 4.0);
    let q = div_up(1.0, 3.0);
    assert!(q.mul_add(3.0, -1.0) >= 0.0, "1/3 rounded up");
    assert_eq!(sqrt_up(4.0), 2.0);
    assert_eq!(sqrt_down(4.0), 2.0);
    let (u, d) = (sqrt_up(2.0), sqrt_down(2.0));
    assert!(u.mul_add(u, -2.0) >= 0.0 && d.mul_add(d, -2.0) <= 0.0 && u > d);
}

#[test]
fn ellipsoid_r_is_a_verified_upper_bound() {
    // Diagonal: exact eigenvalues, R = 4 / 1 exactly.
    let e = Ellipsoid::axis_aligned(vec![0.0, 0.0], &[2.0, 1.0]).unwrap();
    assert_eq!(e.strong_convexity(), StrongConvexity::Exact(4.0));
    assert!(e.eigen_enclosure().unwrap().exact);
    // Rotated: semi-axes^2 = 0.04 and 0.0025, R = 0.04 / 0.05 = 0.8.
    for phi in [0.1, 0.7, 1.3, 2.9] {
        let m = rotated(0.04, 0.0025, phi);
        let e = Ellipsoid::new(vec![0.01, -0.02], &m).unwrap();
        let sc = e.strong_convexity();
        assert!(matches!(sc, StrongConvexity::UpperBound(_)), "{sc:?}");
        assert!(sc.is_verified_upper());
        // True R of the rounded matrix, from its exact 2x2 eigenvalues (closed form, in f64 up
        // to ~1e-16 relative): the bound is above it and within 1e-12 relative.
        let (a, b, c) = (m[(0, 0)], m[(0, 1)], m[(1, 1)]);
        let h = ((0.5 * (a - c)).powi(2) + b * b).sqrt();
        let (l0, l1) = (0.5 * (a + c) - h, 0.5 * (a + c) + h);
        let r_true = l1 / l0.sqrt();
        assert!(sc.upper() >= r_true * (1.0 - 1e-14), "phi {phi}: {} < {r_true}", sc.upper());
        assert!(sc.upper() <= r_true * (1.0 + 1e-12), "phi {phi}: {} vs {r_true}", sc.upper());
        let enc = e.eigen_enclosure().unwrap();
        assert!(enc.min_lower <= l0 && enc.max_upper >= l1 && !enc.exact);
        // Deviation and diameter from above.
        assert!(e.diameter().upper >= 2.0 * l1.sqrt());
    }
    // The example of examples/ellipse-p2.toml.
    let m = DMatrix::from_row_slice(2, 2, &[0.01, 0.002, 0.002, 0.004]);
    let sc = Ellipsoid::new(vec![0.0, 0.0], &m).unwrap().strong_convexity();
    assert!(sc.is_verified_upper());
}

/// Negative controls: a claimed eigenvalue bound that is wrong is rejected, and an enclosure
/// built around wrong estimates is not verified (the flag `is_verified_upper` would be false).
#[test]
fn negative_control_wrong_eigenvalue_claims_are_rejected() {
    let m = rotated(0.04, 0.0025, 0.7);
    let flat: Vec<f64> = m.transpose().iter().copied().collect(); // row-major
                                                                  // lambda_min = 0.0025: proved >= 0.0025 (1 - 1e-9), rejected >= 0.0025 (1 + 1e-9).
    assert!(proves_lambda_min_at_least(&flat, 2, 0.0, 0.0025 * (1.0 - 1e-9)));
    assert!(!proves_lambda_min_at_least(&flat, 2, 0.0, 0.0025 * (1.0 + 1e-9)));
    // Estimates off by 1 % (lambda_min too high, lambda_max too low): no enclosure.
    assert!(symmetric_eigen_enclosure(&flat, 2, 0.0025 * 1.01, 0.04).is_none());
    assert!(symmetric_eigen_enclosure(&flat, 2, 0.0025, 0.04 * 0.99).is_none());
    // The correct estimates verify.
    let enc = symmetric_eigen_enclosure(&flat, 2, 0.0025, 0.04).unwrap();
    assert!(enc.min_lower <= 0.0025 && enc.max_upper >= 0.04);
    // An unverified enclosure gives a Numerical R, which is not a verified upper bound.
    let sc = StrongConvexity::Numerical { value: 0.8, error: 1e-8 };
    assert!(!sc.is_verified_upper());
}

#[test]
fn interval_and_ball_intersection_r_from_above() {
    // [-0.1, 0.3]: the exact length of the two doubles is just below fl(0.4).
    let i = Interval::new(-0.1, 0.3).unwrap();
    assert!(i.strong_convexity().upper() >= 0.2);
    // 1 + 2^-60 wide interval at [-2^-60, 1]: the half length rounds up.
    let j = Interval::new(-(2f64.powi(-60)), 1.0).unwrap();
    assert!(j.strong_convexity().upper() > 0.5);
    assert!(j.diameter().upper > 1.0);
    // A lens: both balls active, R = 0.2.
    let lens = BallIntersection::new(vec![vec![-0.15, 0.0], vec![0.15, 0.0]], vec![0.2, 0.2]).unwrap();
    assert_eq!(lens.strong_convexity(), StrongConvexity::Exact(0.2));
    // A big ball that only touches the small one's boundary (within the activity tolerance) is
    // counted: R is the big radius, the safe side.
    let touch = BallIntersection::new(vec![vec![0.0, 0.0], vec![1.0, 0.0]], vec![0.5, 1.5]).unwrap();
    assert_eq!(touch.strong_convexity().upper(), 1.5);
}
