//! Input effects with per-input parameters (models with several inputs, e.g. a reference in
//! metres and a motor voltage in volts: one play width or saturation limit for both means
//! nothing).
//!
//! The model file's effects act on every input alike, so an effect on input `j` alone is
//! applied here, to the recorded input, before the simulator sees it: on the grid of the
//! simulator's sub-steps (`substeps` points per sample), input `j` is delayed, clamped and
//! passed through a play operator, in that order (as the simulator orders its own input
//! effects), and the loop is simulated over the sub-steps with the same hold. Without a
//! delay the fine grid reproduces the hold exactly (zero-order: the sample repeated;
//! first-order: the interpolation at the sub-step points). A delay is applied to the held
//! signal: zero-order hold by the average of the delayed signal over each sub-step (so the
//! output moves smoothly with the delay), first-order hold by its values at the sub-step
//! points. Clamp and play act on the sub-step values. `fitted.toml` then carries the input as
//! the plant sees it (the model-file format has no per-input effects).
use crate::hypothesis::{Hypothesis, Kind, Scales, DECADES, LEVEL_LOG_SHIFT};
use dynamics::extended::InputHold;
use model::effects::{Effect, PlayLocation};
use model::System;
use serde::Serialize;

/// An input effect that can act on one input.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum InputOp {
    Play,
    Saturation,
    Delay,
}

impl InputOp {
    /// Model-file name of the effect.
    pub fn name(&self) -> &'static str {
        match self {
            InputOp::Play => "backlash",
            InputOp::Saturation => "input_saturation",
            InputOp::Delay => "input_delay",
        }
    }
    /// Label with the input, e.g. `input_saturation(w2)`.
    pub fn label(&self, input: usize) -> String {
        match self {
            InputOp::Play => format!("backlash(input w{})", input + 1),
            _ => format!("{}(w{})", self.name(), input + 1),
        }
    }
    pub fn description(&self, input: usize) -> String {
        let j = input + 1;
        match self {
            InputOp::Play => format!("Play between input w{j} and the plant (the other inputs act directly): the plant only follows w{j} after it has reversed by the width of the play."),
            InputOp::Saturation => format!("The actuator behind input w{j} cannot follow it beyond a limit (voltage or current saturation); the other inputs are not clipped."),
            InputOp::Delay => format!("The plant sees input w{j} late (transport, communication or computation delay); the other inputs arrive on time."),
        }
    }
    /// The same effect on every input (what a model file can state).
    pub fn on_every_input(&self, v: f64) -> Effect {
        match self {
            InputOp::Play => Effect::Backlash { width: v.max(0.0), location: PlayLocation::Input },
            InputOp::Saturation => Effect::InputSaturation { limit: v.max(1e-12) },
            InputOp::Delay => Effect::InputDelay { delay: v.max(0.0) },
        }
    }
}

/// Per-input hypotheses for a model with `m > 1` inputs (none for `m = 1`): for each input,
/// a play of width in `[0, range(w_j)/2]`, a saturation limit in `[0.2, 1] max |w_j|` and a
/// delay in the bound of the global delay, with the global hypotheses' starts.
pub fn candidates(sys: &System, s: &Scales, w: &[f64]) -> Vec<Hypothesis> {
    let m = sys.m();
    if m < 2 {
        return vec![];
    }
    let n = w.len() / m;
    let dmax = s.tau_slow.min(s.duration / 20.0).max(5.0 * s.dt);
    let mut out = Vec::new();
    for j in 0..m {
        let absmax = (0..n).map(|k| w[k * m + j].abs()).fold(0.0, f64::max).max(1e-12);
        let range = s.w_range.get(j).copied().unwrap_or(absmax).max(1e-12);
        let level = |op: InputOp, hi: f64, name: &'static str| Hypothesis {
            kind: Kind::InputOn { op, input: j },
            lower: vec![0.0],
            upper: vec![hi],
            starts: DECADES.iter().map(|f| vec![unit_log(f * hi, 0.0, hi, LEVEL_LOG_SHIFT * hi)]).collect(),
            names: vec![name],
            log_shift: vec![Some(LEVEL_LOG_SHIFT * hi)],
        };
        out.push(level(InputOp::Play, 0.5 * range, "width"));
        let (lo, hi) = (0.2 * absmax, absmax);
        out.push(Hypothesis {
            kind: Kind::InputOn { op: InputOp::Saturation, input: j },
            lower: vec![lo],
            upper: vec![hi],
            starts: [0.52, 0.76, 0.96, 0.99, 0.999].iter().map(|f| vec![(f * absmax - lo) / (hi - lo)]).collect(),
            names: vec!["limit"],
            log_shift: vec![None],
        });
        out.push(level(InputOp::Delay, dmax, "delay"));
    }
    out
}

fn unit_log(theta: f64, lo: f64, hi: f64, c: f64) -> f64 {
    (((theta + c) / (lo + c)).ln() / ((hi + c) / (lo + c)).ln()).clamp(0.0, 1.0)
}

