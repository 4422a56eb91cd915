//! Floating-point rounding in the tube quadrature and the theta assembly is bounded and included
//! (issue 15, item 3): the size of each margin on the examples, and negative controls showing
//! that a wrong claim is rejected (a bound check fails or a verified flag becomes false).
#![allow(non_snake_case)]
use bounds::tube::{tube_diameters, Horizon, TubeKernel, TubeSettings};
use geometry::{ConvexSet, Shape, SphereMaxSettings};
use nalgebra::DMatrix;

fn load(name: &str) -> model::System {
    model::load(std::path::Path::new(&format!("{}/../../examples/{name}", env!("CARGO_MANIFEST_DIR")))).unwrap()
}

/// The floating-point terms are included, are tiny against the quadrature tolerance, and the
/// F enclosure of `fl(A + fl(E C))` adds its own (small) term.
#[test]
fn rounding_terms_are_included_and_tiny_on_the_examples() {
    for name in ["worked-example.toml", "ellipse-p2.toml", "lens-p2.toml", "ellipsoid-p3.toml"] {
        let sys = load(name);
        let F = sys.F();
        let eps = lmi::verify::f_enclosure_radius(&F, &sys.E, &sys.C).norm();
        let st = TubeSettings::default();
        let k0 = TubeKernel::new(&sys.C, &F, &sys.E, &sys.theta, Horizon::Infinite, &st).unwrap();
        let kf =
            TubeKernel::new(&sys.C, &F, &sys.E, &sys.theta, Horizon::Infinite, &TubeSettings { f_radius: eps, ..st })
                .unwrap();
        eprintln!(
            "{name}: cells {}, remainder {:.3e}, tail {:.3e}, rounding {:.3e} (with F enclosure eps = {eps:.3e}: {:.3e})",
            k0.cells(),
            k0.remainder_bound(),
            k0.tail_bound(),
            k0.rounding_bound(),
            kf.rounding_bound()
        );
        assert!(k0.rounding_bound() > 0.0 && k0.rounding_bound() < 1e-9, "{name}");
        assert!(kf.rounding_bound() > k0.rounding_bound() && kf.rounding_bound() < 1e-9, "{name}");
        // The upper value contains the terms: it is at least the upper sums plus remainder,
        // tail and rounding (here checked against the lower value plus the width they add).
        let p = sys.p();
        let mut v = vec![0.0; p];
        v[0] = 1.0;
        let b = kf.support_bounds(&v);
        assert!(b.upper - b.lower >= 2.0 * kf.rounding_bound(), "{name}: {b:?}");
    }
}

/// Negative control for the F enclosure: a kernel for `F` with `f_radius = 0` does not contain the
/// support value of a perturbed `F' = F + D` (`||D||_2 = 1e-4`), while with `f_radius >= ||D||`
/// it does.
#[test]
fn negative_control_f_enclosure_is_needed_and_sufficient() {
    let sys = load("worked-example.toml");
    let F = sys.F();
    let mut Fp = F.clone();
    Fp[(1, 1)] += 1e-4;
    let st = TubeSettings { tol_abs: 1e-8, ..Default::default() };
    let k_p = TubeKernel::new(&sys.C, &Fp, &sys.E, &sys.theta, Horizon::Infinite, &st).unwrap();
    let truth_low = k_p.support_bounds(&[1.0]).lower;
    let k_exact = TubeKernel::new(&sys.C, &F, &sys.E, &sys.theta, Horizon::Infinite, &st).unwrap();
    assert!(k_exact.support_upper(&[1.0]) < truth_low, "without the enclosure the perturbed value is outside");
    let k_encl =
        TubeKernel::new(&sys.C, &F, &sys.E, &sys.theta, Horizon::Infinite, &TubeSettings { f_radius: 1e-4, ..st })
            .unwrap();
    assert!(k_encl.support_upper(&[1.0]) >= truth_low);
}

/// Negative control that flips the flag: an F enclosure too wide for the semigroup bound
/// (`eps I >= 1/2`) makes the support values infinite, and `tube_diameters` reports
/// `verified = false`; the default (exact F) and the true enclosure verify.
#[test]
fn negative_control_unusable_enclosure_unverifies_the_diameters() {
    let sys = load("worked-example.toml");
    let F = sys.F();
    let sphere = SphereMaxSettings { tol_abs: 1e-9, tol_rel: 1e-6, max_evals: 20_000 };
    let eps = lmi::verify::f_enclosure_radius(&F, &sys.E, &sys.C).norm();
    let ok =
        tube_diameters(&sys.C, &F, &sys.E, &sys.theta, &TubeSettings { f_radius: eps, ..Default::default() }, &sphere)
            .unwrap();
    assert!(ok.verified);
    let bad =
        tube_diameters(&sys.C, &F, &sys.E, &sys.theta, &TubeSettings { f_radius: 10.0, ..Default::default() }, &sphere)
            .unwrap();
    assert!(!bad.verified, "{:?}", bad.d);
}

