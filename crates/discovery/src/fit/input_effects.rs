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
use dynamics::extended::InputHold;

/// The input effects on one input (declared in [`crate::physics::input_ops`]).
pub use crate::physics::InputOp;

/// The per-input hypotheses (the physics library at each input alone), as the diagnosis
/// calls them from here.
pub use crate::hypothesis::per_input_candidates as candidates;

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
