//! The generator's own simulator (independent of [`dynamics::extended`]): explicit midpoint
//! (RK2) on a grid 20 times finer than the samples (the recording's truth: finer until it is
//! converged, [`simulate_converged`]), forces and the play held over each fine
//! step, Coulomb friction by a semi-implicit velocity update (stick when the friction-free
//! velocity change cannot reverse the sign), the friction library likewise (the static level
//! from rest or through a reversal, the Stribeck level at the old speed while sliding, levels
//! per direction; cogging as a force in the derivative, evaluated at the RK2 stages),
//! backlash inertia by semi-implicit Euler, input effects on the continuous signal or on its
//! held samples ([`Drive`]).
use super::{Plant, Signal};
pub use dynamics::extended::InputHold;

/// What the plant sees of the command between the recording's samples `w(k dt)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Drive {
    /// The continuous signal itself (the recording samples it).
    Continuous,
    /// The samples through a hold: `Zoh` held until the next sample (a digital controller's
    /// command), `Foh` linearly interpolated between samples.
    Held(InputHold),
}

impl Drive {
    /// `continuous`, `zoh` or `foh` (the benchmark's conditions).
    pub fn name(&self) -> &'static str {
        match self {
            Drive::Continuous => "continuous",
            Drive::Held(h) => h.name(),
        }
    }
}
use model::effects::{Effect, PlayLocation};

/// Fine steps per sample of [`simulate_effects`] (enough for RK2 on the linear part).
const FINE: usize = 20;
/// Most fine steps per sample of [`simulate_converged`].
const FINE_MAX: usize = 2560;

/// Simulates the plant (play half-width `hw`, 0 = none) with at most one effect and returns
/// `y` at the `ns` sample times `k dt`. The plant sees the input through `drive` (held samples
/// are delayed as a whole by an `input_delay`).
#[allow(clippy::too_many_arguments)]
pub fn simulate(
    pl: &Plant,
    hw: f64,
    eff: Option<&Effect>,
    sig: &Signal,
    x0: &[f64],
    dt: f64,
    ns: usize,
    drive: Drive,
) -> Vec<f64> {
    simulate_effects(pl, hw, eff.as_slice(), sig, x0, dt, ns, drive)
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
    drive: Drive,
) -> Vec<f64> {
    simulate_fine(pl, hw, effs, sig, x0, dt, ns, drive, FINE)
}

/// [`simulate_effects`] with its truth converged: the play, the friction laws and backlash
/// inertia are stepped to first order, so the fine grid is doubled (from 20 per sample, at most
/// [`FINE_MAX`]) until doubling changes `y` by less than `tol` (RMS over the samples), and the
/// finer run is returned. A change `d` of the output biases a fitted parameter by at most about
/// `d sqrt(N) / noise` of its sigma (`N` samples of white noise), so `tol = 0.1 noise / sqrt(N)`
/// keeps the truth within a tenth of a sigma of the converged one. A smooth truth (no play, no friction, no inertia, no input jump) is second order
/// at 20 and returned as it is. Returns `y` and the fine steps per sample used.
#[allow(clippy::too_many_arguments)]
pub fn simulate_converged(
    pl: &Plant,
    hw: f64,
    effs: &[&Effect],
    sig: &Signal,
    x0: &[f64],
    dt: f64,
    ns: usize,
    drive: Drive,
    tol: f64,
) -> (Vec<f64>, usize) {
    let at = |fine: usize| simulate_fine(pl, hw, effs, sig, x0, dt, ns, drive, fine);
    let mut fine = FINE;
    let mut y = at(fine);
    if !first_order(hw, effs, sig) {
        return (y, fine);
    }
    while fine < FINE_MAX {
        fine *= 2;
        let finer = at(fine);
        let change = rms_difference(&finer, &y);
        y = finer;
        if change <= tol {
            break;
        }
    }
    (y, fine)
}

/// RMS over the samples of `a - b`.
fn rms_difference(a: &[f64], b: &[f64]) -> f64 {
    (a.iter().zip(b).map(|(u, v)| (u - v).powi(2)).sum::<f64>() / a.len().max(1) as f64).sqrt()
}

/// Whether the truth has an update that [`simulate_fine`] steps to first order: a play, a
/// friction law, backlash inertia, or an input that jumps ([`Signal::has_jumps`]).
fn first_order(hw: f64, effs: &[&Effect], sig: &Signal) -> bool {
    hw > 0.0
        || sig.has_jumps()
        || effs.iter().any(|e| {
            matches!(
                e,
                Effect::Backlash { .. }
                    | Effect::BacklashInertia { .. }
                    | Effect::CoulombFriction { .. }
                    | Effect::StribeckFriction { .. }
                    | Effect::AsymmetricCoulomb { .. }
            )
        })
}

