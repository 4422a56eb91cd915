//! Simulating a model file into a recorded [`Trajectory`] ([`crate::record`], re-exported
//! here): [`simulate_model`] (catching-up, or the extended model when the model has
//! `[[effects]]`) and [`simulate_catching_up`].
use crate::error::DynamicsError;
use crate::extended::simulate::simulate_trajectory;
use crate::integrators::catching_up::{CatchingUpSettings, Simulator};
pub use crate::record::Trajectory;
use model::System;

/// Simulates `sys` for `steps` steps of `h` from `(sys.x0, sys.z0)`, recording every
/// `record_every`-th state (and the first and last): the catching-up scheme for a model of the
/// paper's class, the extended model ([`crate::extended::simulate_trajectory`]) when the model
/// has `[[effects]]` or a `[controller]`. The one entry point of every command that simulates a
/// model file.
pub fn simulate_model(sys: &System, h: f64, steps: usize, record_every: usize) -> Result<Trajectory, DynamicsError> {
    if sys.effects.list.is_empty() && sys.controller.is_none() {
        simulate_catching_up(sys, &CatchingUpSettings { dt: h, ..Default::default() }, steps, record_every)
    } else {
        simulate_trajectory(sys, h, steps, record_every)
    }
}

/// Simulates `steps` catching-up steps from `(sys.x0, sys.z0)` at `t = 0`, recording every
/// `record_every`-th state (and the first). Ignores `[[effects]]`: use [`simulate_model`] for
/// model files.
pub fn simulate_catching_up(
    sys: &System,
    settings: &CatchingUpSettings,
    steps: usize,
    record_every: usize,
) -> Result<Trajectory, DynamicsError> {
    let mut sim = Simulator::new(sys, settings)?;
    let every = record_every.max(1);
    let mut tr = Trajectory::new(sys.n(), sys.m(), sys.p());
    let (mut x, mut z) = (sys.x0.as_slice().to_vec(), sys.z0.as_slice().to_vec());
    let mut w = vec![0.0; sys.m()];
    sys.input.eval(0.0, &mut w);
    tr.push(0.0, &w, &x, &z);
    let mut bad = None;
    sim.run(0.0, &mut x, &mut z, steps, |k, t, x, z| {
        if k % every == 0 || k == steps {
            sys.input.eval(t, &mut w);
            if bad.is_none() && !(x.iter().chain(z).all(|v| v.is_finite())) {
                bad = Some(t);
            }
            tr.push(t, &w, x, z);
        }
    });
    if let Some(t) = bad {
        return Err(DynamicsError::NonFinite { t });
    }
    Ok(tr)
}
