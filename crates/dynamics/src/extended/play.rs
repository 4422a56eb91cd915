//! The play in the loop: `z_{k+1} = y_{k+1} + P_Theta(z_pred - y_{k+1})` (the catching-up
//! projection), with `Theta` the nominal set scaled by `1 + relative_change` (`gap_width`) and
//! widened by a loop `backlash` of width `width` (1-D, or a ball of radius `width / 2` when the
//! nominal has no play). `backlash_inertia` lets the backlash output coast between contacts
//! (its time constant is collected here; the coasting itself is a step of
//! [`super::simulate`]).
use crate::error::DynamicsError;
use geometry::{ConvexSet, Shape};
use model::System;

/// How the play is projected.
#[derive(Debug, Clone)]
pub(super) enum Play {
    /// `Theta = {0}`: `z = y`.
    None,
    /// 1-D interval `[lo, hi]`.
    Interval { lo: f64, hi: f64 },
    /// Ball of radius `r` about 0 (a play added where the nominal, p > 1, has none).
    Ball { r: f64 },
    /// `s Theta` for a general nominal shape: `P_{s Theta}(v) = s P_Theta(v / s)`.
    Scaled { shape: Shape, s: f64 },
}

/// Whether the nominal `Theta` is the singleton `{0}`.
pub fn theta_is_point(sys: &System) -> bool {
    sys.theta.deviation_from_origin().upper <= 0.0
}

/// A `backlash` effect's width, checked (finite, non-negative), for the loop or the input.
pub(super) fn checked_width(width: f64) -> Result<f64, DynamicsError> {
    if !(width >= 0.0 && width.is_finite()) {
        return Err(DynamicsError::BadEffect {
            kind: "backlash",
            reason: "width must be finite and non-negative",
            value: width,
        });
    }
    Ok(width)
}

/// The effects on the play collected from `[[effects]]`, before the play is compiled.
#[derive(Debug, Clone)]
pub(super) struct PlayEffects {
    /// Product of `1 + relative_change` over the `gap_width` effects.
    scale: f64,
    /// Sum of the loop `backlash` widths.
    loop_width: f64,
    /// `mass / damping` of the backlash output (0: massless; the last `backlash_inertia`).
    pub(super) inertia_tau: f64,
}

impl Default for PlayEffects {
    fn default() -> Self {
        Self { scale: 1.0, loop_width: 0.0, inertia_tau: 0.0 }
    }
}

impl PlayEffects {
    /// A loop `backlash` of (checked) width `width`.
    pub(super) fn widen(&mut self, width: f64) {
        self.loop_width += width;
    }

    /// `gap_width`: `Theta` scaled by `1 + relative_change`.
    pub(super) fn scale_gap(&mut self, relative_change: f64) -> Result<(), DynamicsError> {
        if relative_change <= -1.0 {
            return Err(DynamicsError::BadEffect {
                kind: "gap_width",
                reason: "relative_change must exceed -1",
                value: relative_change,
            });
        }
        self.scale *= 1.0 + relative_change;
        Ok(())
    }

    /// `backlash_inertia`: the output coasts with time constant `mass / damping`.
    pub(super) fn set_inertia(&mut self, mass: f64, damping: f64) {
        self.inertia_tau = if mass <= 0.0 {
            0.0
        } else if damping <= 0.0 {
            f64::INFINITY
        } else {
            mass / damping
        };
    }

    /// The play of `sys` with these effects (`p` outputs).
    pub(super) fn compile(&self, sys: &System, p: usize) -> Result<Play, DynamicsError> {
        let (scale, loop_width) = (self.scale, self.loop_width);
        let point = theta_is_point(sys);
        Ok(match (&sys.theta, point) {
            (_, true) if loop_width <= 0.0 => Play::None,
            (_, true) => {
                if p == 1 {
                    Play::Interval { lo: -0.5 * loop_width, hi: 0.5 * loop_width }
                } else {
                    Play::Ball { r: 0.5 * loop_width }
                }
            }
            (Shape::Interval(iv), false) => {
                let (lo, hi) = (iv.lo * scale - 0.5 * loop_width, iv.hi * scale + 0.5 * loop_width);
                Play::Interval { lo, hi }
            }
            (shape, false) => {
                if loop_width > 0.0 {
                    return Err(DynamicsError::BadEffect {
                        kind: "backlash",
                        reason: "a loop play can only be added to a 1-D nominal play or where the nominal has none",
                        value: loop_width,
                    });
                }
                Play::Scaled { shape: shape.clone(), s: scale }
            }
        })
    }
}

impl Play {
    /// Projects the deviation `v = q` onto the play's set in place; returns whether the play
    /// is in contact (`q` on the boundary).
    #[inline]
    pub(super) fn project_q(&self, v: &mut [f64], scratch: &mut [f64]) -> bool {
        match self {
            Play::None => {
                v.iter_mut().for_each(|x| *x = 0.0);
                true
            }
            Play::Interval { lo, hi } => {
                let c = v[0].clamp(*lo, *hi);
                let hit = c != v[0] || v[0] <= *lo || v[0] >= *hi;
                v[0] = c;
                hit
            }
            Play::Ball { r } => {
                let nr = v.iter().map(|x| x * x).sum::<f64>().sqrt();
                if nr >= *r {
                    let f = if nr > 0.0 { r / nr } else { 0.0 };
                    v.iter_mut().for_each(|x| *x *= f);
                    true
                } else {
                    false
                }
            }
            Play::Scaled { shape, s } => {
                if *s <= 0.0 {
                    v.iter_mut().for_each(|x| *x = 0.0);
                    return true;
                }
                let u: Vec<f64> = v.iter().map(|x| x / s).collect();
                shape.project(&u, scratch);
                let mut moved = false;
                for (a, b) in v.iter_mut().zip(scratch.iter()) {
                    let nb = b * s;
                    moved |= (*a - nb).abs() > 1e-15 * (1.0 + a.abs());
                    *a = nb;
                }
                moved || shape.dist_to_boundary(&u) <= 1e-12
            }
        }
    }
}
