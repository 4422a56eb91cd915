//! Generator case of issue 28: a carriage under a sampled position/velocity cascade, as a
//! drive runs it, with Coulomb friction; two kinds of experiment on the same machine.
//!
//! True machine: mass `M` with viscous friction `Fv` and Coulomb friction `Fc`
//! (`M v' = F - Fv v - Fc sgn v`, stuck while `|F| <= Fc` at rest), driven by the force `F` of
//! a digital cascade sampled every `T = 1 ms`: `v_k = (y_k - y_{k-1}) / T` (the difference of
//! two measured positions), `u_k = kv (kp (w_k - y_k) - v_k)`, the force `u_k` applied one
//! period later (one sample of computation delay) and held over the period (zero-order hold).
//! `y_k` is the position quantised to 1 um plus 0.3 um white noise, as the drive reads it.
//! Between ticks the carriage is integrated in closed form, event by event (a velocity that
//! reaches zero stops there exactly, and the force then decides stick or slip): nothing is
//! stepped, so the reference has no step to converge ([`tick`]).
//!
//! Draws per case: `M` log-uniform in [0.5, 5] kg; velocity-loop bandwidth `kv / M`
//! log-uniform in 2 pi [15, 40] rad/s (so `kv T / M` is 0.09-0.25, stable with the delay);
//! `kp = kv / (4 M)` (1/s); `Fv = kv` x U[0.05, 0.2]; `Fc = M` x U[0.5, 2] m/s^2.
//! Experiments ([`Experiment`]), 8 s each, reference `w` in metres:
//! - `multisine`: 4-6 components from 0.05 to 1.2 `kp` rad/s, 10-40 mm in all, faded in over
//!   0.2 s;
//! - `triangle`: a slow triangle of 10-30 mm amplitude and 1.5-3 s period (constant-velocity
//!   strokes and reversals: friction-dominated).
//!
//! The model handed to the diagnosis ([`model_text`]) is the physical one: `[parameters]` `M`,
//! `Fv`, `Fc` (freed) and the gains `kp`, `kv` (known), the plant `A = [[0, 1], [0, -Fv/M]]`,
//! `B = [0, 1/M]`, the cascade in `[controller]` and `coulomb_friction` of level `Fc/M`.
//! [`stand_in_text`] is the continuous-time loop a model file without `[controller]` has to
//! use: `A = [[0, 1], [-kv kp/M, -(Fv + kv)/M]]`, `B = [0, kv kp/M]`.
use super::gauss;
use crate::recording::Recording;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::TAU;

/// Controller period and sample spacing (s).
pub const T: f64 = 1e-3;
/// Length of a record (s).
pub const DURATION: f64 = 8.0;
/// Position quantisation and white position noise (m).
pub const QUANT: f64 = 1e-6;
pub const POS_NOISE: f64 = 0.3e-6;
/// Computation delay of the drive (periods).
pub const DELAY: usize = 1;

/// The kind of experiment.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Experiment {
    Multisine,
    Triangle,
}

impl Experiment {
    pub fn name(&self) -> &'static str {
        match self {
            Experiment::Multisine => "multisine",
            Experiment::Triangle => "triangle",
        }
    }
}

/// The true machine and its controller.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct CascadeTruth {
    /// Mass (kg), viscous (N s/m) and Coulomb (N) friction.
    pub mass: f64,
    pub viscous: f64,
    pub coulomb: f64,
    /// Position gain (1/s) and velocity gain (N s/m).
    pub kp: f64,
    pub kv: f64,
}

/// Truth `index` of `seed`.
pub fn truth(seed: u64, index: usize) -> CascadeTruth {
    let mut rng = rng_for(seed, index, 0);
    let mass = rng.random_range(0.5f64.ln()..5.0f64.ln()).exp();
    let omega_v = TAU * rng.random_range(15.0f64.ln()..40.0f64.ln()).exp();
    let kv = mass * omega_v;
    let kp = omega_v / 4.0;
    let viscous = kv * rng.random_range(0.05..0.2);
    let coulomb = mass * rng.random_range(0.5..2.0);
    CascadeTruth { mass, viscous, coulomb, kp, kv }
}

fn rng_for(seed: u64, index: usize, stream: u64) -> ChaCha8Rng {
    let mix = seed ^ 0xCA5C_ADE0_0000_0000 ^ 0x9E37_79B9_7F4A_7C15u64.wrapping_mul(index as u64 + 1);
    ChaCha8Rng::seed_from_u64(mix.wrapping_add(stream.wrapping_mul(0xD1B5_4A32_D192_ED03)))
}

