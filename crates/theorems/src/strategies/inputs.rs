//! Random `T`-periodic inputs `w(t)` (Section 5 of the paper: bounded, `T`-periodic).
use model::Input;
use proptest::prelude::*;

/// Largest input dimension `m` the strategies generate.
pub const MAX_M: usize = 2;

/// Which periodic waveforms to draw.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Waveform {
    Sine,
    Square,
}

/// Parameters of a periodic input; [`InputParams::build`] makes the [`Input`].
#[derive(Debug, Clone)]
pub struct InputParams {
    pub waveform: Waveform,
    /// Amplitudes `10^amp_exp * a_i`, `a_i in [-1, 1]`.
    pub amplitudes: [f64; MAX_M],
    pub amp_exp: f64,
    /// Angular frequency, period `T = 2 pi / omega`.
    pub omega: f64,
    pub phase: f64,
}

impl InputParams {
    pub fn build(&self, m: usize) -> Input {
        let s = 10f64.powf(self.amp_exp);
        let amplitudes: Vec<f64> = self.amplitudes[..m].iter().map(|a| s * a).collect();
        match self.waveform {
            Waveform::Sine => Input::Sine { amplitudes, omega: self.omega, phase: self.phase },
            Waveform::Square => Input::Square { amplitudes, omega: self.omega, phase: self.phase },
        }
    }
}

/// Settings of [`periodic_input`].
#[derive(Debug, Clone)]
pub struct InputStrategyConfig {
    /// Waveforms drawn uniformly. Default: sine only (smooth `w`, so `eta_T'` is continuous).
    pub waveforms: Vec<Waveform>,
    /// Range of `omega`. Default `[0.5, 3]`.
    pub omega: (f64, f64),
    /// Range of the amplitude exponent. Default `[-1, 1]`.
    pub amp_exp: (f64, f64),
}

impl Default for InputStrategyConfig {
    fn default() -> Self {
        Self { waveforms: vec![Waveform::Sine], omega: (0.5, 3.0), amp_exp: (-1.0, 1.0) }
    }
}

/// Strategy for [`InputParams`].
pub fn periodic_input(cfg: &InputStrategyConfig) -> BoxedStrategy<InputParams> {
    (
        proptest::sample::select(cfg.waveforms.clone()),
        proptest::array::uniform2(-1.0..=1.0f64),
        cfg.amp_exp.0..=cfg.amp_exp.1,
        cfg.omega.0..=cfg.omega.1,
        0.0..std::f64::consts::TAU,
    )
        .prop_map(|(waveform, amplitudes, amp_exp, omega, phase)| InputParams {
            waveform,
            amplitudes,
            amp_exp,
            omega,
            phase,
        })
        .boxed()
}
