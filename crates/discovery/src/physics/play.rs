//! The play family: `backlash` where the nominal model has none (in the feedback loop or
//! between the command and the plant), `gap_width` (the model's play is wider or narrower than
//! its Theta) and `backlash_inertia` (the backlash output coasts).
//!
//! Bounds: play widths `[0, range(y)/2]` (loop) or `[0, range(w)/2]` (input); `gap_width`
//! relative change `[-0.9, s_max - 1]` with `s_max = clamp(2 range(y) / diam(Theta), 5,
//! 1000)` (a play wider than the output range never moves `z`), fitted in the logarithm of the
//! scale `1 + relative_change` and started at +-0.5 %, +-5 %, -50 %, +70 % and +250 %;
//! `backlash_inertia` time constant `mass/damping` in `[0, 2 tau_slow]` (damping fixed to 1:
//! only the ratio is identifiable from `y`, since `z` enters the plant only through `E z`).
//! Widths and the time constant start over decades ([`super::parameters::level`]).
use super::parameters::{level, linear};
use super::{Context, Family, Hypothesis, Kind, Site};
use model::effects::{names, Effect, PlayLocation};

/// Parameter name of a play width.
pub const WIDTH: &str = "width";
const RELATIVE_CHANGE: &str = "relative_change";
const MASS: &str = "mass";

/// The play family (see the module documentation).
pub struct Play;

/// A play of width `width` (negative values clamp to none) at `location`.
pub fn backlash(width: f64, location: PlayLocation) -> Effect {
    Effect::Backlash { width: width.max(0.0), location }
}

impl Family for Play {
    fn hypotheses(&self, site: &Site, cx: &Context) -> Vec<Hypothesis> {
        let Site::Play = site else { return vec![] };
        let (sys, s) = (cx.sys, cx.scales);
        let point = dynamics::extended::theta_is_point(sys);
        let e_nonzero = sys.E.iter().any(|v| *v != 0.0);
        let (yr, wr) = (s.y_range_max(), s.w_range_max());
        let mut out = Vec::new();
        if point && e_nonzero {
            out.push(level(Kind::Backlash { at_input: false }, 0.5 * yr, WIDTH));
        }
        out.push(level(Kind::Backlash { at_input: true }, 0.5 * wr, WIDTH));
        if !point {
            // Scale 1 + relative_change from 0.1 up to the scale at which the play is wider than
            // the whole output range (beyond it z never moves and the scale is not identifiable),
            // at least 5; fitted in log scale.
            let diam = geometry::ConvexSet::diameter(&sys.theta).lower;
            let smax = if diam > 0.0 { (2.0 * yr / diam).clamp(5.0, 1e3) } else { 5.0 };
            let mut h = linear(Kind::GapWidth, -0.9, smax - 1.0, RELATIVE_CHANGE);
            h.log_shift = vec![Some(1.0)];
            out.push(h.starts_at(&[-0.5, -0.05, -0.005, 0.005, 0.05, 0.7, 2.5]));
            out.push(level(Kind::BacklashInertia, 2.0 * s.tau_slow, MASS));
        }
        out
    }

    fn name(&self, kind: Kind) -> Option<&'static str> {
        match kind {
            Kind::Backlash { .. } => Some(names::BACKLASH),
            Kind::GapWidth => Some(names::GAP_WIDTH),
            Kind::BacklashInertia => Some(names::BACKLASH_INERTIA),
            _ => None,
        }
    }

    fn label(&self, kind: Kind) -> Option<String> {
        match kind {
            Kind::Backlash { at_input: true } => Some("backlash(input)".into()),
            Kind::Backlash { at_input: false } => Some("backlash(loop)".into()),
            k => self.name(k).map(String::from),
        }
    }

    fn description(&self, kind: Kind) -> Option<String> {
        Some(match kind {
            Kind::Backlash { at_input: false } => "Play in the feedback path: the backlash output z stays put until y has crossed the gap, as in loose gears or a slack coupling.".into(),
            Kind::Backlash { at_input: true } => "Play between the command and the plant: the actuator only follows the input after the input has reversed by the width of the play.".into(),
            Kind::GapWidth => "The real play is wider (or narrower) than the model's Theta, e.g. from gear wear or a wrong catalogue value.".into(),
            Kind::BacklashInertia => "The backlash output has mass and damping: after y reverses, z coasts on instead of stopping at once.".into(),
            _ => return None,
        })
    }

    fn effect(&self, kind: Kind, theta: &[f64]) -> Option<Effect> {
        Some(match kind {
            Kind::Backlash { at_input } => {
                backlash(theta[0], if at_input { PlayLocation::Input } else { PlayLocation::Loop })
            }
            Kind::GapWidth => Effect::GapWidth { relative_change: theta[0] },
            Kind::BacklashInertia => Effect::BacklashInertia { mass: theta[0].max(0.0), damping: 1.0 },
            _ => return None,
        })
    }

    fn main_parameter(&self, effect: &Effect) -> Option<(f64, Option<&'static str>)> {
        match effect {
            Effect::Backlash { width, .. } => Some((*width, Some(WIDTH))),
            Effect::GapWidth { relative_change } => Some((*relative_change, Some(RELATIVE_CHANGE))),
            Effect::BacklashInertia { mass, damping } => Some((mass / damping, Some(MASS))),
            _ => None,
        }
    }
}
