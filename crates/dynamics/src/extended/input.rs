//! The input path `w -> w_eff`: the measured `w` delayed (`input_delay`), clamped
//! (`input_saturation`) and passed through a play operator (`backlash` at the input), in that
//! order, and how `w_eff` behaves between samples ([`InputHold`]).
//!
//! Either hold is integrated exactly by the linear step maps: an input delay moves the input's
//! breakpoints to `t_k + delay`, and the sub-step that contains one is split there
//! (`Split`, two extra step maps computed once per model). Saturation and the input play act
//! on the held samples exactly (zero-order hold) or on the sub-step knots (first-order hold).
use super::step_maps::StepMaps;
use crate::linear::hold::InputHold;
use model::System;

/// The input effects and the hold between samples.
///
/// The saturation and the play are plain numbers that act as the identity where the effect is
/// absent (an infinite limit, a play of half-width 0), not `Option<f64>`: the optimiser
/// evaluates `0.5 * width` before it tests an `Option`'s tag, and an absent option's payload
/// is whatever bytes were there; a subnormal among them cost a microcode assist on every
/// sub-step of a first-order hold (about 60 ns, 40 % of a friction model's sub-step).
#[derive(Debug, Clone)]
pub(super) struct InputPath {
    /// Total input delay (sum of the `input_delay` effects, negative ones as 0).
    pub(super) delay: f64,
    /// Saturation limit (the last `input_saturation`; infinite without one).
    limit: f64,
    /// Half the width of the play at the input (half the sum of the input `backlash` widths;
    /// 0 without one).
    half_play: f64,
    /// How the input behaves between samples (default: first-order hold).
    pub(super) hold: InputHold,
}

impl Default for InputPath {
    fn default() -> Self {
        Self { delay: 0.0, limit: f64::INFINITY, half_play: 0.0, hold: InputHold::default() }
    }
}

impl InputPath {
    /// A `backlash` of (checked) width `width` at the input.
    pub(super) fn add_play(&mut self, width: f64) {
        self.half_play += 0.5 * width;
    }

    /// `v` saturated (`input_saturation`; `v` itself without one).
    #[inline(always)]
    pub(super) fn saturated(&self, v: f64) -> f64 {
        v.clamp(-self.limit, self.limit)
    }

    /// `v` saturated and passed through the input play from its state `u` (updated; it starts
    /// at the first saturated sample, [`InputPath::play_start`]); without a play, `v` saturated.
    #[inline(always)]
    pub(super) fn shaped(&self, v: f64, u: &mut f64) -> f64 {
        let v = self.saturated(v);
        if self.half_play > 0.0 {
            *u = u.clamp(v - self.half_play, v + self.half_play);
            *u
        } else {
            v
        }
    }

    /// An `input_delay` (negative delays count as 0).
    pub(super) fn add_delay(&mut self, delay: f64) {
        self.delay += delay.max(0.0);
    }

    /// An `input_saturation` at `|limit|`.
    pub(super) fn saturate(&mut self, limit: f64) {
        self.limit = limit.abs();
    }

    /// The effective input on the sample grid (see `ExtendedModel::effective_input`).
    pub(super) fn effective_input(&self, w: &[f64], dt: f64, m: usize) -> Vec<f64> {
        let n = w.len() / m;
        let mut out = w.to_vec();
        if self.delay > 0.0 {
            let sh = self.delay / dt;
            for k in 0..n {
                let s = k as f64 - sh;
                for j in 0..m {
                    out[k * m + j] = if s <= 0.0 {
                        w[j]
                    } else {
                        let i = s.floor() as usize;
                        let a = s - i as f64;
                        let i1 = (i + 1).min(n - 1);
                        w[i * m + j] * (1.0 - a) + w[i1 * m + j] * a
                    };
                }
            }
        }
        self.shape_samples(&mut out, m, n);
        out
    }

    /// Zero-order hold: the `ns` samples of `w` saturated and passed through the input play
    /// (the delay is applied when a sample is picked).
    pub(super) fn held_samples(&self, w: &[f64], m: usize, ns: usize) -> Vec<f64> {
        let mut hv = w.to_vec();
        self.shape_samples(&mut hv, m, ns);
        hv
    }

    /// The `ns` samples `v` (flat, `k * m + j`) saturated and passed through the input play,
    /// in place (the play starts at the first saturated sample).
    fn shape_samples(&self, v: &mut [f64], m: usize, ns: usize) {
        let mut u = self.play_start(v, m);
        for k in 0..ns {
            for (j, uj) in u.iter_mut().enumerate() {
                v[k * m + j] = self.shaped(v[k * m + j], uj);
            }
        }
    }

    /// First-order hold: the start state of the input play (the first sample, saturated).
    pub(super) fn play_start(&self, w: &[f64], m: usize) -> Vec<f64> {
        w[..m].iter().map(|&v| self.saturated(v)).collect()
    }