/// The truth's effects as [`simulate_fine`] steps them: the play's half-width (with a loop
/// backlash and a gap change), the input delay and saturation limit, the constant force,
/// Coulomb friction, backlash inertia's time constant, the sensor offset, the friction library
/// (sliding up, sliding down, static excess, Stribeck velocity) and the cogging force
/// (amplitude, wavenumber, phase, position state).
struct Truth {
    hw: f64,
    delay: f64,
    sat: f64,
    force: f64,
    fric: f64,
    tau: f64,
    offset: f64,
    lib: Option<(f64, f64, f64, f64)>,
    cog: Option<(f64, f64, f64, usize)>,
}

impl Truth {
    fn of(hw: f64, effs: &[&Effect]) -> Self {
        let mut t = Truth {
            hw,
            delay: 0.0,
            sat: f64::INFINITY,
            force: 0.0,
            fric: 0.0,
            tau: 0.0,
            offset: 0.0,
            lib: None,
            cog: None,
        };
        let mut gap = 1.0;
        for eff in effs {
            match eff {
                Effect::Backlash { width, location: PlayLocation::Loop } => t.hw += 0.5 * width,
                Effect::GapWidth { relative_change } => gap *= 1.0 + relative_change,
                Effect::InputDelay { delay: d } => t.delay = *d,
                Effect::InputSaturation { limit } => t.sat = *limit,
                Effect::ConstantForce { force: f, .. } => t.force = *f,
                Effect::CoulombFriction { level, .. } => t.fric = *level,
                Effect::BacklashInertia { mass, damping } => t.tau = mass / damping,
                Effect::SensorOffset { offset: o } => t.offset = o[0],
                Effect::StribeckFriction { level, static_level, stribeck_velocity, .. } => {
                    t.lib = Some((*level, *level, static_level - level, *stribeck_velocity))
                }
                Effect::AsymmetricCoulomb { level_positive, level_negative, .. } => {
                    t.lib = Some((*level_positive, *level_negative, 0.0, 1.0))
                }
                Effect::Cogging { amplitude, period, phase, position_state, .. } => {
                    t.cog = Some((*amplitude, std::f64::consts::TAU / period, *phase, *position_state))
                }
                _ => {}
            }
        }
        t.hw *= gap;
        t
    }
}

/// What the plant sees of the command at time `s` (already delayed): the signal, its sample
/// at or before `s` (held; a hair of tolerance so that the fine grid's sample instants, exact
/// multiples up to rounding, pick their own sample), or the line between that sample and the
/// next (linear).
fn drive_at(sig: &Signal, drive: Drive, dt: f64, s: f64) -> f64 {
    let held = |s: f64| {
        let k = (s / dt + 1e-9).floor();
        (k * dt, (s / dt - k).clamp(0.0, 1.0))
    };
    match drive {
        Drive::Continuous => sig.eval(s),
        Drive::Held(InputHold::Zoh) => sig.eval(held(s).0),
        Drive::Held(InputHold::Foh) => {
            let (tk, f) = held(s);
            (1.0 - f) * sig.eval(tk) + f * sig.eval(tk + dt)
        }
    }
}

/// The simulation at `fine` steps per sample.
#[allow(clippy::too_many_arguments)]
fn simulate_fine(
    pl: &Plant,
    hw: f64,
    effs: &[&Effect],
    sig: &Signal,
    x0: &[f64],
    dt: f64,
    ns: usize,
    drive: Drive,
    fine: usize,
) -> Vec<f64> {
    let run = Fine::new(pl, Truth::of(hw, effs), sig, drive, dt, fine);
    let mut s = FineState::start(x0, run.cy(x0));
    let mut out = Vec::with_capacity(ns);
    for k in 0..ns {
        out.push(run.cy(&s.x) + run.truth.offset);
        if k + 1 == ns {
            break;
        }
        for (t, h) in run.pieces(k) {
            run.step(&mut s, t, h);
        }
    }
    out
}

/// One run of [`simulate_fine`]: the plant, the truth's effects and the input the plant sees.
struct Fine<'a> {
    pl: &'a Plant,
    truth: Truth,
    sig: &'a Signal,
    drive: Drive,
    dt: f64,
    fine: usize,
    /// The fine step `dt / fine`.
    h: f64,
    /// A delayed held input: its switching instant splits a fine step.
    split: bool,
    /// The samples reach the plant through a zero-order hold.
    zoh: bool,
}

