//! Unit tests of every shape against closed forms.
mod common;
use approx::assert_relative_eq;
use common::proj;
use geometry::linalg::{dist, dot, norm};
use geometry::{
    Ball, BallIntersection, ConvexSet, Ellipsoid, Interval, LinearImage, MinkowskiSum, Polytope, StrongConvexity,
    SupportSet,
};
use nalgebra::DMatrix;
use std::sync::Arc;

#[test]
fn interval_projection_support_and_normal_cone() {
    let i = Interval::new(-0.1, 0.3).unwrap();
    assert_eq!(proj(&i, &[0.5]), vec![0.3]);
    assert_eq!(proj(&i, &[-2.0]), vec![-0.1]);
    assert_eq!(proj(&i, &[0.2]), vec![0.2]);
    assert_eq!(i.support(&[2.0]), 0.6);
    assert_eq!(i.support(&[-1.0]), 0.1);
    assert_eq!(i.strong_convexity(), StrongConvexity::Exact(0.2));
    let mut out = [0.0];
    // at the upper end the inward normals are s <= 0: y' > 0 does not drag z, y' < 0 does
    i.project_normal_cone(&[0.3], &[1.0], 1e-12, &mut out);
    assert_eq!(out, [0.0]);
    i.project_normal_cone(&[0.3], &[-1.0], 1e-12, &mut out);
    assert_eq!(out, [-1.0]);
    i.project_normal_cone(&[0.0], &[-1.0], 1e-12, &mut out);
    assert_eq!(out, [0.0]);
    assert_relative_eq!(i.dist_to_boundary(&[0.0]), 0.1);
    assert!(Interval::new(1.0, 0.0).is_err());
    assert!(Interval::new(f64::NAN, 0.0).is_err());
}

#[test]
fn ball_closed_forms() {
    let b = Ball::new(vec![1.0, 0.0], 0.5).unwrap();
    assert_eq!(proj(&b, &[3.0, 0.0]), vec![1.5, 0.0]);
    assert_relative_eq!(b.support(&[0.0, 2.0]), 1.0);
    assert_eq!(b.strong_convexity(), StrongConvexity::Exact(0.5));
    assert_eq!(b.deviation_from_origin().upper, 1.5);
    assert_relative_eq!(b.dist_to_boundary(&[1.2, 0.0]), 0.3, epsilon = 1e-15);
    let mut out = [0.0; 2];
    b.project_normal_cone(&[1.5, 0.0], &[-2.0, 1.0], 1e-12, &mut out);
    assert_eq!(out, [-2.0, 0.0]);
    b.project_normal_cone(&[1.5, 0.0], &[2.0, 1.0], 1e-12, &mut out);
    assert_eq!(out, [0.0, 0.0]);
    assert!(Ball::new(vec![0.0], -1.0).is_err());
}

#[test]
fn ellipsoid_r_and_support_closed_forms() {
    let e = Ellipsoid::axis_aligned(vec![0.0, 0.0], &[2.0, 1.0]).unwrap();
    assert_eq!(e.strong_convexity(), StrongConvexity::Exact(4.0));
    assert_relative_eq!(e.support(&[1.0, 0.0]), 2.0);
    assert_relative_eq!(e.support(&[0.0, -3.0]), 3.0);
    assert_eq!(e.diameter().upper, 4.0);
    assert_eq!(e.deviation_from_origin().upper, 2.0);
    // projection of a point on an axis beyond the vertex is the vertex
    let p = proj(&e, &[5.0, 0.0]);
    assert_relative_eq!(p[0], 2.0, max_relative = 1e-14);
    assert!(p[1].abs() < 1e-15);
    // non-SPD and non-symmetric matrices are rejected
    let bad = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, -1.0]);
    assert!(Ellipsoid::new(vec![0.0, 0.0], &bad).is_err());
    let asym = DMatrix::from_row_slice(2, 2, &[1.0, 0.5, 0.0, 1.0]);
    assert!(Ellipsoid::new(vec![0.0, 0.0], &asym).is_err());
}

