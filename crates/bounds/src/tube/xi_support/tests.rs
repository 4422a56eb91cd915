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

/// A stiff 3-state `F = V J V^{-1}` (issue 29 item 1): `J = diag(fast) + [[-0.5, 0.8], [-0.8,
/// -0.5]]`, eigenvector condition number about 5; with `E` and `C` below.
/// `(F, C, E, V, V^{-1})`.
type StiffSystem = (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>, DMatrix<f64>, DMatrix<f64>);

fn stiff_system(fast: f64) -> StiffSystem {
    let V = DMatrix::from_row_slice(3, 3, &[1.0, 0.9, 0.2, 0.1, 1.0, 0.9, 0.8, -0.3, 1.0]);
    let J = DMatrix::from_row_slice(3, 3, &[fast, 0.0, 0.0, 0.0, -0.5, 0.8, 0.0, -0.8, -0.5]);
    let Vi = V.clone().try_inverse().unwrap();
    let F = &V * &J * &Vi;
    let C = DMatrix::from_row_slice(1, 3, &[1.0, 0.0, 0.0]);
    let E = DMatrix::from_row_slice(3, 1, &[0.0, 1.0, 0.5]);
    (F, C, E, V, Vi)
}

/// `e^{sF}` through the modal form `V e^{sJ} V^{-1}` (independent of the kernel's exponentials).
fn modal_exp(fast: f64, V: &DMatrix<f64>, Vi: &DMatrix<f64>, s: f64) -> DMatrix<f64> {
    let (c, sn) = ((0.8 * s).cos(), (0.8 * s).sin());
    let e = (-0.5 * s).exp();
    let X = DMatrix::from_row_slice(3, 3, &[(fast * s).exp(), 0.0, 0.0, 0.0, e * c, e * sn, 0.0, -e * sn, e * c]);
    V * X * Vi
}

/// `delta int_0^t |L e^{sF} E| ds` by composite Simpson on `[0, 12 / |fast|]` (fine) and on the
/// rest (0.002 steps), with the modal exponential.
fn stiff_reference(fast: f64, L: &DMatrix<f64>, E: &DMatrix<f64>, t: f64, delta: f64) -> f64 {
    let (_, _, _, V, Vi) = stiff_system(fast);
    let f = |s: f64| (L * modal_exp(fast, &V, &Vi, s) * E)[(0, 0)].abs();
    let simpson = |a: f64, b: f64, n: usize| {
        let h = (b - a) / n as f64;
        let mut acc = f(a) + f(b);
        for k in 1..n {
            acc += if k % 2 == 1 { 4.0 } else { 2.0 } * f(a + k as f64 * h);
        }
        acc * h / 3.0
    };
    let split = (12.0 / -fast).min(t);
    delta * (simpson(0.0, split, 24_000) + simpson(split, t, (((t - split) / 0.002) as usize / 2 * 2).max(2)))
}

#[test]
fn stiff_plants_get_a_proven_enclosure_not_an_error() {
    // Before the stiff-plant cells these ended in QuadratureBudget (fast -200) or NoTailBound
    // (fast -2000, -20000: the semigroup grid's factor e^{delta ||F||} overflowed).
    let theta = Shape::Interval(geometry::Interval::symmetric(0.1).unwrap());
    let st = TubeSettings::default();
    for fast in [-200.0, -2000.0, -20000.0] {
        let (F, C, E, _, _) = stiff_system(fast);
        let sg = SemigroupData::new(&F);
        let b = sg.exp_norm().expect("semigroup bounds of a stiff F are proven");
        assert!(b.sup.is_finite() && b.sup < 50.0 && b.integral < 200.0, "{fast}: {b:?}");
        let CF = &C * &F;
        for (L, horizon, t) in
            [(&C, Horizon::Infinite, 80.0), (&CF, Horizon::Infinite, 80.0), (&C, Horizon::Finite(6.0), 6.0)]
        {
            let k = TubeKernel::with_shared(L, &F, &E, &theta, 0.1, &sg, horizon, &st)
                .unwrap_or_else(|e| panic!("fast {fast}, {horizon:?}: {e}"));
            let enc = k.support_bounds(&[1.0]);
            let reference = stiff_reference(fast, L, &E, t, 0.1);
            let slack = 1e-7 * (1.0 + reference);
            assert!(
                enc.lower <= reference + slack && reference <= enc.upper + slack,
                "{fast} {horizon:?}: {enc:?} vs {reference}"
            );
            // useful: within the target tolerance plus the rounding terms, few cells
            assert!(
                enc.upper - enc.lower <= 2e-4 * (1.0 + reference),
                "{fast} {horizon:?} L = {L}: {enc:?}, remainder {}, tail {}, rounding {}, cells {}",
                k.remainder_bound(),
                k.tail_bound(),
                k.rounding_bound(),
                k.cells()
            );
            assert!(k.cells() <= 60_000, "{fast} {horizon:?}: {} cells", k.cells());
            // Negative control: an upper value 1e-3 (relative) below the enclosure fails the check.
            let wrong = enc.lower - 1e-3 * reference;
            assert!(reference > wrong + slack, "{fast} {horizon:?}: the check cannot see a 1e-3 error");
        }
    }
}