/// The state [`Fine::step`] advances: the plant's `x`, the play's `z` and, with backlash
/// inertia, the play's speed `vz`; the stage buffers of the midpoint rule.
struct FineState {
    x: Vec<f64>,
    z: f64,
    vz: f64,
    k1: Vec<f64>,
    xm: Vec<f64>,
    k2: Vec<f64>,
}

impl FineState {
    fn start(x0: &[f64], z0: f64) -> Self {
        let n = x0.len();
        FineState { x: x0.to_vec(), z: z0, vz: 0.0, k1: vec![0.0; n], xm: vec![0.0; n], k2: vec![0.0; n] }
    }
}

impl<'a> Fine<'a> {
    fn new(pl: &'a Plant, truth: Truth, sig: &'a Signal, drive: Drive, dt: f64, fine: usize) -> Self {
        let split = drive != Drive::Continuous && truth.delay > 0.0;
        let zoh = drive == Drive::Held(InputHold::Zoh);
        Fine { pl, truth, sig, drive, dt, fine, h: dt / fine as f64, split, zoh }
    }

    /// The input the plant sees at `t`: delayed, held as the drive says, saturated.
    fn input(&self, t: f64) -> f64 {
        drive_at(self.sig, self.drive, self.dt, t - self.truth.delay).clamp(-self.truth.sat, self.truth.sat)
    }

    fn cy(&self, x: &[f64]) -> f64 {
        (0..x.len()).map(|j| self.pl.C[(0, j)] * x[j]).sum::<f64>()
    }

    /// `x' = A x + B w + E z`, the constant force and the cogging force on the velocity.
    fn deriv(&self, x: &[f64], w: f64, z: f64, out: &mut [f64]) {
        let (pl, n) = (self.pl, x.len());
        for i in 0..n {
            out[i] = (0..n).map(|j| pl.A[(i, j)] * x[j]).sum::<f64>() + pl.B[(i, 0)] * w + pl.E[(i, 0)] * z;
        }
        out[pl.vel] += self.truth.force;
        if let Some((a, k, ph, ip)) = self.truth.cog {
            out[pl.vel] += a * (k * x[ip] + ph).sin();
        }
    }

    /// The fine grid of sample interval `k`, with the delayed held input's switching instant
    /// added where it falls between grid points (the midpoint rule then sees a constant input
    /// on every piece: the delay is integrated exactly, not rounded to h; a delayed linear hold
    /// has a kink there: split too, so each piece sees a line).
    fn pieces(&self, k: usize) -> Vec<(f64, f64)> {
        let (fine, h) = (self.fine, self.h);
        let t_k = k as f64 * self.dt;
        let mut pieces: Vec<(f64, f64)> = (0..fine).map(|jf| (t_k + jf as f64 * h, h)).collect();
        if self.split {
            let off = (self.truth.delay / self.dt).fract() * self.dt;
            let j = ((off / h).floor() as usize).min(fine - 1);
            let a = off - j as f64 * h;
            if a > 1e-9 * h && a < h * (1.0 - 1e-9) {
                let t = pieces[j].0;
                pieces.splice(j..=j, [(t, a), (t + a, h - a)]);
            }
        }
        pieces
    }

    /// One piece `[t, t + h]`: the midpoint rule on the linear part and the forces, then the
    /// friction laws, then the play.
    fn step(&self, s: &mut FineState, t: f64, h: f64) {
        let (n, vel) = (s.x.len(), self.pl.vel);
        // Held and delayed: the input is constant on each piece (its midpoint's value).
        let u_mid = self.input(t + 0.5 * h);
        let u1 = if self.split && self.zoh { u_mid } else { self.input(t) };
        self.deriv(&s.x, u1, s.z, &mut s.k1);
        for i in 0..n {
            s.xm[i] = s.x[i] + 0.5 * h * s.k1[i];
        }
        self.deriv(&s.xm, u_mid, s.z, &mut s.k2);
        let v_old = s.x[vel];
        for i in 0..n {
            s.x[i] += h * s.k2[i];
        }
        s.x[vel] = self.friction(v_old, s.x[vel], h);
        self.play(s, h);
    }