/// Value of input `j` of the held signal at time `t` (sample `k` at `k dt`; before the start
/// the first sample, after the end the last).
fn held(w: &[f64], m: usize, j: usize, dt: f64, hold: InputHold, t: f64) -> f64 {
    let n = w.len() / m;
    if t <= 0.0 {
        return w[j];
    }
    let s = t / dt;
    let k = (s.floor() as usize).min(n - 1);
    match hold {
        InputHold::Zoh => w[k * m + j],
        InputHold::Foh => {
            if k + 1 >= n {
                w[(n - 1) * m + j]
            } else {
                let a = s - k as f64;
                w[k * m + j] * (1.0 - a) + w[(k + 1) * m + j] * a
            }
        }
    }
}

/// Average of the zero-order-held input `j` over `[a, b)` (`b - a <= dt`).
fn held_average(w: &[f64], m: usize, j: usize, dt: f64, a: f64, b: f64) -> f64 {
    let n = w.len() / m;
    let at = |t: f64| if t <= 0.0 { 0 } else { ((t / dt).floor() as usize).min(n - 1) };
    let (ka, kb) = (at(a), at(b - 1e-12 * dt));
    if ka == kb {
        return w[ka * m + j];
    }
    // One boundary inside (b - a <= dt): at t_b = kb dt.
    let tb = kb as f64 * dt;
    let fa = ((tb - a) / (b - a)).clamp(0.0, 1.0);
    w[ka * m + j] * fa + w[kb * m + j] * (1.0 - fa)
}

/// The input the plant sees, on the sub-step grid: `(len - 1) substeps + 1` points, flat
/// `i * m + j`, from the recorded `w` (flat, `len` samples). `ops`: `(op, input, value)`.
pub fn transform(
    w: &[f64],
    m: usize,
    dt: f64,
    substeps: usize,
    hold: InputHold,
    ops: &[(InputOp, usize, f64)],
) -> Vec<f64> {
    let len = w.len() / m;
    let sub = substeps.max(1);
    let nf = (len - 1) * sub + 1;
    let h = dt / sub as f64;
    let mut out = vec![0.0; nf * m];
    for j in 0..m {
        let delay: f64 = ops.iter().filter(|o| o.0 == InputOp::Delay && o.1 == j).map(|o| o.2.max(0.0)).sum();
        let limit = ops.iter().filter(|o| o.0 == InputOp::Saturation && o.1 == j).map(|o| o.2.abs()).reduce(f64::min);
        let width: f64 = ops.iter().filter(|o| o.0 == InputOp::Play && o.1 == j).map(|o| o.2.max(0.0)).sum();
        for i in 0..nf {
            let (k, r) = (i / sub, i % sub);
            let v = if delay > 0.0 {
                let t = i as f64 * h - delay;
                match hold {
                    InputHold::Zoh => held_average(w, m, j, dt, t, t + h),
                    InputHold::Foh => held(w, m, j, dt, hold, t),
                }
            } else {
                match hold {
                    InputHold::Zoh => w[k * m + j],
                    InputHold::Foh if r == 0 || k + 1 >= len => w[k * m + j],
                    InputHold::Foh => {
                        let a = r as f64 / sub as f64;
                        w[k * m + j] * (1.0 - a) + w[(k + 1) * m + j] * a
                    }
                }
            };
            out[i * m + j] = match limit {
                Some(l) => v.clamp(-l, l),
                None => v,
            };
        }
        if width > 0.0 {
            let rr = 0.5 * width;
            let mut u = out[j];
            for i in 0..nf {
                let v = out[i * m + j];
                u = u.clamp(v - rr, v + rr);
                out[i * m + j] = u;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_op_reproduces_the_hold_and_ops_act_on_their_input_only() {
        let (m, dt, sub) = (2, 0.1, 4);
        let w: Vec<f64> = (0..20).flat_map(|k| [(k as f64 * 0.3).sin(), 2.0 * (k as f64 * 0.2).cos()]).collect();
        for hold in [InputHold::Zoh, InputHold::Foh] {
            let f = transform(&w, m, dt, sub, hold, &[]);
            assert_eq!(f.len(), (19 * sub + 1) * m);
            for k in 0..20 {
                assert_eq!(f[k * sub * m], w[k * m]);
                assert_eq!(f[k * sub * m + 1], w[k * m + 1]);
            }
            // Saturation of input 2 leaves input 1 alone.
            let g = transform(&w, m, dt, sub, hold, &[(InputOp::Saturation, 1, 1.0)]);
            for i in 0..f.len() / m {
                assert_eq!(g[i * m], f[i * m]);
                assert!(g[i * m + 1].abs() <= 1.0 + 1e-15);
            }
        }
        // A delay of a whole sample shifts the held signal by one sample.
        let d = transform(&w, m, dt, sub, InputHold::Zoh, &[(InputOp::Delay, 0, dt)]);
        for k in 1..19 {
            assert!((d[k * sub * m] - w[(k - 1) * m]).abs() < 1e-12, "k = {k}");
            assert_eq!(d[k * sub * m + 1], w[k * m + 1]);
        }
        // Half a sub-step of delay under zero-order hold: the sub-step straddling a sample
        // boundary averages the two samples, so the output moves continuously with the delay.
        let e = transform(&w, m, dt, sub, InputHold::Zoh, &[(InputOp::Delay, 0, 0.5 * dt / sub as f64)]);
        let i = 5 * sub;
        assert!((e[i * m] - 0.5 * (w[4 * m] + w[5 * m])).abs() < 1e-12);
    }
}
