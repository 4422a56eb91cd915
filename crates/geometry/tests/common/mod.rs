//! Strategies for random convex sets used by the geometry property tests.
#![allow(dead_code)]
use geometry::{Ball, BallIntersection, ConvexSet, Ellipsoid, Interval, Polytope, Shape};
use nalgebra::DMatrix;
use proptest::prelude::*;

/// Random rotation in R^p from angles (product of Givens rotations).
pub fn rotation(p: usize, angles: &[f64]) -> DMatrix<f64> {
    let mut q = DMatrix::<f64>::identity(p, p);
    let mut k = 0;
    for i in 0..p {
        for j in i + 1..p {
            let (s, c) = angles[k % angles.len()].sin_cos();
            k += 1;
            let mut g = DMatrix::<f64>::identity(p, p);
            g[(i, i)] = c;
            g[(j, j)] = c;
            g[(i, j)] = -s;
            g[(j, i)] = s;
            q = g * q;
        }
    }
    q
}

/// Ellipsoid in R^p (p = 2 or 3) with semi-axes in [0.05, 1], condition number <= 20,
/// random orientation and a centre near the origin.
pub fn ellipsoid(p: usize) -> impl Strategy<Value = Ellipsoid> {
    (
        prop::collection::vec(0.05f64..1.0, p),
        prop::collection::vec(0.0f64..std::f64::consts::PI, 3),
        prop::collection::vec(-0.3f64..0.3, p),
    )
        .prop_map(move |(mut axes, angles, centre)| {
            let amax = axes.iter().cloned().fold(0.0, f64::max);
            axes.iter_mut().for_each(|a| *a = a.max(amax / 20.0));
            let q = rotation(p, &angles);
            let d = DMatrix::from_diagonal(&nalgebra::DVector::from_iterator(p, axes.iter().map(|a| a * a)));
            let m = &q * d * q.transpose();
            let m = (&m + m.transpose()) * 0.5;
            Ellipsoid::new(centre, &m).expect("valid ellipsoid")
        })
}

pub fn ball(p: usize) -> impl Strategy<Value = Ball> {
    (prop::collection::vec(-0.5f64..0.5, p), 0.05f64..1.0).prop_map(|(c, r)| Ball::new(c, r).unwrap())
}

pub fn interval() -> impl Strategy<Value = Interval> {
    (-1.0f64..0.0, 0.01f64..1.0).prop_map(|(lo, w)| Interval::new(lo, lo + w).unwrap())
}

/// Intersection of 2 or 3 balls in R^p that all contain the origin with margin.
pub fn ball_intersection(p: usize) -> impl Strategy<Value = BallIntersection> {
    prop::collection::vec((prop::collection::vec(-1.0f64..1.0, p), 0.2f64..1.0), 2..=3).prop_map(move |balls| {
        let centres: Vec<Vec<f64>> = balls
            .iter()
            .map(|(c, r)| {
                // scale the centre so that the origin is inside with margin 0.1 r
                let n = geometry::linalg::norm(c).max(1e-9);
                let s = (0.9 * r / n).min(1.0);
                c.iter().map(|x| x * s).collect()
            })
            .collect();
        let radii: Vec<f64> = balls.iter().map(|(_, r)| *r).collect();
        BallIntersection::new(centres, radii).expect("contains the origin")
    })
}

/// Random polygon / polytope around the origin from k outward normals at unit-ish offsets.
pub fn polytope(p: usize) -> impl Strategy<Value = Polytope> {
    prop::collection::vec((prop::collection::vec(-1.0f64..1.0, p), 0.2f64..1.0), 3..7).prop_map(move |hs| {
        let mut normals: Vec<Vec<f64>> = hs.iter().map(|(a, _)| a.clone()).collect();
        let mut offsets: Vec<f64> = hs.iter().map(|(_, b)| *b).collect();
        // close it with a box so it is bounded
        for i in 0..p {
            for s in [1.0, -1.0] {
                let mut e = vec![0.0; p];
                e[i] = s;
                normals.push(e);
                offsets.push(1.5);
            }
        }
        for (a, b) in normals.iter_mut().zip(offsets.iter_mut()) {
            let n = geometry::linalg::norm(a);
            if n < 1e-3 {
                a.iter_mut().enumerate().for_each(|(i, x)| *x = if i == 0 { 1.0 } else { 0.0 });
                *b = 1.5;
            }
        }
        Polytope::new(normals, offsets).expect("bounded")
    })
}

/// Any parametric shape in R^p (for p = 1 only intervals and balls).
pub fn shape(p: usize) -> BoxedStrategy<Shape> {
    if p == 1 {
        prop_oneof![interval().prop_map(Shape::Interval), ball(1).prop_map(Shape::Ball)].boxed()
    } else {
        prop_oneof![
            ball(p).prop_map(Shape::Ball),
            ellipsoid(p).prop_map(Shape::Ellipsoid),
            ball_intersection(p).prop_map(Shape::BallIntersection),
            polytope(p).prop_map(Shape::Polytope),
        ]
        .boxed()
    }
}

/// Strongly convex shapes only (no polytopes).
pub fn strongly_convex(p: usize) -> BoxedStrategy<Shape> {
    if p == 1 {
        interval().prop_map(Shape::Interval).boxed()
    } else {
        prop_oneof![
            ball(p).prop_map(Shape::Ball),
            ellipsoid(p).prop_map(Shape::Ellipsoid),
            ball_intersection(p).prop_map(Shape::BallIntersection),
        ]
        .boxed()
    }
}

pub fn point(p: usize, r: f64) -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(-r..r, p)
}

pub fn unit(p: usize) -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(-1.0f64..1.0, p).prop_filter_map("nonzero", |v| {
        let n = geometry::linalg::norm(&v);
        (n > 1e-3).then(|| v.iter().map(|x| x / n).collect())
    })
}

pub fn proj<S: ConvexSet + ?Sized>(s: &S, x: &[f64]) -> Vec<f64> {
    geometry::convex_set::project_vec(s, x)
}

/// Runs `prop` over `strategy` with a fixed seed and returns whether a counterexample was
/// found: the negative controls assert `true`.
pub fn finds_counterexample<S: Strategy>(
    strategy: S,
    cases: u32,
    prop: impl Fn(S::Value) -> Result<(), TestCaseError>,
) -> bool
where
    S::Value: std::fmt::Debug,
{
    let cfg = ProptestConfig { cases, failure_persistence: None, ..ProptestConfig::default() };
    let mut runner = proptest::test_runner::TestRunner::new_with_rng(
        cfg,
        proptest::test_runner::TestRng::deterministic_rng(proptest::test_runner::RngAlgorithm::ChaCha),
    );
    runner.run(&strategy, prop).is_err()
}
