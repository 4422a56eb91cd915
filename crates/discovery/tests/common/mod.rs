//! Shared by the integration tests that drive the solver directly.
use discovery::fit::Problem;
use discovery::hypothesis::{Hypothesis, Scales};
use dynamics::extended::{InputHold, StepMaps};

/// The least-squares problem of one hypothesis on a one-input, one-output record: estimation
/// segment `[0, k_est)`, output weight `weight`, `substeps` per sample with a first-order hold,
/// the backlash at rest in the play, nothing held out, the nominal fixed.
#[allow(clippy::too_many_arguments)]
pub fn scalar_problem<'a>(
    sys: &'a model::System,
    h: &Hypothesis,
    scales: &'a Scales,
    w: &'a [f64],
    y: &'a [f64],
    k_est: usize,
    weight: f64,
    substeps: usize,
) -> Problem<'a> {
    let dt = scales.dt;
    Problem {
        sys,
        fixed: vec![],
        parts: vec![h.clone()],
        scales,
        w,
        y,
        m: 1,
        p: 1,
        dt,
        k_est,
        weights: vec![weight],
        maps: StepMaps::new(&sys.F(), &sys.B, &sys.E, dt / substeps as f64),
        substeps,
        hold: InputHold::Foh,
        z0: None,
        exclude: None,
        refit: None,
    }
}

/// Scales of the one-input test records (input range 3.6 about 0, slowest time constant 1.7 s):
/// output range `y_range`, `n` samples of `dt`.
#[allow(dead_code)] // not every test binary that includes `common` uses it
pub fn test_scales(y_range: f64, n: usize, dt: f64) -> Scales {
    Scales {
        y_range: vec![y_range],
        w_range: vec![3.6],
        w_absmax: 1.8,
        tau_slow: 1.7,
        dt,
        duration: n as f64 * dt,
        ..Default::default()
    }
}
