use super::*;

#[test]
fn dxx_bounds_the_hausdorff_gap_between_xi_t_and_xi_inf() {
    let F = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -1.0, -0.6]);
    let E = DMatrix::from_row_slice(2, 1, &[0.0, 1.0]);
    let theta = Shape::Interval(geometry::Interval::symmetric(0.1).unwrap());
    let I = DMatrix::<f64>::identity(2, 2);
    let st = TubeSettings { tol_abs: 1e-7, ..Default::default() };
    let kinf = TubeKernel::new(&I, &F, &E, &theta, Horizon::Infinite, &st).unwrap();
    for t in [1.0, 5.0, 15.0] {
        let kt = TubeKernel::new(&I, &F, &E, &theta, Horizon::Finite(t), &st).unwrap();
        let bound = dxx_bound(&F, &E, &theta, t).unwrap();
        let mut gap = 0.0f64;
        for k in 0..64 {
            let a = std::f64::consts::TAU * k as f64 / 64.0;
            let u = [a.cos(), a.sin()];
            gap = gap.max(kinf.support_bounds(&u).lower - kt.support_upper(&u));
        }
        assert!(gap <= bound, "t = {t}: gap {gap} > (DXX) {bound}");
        assert!(gap > 0.0 || t > 10.0);
        // Negative control: a rate faster than mu (e^{-t} instead of e^{-0.3 t}) is violated.
        if t == 5.0 {
            assert!(gap > 0.1 * (-t).exp(), "{gap}");
        }
    }
}

#[test]
fn fast_disc_intersection_support_matches_geometry() {
    let lens = geometry::BallIntersection::new(vec![vec![-0.15, 0.0], vec![0.15, 0.0]], vec![0.2, 0.2]).unwrap();
    let three =
        geometry::BallIntersection::new(vec![vec![0.0, 0.0], vec![0.3, 0.1], vec![0.1, -0.25]], vec![0.3, 0.35, 0.4])
            .unwrap();
    for bi in [lens, three] {
        let shape = Shape::BallIntersection(bi);
        let fast = ThetaSupport::new(&shape);
        assert!(matches!(fast, ThetaSupport::Discs { .. }));
        for k in 0..720 {
            let a = std::f64::consts::TAU * k as f64 / 720.0 + 0.001;
            let u = [2.0 * a.cos(), 2.0 * a.sin()];
            let (x, y) = (fast.support(&u), shape.support(&u));
            assert!((x - y).abs() <= 1e-12 * (1.0 + y.abs()), "{a}: {x} vs {y}");
        }
    }
    // Negative control: dropping the vertices breaks the support at the lens' tips.
    let shape = Shape::BallIntersection(
        geometry::BallIntersection::new(vec![vec![-0.15, 0.0], vec![0.15, 0.0]], vec![0.2, 0.2]).unwrap(),
    );
    if let ThetaSupport::Discs { centres, radii, .. } = ThetaSupport::new(&shape) {
        let broken = ThetaSupport::Discs { centres, radii, vertices: vec![], pairs: vec![] };
        assert!((broken.support(&[0.0, 1.0]) - shape.support(&[0.0, 1.0])).abs() > 1e-3);
    }
}
