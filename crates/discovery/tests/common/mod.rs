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

/// A damped mass on a spring driven by two sines, recorded with Coulomb friction of `level` on
/// its velocity (from `x0 = [0.1, 0]`) and deterministic pseudo-noise of 1 % of the output's
/// range: the nominal model (no friction), the input, the recorded output, its range, and the
/// Coulomb friction hypothesis with its scales.
#[allow(dead_code)]
pub struct CoulombMass {
    pub sys: model::System,
    pub w: Vec<f64>,
    pub y: Vec<f64>,
    pub y_range: f64,
    pub scales: Scales,
    pub hypothesis: Hypothesis,
}

#[allow(dead_code)]
impl CoulombMass {
    /// `n` samples of `dt = 0.02`, damping 1.2, the truth stepped at 2 sub-steps.
    pub fn new(level: f64, n: usize) -> Self {
        Self::stepped(level, n, 1.2, 0.02, 2)
    }

    /// `n` samples of `dt`, damping `damping` (`x'' = -4 x - damping x' + w`), the truth stepped
    /// at `truth_substeps` sub-steps per sample.
    pub fn stepped(level: f64, n: usize, damping: f64, dt: f64, truth_substeps: usize) -> Self {
        use dynamics::extended::ExtendedModel;
        let text = "name = \"mass\"\n[plant]\nA = [[0.0, 1.0], [-4.0, -DAMPING]]\nB = [[0.0], [1.0]]\nC = [[1.0, 0.0]]\nE = [[0.0], [0.0]]\n[input]\nkind = \"sine\"\namplitudes = [1.0]\nomega = 1.0\n[initial]\nx0 = [0.0, 0.0]\nz0 = [0.0]\n";
        let sys = model::parse_str(&text.replace("DAMPING", &format!("{damping:?}"))).unwrap();
        let w: Vec<f64> =
            (0..n).map(|k| (0.9 * k as f64 * dt).sin() + 0.5 * (2.3 * k as f64 * dt + 1.0).sin()).collect();
        let truth = [model::effects::Effect::CoulombFriction { state: 1, level }];
        let y0 = ExtendedModel::new(&sys, &truth, dt, truth_substeps).unwrap().simulate(&w, dt, &[0.1, 0.0]).y;
        let hi = y0.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let y_range = hi - y0.iter().copied().fold(f64::INFINITY, f64::min);
        let y = y0.iter().enumerate().map(|(k, v)| v + 0.01 * y_range * (((k * 7919) % 1000) as f64 / 1000.0 - 0.5));
        let scales = test_scales(y_range, n, dt);
        let hypothesis = discovery::hypothesis::candidates(&sys, &scales)
            .into_iter()
            .find(|h| h.kind == discovery::hypothesis::Kind::CoulombFriction { state: 1 })
            .expect("Coulomb friction on the velocity state is a candidate");
        Self { sys, w, y: y.collect(), y_range, scales, hypothesis }
    }

    /// Its least-squares problem: estimation segment the first 70 %, 2 sub-steps.
    pub fn problem(&self) -> Problem<'_> {
        self.problem_at(2)
    }

    /// Its least-squares problem at `substeps` sub-steps per sample.
    pub fn problem_at(&self, substeps: usize) -> Problem<'_> {
        let k_est = 7 * self.w.len() / 10;
        scalar_problem(&self.sys, &self.hypothesis, &self.scales, &self.w, &self.y, k_est, 1.0 / self.y_range, substeps)
    }
}