/// KKT check of the ellipsoid projection to 1e-12 relative: `P` on the boundary and
/// `x - P` parallel to the outward normal `M^{-1}(P - c)` with a non-negative factor.
#[test]
fn ellipsoid_projection_satisfies_kkt_to_1e_12() {
    let m = DMatrix::from_row_slice(3, 3, &[0.04, 0.01, 0.0, 0.01, 0.02, 0.005, 0.0, 0.005, 0.01]);
    let c = vec![0.01, -0.02, 0.0];
    let e = Ellipsoid::new(c.clone(), &m).unwrap();
    let minv = m.clone().try_inverse().unwrap();
    let mut worst = 0.0f64;
    for k in 0..200 {
        let t = k as f64 * 0.731;
        let x = [0.5 * t.sin() * (1.0 + k as f64 * 0.01), 0.3 * (1.7 * t).cos(), 0.2 * (0.3 * t).sin() + 0.05];
        let p = proj(&e, &x);
        let d = nalgebra::DVector::from_iterator(3, p.iter().zip(&c).map(|(a, b)| a - b));
        let level = (d.transpose() * &minv * &d)[(0, 0)];
        if dist(&x, &p) == 0.0 {
            continue;
        }
        worst = worst.max((level - 1.0).abs());
        let n = &minv * &d;
        let r: Vec<f64> = (0..3).map(|i| x[i] - p[i]).collect();
        let cosang = dot(&r, n.as_slice()) / (norm(&r) * n.norm());
        worst = worst.max(1.0 - cosang);
    }
    assert!(worst < 1e-12, "KKT residual {worst:e}");
}

#[test]
fn ellipsoid_distance_to_boundary_matches_circle_and_axis_cases() {
    let circle = Ellipsoid::axis_aligned(vec![0.0, 0.0], &[1.0, 1.0]).unwrap();
    assert_relative_eq!(circle.dist_to_boundary(&[0.3, 0.4]), 0.5, epsilon = 1e-12);
    let e = Ellipsoid::axis_aligned(vec![0.0, 0.0], &[2.0, 1.0]).unwrap();
    // from the centre the nearest boundary point is the end of the minor axis (hard case)
    assert_relative_eq!(e.dist_to_boundary(&[0.0, 0.0]), 1.0, epsilon = 1e-12);
    // on the minor axis: distance along it
    assert_relative_eq!(e.dist_to_boundary(&[0.0, 0.5]), 0.5, epsilon = 1e-12);
    // generic point: compare with a dense scan of the boundary
    let x = [0.7, 0.2];
    let scan = (0..200_000)
        .map(|k| {
            let a = k as f64 * std::f64::consts::TAU / 200_000.0;
            dist(&x, &[2.0 * a.cos(), a.sin()])
        })
        .fold(f64::INFINITY, f64::min);
    let d = e.dist_to_boundary(&x);
    assert!(d <= scan + 1e-12 && d >= scan - 1e-8, "{d} vs scan {scan}");
}

#[test]
fn lens_projection_and_r_are_exact() {
    // two discs of radius 1 with centres (+-0.6, 0): corners at (0, +-0.8)
    let lens = BallIntersection::new(vec![vec![-0.6, 0.0], vec![0.6, 0.0]], vec![1.0, 1.0]).unwrap();
    let p = proj(&lens, &[0.0, 3.0]);
    assert!(dist(&p, &[0.0, 0.8]) < 1e-10, "{p:?}");
    // a point whose projection is on the right disc's arc (the left sphere) away from the corner
    let x = [-1.0, 0.1];
    let p = proj(&lens, &x);
    let expect: Vec<f64> = {
        let c = [0.6, 0.0];
        let d = dist(&x, &c);
        (0..2).map(|i| c[i] + (x[i] - c[i]) / d).collect()
    };
    assert!(dist(&p, &expect) < 1e-10, "{p:?} vs {expect:?}");
    assert_eq!(lens.strong_convexity(), StrongConvexity::Exact(1.0));
    assert_relative_eq!(lens.deviation_from_origin().upper, 0.8, epsilon = 1e-12);
    assert_relative_eq!(lens.support(&[0.0, 1.0]), 0.8, epsilon = 1e-12);
    assert_relative_eq!(lens.support(&[1.0, 0.0]), 0.4, epsilon = 1e-12);
    // normal cone at the corner is spanned by the two inward normals
    let mut out = [0.0; 2];
    lens.project_normal_cone(&[0.0, 0.8], &[0.0, -1.0], 1e-9, &mut out);
    assert!(dist(&out, &[0.0, -1.0]) < 1e-12, "{out:?}");
    // a redundant big ball does not change R
    let with_big =
        BallIntersection::new(vec![vec![-0.6, 0.0], vec![0.6, 0.0], vec![0.0, 0.0]], vec![1.0, 1.0, 5.0]).unwrap();
    assert_eq!(with_big.active(), &[true, true, false]);
    assert_eq!(with_big.strong_convexity(), StrongConvexity::Exact(1.0));
    assert!(BallIntersection::new(vec![vec![-3.0, 0.0], vec![3.0, 0.0]], vec![1.0, 1.0]).is_err());
}

