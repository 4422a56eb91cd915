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
#[derive(Debug, Clone, Default)]
pub(super) struct InputPath {
    /// Total input delay (sum of the `input_delay` effects, negative ones as 0).
    pub(super) delay: f64,
    /// Saturation limit (the last `input_saturation`).
    pub(super) saturation: Option<f64>,
    /// Width of the play at the input (sum of the input `backlash` widths).
    pub(super) play: Option<f64>,
    /// How the input behaves between samples (default: first-order hold).
    pub(super) hold: InputHold,
}

impl InputPath {
    /// A `backlash` of (checked) width `width` at the input.
    pub(super) fn add_play(&mut self, width: f64) {
        self.play = Some(self.play.unwrap_or(0.0) + width);
    }

    /// An `input_delay` (negative delays count as 0).
    pub(super) fn add_delay(&mut self, delay: f64) {
        self.delay += delay.max(0.0);
    }

    /// An `input_saturation` at `|limit|`.
    pub(super) fn saturate(&mut self, limit: f64) {
        self.saturation = Some(limit.abs());
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
        if let Some(l) = self.saturation {
            out.iter_mut().for_each(|v| *v = v.clamp(-l, l));
        }
        if let Some(width) = self.play {
            let r = 0.5 * width;
            let mut u: Vec<f64> = out[..m].to_vec();
            for k in 0..n {
                for j in 0..m {
                    let v = out[k * m + j];
                    u[j] = u[j].clamp(v - r, v + r);
                    out[k * m + j] = u[j];
                }
            }
        }
        out
    }

    /// Zero-order hold: the `ns` samples of `w` saturated and passed through the input play
    /// (the delay is applied when a sample is picked).
    pub(super) fn held_samples(&self, w: &[f64], m: usize, ns: usize) -> Vec<f64> {
        let mut hv = w.to_vec();
        if let Some(l) = self.saturation {
            hv.iter_mut().for_each(|v| *v = v.clamp(-l, l));
        }
        if let Some(width) = self.play {
            let r = 0.5 * width;
            let mut u: Vec<f64> = hv[..m].to_vec();
            for k in 0..ns {
                for j in 0..m {
                    u[j] = u[j].clamp(hv[k * m + j] - r, hv[k * m + j] + r);
                    hv[k * m + j] = u[j];
                }
            }
        }
        hv
    }

    /// First-order hold: the start state of the input play (the first sample, saturated).
    pub(super) fn play_start(&self, w: &[f64], m: usize) -> Vec<f64> {
        (0..m).map(|j| self.saturation.map_or(w[j], |l| w[j].clamp(-l, l))).collect()
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
            let mut u = match self.saturation {
                Some(l) => raw.clamp(-l, l),
                None => raw,
            };
            if let Some(width) = self.play {
                let r = 0.5 * width;
                uplay[j] = uplay[j].clamp(u - r, u + r);
                u = uplay[j];
            }
            outv[j] = u;
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