#[test]
fn a_cell_budget_too_small_degrades_the_enclosure_instead_of_failing() {
    let theta = Shape::Interval(geometry::Interval::symmetric(0.1).unwrap());
    let (F, C, E, _, _) = stiff_system(-2000.0);
    let st = TubeSettings { tol_abs: 1e-9, max_cells: 3000, ..Default::default() };
    let k = TubeKernel::new(&C, &F, &E, &theta, Horizon::Infinite, &st).expect("a wider enclosure, not an error");
    assert!(k.cells() <= 3000);
    assert!(k.remainder_bound() > 0.5e-9, "the target cannot be met with 3000 cells");
    let enc = k.support_bounds(&[1.0]);
    let reference = stiff_reference(-2000.0, &C, &E, 80.0, 0.1);
    assert!(enc.lower <= reference + 1e-7 && reference <= enc.upper + 1e-7, "{enc:?} vs {reference}");
}

#[test]
fn long_steps_by_squaring_carry_their_error() {
    let (F, _, _, V, Vi) = stiff_system(-5000.0);
    let sg = SemigroupData::new(&F);
    let msup = sg.exp_norm().unwrap().sup;
    for t in [0.01, 0.37, 2.0, 9.0] {
        let (X, e) = semigroup::exp_long(&F, t, msup);
        let reference = modal_exp(-5000.0, &V, &Vi, t);
        let dist = (&X - &reference).norm();
        // the modal reference is accurate to about 1e-15 cond(V) ||e^{tF}||
        assert!(dist <= e + 1e-13, "t {t}: {dist} > {e}");
        assert!(e < 1e-8, "t {t}: error bound {e} is useless");
        // Negative control: a matrix off by 10 times the bound is detected.
        let mut Y = X.clone();
        Y[(0, 0)] += 10.0 * e + 1e-12;
        assert!((&Y - &reference).norm() > e + 1e-13);
    }
}

#[test]
fn the_two_norm_bound_is_proven_and_a_smaller_one_is_rejected() {
    let (F, _, _, _, _) = stiff_system(-300.0);
    for t in [0.001, 0.01, 0.3, 3.0] {
        let P = dynamics::linear::expm::expm(&(&F * t));
        let sigma = P.clone().singular_values().max();
        let b = semigroup::norm2_up(&P);
        assert!(b >= sigma && b <= sigma * (1.0 + 1e-6), "t {t}: {b} vs {sigma}");
        // Negative control: Rump's test does not prove a t below sigma^2.
        let t2 = (0.999 * sigma).powi(2);
        let M = DMatrix::<f64>::identity(3, 3) * t2 - P.transpose() * &P;
        assert!(!lmi::verify::proves_lambda_min_at_least(&M, 0.0, 0.0));
    }
    // the stiff semigroup bound covers the sampled norms
    let (F, _, _, V, Vi) = stiff_system(-3000.0);
    let b = exp_norm_bounds(&F).unwrap();
    let sampled = (0..4000)
        .map(|k| modal_exp(-3000.0, &V, &Vi, 1e-5 * 1.004f64.powi(k)).singular_values().max())
        .fold(0.0, f64::max);
    assert!(sampled <= b.sup, "{sampled} > {}", b.sup);
}
