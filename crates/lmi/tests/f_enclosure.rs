//! The certificate of eqs. (ALI), (bet) covers the rounding of `F = fl(A + fl(E C))` (issue 15,
//! item 3): every `F` in the entrywise enclosure `[F - r_F, F + r_F]`,
//! `r_F = 2 (gamma_1 |F| + gamma_p |E||C|)`, satisfies the proved inequalities. Negative
//! controls: a certificate whose margin is below the enclosure's effect is rejected.
#![allow(non_snake_case)]
use lmi::fixtures::paper_example;
use lmi::verify::{
    certify, check_certificate, check_certificate_with, f_enclosure_radius, lyapunov_matrix, lyapunov_matrix_enclosed,
    schur_block, schur_block_enclosed, VerifySettings,
};
use lmi::{certified_beta, BetaSdpSettings};
use nalgebra::DMatrix;
use rounding::gamma;

/// A system with a huge loop gain `E C` (entries 1e6), so that the rounding of `A + E C` is
/// ~2e-10 per entry, while `F = -I` has (ALI) margin `1 - lambda` with `Pi = I`.
fn big_gain() -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) {
    let E = DMatrix::from_row_slice(2, 1, &[1e3, 0.0]);
    let C = DMatrix::from_row_slice(1, 2, &[1e3, 0.0]);
    let A = DMatrix::from_row_slice(2, 2, &[-1.0 - 1e6, 0.0, 0.0, -1.0]);
    let F = &A + &E * &C;
    (F, E, C)
}

#[test]
fn radius_formula_and_exactness_of_the_worked_example() {
    let (F, E, C) = paper_example();
    let r = f_enclosure_radius(&F, &E, &C);
    // |F| = [[0, 1], [1, 0.6]], |E||C| = [[0, 0], [1, 0]]: r = 2 (g1 |F| + g1 |E||C|).
    let g = gamma(1);
    assert!((r[(0, 1)] - 2.0 * g).abs() <= 1e-30 + 1e-12 * g);
    assert!((r[(1, 0)] - 4.0 * g).abs() <= 1e-30 + 1e-12 * g);
    assert!(r[(0, 0)] < 1e-299, "zero entry: only the underflow slack");
    // Big gain: the radius is ~ 2 gamma_1 1e6 = 2.2e-10 on entry (0, 0).
    let (F, E, C) = big_gain();
    let r = f_enclosure_radius(&F, &E, &C);
    assert!(r[(0, 0)] > 2.2e-10 && r[(0, 0)] < 2.3e-10, "{}", r[(0, 0)]);
}

#[test]
fn enclosure_enters_the_rump_margins_of_ali_and_bet() {
    let (F, E, C) = big_gain();
    let Pi = DMatrix::<f64>::identity(2, 2);
    let Fr = f_enclosure_radius(&F, &E, &C);
    let (_, r0) = lyapunov_matrix(&F, &Pi, 0.5);
    let (_, r1) = lyapunov_matrix_enclosed(&F, Some(&Fr), &Pi, 0.5);
    assert!(r1 - r0 > 1e-10, "(ALI) margin grows by the enclosure: {r0} -> {r1}");
    let (_, s0) = schur_block(&F, &E, &C, &Pi, 1e7);
    let (_, s1) = schur_block_enclosed(&F, Some(&Fr), &E, &C, &Pi, 1e7);
    assert!(s1 - s0 > 1e-8, "(bet) margin grows by r_F^T |C|^T / 2: {s0} -> {s1}");
}

/// Negative control: `Pi = I` proves (ALI) at `lambda = 1 - 1e-12` for the rounded `F = -I`
/// taken as exact (margin 1e-12 against a rounding of ~1e-15), but not for the enclosure
/// (radius 2.2e-10): the flag flips. `certify` then backs `lambda` off by about the radius.
#[test]
fn negative_control_margin_below_the_f_rounding_is_rejected() {
    let (F, E, C) = big_gain();
    let Pi = DMatrix::<f64>::identity(2, 2);
    let lambda = 1.0 - 1e-12;
    // H = (E - F^T C^T)/2 = (1e3 + 1e3)/2 e1 = 1e3 e1: beta = 1e6.
    let b = 1e6 * (1.0 + 1e-6);
    let exact = check_certificate_with(&F, &E, &C, &Pi, lambda, b, false).unwrap();
    assert!(exact.verified && exact.f_radius == 0.0, "{exact:?}");
    let enclosed = check_certificate(&F, &E, &C, &Pi, lambda, b).unwrap();
    assert!(!enclosed.lyapunov.verified && !enclosed.verified, "{enclosed:?}");
    assert!(enclosed.f_radius > 2.2e-10);
    let cert = certify(&F, &E, &C, &Pi, lambda, b, &VerifySettings::default()).unwrap();
    assert!(cert.verified, "{cert:?}");
    assert!(cert.lambda < 1.0 - 2e-10 && cert.lambda > 1.0 - 1e-8, "backed off: {}", cert.lambda);
    // (bet) at b just above beta = 1e6: lambda_min(K) ~ (b - |H|^2) / b ~ 1e-8, while
    // |Delta H| <= r_F^T |C|^T / 2 ~ 1.1e-7: b = 1e6 (1 + 1e-8) passes for the exact F only.
    let tight = 1e6 * (1.0 + 1e-8);
    let ex = check_certificate_with(&F, &E, &C, &Pi, 0.5, tight, false).unwrap();
    let en = check_certificate(&F, &E, &C, &Pi, 0.5, tight).unwrap();
    assert!(ex.schur.verified && !en.schur.verified, "{ex:?} / {en:?}");
}

/// On the worked example the enclosure costs nothing visible: the certified beta SDP is verified
/// at the requested lambda, and the certificate records the radius (~1e-15).
#[test]
fn worked_example_certificate_covers_the_enclosure() {
    let (F, E, C) = paper_example();
    let cb = certified_beta(&F, &E, &C, 0.15, &BetaSdpSettings::default()).unwrap();
    assert!(cb.certificate.verified && cb.certificate.lambda == 0.15);
    assert!(cb.certificate.f_radius > 0.0 && cb.certificate.f_radius < 1e-14, "{}", cb.certificate.f_radius);
}