/// The disc fast path's upper support value (split certificate) is above the plain value and
/// tight; a shape's `support_upper` likewise.
#[test]
fn upper_support_values_bracket_the_plain_ones() {
    let sys = load("lens-p2.toml");
    let fast = bounds::tube::xi_support::ThetaSupport::new(&sys.theta);
    for k in 0..720 {
        let a = std::f64::consts::TAU * k as f64 / 720.0 + 0.0007;
        let u = [1.7 * a.cos(), 1.7 * a.sin()];
        let (plain, upper, shape_up) = (fast.support(&u), fast.support_upper(&u), sys.theta.support_upper(&u));
        assert!(upper >= plain && upper <= plain + 1e-13, "{a}: {upper} vs {plain}");
        assert!(shape_up >= sys.theta.support(&u) && shape_up <= plain + 1e-13, "{a}: {shape_up} vs {plain}");
    }
    // A matrix-valued check for the other shapes used by the examples.
    for name in ["ellipse-p2.toml", "ellipsoid-p3.toml", "worked-example.toml"] {
        let th = load(name).theta;
        let p = th.dim();
        for k in 0..200 {
            let u: Vec<f64> = (0..p).map(|i| ((k * (i + 3)) as f64 * 0.37).sin()).collect();
            let (plain, upper) = (th.support(&u), th.support_upper(&u));
            assert!(upper >= plain && upper <= plain + 1e-14 * (1.0 + plain.abs()), "{name}: {upper} vs {plain}");
        }
    }
    let _ = DMatrix::<f64>::zeros(1, 1);
    let _ = Shape::origin(1);
}

/// `a b = hi + lo` exactly (FMA).
fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

/// Item (d): `gamma_1` (down), `gamma_inf` (up) and `kappa` (down) against the exact values of
/// their formulas in the report's own inputs: `gamma_1 T R <= osc - d` and
/// `gamma_inf R >= eta_dot_inf + D(...)` checked in exact arithmetic (error-free
/// transformations), and `kappa <= gamma_1 / gamma_inf`. Negative control: the nearest-rounded
/// quotient is above the exact one for some of these inputs, so the direction matters.
#[test]
fn gamma_and_kappa_are_rounded_in_the_safe_direction() {
    let settings = bounds::ThetaSettings::bound_only();
    let mut nearest_above = 0;
    for name in
        ["worked-example.toml", "worked-example-a5.toml", "ellipse-p2.toml", "lens-p2.toml", "ellipsoid-p3.toml"]
    {
        let r = bounds::assemble(&load(name), &settings).unwrap();
        let (T, R) = (r.period, r.R);
        // gamma_1 T R <= osc - d, exactly: g (TR_hi + TR_lo) vs osc - d.
        let (tr, tr_lo) = two_prod(T, R);
        let (p, p_lo) = two_prod(r.gamma_1, tr);
        let (od, od_lo) = two_sum(r.osc, -r.d);
        let lhs_minus_rhs = (p - od) + (p_lo + r.gamma_1 * tr_lo - od_lo);
        assert!(lhs_minus_rhs <= 0.0, "{name}: gamma_1 T R > osc - d by {lhs_minus_rhs}");
        // gamma_inf R >= zdot_bound.
        let (q, q_lo) = two_prod(r.gamma_inf, R);
        assert!((q - r.zdot_bound) + q_lo >= 0.0, "{name}: gamma_inf R < zdot");
        // kappa <= gamma_1 / gamma_inf: kappa gamma_inf <= gamma_1 exactly.
        let (k, k_lo) = two_prod(r.kappa, r.gamma_inf);
        assert!((k - r.gamma_1) + k_lo <= 0.0, "{name}: kappa too large");
        // Negative control bookkeeping: is the nearest quotient above the exact one?
        let g_near = (r.osc - r.d) / (T * R);
        let (pn, pn_lo) = two_prod(g_near, tr);
        if r.osc > r.d && (pn - od) + (pn_lo + g_near * tr_lo - od_lo) > 0.0 {
            nearest_above += 1;
        }
    }
    eprintln!("nearest-rounded gamma_1 above its exact value on {nearest_above} of 5 examples");
    assert!(nearest_above >= 1, "negative control: round-to-nearest overshoots on some example");
}

/// Knuth's TwoSum: `a + b = s + e` exactly.
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}
