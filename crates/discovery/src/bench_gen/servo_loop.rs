//! Grey-box generator case: a sampled (1 kHz) PD position loop on a mass with viscous
//! friction, whose nominal model has the wrong mass and the wrong viscous term (issue 14).
//!
//! True machine: a carriage of mass `m` with viscous friction `c` (`m x'' = u - c x'`),
//! driven by a digital PD controller sampled every `h = 1 ms`:
//! `u_k = Kp (r_k - y_k) - Kd v_k`, held over the sample (zero-order hold), with `y_k` the
//! measured position (quantised to 1 um, plus 0.3 um white noise) and `v_k` the drive's
//! velocity estimate (the true velocity plus white noise of 0.1 mm/s), `r_k` the reference.
//! Between samples the plant is integrated exactly (closed form of the mass with viscous
//! friction under a constant force), so this simulator shares nothing with the diagnoser's.
//! Closed loop: natural frequency `omega_n` log-uniform in 2-6 Hz, damping ratio in
//! [0.5, 0.8], `Kp = m omega_n^2`, `Kd = 2 zeta omega_n m - c` with `c` 10-40 % of the total
//! damping; `m` log-uniform in [0.5, 5] kg. Reference: a multisine of 4-6 components from
//! 0.05 to 1.2 `omega_n` (10-40 mm in all), faded in over 0.2 s; 8 s recorded.
//!
//! Nominal model handed to the diagnosis (the continuous-time loop, state `x = (position,
//! velocity)`, input the reference, output the position):
//! `A = [[0, 1], [-Kp/m, -(c + Kd)/m]]`, `B = [[0], [Kp/m]]`, `C = [[1, 0]]`, `E = 0`,
//! `Theta = {0}`, with `m` off by 20-40 % (either sign) and `c` by a factor in [0.5, 2]
//! (either way), the gains `Kp`, `Kd` known exactly (they are the controller's). The model
//! file frees `plant.A[1][0]`, `plant.A[1][1]`, `plant.B[1][0]` (`[fit] free`); the mass is
//! recovered as `m = Kp / B[1][0]` and the viscous term as `c = -A[1][1] m - Kd`.
//! With `correct_nominal` the nominal is the truth (negative control).
//!
//! The continuous loop is itself an approximation of the sampled one: the hold and the
//! sampled velocity delay the control force by about `h / 2`, which a continuous model
//! absorbs as a mass smaller by about `Kd h / 2` (relative `zeta omega_n h`, 0.5-2.4 % here).
use super::gauss;
use crate::recording::Recording;
use model::model_file::{FreeParam, PlantMatrix, Signals};
use model::{Input, SimDefaults, System};
use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::TAU;

/// Sample period of the controller and the recording (s).
pub const H: f64 = 1e-3;
/// Length of a record (s).
pub const DURATION: f64 = 8.0;
/// Position quantisation (m) and white position noise (m).
pub const QUANT: f64 = 1e-6;
pub const POS_NOISE: f64 = 0.3e-6;
/// White noise of the drive's velocity estimate (m/s).
pub const VEL_NOISE: f64 = 1e-4;

/// The true machine of a case.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct ServoTruth {
    pub mass: f64,
    pub viscous: f64,
    /// Coulomb friction force (N; 0 in the grey-box cases).
    pub coulomb: f64,
    pub kp: f64,
    pub kd: f64,
    pub omega_n: f64,
    pub zeta: f64,
}

/// A generated grey-box case.
#[derive(Debug, Clone)]
pub struct ServoCase {
    pub truth: ServoTruth,
    /// Mass and viscous term of the nominal model.
    pub nominal_mass: f64,
    pub nominal_viscous: f64,
    /// The nominal model (with `[fit] free` and `[signals]` set).
    pub nominal: System,
    pub recording: Recording,
    pub description: String,
}

/// The parameters the nominal model frees.
pub const FREE: [&str; 3] = ["plant.A[1][0]", "plant.A[1][1]", "plant.B[1][0]"];