#[test]
fn ball_intersection_projection_exact_in_3d_corner() {
    // three unit balls whose spheres meet: project a far point onto the "tip"
    let s = 0.5;
    let centres =
        vec![vec![s, 0.0, 0.0], vec![-s / 2.0, s * 0.75f64.sqrt(), 0.0], vec![-s / 2.0, -s * 0.75f64.sqrt(), 0.0]];
    let k = BallIntersection::new(centres.clone(), vec![1.0; 3]).unwrap();
    let tip_z = (1.0 - s * s).sqrt();
    let p = proj(&k, &[0.0, 0.0, 10.0]);
    assert!(dist(&p, &[0.0, 0.0, tip_z]) < 1e-10, "{p:?}");
}

#[test]
fn polytope_projection_vertices_and_infinite_r() {
    let sq = Polytope::from_box(&[-1.0, -1.0], &[1.0, 1.0]).unwrap();
    assert_eq!(sq.vertices().len(), 4);
    assert_eq!(proj(&sq, &[3.0, 0.5]), vec![1.0, 0.5]);
    assert_eq!(proj(&sq, &[3.0, 3.0]), vec![1.0, 1.0]);
    assert_eq!(sq.strong_convexity(), StrongConvexity::Infinite);
    assert_relative_eq!(sq.diameter().upper, 8f64.sqrt());
    let mut out = [0.0; 2];
    sq.project_normal_cone(&[1.0, 1.0], &[-1.0, -2.0], 1e-12, &mut out);
    assert_eq!(out, [-1.0, -2.0]);
    sq.project_normal_cone(&[1.0, 0.0], &[-1.0, -2.0], 1e-12, &mut out);
    assert_eq!(out, [-1.0, 0.0]);
    // unbounded: a half-plane
    assert!(Polytope::new(vec![vec![1.0, 0.0], vec![-1.0, 0.0]], vec![1.0, 1.0]).is_err());
    assert!(Polytope::new(vec![vec![1.0, 0.0], vec![0.0, 1.0], vec![-1.0, -1.0]], vec![1.0, 1.0, -5.0]).is_err());
}

/// Issue 31 item 7: a polytope with an empty interior was accepted. Refused, naming the row
/// across which it has no width; a thin but full-dimensional one stays accepted (control).
#[test]
fn degenerate_polytopes_are_refused_with_the_reason() {
    use geometry::GeometryError;
    // the segment {0} x [-1, 1]: all vertices on a line in R^2
    let e = Polytope::from_box(&[0.0, -1.0], &[0.0, 1.0]).unwrap_err();
    assert!(matches!(e, GeometryError::DegeneratePolytope { index: 0, .. }), "{e:?}");
    assert!(e.to_string().contains("empty interior"), "{e}");
    // a single point (the origin), by three half-planes
    let e = Polytope::new(vec![vec![1.0, 0.0], vec![0.0, 1.0], vec![-1.0, -1.0]], vec![0.0, 0.0, 0.0]).unwrap_err();
    assert!(matches!(e, GeometryError::DegeneratePolytope { diameter, .. } if diameter == 0.0), "{e:?}");
    // a flat triangle in R^3 (z = 0 implied by z <= 0 and -z <= 0)
    let e = Polytope::new(
        vec![
            vec![1.0, 0.0, 0.0],
            vec![0.0, 1.0, 0.0],
            vec![-1.0, -1.0, 0.0],
            vec![0.0, 0.0, 1.0],
            vec![0.0, 0.0, -1.0],
        ],
        vec![1.0, 1.0, 1.0, 0.0, 0.0],
    )
    .unwrap_err();
    assert!(matches!(e, GeometryError::DegeneratePolytope { .. }), "{e:?}");
    // control: thin (width 1e-6 against diameter 2) but full-dimensional
    assert!(Polytope::from_box(&[-1e-6, -1.0], &[0.0, 1.0]).is_ok());
}

