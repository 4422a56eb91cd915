//! `Shape::support_upper` (issue 15, item 3) is a proven upper bound of the support function,
//! the rounding of its evaluation included: it is never below the best point of the set found
//! independently (the support point, which lies in the set up to rounding) and it is tight.
//! Random ellipsoids' `R` is verified from an eigenvalue enclosure and is above the
//! floating-point value. 500 cases per property (`PROPTEST_CASES` overrides).
mod common;
use common::*;
use geometry::linalg::{dot, norm};
use geometry::{ConvexSet, Shape};
use proptest::prelude::*;

fn config() -> ProptestConfig {
    let cases = std::env::var("PROPTEST_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(500);
    ProptestConfig { cases, ..ProptestConfig::default() }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn support_upper_is_above_and_tight(
        s in (1usize..=3).prop_flat_map(shape),
        dir in prop::collection::vec(-1.0f64..1.0, 3),
        scale in -3.0f64..3.0,
    ) {
        let p = s.dim();
        let u: Vec<f64> = dir[..p].iter().map(|x| x * 10f64.powf(scale)).collect();
        prop_assume!(norm(&u) > 1e-12);
        let plain = s.support(&u);
        let up = s.support_upper(&u);
        let mut x = vec![0.0; p];
        s.support_point(&u, &mut x);
        let dev = s.deviation_from_origin().upper;
        let slack = 1e-9 * dev * norm(&u);
        // Above every (nearly feasible) point's value and the plain evaluation, and tight.
        prop_assert!(up >= dot(&u, &x) - slack, "{up} < u.x = {}", dot(&u, &x));
        prop_assert!(up >= plain, "{up} < {plain}");
        prop_assert!(up <= plain + 1e-11 * dev * norm(&u) + 1e-300, "{up} vs {plain}: not tight ({s:?})");
    }

    #[test]
    fn random_ellipsoids_have_a_verified_r_above_the_estimate(e in (2usize..=3).prop_flat_map(ellipsoid)) {
        let sc = e.strong_convexity();
        prop_assert!(sc.is_verified_upper(), "{sc:?}");
        let axes = e.semi_axes();
        let est = axes[axes.len() - 1].powi(2) / axes[0];
        prop_assert!(sc.upper() >= est * (1.0 - 1e-13) && sc.upper() <= est * (1.0 + 1e-9), "{} vs {est}", sc.upper());
    }
}

/// Negative control: `support_upper` of a set is *below* the value of a point of a slightly
/// larger set in some direction, i.e. the bound is specific to the set and not a loose
/// over-estimate (a 1e-6 relative enlargement is detected in every shape kind).
#[test]
fn negative_control_enlarged_set_exceeds_the_bound() {
    let e = geometry::Ellipsoid::axis_aligned(vec![0.0, 0.0], &[2.0, 1.0]).unwrap();
    let big = geometry::Ellipsoid::axis_aligned(vec![0.0, 0.0], &[2.0 * (1.0 + 1e-6), 1.0]).unwrap();
    let u = [1.0, 0.0];
    assert!(Shape::Ellipsoid(e).support_upper(&u) < big.support(&u));
    let lens = geometry::BallIntersection::new(vec![vec![-0.15, 0.0], vec![0.15, 0.0]], vec![0.2, 0.2]).unwrap();
    let fat = geometry::BallIntersection::new(
        vec![vec![-0.15, 0.0], vec![0.15, 0.0]],
        vec![0.2 * (1.0 + 1e-6), 0.2 * (1.0 + 1e-6)],
    )
    .unwrap();
    for u in [[0.0, 1.0], [0.3, 1.0], [1.0, 0.0]] {
        assert!(Shape::BallIntersection(lens.clone()).support_upper(&u) < fat.support(&u), "{u:?}");
    }
}
