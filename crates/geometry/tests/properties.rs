//! Property tests of the projection and of the strong-convexity constant, each with a negative
//! control that must produce a counterexample. 2,000 cases per property by default
//! (`PROPTEST_CASES` overrides).
mod common;
use common::*;
use geometry::linalg::{dist, dot, norm};
use geometry::{ConvexSet, Ellipsoid, Shape};
use proptest::prelude::*;

fn cases() -> u32 {
    std::env::var("PROPTEST_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(2000)
}

fn config() -> ProptestConfig {
    ProptestConfig { cases: cases(), ..ProptestConfig::default() }
}

/// Shape with its dimension drawn from {1, 2, 3}.
fn any_shape() -> impl Strategy<Value = Shape> {
    (1usize..=3).prop_flat_map(shape)
}
fn any_strongly_convex() -> impl Strategy<Value = Shape> {
    (1usize..=3).prop_flat_map(strongly_convex)
}

/// Two points and a set of matching dimension.
fn shape_and_points() -> impl Strategy<Value = (Shape, Vec<f64>, Vec<f64>)> {
    any_shape().prop_flat_map(|s| {
        let p = s.dim();
        (Just(s), point(p, 2.0), point(p, 2.0))
    })
}

/// A "projection" that is not one: radial retraction `c + (x - c)/level` onto an ellipsoid.
/// It maps onto the set but is neither non-expansive nor the nearest point.
fn radial_retraction(e: &Ellipsoid, x: &[f64]) -> Vec<f64> {
    let c = e.centre();
    let p = e.dim();
    let m = nalgebra::DMatrix::from_row_slice(p, p, e.matrix());
    let minv = m.try_inverse().unwrap();
    let d = nalgebra::DVector::from_iterator(p, x.iter().zip(c).map(|(a, b)| a - b));
    let level = (d.transpose() * minv * &d)[(0, 0)].sqrt();
    if level <= 1.0 {
        x.to_vec()
    } else {
        (0..p).map(|i| c[i] + d[i] / level).collect()
    }
}

fn pp_holds(px: &[f64], py: &[f64], x: &[f64], y: &[f64]) -> Result<(), TestCaseError> {
    let lhs = dist(px, py);
    let rhs = dist(x, y);
    prop_assert!(lhs <= rhs * (1.0 + 1e-10) + 1e-12, "|P x - P y| = {lhs} > |x - y| = {rhs}");
    Ok(())
}

/// Variational inequality characterising `P_S(x)`: `(x - P x)^T (s - P x) <= 0` for all
/// `s in S`, checked at support points in many directions.
// 0.7853 is near pi/4 on purpose: exact multiples of pi/4 would repeat eight directions.
#[allow(clippy::approx_constant)]
fn vi_holds(s: &Shape, x: &[f64], px: &[f64]) -> Result<(), TestCaseError> {
    let p = s.dim();
    let r: Vec<f64> = (0..p).map(|i| x[i] - px[i]).collect();
    let mut sp = vec![0.0; p];
    let dirs = 24;
    for k in 0..dirs {
        let u: Vec<f64> = (0..p)
            .map(|i| ((k * (i + 3) + 7 * i) as f64 * 0.7853).sin() + if i == k % p { 0.5 } else { 0.0 })
            .collect();
        s.support_point(&u, &mut sp);
        let v = dot(&r, &sp) - dot(&r, px);
        prop_assert!(v <= 1e-10 * (1.0 + norm(&r)), "VI violated: (x-Px).(s-Px) = {v:e} for s = {sp:?}");
    }
    // the residual direction itself is the most demanding test point
    if norm(&r) > 0.0 {
        s.support_point(&r, &mut sp);
        let v = dot(&r, &sp) - dot(&r, px);
        prop_assert!(
            v <= 1e-9 * (1.0 + norm(&r)) * (1.0 + norm(&sp)),
            "VI violated at the support point of x - Px: {v:e}"
        );
    }
    Ok(())
}

/// Defining inclusion of `R` (eq. (R)): `S subset B_R(u + R v)` for a boundary point `u`
/// with unit inward normal `v`, checked at support points in many directions.
fn r_inclusion_holds(s: &Shape, r: f64, d: &[f64]) -> Result<(), TestCaseError> {
    let p = s.dim();
    let mut u = vec![0.0; p];
    s.support_point(d, &mut u);
    let dn = norm(d);
    let centre: Vec<f64> = (0..p).map(|i| u[i] - r * d[i] / dn).collect();
    let mut sp = vec![0.0; p];
    for k in 0..48 {
        let e: Vec<f64> = (0..p).map(|i| ((k as f64 + 0.37) * (1.3 + i as f64)).sin()).collect();
        s.support_point(&e, &mut sp);
        let gap = dist(&sp, &centre) - r;
        prop_assert!(gap <= 1e-9 * (1.0 + r), "point {sp:?} of S lies {gap:e} outside B_R(u + R v), R = {r}");
    }
    Ok(())
}

proptest! {
    #![proptest_config(config())]

    /// (PP): the metric projection is non-expansive, for every shape.
    #[test]
    fn projection_is_nonexpansive((s, x, y) in shape_and_points()) {
        let px = proj(&s, &x);
        let py = proj(&s, &y);
        prop_assert!(s.contains(&px, 1e-10), "P(x) = {px:?} not in S");
        pp_holds(&px, &py, &x, &y)?;
    }

    /// Variational inequality characterising the projection (eq. (P)).
    #[test]
    fn projection_satisfies_variational_inequality((s, x, _y) in shape_and_points()) {
        let px = proj(&s, &x);
        vi_holds(&s, &x, &px)?;
    }

    /// The defining inclusion of R, eq. (R), at boundary points with unit inward normals.
    #[test]
    fn strongly_convex_set_lies_in_supporting_ball_of_radius_r(
        (s, d) in any_strongly_convex().prop_flat_map(|s| { let p = s.dim(); (Just(s), unit(p)) })
    ) {
        let r = s.strong_convexity().upper();
        prop_assert!(r.is_finite());
        r_inclusion_holds(&s, r, &d)?;
    }

    /// Projection onto the inward normal cone (eq. (zdot)): the result is an inward normal
    /// (`w^T (s - q) >= 0` for s in S) and `v - w` is orthogonal to `w`.
    #[test]
    fn normal_cone_projection_is_an_inward_normal((s, d, v) in any_shape().prop_flat_map(|s| { let p = s.dim(); (Just(s), unit(p), point(p, 1.0)) })) {
        let p = s.dim();
        let mut q = vec![0.0; p];
        s.support_point(&d, &mut q);
        let mut w = vec![0.0; p];
        s.project_normal_cone(&q, &v, 1e-9, &mut w);
        let r: Vec<f64> = (0..p).map(|i| v[i] - w[i]).collect();
        prop_assert!(dot(&r, &w).abs() <= 1e-9 * (1.0 + norm(&v) * norm(&v)), "v - w not orthogonal to w");
        let mut sp = vec![0.0; p];
        for k in 0..16 {
            let e: Vec<f64> = (0..p).map(|i| ((k as f64 + 0.5) * (2.1 + i as f64)).cos()).collect();
            s.support_point(&e, &mut sp);
            let val = dot(&w, &sp) - dot(&w, &q);
            prop_assert!(val >= -1e-7 * (1.0 + norm(&w)), "w = {w:?} is not an inward normal at q = {q:?}: w.(s-q) = {val:e}");
        }
    }
}

// ---------------------------------------------------------------------------------------
// Negative controls: the same checks must reject a wrong claim.

fn eccentric_ellipse() -> impl Strategy<Value = Ellipsoid> {
    ellipsoid(2).prop_filter("eccentric", |e| {
        let a = e.semi_axes();
        a[1] / a[0] > 1.5
    })
}

#[test]
fn negative_control_pp_rejects_radial_retraction() {
    let strat = (eccentric_ellipse(), point(2, 2.0), point(2, 2.0));
    let found = finds_counterexample(strat, 2000, |(e, x, y)| {
        pp_holds(&radial_retraction(&e, &x), &radial_retraction(&e, &y), &x, &y)
    });
    assert!(found, "the non-expansiveness check failed to reject a map that is not a projection");
}

#[test]
fn negative_control_vi_rejects_radial_retraction() {
    let strat = (eccentric_ellipse(), point(2, 2.0));
    let found = finds_counterexample(strat, 2000, |(e, x)| {
        let px = radial_retraction(&e, &x);
        vi_holds(&Shape::Ellipsoid(e), &x, &px)
    });
    assert!(found, "the variational-inequality check failed to reject the radial retraction");
}

#[test]
fn negative_control_r_over_two_is_rejected() {
    let strat = (eccentric_ellipse(), unit(2));
    let found = finds_counterexample(strat, 2000, |(e, d)| {
        let r = e.strong_convexity().upper() / 2.0;
        r_inclusion_holds(&Shape::Ellipsoid(e), r, &d)
    });
    assert!(found, "R/2 for a non-round ellipse was not rejected");
}

#[test]
fn negative_control_normal_cone_with_wrong_sign_is_rejected() {
    // outward instead of inward normals: must be caught
    let strat = (ellipsoid(2), unit(2));
    let found = finds_counterexample(strat, 500, |(e, d)| {
        let mut q = vec![0.0; 2];
        e.support_point(&d, &mut q);
        let w: Vec<f64> = d.clone(); // outward normal
        let mut sp = vec![0.0; 2];
        for k in 0..16 {
            let ee = [((k as f64) * 0.4).cos(), ((k as f64) * 0.4).sin()];
            e.support_point(&ee, &mut sp);
            prop_assert!(dot(&w, &sp) - dot(&w, &q) >= -1e-7);
        }
        Ok(())
    });
    assert!(found);
}
