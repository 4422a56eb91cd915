//! The two typos of the paper confirmed by computation (proofs-notes/xT-typo.md, theorem1.md).
#![allow(non_snake_case)]
use nalgebra::{DMatrix, DVector};
use proptest::strategy::{Strategy, ValueTree};
use proptest::test_runner::TestRunner;
use theorems::strategies::systems::{system_params, SystemStrategyConfig};

/// `int_0^T K(s) B w(s) ds` by composite Simpson with `2 N` panels, `K` given per node.
fn simpson(sys: &model::System, T: f64, N: usize, kernel: impl Fn(f64) -> DMatrix<f64>) -> DVector<f64> {
    let h = T / (2 * N) as f64;
    let mut w = DVector::zeros(sys.m());
    let mut acc = DVector::zeros(sys.n());
    for i in 0..=2 * N {
        let s = i as f64 * h;
        sys.input.eval(s, w.as_mut_slice());
        let c = if i == 0 || i == 2 * N {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        acc += kernel(s) * (&sys.B * &w) * c;
    }
    acc * (h / 3.0)
}

/// (xT): with the corrected integrand `e^{(T-s)F} B w(s)`, `xi(0) = (I - e^{TF})^{-1} int` is
/// `T`-periodic (`xi(T) = xi(0)` to quadrature accuracy); the printed `e^{(T-t)F}` read at
/// `t = 0` (`e^{TF}` outside the integral) is not, on every one of 50 random systems.
#[test]
fn xT_corrected_integrand_is_periodic_printed_is_not() {
    let mut runner = TestRunner::deterministic();
    let strat = system_params(&SystemStrategyConfig::default());
    let (mut worst_fixed, mut best_printed) = (0.0f64, f64::INFINITY);
    for _ in 0..50 {
        let sys = strat.new_tree(&mut runner).unwrap().current().build();
        let T = sys.period().unwrap();
        let F = sys.F();
        let n = sys.n();
        let inv = (DMatrix::identity(n, n) - (&F * T).exp()).try_inverse().unwrap();
        let fixed = &inv * simpson(&sys, T, 2000, |s| (&F * (T - s)).exp());
        let printed = &inv * simpson(&sys, T, 2000, |_| (&F * T).exp());
        // xi(T) from xi(0) by the exact flow of xi' = F xi + B w
        let flow = |x0: &DVector<f64>| {
            let mut s = sys.clone();
            s.x0 = x0.clone();
            theorems::properties::simulation::linear_response_exact(&s, &F, T / 100.0, 100).unwrap().pop().unwrap()
        };
        let scale = fixed.norm() + 1e-300;
        worst_fixed = worst_fixed.max((flow(&fixed) - &fixed).norm() / scale);
        best_printed = best_printed.min((flow(&printed) - &printed).norm() / scale);
    }
    eprintln!("(xT): max |xi(T) - xi(0)|/|xi(0)| corrected = {worst_fixed:.2e}; min printed = {best_printed:.2e}");
    assert!(worst_fixed < 1e-8, "corrected formula not periodic: {worst_fixed:e}");
    assert!(best_printed > 1e-2, "printed formula periodic on some system: {best_printed:e}");
}

/// (Phi): `t C Psi(tA) E` is `p x p`, so `I_p - t C Psi E` is the well-formed matrix; the printed
/// `I_n - ...` does not exist when `n != p` (a shape fact, checked on the random systems).
#[test]
fn phi_is_p_by_p_and_I_n_is_ill_formed() {
    let mut runner = TestRunner::deterministic();
    let strat = system_params(&SystemStrategyConfig::default());
    let mut mismatched = 0;
    for _ in 0..50 {
        let sys = strat.new_tree(&mut runner).unwrap().current().build();
        let (n, p) = (sys.n(), sys.p());
        let cpe = &sys.C * dynamics::linear::expm::t_psi(&sys.A, 0.7) * &sys.E;
        assert_eq!(cpe.shape(), (p, p));
        let phi = DMatrix::<f64>::identity(p, p) - &cpe; // (Phi) with I_p
        assert!(phi.iter().all(|v| v.is_finite()));
        if n != p {
            mismatched += 1;
            // I_n - (p x p) is undefined (nalgebra would panic on the dimension mismatch)
            assert_ne!(DMatrix::<f64>::identity(n, n).shape(), cpe.shape(), "n = {n}, p = {p}");
        }
    }
    assert!(mismatched > 10, "too few n != p systems: {mismatched}");
}
