//! The long recording of the speed benchmarks (`benches/diagnose.rs`, `examples/speed.rs`):
//! the plant of the generator's `coulomb_friction` case (seed 3, case 0) with its true friction,
//! driven by a three-sine input for `n` samples and simulated by the diagnoser's own extended
//! model at 8 sub-steps, with measurement noise of about 1 % of the output range.
use crate::Recording;
use dynamics::extended::ExtendedModel;
use rand::{Rng, SeedableRng};

/// The noise of [`long_recording`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LongNoise {
    /// Deterministic: a sawtooth of period 1000 samples and amplitude 1 % of the range (strongly
    /// coloured, so the selected model's residual is never white and the pair search of the
    /// forward selection always runs).
    Sawtooth,
    /// Gaussian white noise of the sawtooth's standard deviation (seeded).
    White,
}

/// The nominal model and the `n`-sample recording.
pub fn long_recording(n: usize, noise: LongNoise) -> (model::System, Recording) {
    let case = super::generate("coulomb_friction", 3, 0);
    let sys = case.nominal.clone();
    let dt = case.recording.dt;
    let w: Vec<f64> = (0..n)
        .map(|k| {
            let t = k as f64 * dt;
            0.6 * (0.31 * t).sin() + 0.3 * (0.97 * t + 1.0).sin() + 0.2 * (2.3 * t + 2.0).sin()
        })
        .collect();
    let truth = case.truth.clone().into_iter().collect::<Vec<_>>();
    let y = ExtendedModel::new(&sys, &truth, dt, 8).expect("the generator's model compiles").simulate(
        &w,
        dt,
        sys.x0.as_slice(),
    );
    let y = y.y;
    let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
    let yr = y.iter().copied().fold(f64::NEG_INFINITY, f64::max) - y.iter().copied().fold(f64::INFINITY, f64::min);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(27);
    let mut gauss = || {
        let u1: f64 = rng.random::<f64>().max(1e-300);
        let u2: f64 = rng.random();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    };
    let ys: Vec<Vec<f64>> = y
        .iter()
        .enumerate()
        .map(|(k, v)| match noise {
            LongNoise::Sawtooth => vec![v + 0.01 * yr * (((k * 7919) % 1000) as f64 / 1000.0 - 0.5)],
            LongNoise::White => vec![v + 0.01 * yr / 12f64.sqrt() * gauss()],
        })
        .collect();
    let rec = Recording::from_samples("long", &t, w.iter().map(|v| vec![*v]).collect(), ys, None);
    (sys, rec)
}
