//! `eta_T` in closed form for a multisine input `w = a sum_j c_j sin(k_j theta + phi_j)`,
//! `theta = omega t + phase` (proofs-notes/eta-multisine.md).
//!
//! The linearised system (eq. (xieta)) is linear, so its `T`-periodic orbit is the sum of the
//! sine orbits of the harmonics: with `g_j = (i k_j omega I - F)^{-1} B a`,
//! `P_j = C Re g_j`, `Q_j = C Im g_j` and `alpha_j = k_j theta + phi_j`,
//! `eta_T = sum_j c_j (P_j sin alpha_j + Q_j cos alpha_j)` and
//! `eta_T' = sum_j c_j k_j omega (P_j cos alpha_j - Q_j sin alpha_j)`.
//! Unlike a single sine the orbit is no ellipse, so `osc` and `||eta_T'||_inf` come from
//! samples (`EtaOrbit::certify_samples`): `osc` from below by the samples' diameter, and
//! `||eta_T'||_inf` from above by the samples and the Lipschitz constant of `eta_T'`,
//! `|eta_T''| <= L = sum_j |c_j| (k_j omega)^2 rho_j` with `rho_j = sqrt(|P_j|^2 + |Q_j|^2)`
//! (each term `P sin + Q cos` has norm at most `rho_j`).
//!
//! Rounding: each phasor carries the sine's relative margin `1e-12 + 16 n cond(i k_j omega I -
//! F) eps`; the sines, products and the sum over `J` harmonics add `gamma_{J + 4}` relative to
//! the sum of the terms' sizes. The error of a sample is therefore at most `m sum_j |c_j| rho_j`
//! (of `eta_T'`: `m sum_j |c_j| k_j omega rho_j`), which is passed to
//! `EtaOrbit::certify_samples` relative to the largest sample, so harmonics that cancel in
//! the samples still count with their full size.
use super::eta_orbit::EtaOrbit;
use dynamics::periodic::linearised::sine_phasor;
use model::input::Harmonic;
use model::System;
use nalgebra::DVector;

/// One harmonic's phasor: `(k omega, c, phi, P, Q, rho)`.
struct Term {
    freq: f64,
    k: f64,
    weight: f64,
    phase: f64,
    P: DVector<f64>,
    Q: DVector<f64>,
    rho: f64,
}

/// The orbit of `sys` under its multisine input (amplitudes `a`, fundamental `omega`, `phase`,
/// `harmonics`) on `K` sample intervals of the period `T`. Not verified when a harmonic's
/// frequency is an eigenvalue of `F` to working precision, the margin exceeds `1e-3`, or the
/// orbit is a point.
pub(super) fn orbit(
    sys: &System,
    a: &[f64],
    omega: f64,
    phase: f64,
    harmonics: &[Harmonic],
    T: f64,
    K: usize,
) -> EtaOrbit {
    let n = sys.n();
    let F = sys.F();
    let mut terms = Vec::with_capacity(harmonics.len());
    let mut cond_max = 0.0f64;
    for h in harmonics {
        let freq = h.k as f64 * omega;
        let (P, Q, cond) = match sine_phasor(&F, &sys.B, a, freq) {
            Some(ph) => (&sys.C * ph.g.map(|z| z.re), &sys.C * ph.g.map(|z| z.im), ph.cond),
            None => (DVector::from_element(sys.p(), f64::NAN), DVector::from_element(sys.p(), f64::NAN), f64::INFINITY),
        };
        cond_max = cond_max.max(cond);
        let rho = (P.norm_squared() + Q.norm_squared()).sqrt();
        terms.push(Term { freq, k: h.k as f64, weight: h.weight, phase: h.phase, P, Q, rho });
    }
    let size: f64 = terms.iter().map(|t| t.weight.abs() * t.rho).sum();
    let dsize: f64 = terms.iter().map(|t| t.weight.abs() * t.freq * t.rho).sum();
    let deta_lipschitz = terms.iter().map(|t| t.weight.abs() * t.freq * t.freq * t.rho).sum::<f64>() * (1.0 + 1e-12);
    let dt = T / K as f64;
    let (mut ts, mut eta, mut deta) = (Vec::with_capacity(K + 1), Vec::with_capacity(K + 1), Vec::with_capacity(K + 1));
    for i in 0..=K {
        let t = i as f64 * dt;
        let theta = omega * t + phase;
        let (mut e, mut d) = (vec![0.0; sys.p()], vec![0.0; sys.p()]);
        for term in &terms {
            let (s, c) = (term.k * theta + term.phase).sin_cos();
            for r in 0..sys.p() {
                e[r] += term.weight * (term.P[r] * s + term.Q[r] * c);
                d[r] += term.weight * term.freq * (term.P[r] * c - term.Q[r] * s);
            }
        }
        ts.push(t);
        eta.push(e);
        deta.push(d);
    }
    let m = 1e-12 + 16.0 * n as f64 * cond_max * f64::EPSILON + rounding::gamma(harmonics.len() + 4);
    let mut o = EtaOrbit::from_samples(T, ts, eta, deta, deta_lipschitz, vec![]);
    // the samples' errors relative to the largest sample (what certify_samples expects); a
    // point orbit (osc 0) is refused by certify_samples itself
    let (big_eta, big_deta) = o.largest_samples();
    let relative = |abs: f64, largest: f64| if abs == 0.0 { 0.0 } else { abs / largest };
    let margin = relative(m * size, big_eta).max(relative(m * dsize, big_deta)) * (1.0 + 1e-12);
    let finite = size.is_finite() && dsize.is_finite() && deta_lipschitz.is_finite();
    let verified = finite && margin < 1e-3;
    o.certify_samples(if finite { margin } else { f64::INFINITY }, verified);
    o.method = "closed form (multisine: a sum of phasors; osc from the samples, ||eta_T'|| from the samples and sum c (k omega)^2 |C g|)";
    o
}
