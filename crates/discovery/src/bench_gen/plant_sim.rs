//! The generator's own simulator (independent of [`dynamics::extended`]): explicit midpoint
//! (RK2) on a grid 20 times finer than the samples, forces and the play held over each fine
//! step, Coulomb friction by a semi-implicit velocity update (stick when the friction-free
//! velocity change cannot reverse the sign), the friction library likewise (the static level
//! from rest or through a reversal, the Stribeck level at the old speed while sliding, levels
//! per direction; cogging as a force in the derivative, evaluated at the RK2 stages),
//! backlash inertia by semi-implicit Euler, input effects on the continuous signal or on its
//! zero-order-held samples.
use super::{Plant, Signal};
use model::effects::{Effect, PlayLocation};

const FINE: usize = 20;

/// Simulates the plant (play half-width `hw`, 0 = none) with at most one effect and returns
/// `y` at the `ns` sample times `k dt`. With `zoh`, the plant sees the input sampled at `k dt`
/// and held constant until the next sample (a digital controller's command), delayed as a
/// whole by an `input_delay`; otherwise it sees the continuous signal.
#[allow(clippy::too_many_arguments)]
pub fn simulate(
    pl: &Plant,
    hw: f64,
    eff: Option<&Effect>,
    sig: &Signal,
    x0: &[f64],
    dt: f64,
    ns: usize,
    zoh: bool,
) -> Vec<f64> {
    simulate_effects(pl, hw, eff.as_slice(), sig, x0, dt, ns, zoh)
}