/// The reference of experiment `e` for case `(seed, index)`, as a function of time.
fn reference(seed: u64, index: usize, e: Experiment, kp: f64) -> Box<dyn Fn(f64) -> f64> {
    let mut rng = rng_for(seed, index, 1 + e as u64);
    match e {
        Experiment::Multisine => {
            let k = rng.random_range(4..=6);
            let amp_total: f64 = rng.random_range(0.01..0.04);
            let comps: Vec<(f64, f64, f64)> = (0..k)
                .map(|_| {
                    let f = kp * rng.random_range(0.05f64.ln()..1.2f64.ln()).exp();
                    (amp_total / k as f64 * rng.random_range(0.5..1.5), f, rng.random_range(0.0..TAU))
                })
                .collect();
            Box::new(move |t: f64| {
                let fade = (t / 0.2).min(1.0);
                let fade = fade * fade * (3.0 - 2.0 * fade);
                fade * comps.iter().map(|(a, w, p)| a * ((w * t + p).sin() - p.sin())).sum::<f64>()
            })
        }
        Experiment::Triangle => {
            let amp: f64 = rng.random_range(0.01..0.03);
            let period: f64 = rng.random_range(1.5..3.0);
            Box::new(move |t: f64| {
                let ph = (t / period).fract();
                amp * if ph < 0.25 {
                    4.0 * ph
                } else if ph < 0.75 {
                    2.0 - 4.0 * ph
                } else {
                    4.0 * ph - 4.0
                }
            })
        }
    }
}

/// Exact step of `x' = v`, `v' = a (vinf - v)` over `h`.
fn slide(x: f64, v: f64, vinf: f64, a: f64, h: f64) -> (f64, f64) {
    let e = (-a * h).exp();
    (x + vinf * h + (v - vinf) * (1.0 - e) / a, vinf + (v - vinf) * e)
}

/// The carriage over one period under the held force `f`, in closed form event by event:
/// sliding against `Fv v + Fc sgn v` until the velocity reaches zero (found exactly), then
/// stuck while `|f| <= Fc`, else sliding off in the force's direction.
pub fn tick(tr: &CascadeTruth, x: f64, v: f64, f: f64, h: f64) -> (f64, f64) {
    let a = tr.viscous / tr.mass;
    let (mut x, mut v, mut rem) = (x, v, h);
    for _ in 0..3 {
        if v == 0.0 && f.abs() <= tr.coulomb {
            return (x, 0.0);
        }
        let dir = if v != 0.0 { v.signum() } else { f.signum() };
        let vinf = (f - tr.coulomb * dir) / tr.viscous;
        let (xn, vn) = slide(x, v, vinf, a, rem);
        if vn * dir >= 0.0 {
            return (xn, vn);
        }
        let tau = ((v - vinf) / (0.0 - vinf)).ln() / a;
        x = slide(x, v, vinf, a, tau).0;
        v = 0.0;
        rem -= tau;
        if rem <= 0.0 {
            break;
        }
    }
    (x, v)
}

/// Records experiment `e` on truth `(seed, index)` (noise from a stream of its own).
pub fn record(seed: u64, index: usize, e: Experiment) -> Recording {
    record_with_noise(seed, index, e, true)
}

/// [`record`], with the position quantisation and noise (`noisy`) or without (a clean
/// recording for negative controls: what the fit can tell without the noise floor).
pub fn record_with_noise(seed: u64, index: usize, e: Experiment, noisy: bool) -> Recording {
    let tr = truth(seed, index);
    let r = reference(seed, index, e, tr.kp);
    let mut rng = rng_for(seed, index, 10 + e as u64);
    let ns = (DURATION / T).round() as usize + 1;
    let (mut x, mut v) = (0.0f64, 0.0f64);
    let mut y_prev: Option<f64> = None;
    let mut issued: Vec<f64> = Vec::with_capacity(ns);
    let (mut t, mut w, mut y) = (Vec::with_capacity(ns), Vec::with_capacity(ns), Vec::with_capacity(ns));
    for k in 0..ns {
        let tk = k as f64 * T;
        let noise = POS_NOISE * gauss(&mut rng);
        let yk = if noisy { ((x + noise) / QUANT).round() * QUANT } else { x };
        let wk = r(tk);
        t.push(tk);
        w.push(vec![wk]);
        y.push(vec![yk]);
        let vhat = (yk - y_prev.unwrap_or(yk)) / T;
        y_prev = Some(yk);
        issued.push(tr.kv * (tr.kp * (wk - yk) - vhat));
        let f = if k >= DELAY { issued[k - DELAY] } else { 0.0 };
        (x, v) = tick(&tr, x, v, f, T);
    }
    Recording::from_samples(&format!("servo-cascade-{seed}-{index}-{}", e.name()), &t, w, y, None)
}