    /// First-order hold: the delayed, interpolated input at sample time `tau` (in samples,
    /// the first sample held before the start and the last after the end), saturated and
    /// passed through the input play (state `uplay`), into `outv`.
    #[inline]
    pub(super) fn foh_at(&self, w: &[f64], m: usize, ns: usize, tau: f64, uplay: &mut [f64], outv: &mut [f64]) {
        for j in 0..m {
            let raw = if tau <= 0.0 {
                w[j]
            } else {
                // `tau > 0`: truncation is the floor (and no call into libm).
                let i = tau as usize;
                if i + 1 >= ns {
                    w[(ns - 1) * m + j]
                } else {
                    let a = tau - i as f64;
                    w[i * m + j] * (1.0 - a) + w[(i + 1) * m + j] * a
                }
            };
            outv[j] = self.shaped(raw, &mut uplay[j]);
        }
    }
}

/// The sub-step of every sample interval that contains the delayed input's breakpoint
/// `t_k + delay`, split there: `first` covers `at h`, `second` `(1 - at) h`.
#[derive(Debug, Clone)]
pub(super) struct Split {
    pub(super) substep: usize,
    pub(super) at: f64,
    pub(super) first: StepMaps,
    pub(super) second: StepMaps,
}

impl Split {
    /// The split for an input delay `delay > 0` with sub-steps of `h` (`substeps` per
    /// sample); `None` when the breakpoint falls on a sub-step knot.
    pub(super) fn for_delay(sys: &System, delay: f64, h: f64, substeps: usize) -> Option<Split> {
        // Breakpoints of the delayed input at t_k + delay: fraction `phi` of a sample
        // interval, in sub-step `s` at fraction `at` of it.
        let sub = substeps as f64;
        let pos = (delay / (h * sub)).fract() * sub;
        let (si, at) = (pos.floor(), pos - pos.floor());
        if at > 1e-9 && at < 1.0 - 1e-9 {
            let F = sys.F();
            Some(Split {
                substep: (si as usize).min(substeps - 1),
                at,
                first: StepMaps::new(&F, &sys.B, &sys.E, at * h),
                second: StepMaps::new(&F, &sys.B, &sys.E, (1.0 - at) * h),
            })
        } else {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A saturation at 1.8 and a play of width 0.4 at the input.
    fn saturated_play() -> InputPath {
        let mut p = InputPath::default();
        p.saturate(-1.8);
        p.add_play(0.4);
        p
    }

    #[test]
    fn without_effects_the_input_passes_unchanged() {
        let p = InputPath::default();
        let mut u = 0.0;
        for v in [0.0, -3.5, 1e300, f64::INFINITY, f64::NEG_INFINITY, 5e-324] {
            assert_eq!(p.shaped(v, &mut u).to_bits(), v.to_bits());
        }
        // A missing sample is passed on, not a panic.
        assert!(p.shaped(f64::NAN, &mut u).is_nan());
        let w = [0.3, -2.0, 7.0];
        assert_eq!(p.held_samples(&w, 1, 3), w.to_vec());
        assert_eq!(p.effective_input(&w, 0.1, 1), w.to_vec());
    }

    #[test]
    fn saturation_then_the_play_act_on_the_samples() {
        // Saturated: 0, 1, 1.8, 1.5, 0.2; the play (half-width 0.2) starts at 0.
        let w = [0.0, 1.0, 2.0, 1.5, 0.2];
        let want = [0.0, 0.8, 1.6, 1.6, 0.4];
        let p = saturated_play();
        for got in [p.held_samples(&w, 1, 5), p.effective_input(&w, 0.1, 1)] {
            for (g, e) in got.iter().zip(want) {
                assert!((g - e).abs() < 1e-15, "{got:?} against {want:?}");
            }
        }
        // Negative control: the play alone (no saturation) ends elsewhere.
        let mut play_only = InputPath::default();
        play_only.add_play(0.4);
        assert!((play_only.held_samples(&w, 1, 5)[2] - 1.8).abs() < 1e-15);
    }

    #[test]
    fn the_first_order_hold_shapes_the_interpolated_input() {
        let (w, p) = ([0.0, 1.0, 3.0], saturated_play());
        let mut u = p.play_start(&w, 1);
        let mut out = [0.0];
        // Between samples 1 and 2 at a quarter: 1.5; then past the limit: 1.8.
        for (tau, want) in [(0.5, 0.3), (1.25, 1.3), (1.75, 1.6), (2.5, 1.6)] {
            p.foh_at(&w, 1, 3, tau, &mut u, &mut out);
            assert!((out[0] - want).abs() < 1e-15, "tau {tau}: {} against {want}", out[0]);
        }
    }
}
