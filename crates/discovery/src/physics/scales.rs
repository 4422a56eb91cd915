//! Scales of the problem the hypotheses' bounds and starts derive from (the recording's
//! ranges, the nominal model's time constants and its free run), never from how a benchmark
//! was generated.

/// Scales of the problem used for bounds.
#[derive(Debug, Clone, Default)]
pub struct Scales {
    pub y_range: Vec<f64>,
    pub w_range: Vec<f64>,
    pub w_absmax: f64,
    /// `max |w|` over the estimation segment alone, where the fits run (0: unknown, take
    /// `w_absmax`). A saturation limit started above it clips nothing there: a fit with zero
    /// gradient, stuck where the effect cannot act (issue 27 item 3).
    pub w_absmax_est: f64,
    /// Slowest time constant `1 / |mu|` of the nominal `F`.
    pub tau_slow: f64,
    pub dt: f64,
    pub duration: f64,
    /// Range of each state over the nominal model's simulation of the record (empty when
    /// unknown; see [`Scales::with_nominal`]).
    pub state_range: Vec<f64>,
    /// Root mean square of each state over the same simulation (velocity scale of the
    /// Stribeck velocity).
    pub state_rms: Vec<f64>,
    /// The nominal simulation and the measured output, for data-derived starts (the cogging
    /// period scan); `None`: the hypotheses that need it are not offered.
    pub nominal: Option<std::sync::Arc<NominalRun>>,
}

/// The nominal model's free-run simulation of the record next to the measured output.
#[derive(Debug, Clone, Default)]
pub struct NominalRun {
    /// States `x[k * n + i]`.
    pub x: Vec<f64>,
    /// Simulated output `y[k * p + i]`.
    pub y_nominal: Vec<f64>,
    /// Measured output `y[k * p + i]`.
    pub y: Vec<f64>,
    /// Estimation samples `k < k_est` (the scan never looks at the validation segment).
    pub k_est: usize,
}

impl Scales {
    /// Adds the state scales and the nominal run: `x` (flat `k * n + i`) and `y_nominal` from
    /// a free-run simulation of the nominal model, `y` the recording's output.
    pub fn with_nominal(mut self, x: &[f64], y_nominal: &[f64], y: &[f64], k_est: usize) -> Self {
        let p = self.y_range.len().max(1);
        let ns = y.len() / p;
        if ns == 0 || !x.len().is_multiple_of(ns) || y_nominal.len() != y.len() {
            return self;
        }
        let n = x.len() / ns;
        let (mut lo, mut hi, mut sq) = (vec![f64::INFINITY; n], vec![f64::NEG_INFINITY; n], vec![0.0; n]);
        for k in 0..ns {
            for i in 0..n {
                let v = x[k * n + i];
                lo[i] = lo[i].min(v);
                hi[i] = hi[i].max(v);
                sq[i] += v * v;
            }
        }
        self.state_range = (0..n).map(|i| hi[i] - lo[i]).collect();
        self.state_rms = sq.iter().map(|v| (v / ns as f64).sqrt()).collect();
        self.nominal = Some(std::sync::Arc::new(NominalRun {
            x: x.to_vec(),
            y_nominal: y_nominal.to_vec(),
            y: y.to_vec(),
            k_est: k_est.min(ns),
        }));
        self
    }
    /// The largest output range (at least `1e-12`).
    pub fn y_range_max(&self) -> f64 {
        self.y_range.iter().copied().fold(0.0, f64::max).max(1e-12)
    }
    /// The largest input range (at least `1e-12`).
    pub fn w_range_max(&self) -> f64 {
        self.w_range.iter().copied().fold(0.0, f64::max).max(1e-12)
    }
}