#[test]
fn linear_image_and_minkowski_sum_via_support_functions() {
    let b = Ball::centred(2, 1.0).unwrap();
    // M B: an ellipse with semi-axes 2 and 0.5
    let m = DMatrix::from_row_slice(2, 2, &[2.0, 0.0, 0.0, 0.5]);
    let img = LinearImage::new(m, b.clone()).unwrap();
    let e = Ellipsoid::axis_aligned(vec![0.0, 0.0], &[2.0, 0.5]).unwrap();
    for k in 0..16 {
        let a = k as f64 * 0.4;
        let u = [a.cos(), a.sin()];
        assert_relative_eq!(img.support(&u), e.support(&u), epsilon = 1e-14);
    }
    let x = [3.0, 1.0];
    let pi = proj(&img, &x);
    let pe = proj(&e, &x);
    assert!(dist(&pi, &pe) < 1e-7, "{pi:?} vs {pe:?}");
    match img.strong_convexity() {
        StrongConvexity::Numerical { value, error } => {
            assert!((value - 8.0).abs() <= error.max(1e-4), "{value} +- {error}")
        }
        other => panic!("expected a numerical R, got {other:?}"),
    }
    // B_1 + B_2 = B_3
    let sum = MinkowskiSum::new(vec![Box::new(b.clone()), Box::new(Ball::centred(2, 2.0).unwrap())]).unwrap();
    assert_relative_eq!(sum.support(&[0.6, 0.8]), 3.0, epsilon = 1e-14);
    assert_eq!(sum.strong_convexity(), StrongConvexity::UpperBound(3.0));
    assert_relative_eq!(sum.deviation_from_origin().upper, 3.0, max_relative = 1e-6);
    // 1-D image: an interval, exact R
    let row = LinearImage::new(DMatrix::from_row_slice(1, 2, &[3.0, 4.0]), b).unwrap();
    assert_eq!(row.strong_convexity(), StrongConvexity::Exact(5.0));
    assert!(MinkowskiSum::new(vec![
        Box::new(Ball::centred(2, 1.0).unwrap()),
        Box::new(Interval::symmetric(1.0).unwrap())
    ])
    .is_err());
}

#[test]
fn support_set_recovers_a_ball() {
    let s = SupportSet::new(2, Arc::new(|u: &[f64]| 0.5 * norm(u) + 0.1 * u[0]), 0.6, "ball");
    let p = proj(&s, &[2.0, 0.0]);
    assert!(dist(&p, &[0.6, 0.0]) < 1e-8, "{p:?}");
    let mut sp = [0.0; 2];
    s.support_point(&[0.0, 1.0], &mut sp);
    assert!(dist(&sp, &[0.1, 0.5]) < 1e-8, "{sp:?}");
    match s.strong_convexity() {
        StrongConvexity::Numerical { value, error } => assert!((value - 0.5).abs() <= error.max(1e-6)),
        other => panic!("{other:?}"),
    }
    assert!(s.contains(&[0.1, 0.45], 0.0));
    assert!(!s.contains(&[0.1, 0.55], 1e-6));
    // certified lower bound of r (sphere_max); the exact value is 0.5 - |x - c|
    let r = s.dist_to_boundary(&[0.3, 0.1]);
    let exact = 0.5 - (0.2f64 * 0.2 + 0.1 * 0.1).sqrt();
    assert!(r <= exact + 1e-12 && r >= exact - 1e-6, "{r} vs {exact}");
}