/// The physical model file: `M`, `Fv`, `Fc` at the given values (freed), the cascade in
/// `[controller]` with gains `gains = (kp, kv)` and computation delay `delay`.
pub fn model_text(mass: f64, viscous: f64, coulomb: f64, gains: (f64, f64), delay: usize) -> String {
    let (kp, kv) = gains;
    format!(
        r#"name = "carriage under a sampled cascade"
[parameters]
M = {mass:e}
Fv = {viscous:e}
Fc = {coulomb:e}
kp = {kp:e}
kv = {kv:e}
[plant]
A = [[0, 1], [0, "-Fv/M"]]
B = [0, "1/M"]
C = [[1, 0]]
E = [0, 0]
[controller]
period = {T:e}
delay = {delay}
kind = "cascade"
kp = "kp"
kv = "kv"
[[effects]]
kind = "coulomb_friction"
state = 1
level = "Fc/M"
[fit]
free = ["M", "Fv", "Fc"]
[signals]
y = "m"
w = "m"
t = "s"
reference = "w"
"#
    )
}

/// The continuous-time stand-in for the same machine (no `[controller]`: the cascade as
/// continuous gains, no sampling, hold or delay), parameters freed as in [`model_text`].
pub fn stand_in_text(tr: &CascadeTruth, mass: f64, viscous: f64, coulomb: f64) -> String {
    format!(
        r#"name = "carriage, continuous stand-in for the cascade"
[parameters]
M = {mass:e}
Fv = {viscous:e}
Fc = {coulomb:e}
kp = {kp:e}
kv = {kv:e}
[plant]
A = [[0, 1], ["-kv*kp/M", "-(Fv + kv)/M"]]
B = [0, "kv*kp/M"]
C = [[1, 0]]
E = [0, 0]
[[effects]]
kind = "coulomb_friction"
state = 1
level = "Fc/M"
[fit]
free = ["M", "Fv", "Fc"]
[signals]
y = "m"
w = "m"
t = "s"
reference = "w"
"#,
        kp = tr.kp,
        kv = tr.kv
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use dynamics::extended::ExtendedModel;

    fn rmse(a: &[f64], b: &[f64]) -> f64 {
        (a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / a.len() as f64).sqrt()
    }

    #[test]
    fn the_true_model_file_reproduces_the_recording_to_the_noise() {
        let tr = truth(3, 0);
        for e in [Experiment::Multisine, Experiment::Triangle] {
            let rec = record(3, 0, e);
            let y: Vec<f64> = rec.y.iter().map(|r| r[0]).collect();
            let w: Vec<f64> = rec.w.iter().map(|r| r[0]).collect();
            let run = |text: &str, sub: usize| {
                let sys = model::parse_str(text).unwrap();
                ExtendedModel::new(&sys, &[], T, sub).unwrap().simulate(&w, T, &[0.0, 0.0]).y
            };
            let model = |kv: f64, delay: usize| model_text(tr.mass, tr.viscous, tr.coulomb, (tr.kp, kv), delay);
            let good = rmse(&run(&model(tr.kv, DELAY), 16), &y);
            // negative controls: no computation delay; a velocity gain 10 % off
            let no_delay = rmse(&run(&model(tr.kv, 0), 16), &y);
            let wrong_kv = rmse(&run(&model(1.1 * tr.kv, DELAY), 16), &y);
            eprintln!("{}: true model RMSE {good:e}, without delay {no_delay:e}, kv +10 % {wrong_kv:e}", e.name());
            assert!(good < 3e-6, "{}: {good:e}", e.name());
            assert!(no_delay > 2.0 * good && wrong_kv > 2.0 * good, "{no_delay:e} {wrong_kv:e}");
        }
    }

    #[test]
    fn the_event_driven_tick_agrees_with_fine_stepping() {
        let tr = truth(3, 1);
        // from sliding up against a force that stops it and then pulls it down
        for (v0, f) in [(0.05, -3.0 * tr.coulomb), (0.01, 0.5 * tr.coulomb), (0.0, 2.0 * tr.coulomb), (0.0, 0.2)] {
            let (x1, v1) = tick(&tr, 0.0, v0, f, T);
            let (mut x, mut v) = (0.0f64, v0);
            let n = 200_000;
            let h = T / n as f64;
            for _ in 0..n {
                // explicit Euler with a sticking rule (an independent discretisation)
                let fric = if v != 0.0 { -tr.coulomb * v.signum() } else { -f.clamp(-tr.coulomb, tr.coulomb) };
                let vn = v + h * (f + fric - tr.viscous * v) / tr.mass;
                x += h * v;
                v = if v != 0.0 && vn * v < 0.0 { 0.0 } else { vn };
            }
            assert!((x1 - x).abs() < 2e-5 * (x.abs() + 1e-6), "v0 {v0} f {f}: x {x1} against {x}");
            assert!((v1 - v).abs() < 1e-4 * (v.abs() + 1e-3), "v0 {v0} f {f}: v {v1} against {v}");
        }
    }
}
