//! Certificates on seeded random systems (the same family as the CVXPY/SCS cross-check).
#![allow(non_snake_case)]

use approx::assert_relative_eq;
use lmi::fixtures::random_hurwitz_system;
use lmi::verify::{beta_estimate, check_certificate, lambda_of_pi};
use lmi::{certified_beta, hurwitz_mu, BetaSdpSettings};

#[test]
fn twenty_random_systems_certify_without_back_off() {
    let s = BetaSdpSettings::default();
    for seed in 0..20u64 {
        let n = 1 + (seed as usize % 6);
        let p = 1 + (seed as usize % 3);
        let (F, E, C) = random_hurwitz_system(seed, n, p);
        let lambda = 0.5 * -hurwitz_mu(&F).unwrap();
        let cb = certified_beta(&F, &E, &C, lambda, &s).unwrap_or_else(|e| panic!("seed {seed}: {e}"));
        let cert = &cb.certificate;
        assert!(cert.verified, "seed {seed}");
        assert_eq!(cert.lambda, lambda, "seed {seed}: lambda backed off");
        // b_hat is the SDP optimum up to a tiny inflation, and beta(Pi) agrees with it.
        assert!(cert.b_hat >= cb.solution.beta);
        assert_relative_eq!(cert.b_hat, cb.solution.beta, max_relative = 1e-6, epsilon = 1e-9);
        assert_relative_eq!(beta_estimate(&F, &E, &C, &cert.Pi), cb.solution.beta, max_relative = 1e-5, epsilon = 1e-9);
        assert!(lambda_of_pi(&F, &cert.Pi) >= lambda);
        // Independent re-check of the stored certificate.
        assert!(check_certificate(&F, &E, &C, &cert.Pi, cert.lambda, cert.b_hat).unwrap().verified);
    }
}