    /// The velocity after Coulomb friction and the friction library over a step of `h`, from
    /// the friction-free velocity `v_free` and the velocity `v_old` at the step's start.
    fn friction(&self, v_old: f64, mut v_free: f64, h: f64) -> f64 {
        let truth = &self.truth;
        if truth.fric > 0.0 {
            let dv = truth.fric * h;
            v_free = if v_free.abs() <= dv && (v_old.abs() <= dv || v_old * v_free <= 0.0 || v_free.abs() <= dv) {
                0.0
            } else {
                v_free - dv * v_free.signum()
            };
        }
        if let Some((up, down, excess, vs)) = truth.lib {
            // Stick unless the friction-free velocity change beats the static level (at rest
            // or reversing within the step) or the Stribeck level at the old speed.
            let dir = v_free.signum();
            let base = if dir > 0.0 { up } else { down };
            let level = if v_old == 0.0 || v_old * v_free <= 0.0 {
                base + excess
            } else {
                base + excess * (-(v_old / vs).powi(2)).exp()
            };
            let dv = level * h;
            v_free = if v_free.abs() <= dv { 0.0 } else { v_free - dv * dir };
        }
        v_free
    }

    /// The play after a step of `h`: `z` kept within `hw` of `y`, with backlash inertia a
    /// damped speed `vz` that the play's edge stops.
    fn play(&self, s: &mut FineState, h: f64) {
        let (hw, tau) = (self.truth.hw, self.truth.tau);
        let y = self.cy(&s.x);
        if hw > 0.0 {
            if tau > 0.0 {
                s.vz -= h * s.vz / tau;
                let zp = s.z + h * s.vz;
                let zn = zp.clamp(y - hw, y + hw);
                if zn != zp {
                    s.vz = (zn - s.z) / h;
                }
                s.z = zn;
            } else {
                s.z = s.z.clamp(y - hw, y + hw);
            }
        } else {
            s.z = y;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    /// A damped oscillator (position, velocity) behind a play of half-width 0.2, with Coulomb
    /// friction: two first-order updates in the truth.
    fn case() -> (Plant, Signal, Effect) {
        let plant = Plant {
            A: DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -4.0, -0.8]),
            B: DMatrix::from_row_slice(2, 1, &[0.0, 4.0]),
            C: DMatrix::from_row_slice(1, 2, &[1.0, 0.0]),
            E: DMatrix::from_row_slice(2, 1, &[0.0, 0.0]),
            half_width: 0.2,
            vel: 1,
            omega0: 2.0,
            zeta: 0.2,
        };
        let sig = Signal::Multisine { a: vec![1.0, 0.4], omega: vec![0.7, 2.3], phi: vec![0.0, 1.0] };
        let fric = Effect::CoulombFriction { state: 1, level: 1.5 };
        (plant, sig, fric)
    }

    /// RMS of `y` about its mean.
    fn rms_spread(y: &[f64]) -> f64 {
        let m = y.iter().sum::<f64>() / y.len().max(1) as f64;
        (y.iter().map(|v| (v - m).powi(2)).sum::<f64>() / y.len().max(1) as f64).sqrt()
    }

    /// The converged truth moves by less than its tolerance when the step is halved once more;
    /// negative control: the 20-per-sample grid the generator used before is off by far more
    /// (the friction's first-order update), so the check can fail.
    #[test]
    fn the_generators_truth_is_converged_under_halving_the_step() {
        let (pl, sig, fric) = case();
        let (dt, ns) = (0.05, 1500);
        let x0 = [0.1, 0.0];
        // the generator's tolerance at 30 dB SNR
        let tol = 0.1
            * rms_spread(&simulate_effects(&pl, 0.2, &[&fric], &sig, &x0, dt, ns, Drive::Continuous))
            * 10f64.powf(-1.5)
            / (ns as f64).sqrt();
        let (y, fine) = simulate_converged(&pl, 0.2, &[&fric], &sig, &x0, dt, ns, Drive::Continuous, tol);
        assert!(fine > FINE && fine < FINE_MAX, "doubled to {fine}");
        let halved = simulate_fine(&pl, 0.2, &[&fric], &sig, &x0, dt, ns, Drive::Continuous, 2 * fine);
        let change = rms_difference(&y, &halved);
        assert!(change <= tol, "halving moves y by {change:e} > {tol:e}");
        let coarse = simulate_effects(&pl, 0.2, &[&fric], &sig, &x0, dt, ns, Drive::Continuous);
        let off = rms_difference(&coarse, &y);
        assert!(off > 3.0 * tol, "20 per sample is already converged? {off:e} against {tol:e}");
    }

    /// A smooth truth (no play, no friction) is second order at 20 per sample and not refined.
    #[test]
    fn a_smooth_truth_is_not_refined() {
        let (pl, sig, _) = case();
        let (_, fine) = simulate_converged(&pl, 0.0, &[], &sig, &[0.1, 0.0], 0.02, 500, Drive::Continuous, 1e-12);
        assert_eq!(fine, FINE);
    }
}