/// The continuous-time loop model of mass `m`, viscous term `c` and gains `kp`, `kd`.
pub fn loop_model(name: &str, m: f64, c: f64, kp: f64, kd: f64) -> System {
    let A = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -kp / m, -(c + kd) / m]);
    let B = DMatrix::from_row_slice(2, 1, &[0.0, kp / m]);
    let mut sys = System::builder()
        .name(name)
        .A(A)
        .B(B)
        .C(DMatrix::from_row_slice(1, 2, &[1.0, 0.0]))
        .E(DMatrix::zeros(2, 1))
        .input(Input::Zero { m: 1 })
        .x0(DVector::zeros(2))
        .z0(DVector::zeros(1))
        .sim(SimDefaults { dt: H, periods: 1, t_end: Some(DURATION) })
        .build()
        .expect("the loop model is valid");
    sys.fit.free = vec![
        FreeParam::entry(PlantMatrix::A, 1, 0),
        FreeParam::entry(PlantMatrix::A, 1, 1),
        FreeParam::entry(PlantMatrix::B, 1, 0),
    ];
    sys.signals = Signals { y: vec!["m".into()], w: vec!["m".into()], t: "s".into(), reference: vec![0] };
    sys
}

/// Mass and viscous term read off a loop model: `m = Kp / B[1][0]`, `c = -A[1][1] m - Kd`.
pub fn mass_and_viscous(sys: &System, kp: f64, kd: f64) -> (f64, f64) {
    let m = kp / sys.B[(1, 0)];
    (m, -sys.A[(1, 1)] * m - kd)
}

/// Case `index` of `seed`; `correct_nominal`: the nominal model is the truth.
pub fn generate(seed: u64, index: usize, correct_nominal: bool) -> ServoCase {
    generate_with_friction(seed, index, correct_nominal, 0.0)
}

/// As [`generate`], the carriage also under Coulomb friction of `friction` times the largest
/// control force of the frictionless run's reference swing (`Fc = friction * Kp * max |r|`):
/// stuck while the drive force stays within `Fc`, sliding against `Fc` otherwise. Integrated
/// by 50 exact sub-steps per sample (constant force between velocity reversals; a sub-step
/// that would reverse the velocity stops at rest), nothing shared with the diagnoser. The
/// nominal model leaves the friction out: a friction-dominated sampled position loop
/// (issue 14's acceptance case).
pub fn generate_with_friction(seed: u64, index: usize, correct_nominal: bool, friction: f64) -> ServoCase {
    let mix = seed ^ 0x5E7B_0000_0000_0000 ^ 0x9E37_79B9_7F4A_7C15u64.wrapping_mul(index as u64 + 1);
    let mut rng = ChaCha8Rng::seed_from_u64(mix);
    let mass = (rng.random_range(0.5f64.ln()..5.0f64.ln())).exp();
    let omega_n = TAU * (rng.random_range(2.0f64.ln()..6.0f64.ln())).exp();
    let zeta: f64 = rng.random_range(0.5..0.8);
    let total = 2.0 * zeta * omega_n * mass;
    let viscous = total * rng.random_range(0.1..0.4);
    let kp = mass * omega_n * omega_n;
    let kd = total - viscous;
    let m_err = rng.random_range(0.2..0.4) * if rng.random::<bool>() { 1.0 } else { -1.0 };
    let c_fac = (rng.random_range(0.5f64.ln()..2.0f64.ln())).exp();
    let (nominal_mass, nominal_viscous) =
        if correct_nominal { (mass, viscous) } else { (mass * (1.0 + m_err), viscous * c_fac) };
    // Reference: multisine faded in.
    let k = rng.random_range(4..=6);
    let amp_total: f64 = rng.random_range(0.01..0.04);
    let comps: Vec<(f64, f64, f64)> = (0..k)
        .map(|_| {
            let f = omega_n * (rng.random_range(0.05f64.ln()..1.2f64.ln())).exp();
            (amp_total / k as f64 * rng.random_range(0.5..1.5), f, rng.random_range(0.0..TAU))
        })
        .collect();
    let reference = |t: f64| {
        let fade = (t / 0.2).min(1.0);
        let fade = fade * fade * (3.0 - 2.0 * fade);
        fade * comps.iter().map(|(a, w, p)| a * ((w * t + p).sin() - p.sin())).sum::<f64>()
    };
    let ns = (DURATION / H).round() as usize + 1;
    let rmax = (0..ns).map(|kk| reference(kk as f64 * H).abs()).fold(0.0, f64::max);
    let fc = friction.max(0.0) * kp * rmax;
    let a = viscous / mass;
    let (mut x, mut v) = (0.0f64, 0.0f64);
    let (mut t, mut w, mut y) = (Vec::with_capacity(ns), Vec::with_capacity(ns), Vec::with_capacity(ns));
    for kk in 0..ns {
        let tk = kk as f64 * H;
        let yk = ((x + POS_NOISE * gauss(&mut rng)) / QUANT).round() * QUANT;
        let vk = v + VEL_NOISE * gauss(&mut rng);
        let rk = reference(tk);
        t.push(tk);
        w.push(vec![rk]);
        y.push(vec![yk]);
        let u = kp * (rk - yk) - kd * vk;
        if fc == 0.0 {
            (x, v) = slide(x, v, u / viscous, a, H);
        } else {
            let hs = H / 50.0;
            for _ in 0..50 {
                if v == 0.0 && u.abs() <= fc {
                    continue; // stuck: static friction balances the drive
                }
                // sliding direction: of the velocity, or of the drive when starting from rest
                let dir = if v != 0.0 { v.signum() } else { u.signum() };
                let vinf = (u - fc * dir) / viscous;
                let (xn, vn) = slide(x, v, vinf, a, hs);
                if vn * dir < 0.0 {
                    // the velocity reaches 0 within the sub-step: stop there (at rest)
                    let tau = ((v - vinf) / (0.0 - vinf)).ln() / a;
                    x = slide(x, v, vinf, a, tau).0;
                    v = 0.0;
                } else {
                    (x, v) = (xn, vn);
                }
            }
        }
    }
    let recording = Recording::from_samples(&format!("servo-loop-{seed}-{index}"), &t, w, y, None);
    let nominal = loop_model(
        &format!("sampled PD loop #{index} (nominal{})", if correct_nominal { ", correct" } else { "" }),
        nominal_mass,
        nominal_viscous,
        kp,
        kd,
    );
    let description = format!(
        "m = {mass:.3} kg (nominal {nominal_mass:.3}), c = {viscous:.3} N s/m (nominal {nominal_viscous:.3}), omega_n = {:.2} Hz, zeta = {zeta:.2}, Kp = {kp:.1} N/m, Kd = {kd:.2} N s/m, Coulomb friction {fc:.3} N (not in the nominal), {ns} samples at 1 kHz",
        omega_n / TAU
    );
    ServoCase {
        truth: ServoTruth { mass, viscous, coulomb: fc, kp, kd, omega_n, zeta },
        nominal_mass,
        nominal_viscous,
        nominal,
        recording,
        description,
    }
}