/// [`simulate`] with every effect of `effs` at once (two concealed effects, issue 27 item 4):
/// each acts as it does alone (a play widened by both a backlash and a gap change takes both,
/// the backlash first; at most one of the friction library and one cogging force).
#[allow(clippy::too_many_arguments)]
pub fn simulate_effects(
    pl: &Plant,
    hw: f64,
    effs: &[&Effect],
    sig: &Signal,
    x0: &[f64],
    dt: f64,
    ns: usize,
    zoh: bool,
) -> Vec<f64> {
    let n = pl.A.nrows();
    let h = dt / FINE as f64;
    let mut hw = hw;
    let (mut delay, mut sat, mut force, mut fric, mut tau, mut offset) = (0.0, f64::INFINITY, 0.0, 0.0, 0.0, 0.0);
    let mut gap = 1.0;
    // The friction library: (sliding up, sliding down, static excess, Stribeck velocity) and
    // the cogging force (amplitude, wavenumber, phase) with position state 0.
    let mut lib: Option<(f64, f64, f64, f64)> = None;
    let mut cog: Option<(f64, f64, f64, usize)> = None;
    for eff in effs {
        match eff {
            Effect::Backlash { width, location: PlayLocation::Loop } => hw += 0.5 * width,
            Effect::GapWidth { relative_change } => gap *= 1.0 + relative_change,
            Effect::InputDelay { delay: d } => delay = *d,
            Effect::InputSaturation { limit } => sat = *limit,
            Effect::ConstantForce { force: f, .. } => force = *f,
            Effect::CoulombFriction { level, .. } => fric = *level,
            Effect::BacklashInertia { mass, damping } => tau = mass / damping,
            Effect::SensorOffset { offset: o } => offset = o[0],
            Effect::StribeckFriction { level, static_level, stribeck_velocity, .. } => {
                lib = Some((*level, *level, static_level - level, *stribeck_velocity))
            }
            Effect::AsymmetricCoulomb { level_positive, level_negative, .. } => {
                lib = Some((*level_positive, *level_negative, 0.0, 1.0))
            }
            Effect::Cogging { amplitude, period, phase, position_state, .. } => {
                cog = Some((*amplitude, std::f64::consts::TAU / period, *phase, *position_state))
            }
            _ => {}
        }
    }
    hw *= gap;
    let input = |t: f64| {
        let s = t - delay;
        // Held: the sample at or before `s` (a hair of tolerance so that the fine grid's
        // sample instants, which are exact multiples up to rounding, pick their own sample).
        let s = if zoh { dt * (s / dt + 1e-9).floor() } else { s };
        sig.eval(s).clamp(-sat, sat)
    };
    let cy = |x: &[f64]| (0..n).map(|j| pl.C[(0, j)] * x[j]).sum::<f64>();
    let deriv = |x: &[f64], w: f64, z: f64, out: &mut [f64]| {
        for i in 0..n {
            out[i] = (0..n).map(|j| pl.A[(i, j)] * x[j]).sum::<f64>() + pl.B[(i, 0)] * w + pl.E[(i, 0)] * z;
        }
        out[pl.vel] += force;
        if let Some((a, k, ph, ip)) = cog {
            out[pl.vel] += a * (k * x[ip] + ph).sin();
        }
    };
    let mut x = x0.to_vec();
    let mut z = cy(&x);
    let mut vz = 0.0;
    let (mut k1, mut xm, mut k2) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut out = Vec::with_capacity(ns);
    for k in 0..ns {
        out.push(cy(&x) + offset);
        if k + 1 == ns {
            break;
        }
        // The fine grid of this sample interval, with the delayed held input's switching
        // instant added where it falls between grid points (the midpoint rule then sees a
        // constant input on every piece: the delay is integrated exactly, not rounded to h).
        let t_k = k as f64 * dt;
        let mut pieces: Vec<(f64, f64)> = (0..FINE).map(|jf| (t_k + jf as f64 * h, h)).collect();
        let split = zoh && delay > 0.0;
        if split {
            let off = (delay / dt).fract() * dt;
            let j = ((off / h).floor() as usize).min(FINE - 1);
            let a = off - j as f64 * h;
            if a > 1e-9 * h && a < h * (1.0 - 1e-9) {
                let t = pieces[j].0;
                pieces.splice(j..=j, [(t, a), (t + a, h - a)]);
            }
        }
        for (t, h) in pieces {
            // Held and delayed: the input is constant on each piece (its midpoint's value).
            let u1 = if split { input(t + 0.5 * h) } else { input(t) };
            deriv(&x, u1, z, &mut k1);
            for i in 0..n {
                xm[i] = x[i] + 0.5 * h * k1[i];
            }
            deriv(&xm, input(t + 0.5 * h), z, &mut k2);
            let v_old = x[pl.vel];
            for i in 0..n {
                x[i] += h * k2[i];
            }
            if fric > 0.0 {
                let v_free = x[pl.vel];
                let dv = fric * h;
                x[pl.vel] = if v_free.abs() <= dv && (v_old.abs() <= dv || v_old * v_free <= 0.0 || v_free.abs() <= dv)
                {
                    0.0
                } else {
                    v_free - dv * v_free.signum()
                };
            }
            if let Some((up, down, excess, vs)) = lib {
                // Stick unless the friction-free velocity change beats the static level (at
                // rest or reversing within the step) or the Stribeck level at the old speed.
                let v_free = x[pl.vel];
                let dir = v_free.signum();
                let base = if dir > 0.0 { up } else { down };
                let level = if v_old == 0.0 || v_old * v_free <= 0.0 {
                    base + excess
                } else {
                    base + excess * (-(v_old / vs).powi(2)).exp()
                };
                let dv = level * h;
                x[pl.vel] = if v_free.abs() <= dv { 0.0 } else { v_free - dv * dir };
            }
            let y = cy(&x);
            if hw > 0.0 {
                if tau > 0.0 {
                    vz -= h * vz / tau;
                    let zp = z + h * vz;
                    let zn = zp.clamp(y - hw, y + hw);
                    if zn != zp {
                        vz = (zn - z) / h;
                    }
                    z = zn;
                } else {
                    z = z.clamp(y - hw, y + hw);
                }
            } else {
                z = y;
            }
        }
    }
    out
}
