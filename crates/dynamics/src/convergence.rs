//! Accuracy of the catching-up scheme against the event-driven reference: the error
//! `max_t |(x, z)_h(t) - (x, z)_ref(t)|_inf` on a common grid for a ladder of steps
//! `h_0, h_0/2, h_0/4, ...` and the fitted order (slope of `ln err` against `ln h`).
use crate::error::DynamicsError;
use crate::integrators::catching_up::CatchingUpSettings;
use crate::integrators::event_driven::{event_driven, EventDrivenSettings};
use crate::linear::step_map::InputHold;
use crate::rate::lyapunov_exponent::regression_slope;
use crate::trajectory::{simulate_catching_up, Trajectory};
use serde::Serialize;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ConvergenceSettings {
    /// Largest step of the ladder (adjusted to divide `t_end / grid_points`). Default `1e-2`.
    pub h0: f64,
    /// Number of halvings. Default `6`.
    pub levels: usize,
    /// Horizon. Default: 20 periods or 20 time units.
    pub t_end: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ConvergenceStudy {
    pub t_end: f64,
    pub h: Vec<f64>,
    pub error: Vec<f64>,
    /// Least-squares slope of `ln error` against `ln h`.
    pub order: f64,
    pub events: usize,
}

/// The study for `sys`: against the event-driven reference for a model of the paper's class;
/// for a model with `[[effects]]` (no event-driven reference exists) the extended-model
/// simulator against itself at the finest step halved once more (`events = 0`).
pub fn convergence_study(sys: &model::System, st: &ConvergenceSettings) -> Result<ConvergenceStudy, DynamicsError> {
    crate::error::check_dt(st.h0)?;
    if st.levels < 2 {
        return Err(DynamicsError::BadSetting {
            name: "levels",
            value: st.levels as f64,
            reason: "needs at least 2 steps to fit an order",
        });
    }
    let n0 = (st.t_end / st.h0).ceil() as usize;
    let h0 = st.t_end / n0 as f64;
    if sys.effects.list.is_empty() {
        let (reference, events) =
            event_driven(sys, &EventDrivenSettings { dt_out: h0, t_end: st.t_end, ..Default::default() })?;
        ladder(st, h0, events, &reference, |h, steps, every| {
            simulate_catching_up(sys, &CatchingUpSettings { dt: h, hold: InputHold::Foh }, steps, every)
        })
    } else {
        let rr = 1usize << st.levels;
        let reference = crate::extended::simulate_trajectory(sys, h0 / rr as f64, n0 * rr, rr)?;
        ladder(st, h0, 0, &reference, |h, steps, every| crate::extended::simulate_trajectory(sys, h, steps, every))
    }
}

/// Errors `max |(x, z)_h - (x, z)_ref|_inf` on the grid of `h0` for `h = h0 / 2^l`,
/// `l < levels`, and the fitted order.
fn ladder(
    st: &ConvergenceSettings,
    h0: f64,
    events: usize,
    reference: &Trajectory,
    simulate: impl Fn(f64, usize, usize) -> Result<Trajectory, DynamicsError>,
) -> Result<ConvergenceStudy, DynamicsError> {
    let n0 = (st.t_end / h0).round() as usize;
    let mut hs = Vec::new();
    let mut errs = Vec::new();
    for l in 0..st.levels {
        let r = 1usize << l;
        let h = h0 / r as f64;
        let tr = simulate(h, n0 * r, r)?;
        let mut e: f64 = 0.0;
        for i in 0..reference.len().min(tr.len()) {
            for (u, v) in reference.x_at(i).iter().chain(reference.z_at(i)).zip(tr.x_at(i).iter().chain(tr.z_at(i))) {
                e = e.max((u - v).abs());
            }
        }
        hs.push(h);
        errs.push(e);
    }
    let lh: Vec<f64> = hs.iter().map(|h| h.ln()).collect();
    let le: Vec<f64> = errs.iter().map(|e| e.max(1e-300).ln()).collect();
    let (order, _) = regression_slope(&lh, &le);
    Ok(ConvergenceStudy { t_end: st.t_end, h: hs, error: errs, order, events })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn catching_up_is_first_order_on_the_worked_example() {
        let sys = model::parse_str(include_str!("../../../examples/worked-example.toml")).unwrap();
        let s =
            convergence_study(&sys, &ConvergenceSettings { h0: 1e-2, levels: 4, t_end: 4.0 * sys.period().unwrap() })
                .unwrap();
        assert!(s.order > 0.8 && s.order < 1.3, "{s:?}");
        assert!(s.error.windows(2).all(|w| w[1] < w[0]), "{s:?}");
    }
}