/// Exact step of `x' = v`, `v' = a (vinf - v)` (the mass with viscous friction under a constant
/// force, `vinf` = force / viscous term) over `h`: the new `(x, v)`.
fn slide(x: f64, v: f64, vinf: f64, a: f64, h: f64) -> (f64, f64) {
    let e = (-a * h).exp();
    (x + vinf * h + (v - vinf) * (1.0 - e) / a, vinf + (v - vinf) * e)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nominal_of_the_truth_tracks_the_recording_and_the_wrong_one_does_not() {
        let good = generate(5, 0, true);
        let bad = generate(5, 0, false);
        assert_eq!(good.recording.y, bad.recording.y, "same machine, same record");
        let (m, c) = mass_and_viscous(&good.nominal, good.truth.kp, good.truth.kd);
        assert!((m / good.truth.mass - 1.0).abs() < 1e-12 && (c / good.truth.viscous - 1.0).abs() < 1e-9);
        let w: Vec<f64> = good.recording.w.iter().map(|r| r[0]).collect();
        let y: Vec<f64> = good.recording.y.iter().map(|r| r[0]).collect();
        let rms = |sys: &System| {
            let o = dynamics::extended::ExtendedModel::new(sys, &[], H, 4)
                .unwrap()
                .with_hold(dynamics::extended::InputHold::Zoh)
                .simulate(&w, H, &[0.0, 0.0]);
            (o.y.iter().zip(&y).map(|(a, b)| (a - b).powi(2)).sum::<f64>() / y.len() as f64).sqrt()
        };
        let (e_good, e_bad) = (rms(&good.nominal), rms(&bad.nominal));
        // The continuous model of the true machine tracks it to a few um (sampling, noise);
        // the wrong mass and viscous term miss by several times more.
        eprintln!("true nominal RMSE {e_good:e}, wrong {e_bad:e}");
        assert!(e_good < 1e-4, "true nominal RMSE {e_good:e}");
        assert!(e_bad > 3.0 * e_good, "wrong nominal RMSE {e_bad:e} against {e_good:e}");
    }
}
