//! Generator of benchmark recordings with one concealed effect (or none). Kept apart from the
//! diagnosis: no diagnosis module imports this one, and it has its own simulator
//! ([`plant_sim`]: explicit midpoint on a grid 20 times finer than the samples, exact
//! evaluation of the continuous input, its own play / friction / inertia discretisation), so
//! the diagnosis never sees its own discretisation mirrored in the data.
//!
//! Plants (p = m = 1, n from 2 to 4, position output, part of the stiffness acting through
//! the play so that `E != 0`):
//! - n = 2: mass-spring-damper, `x = (pos, vel)`;
//! - n = 3: the same driven through a first-order actuator lag, `x = (pos, vel, act)`;
//! - n = 4: two masses coupled by a spring, `x = (pos1, vel1, pos2, vel2)`, output `pos1`.
//!
//! Two profiles ([`Profile`]):
//! - `classic` (the original benchmark): natural frequency `omega0` in [1, 4] rad/s, damping
//!   ratio in [0.1, 0.7], 60 samples per natural period, the plant driven by the continuous
//!   input signal (the recording samples it), white measurement noise;
//! - `digital` (recordings of a digitally controlled machine): sample period log-uniform in
//!   [1, 10] ms, 30-100 samples per natural period (so `omega0 = 2 pi / (N dt)`), half the
//!   plants lightly damped (damping ratio in [0.03, 0.1]), the recorded command held constant
//!   over each sample (zero-order hold) as the plant sees it, and the measurement noise white
//!   or AR(1)-coloured (`rho` in [0.5, 0.9], half the cases each);
//! - `mixed` (every convention of issue 27's acceptance at once): as `digital`, with the sample
//!   period log-uniform in [0.5, 20] ms and the plant driven, a third of the cases each, by the
//!   continuous signal, its zero-order-held or its linearly interpolated (first-order-held)
//!   samples ([`plant_sim::Drive`]).
//!
//! Both: input a multisine, low-pass filtered noise or a sequence of sine segments, at least
//! 10 slowest time constants and 25 natural periods (at most 80). The effect's magnitude is
//! set by bisection so that the nominal model, simulated from the true initial state, fits
//! the noisy recording to a target drawn from [86, 94] %; measurement noise at 30 dB SNR.
//! The classic profile draws exactly the random numbers it always did (old seeds reproduce);
//! the digital profile's extra draws come from a second stream.
pub mod long_record;
pub mod plant_sim;
pub mod servo_cascade;
pub mod servo_loop;

use crate::recording::Recording;
use model::effects::{names, Effect, PlayLocation};
use model::{Input, SimDefaults, System};
use nalgebra::{DMatrix, DVector};
use plant_sim::{Drive, InputHold};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::{PI, TAU};

/// The classes of concealed effects.
pub const CLASSES: [&str; 9] = [
    NONE,
    names::BACKLASH,
    names::GAP_WIDTH,
    names::COULOMB_FRICTION,
    names::CONSTANT_FORCE,
    names::BACKLASH_INERTIA,
    names::INPUT_DELAY,
    names::INPUT_SATURATION,
    names::SENSOR_OFFSET,
];

/// The class of cases without a concealed effect.
pub const NONE: &str = "none";

/// The classes of the friction library (issue 14): Stribeck friction with a static level,
/// direction-dependent Coulomb levels and a cogging force. Kept apart from [`CLASSES`] so that
/// the original benchmark keeps its classes (and its seeds their cases); [`all_classes`]
/// lists both.
pub const FRICTION_CLASSES: [&str; 3] = [names::STRIBECK_FRICTION, names::ASYMMETRIC_COULOMB, names::COGGING];

/// [`CLASSES`] followed by [`FRICTION_CLASSES`].
pub fn all_classes() -> Vec<&'static str> {
    CLASSES.iter().chain(FRICTION_CLASSES.iter()).copied().collect()
}

/// Shape of the friction-library effects beyond their magnitude (drawn per case from a
/// stream of their own, so that no other class's draws change).
#[derive(Debug, Clone, Copy)]
struct FrictionShape {
    /// `static_level / level` of Stribeck friction, in [1.8, 3].
    static_ratio: f64,
    /// Stribeck velocity over the RMS velocity of the nominal run, in [0.05, 0.25].
    stribeck_frac: f64,
    /// Weaker over stronger direction-dependent level, in [0.2, 0.6].
    asym_ratio: f64,
    /// Whether the stronger level opposes upward motion.
    asym_up: bool,
    /// Cogging periods over the nominal position range, in [3, 10].
    cog_periods: f64,
    /// Cogging phase, uniform in [0, 2 pi).
    cog_phase: f64,
    /// RMS velocity and position range of the nominal run (set after it).
    v_rms: f64,
    pos_range: f64,
}

/// Which kind of recording the generator makes (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Profile {
    Classic,
    Digital,
    Mixed,
}

impl Profile {
    pub fn name(&self) -> &'static str {
        match self {
            Profile::Classic => "classic",
            Profile::Digital => "digital",
            Profile::Mixed => "mixed",
        }
    }
    /// From its name (`classic`, `digital` or `mixed`).
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "classic" => Some(Profile::Classic),
            "digital" => Some(Profile::Digital),
            "mixed" => Some(Profile::Mixed),
            _ => None,
        }
    }
}

/// Benchmark variable `key` as `parse` reads it: `Ok(None)` unset, `Err` naming the variable
/// and its value where `parse` refuses it (`expected`: what it takes). The generator reads each
/// leniently (a refused value falls back to the default); [`env_error`] refuses to run on one.
fn bench_var<T>(key: &str, parse: impl Fn(&str) -> Option<T>, expected: &str) -> Result<Option<T>, String> {
    match std::env::var(key) {
        Err(_) => Ok(None),
        Ok(v) => parse(&v).map(Some).ok_or_else(|| format!("{key}={v:?}: expected {expected}")),
    }
}

/// `BENCH_TRUTH` (`coarse`).
fn truth_var() -> Result<Option<()>, String> {
    bench_var("BENCH_TRUTH", |v| (v == "coarse").then_some(()), "coarse (or unset: the converged truth)")
}

/// `BENCH_LENGTH` (a positive factor).
fn length_var() -> Result<Option<f64>, String> {
    let positive = |v: &str| v.parse::<f64>().ok().filter(|f| f.is_finite() && *f > 0.0);
    bench_var("BENCH_LENGTH", positive, "a positive factor (default 1)")
}

/// `BENCH_NOISE_DB` (a finite level in dB).
fn noise_var() -> Result<Option<f64>, String> {
    let finite = |v: &str| v.parse::<f64>().ok().filter(|f| f.is_finite());
    bench_var("BENCH_NOISE_DB", finite, "a finite level in dB (default -30)")
}

/// `BENCH_NEXT` (`1`).
fn next_var() -> Result<Option<()>, String> {
    bench_var("BENCH_NEXT", |v| (v == "1").then_some(()), "1 (or unset: one recording per case)")
}

/// Whether each case also records its machine's next experiment ([`NextExperiment`]):
/// `BENCH_NEXT=1`. The first recording's draws are the same either way.
pub fn next_requested() -> bool {
    matches!(next_var(), Ok(Some(())))
}

/// `BENCH_SIGNAL` ([`ForcedInput::parse`]).
fn signal_var() -> Result<Option<ForcedInput>, String> {
    bench_var("BENCH_SIGNAL", ForcedInput::parse, "chirp or steps (or unset: the drawn inputs)")
}

/// Each recording's truth is stepped until halving the step moves it by less than a tenth of a
/// sigma of any fitted parameter ([`plant_sim::simulate_converged`]). `BENCH_TRUTH=coarse`
/// gives the truth of the tables before 2026-11-26 instead (20 fine steps per sample, whose
/// first-order play, friction and inertia updates leave it up to about a sigma off on
/// friction and backlash-inertia cases; BENCHMARKS.md, issue 27 item 2).
pub fn converged_truth() -> bool {
    !matches!(truth_var(), Ok(Some(())))
}

/// Each recording's duration is multiplied by `BENCH_LENGTH` (a positive number; default 1):
/// the long records of the screening benchmark (BENCHMARKS "Long records screened"). The
/// draws after the input signal differ from the default length's (the signal's draws depend
/// on its duration): fresh cases, not the short ones made long.
pub fn length_factor() -> f64 {
    length_var().ok().flatten().unwrap_or(1.0)
}

/// The measurement noise's level in dB of the nominal output's standard deviation:
/// `BENCH_NOISE_DB` (a finite number; default -30, about 3.2 %). The noise stream is the
/// same at every level (scaled), and the effects' magnitudes are set against the default
/// level, so a case differs only by its noise (and the truth's stepping, converged to a tenth
/// of the new noise's sigma).
pub fn noise_db() -> f64 {
    noise_var().ok().flatten().unwrap_or(-30.0)
}

/// What is wrong with the benchmark's environment variables (`BENCH_SIGNAL`,
/// `BENCH_NOISE_DB`, `BENCH_LENGTH`, `BENCH_TRUTH`, `BENCH_NEXT`), naming the first refused
/// variable and its value; `None` where each is unset or valid. The generator reads them leniently; the runners
/// refuse to start on one, so a typo does not pass for a measurement under the condition it
/// names.
pub fn env_error() -> Option<String> {
    [signal_var().err(), noise_var().err(), length_var().err(), truth_var().err(), next_var().err()]
        .into_iter()
        .flatten()
        .next()
}

/// The sampling and noise conditions of one case (reported per case by the benchmark).
#[derive(Debug, Clone, serde::Serialize)]
pub struct Conditions {
    pub profile: Profile,
    /// What the plant sees of the command: `continuous`, `zoh` or `foh` ([`plant_sim::Drive`]).
    pub hold: &'static str,
    /// Sample period (s).
    pub dt: f64,
    /// AR(1) coefficient of the measurement noise (0 = white).
    pub noise_rho: f64,
    pub omega0: f64,
    pub zeta: f64,
}

impl Conditions {
    pub fn short(&self) -> String {
        format!(
            "{} hold, dt {:.2} ms, noise {}, zeta {:.2}",
            self.hold,
            1e3 * self.dt,
            if self.noise_rho > 0.0 { format!("AR(1) {:.2}", self.noise_rho) } else { "white".into() },
            self.zeta
        )
    }
}

/// The continuous input signal of a case.
#[derive(Debug, Clone)]
pub enum Signal {
    /// `sum a_i sin(omega_i t + phi_i)`.
    Multisine { a: Vec<f64>, omega: Vec<f64>, phi: Vec<f64> },
    /// Knots of low-pass filtered noise, linearly interpolated (`dt_knot` apart).
    Knots { dt_knot: f64, v: Vec<f64> },
    /// Sine segments of length `seg`: amplitude and frequency per segment.
    Segments { seg: f64, a: Vec<f64>, omega: Vec<f64> },
    /// A logarithmic frequency sweep `a sin(phi(t))` from `omega_lo` to `omega_hi` over
    /// `duration` (held at `omega_hi` after it).
    Chirp { a: f64, omega_lo: f64, omega_hi: f64, duration: f64 },
    /// Random steps: level `v[i]` from `edges[i]` on (`edges[0] = 0`, ascending).
    Steps { edges: Vec<f64>, v: Vec<f64> },
}

impl Signal {
    pub fn eval(&self, t: f64) -> f64 {
        let t = t.max(0.0);
        match self {
            Signal::Multisine { a, omega, phi } => {
                a.iter().zip(omega).zip(phi).map(|((a, w), p)| a * (w * t + p).sin()).sum()
            }
            Signal::Knots { dt_knot, v } => {
                let s = t / dt_knot;
                let i = (s.floor() as usize).min(v.len() - 2);
                let f = (s - i as f64).clamp(0.0, 1.0);
                v[i] * (1.0 - f) + v[i + 1] * f
            }
            Signal::Segments { seg, a, omega } => {
                let i = ((t / seg).floor() as usize).min(a.len() - 1);
                let tl = t - i as f64 * seg;
                // Smooth window so that segments join continuously.
                a[i] * (omega[i] * tl).sin() * (PI * tl / seg).sin().powi(2).sqrt()
            }
            Signal::Chirp { a, omega_lo, omega_hi, duration } => {
                let r = omega_hi / omega_lo;
                let phi = |t: f64| omega_lo * duration / r.ln() * (r.powf(t / duration) - 1.0);
                let ph = if t <= *duration { phi(t) } else { phi(*duration) + omega_hi * (t - duration) };
                a * ph.sin()
            }
            Signal::Steps { edges, v } => v[edges.partition_point(|&e| e <= t).saturating_sub(1)],
        }
    }

    /// Whether the signal jumps (steps): a jump between fine grid points, as a delayed one
    /// falls, is a first-order error of the fine stepping.
    pub fn has_jumps(&self) -> bool {
        matches!(self, Signal::Steps { .. })
    }
}

/// An input kind forced on every case in place of the drawn one (multisine, filtered noise
/// or sine segments): inputs the diagnosis was never developed on, for held-out checks. The
/// forced input is drawn from a stream of its own, so every other draw of a case stays as it
/// was.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ForcedInput {
    /// A logarithmic sweep from 0.05-0.15 to 1.2-2 times the natural frequency.
    Chirp,
    /// Random levels in [-1, 1] held for one to six natural periods, changing on samples.
    Steps,
}

impl ForcedInput {
    /// From its name (`chirp` or `steps`).
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "chirp" => Some(ForcedInput::Chirp),
            "steps" => Some(ForcedInput::Steps),
            _ => None,
        }
    }
}

/// The input kind that `BENCH_SIGNAL` (`chirp` or `steps`) forces on every case of the
/// benchmarks ([`ForcedInput`]; unset: the drawn kinds).
pub fn forced_signal() -> Option<ForcedInput> {
    signal_var().ok().flatten()
}

/// The `forced` input for a plant of natural frequency `w0` over `duration`, sampled every
/// `dt` (steps change on the sample grid).
fn forced(forced: ForcedInput, mix: u64, w0: f64, duration: f64, dt: f64) -> (Signal, &'static str) {
    let mut rng = ChaCha8Rng::seed_from_u64(mix ^ 0x5167_4A1E_0000_0031);
    if forced == ForcedInput::Chirp {
        let (lo, hi) = (w0 * rng.random_range(0.05..0.15), w0 * rng.random_range(1.2..2.0));
        return (Signal::Chirp { a: rng.random_range(0.6..1.0), omega_lo: lo, omega_hi: hi, duration }, "chirp");
    }
    // Dwell times of one to six natural periods, levels uniform in [-1, 1].
    let period = TAU / w0;
    // (edges at `k dt` computed as the sample times are, so each falls on its sample exactly)
    let (mut edges, mut v, mut k) = (vec![0.0], vec![rng.random_range(-1.0..1.0)], 0usize);
    while (k as f64) * dt < duration {
        k += ((rng.random_range(1.0..6.0) * period) / dt).round().max(1.0) as usize;
        edges.push(k as f64 * dt);
        v.push(rng.random_range(-1.0..1.0));
    }
    (Signal::Steps { edges, v }, "random steps")
}

/// A generated case.
#[derive(Debug, Clone)]
pub struct Case {
    pub class: &'static str,
    /// The nominal model handed to the diagnosis.
    pub nominal: System,
    /// The true concealed effect (the first of two with [`generate_pair`]).
    pub truth: Option<Effect>,
    /// Every true concealed effect (one, none, or two with [`generate_pair`]), in the order of
    /// `classes`.
    pub truths: Vec<Effect>,
    /// The concealed classes (`[class]`, or the pair).
    pub classes: Vec<&'static str>,
    pub recording: Recording,
    /// Fit % of the nominal model (true initial state) on the noisy recording.
    pub nominal_fit: f64,
    pub description: String,
    pub conditions: Conditions,
    /// The machine's next experiment, where `BENCH_NEXT=1` asks for it ([`next_requested`]).
    pub next: Option<NextExperiment>,
}

/// A second recording of a case's machine: the same plant, concealed effects, initial state,
/// hold, sampling, duration and noise level and colour; a new input and new noise. A model
/// fitted on the first recording must predict it (issue 27: in-sample is not validation).
#[derive(Debug, Clone)]
pub struct NextExperiment {
    pub recording: Recording,
    /// Its output without measurement noise.
    pub clean: Vec<f64>,
    /// The input's family (`multisine`, `filtered noise`, `sine segments`).
    pub input: &'static str,
}

/// The true plant in physical form.
#[derive(Debug, Clone)]
pub struct Plant {
    pub A: DMatrix<f64>,
    pub B: DMatrix<f64>,
    pub C: DMatrix<f64>,
    pub E: DMatrix<f64>,
    pub half_width: f64,
    /// Index of the velocity state on which friction / force act.
    pub vel: usize,
    pub omega0: f64,
    pub zeta: f64,
}

/// A random plant; `over = Some((omega0, zeta))` replaces the drawn natural frequency and
/// damping (the draws are still made, so the stream is the same).
fn random_plant(rng: &mut ChaCha8Rng, n: usize, over: Option<(f64, f64)>) -> Plant {
    let w0: f64 = rng.random_range(1.0..4.0);
    let zeta: f64 = rng.random_range(0.1..0.7);
    let (w0, zeta) = over.unwrap_or((w0, zeta));
    let k = w0 * w0;
    let c = 2.0 * zeta * w0;
    let kappa: f64 = rng.random_range(0.2..0.6);
    let (mut A, mut B, mut C, mut E) =
        (DMatrix::zeros(n, n), DMatrix::zeros(n, 1), DMatrix::zeros(1, n), DMatrix::zeros(n, 1));
    A[(0, 1)] = 1.0;
    A[(1, 0)] = -k * (1.0 - kappa);
    A[(1, 1)] = -c;
    E[(1, 0)] = -k * kappa;
    C[(0, 0)] = 1.0;
    match n {
        2 => B[(1, 0)] = k,
        3 => {
            let ta: f64 = rng.random_range(0.05..0.3) / w0;
            A[(1, 2)] = 1.0;
            A[(2, 2)] = -1.0 / ta;
            B[(2, 0)] = k / ta;
        }
        _ => {
            let w2: f64 = rng.random_range(1.5..3.0) * w0;
            let ks = 0.5 * k;
            A[(1, 0)] -= ks;
            A[(1, 2)] = ks;
            A[(2, 3)] = 1.0;
            A[(3, 0)] = w2 * w2 * 0.5;
            A[(3, 2)] = -w2 * w2;
            A[(3, 3)] = -2.0 * 0.2 * w2;
            B[(1, 0)] = k;
        }
    }
    Plant { A, B, C, E, half_width: rng.random_range(0.03..0.1), vel: 1, omega0: w0, zeta }
}

fn random_signal(rng: &mut ChaCha8Rng, w0: f64, duration: f64) -> (Signal, &'static str) {
    match rng.random_range(0..3) {
        0 => {
            let k = rng.random_range(3..7);
            let omega: Vec<f64> = (0..k).map(|_| w0 * rng.random_range(0.1..1.5)).collect();
            let a: Vec<f64> = (0..k).map(|_| rng.random_range(0.3..1.0) / (k as f64).sqrt()).collect();
            let phi = (0..k).map(|_| rng.random_range(0.0..TAU)).collect();
            (Signal::Multisine { a, omega, phi }, "multisine")
        }
        1 => {
            // White noise through a first-order low-pass at omega0 / 2, sampled at knots.
            let dtk = 0.25 / w0;
            let nk = (duration / dtk) as usize + 3;
            let alpha = (-dtk * 0.5 * w0).exp();
            let mut v = vec![0.0; nk];
            let mut s = 0.0;
            for x in v.iter_mut() {
                s = alpha * s + (1.0 - alpha * alpha).sqrt() * (rng.random::<f64>() * 2.0 - 1.0) * 1.7;
                *x = s;
            }
            (Signal::Knots { dt_knot: dtk, v }, "filtered noise")
        }
        _ => {
            let seg = 8.0 * TAU / w0;
            let ns = (duration / seg) as usize + 2;
            (
                Signal::Segments {
                    seg,
                    a: (0..ns).map(|_| rng.random_range(0.4..1.2)).collect(),
                    omega: (0..ns).map(|_| w0 * rng.random_range(0.2..1.3)).collect(),
                },
                "sine segments",
            )
        }
    }
}

/// The true effect of `class` at magnitude `a >= 0` (`sign` for signed effects; `fr` shapes
/// the friction-library effects: `a` is the sliding level of Stribeck friction, the stronger
/// directional level and the cogging amplitude; the cogging acts with position state 0).
fn effect_at(class: &str, a: f64, sign: f64, wmax: f64, vel: usize, fr: &FrictionShape) -> Option<Effect> {
    Some(match class {
        names::STRIBECK_FRICTION => Effect::StribeckFriction {
            state: vel,
            level: a,
            static_level: a * fr.static_ratio,
            stribeck_velocity: fr.stribeck_frac * fr.v_rms,
            viscous: 0.0,
        },
        names::ASYMMETRIC_COULOMB => {
            let (up, down) = if fr.asym_up { (a, a * fr.asym_ratio) } else { (a * fr.asym_ratio, a) };
            Effect::AsymmetricCoulomb { state: vel, level_positive: up, level_negative: down }
        }
        names::COGGING => Effect::Cogging {
            state: vel,
            position_state: 0,
            amplitude: a,
            period: fr.pos_range / fr.cog_periods,
            phase: fr.cog_phase,
        },
        names::BACKLASH => Effect::Backlash { width: a, location: PlayLocation::Loop },
        names::GAP_WIDTH => Effect::GapWidth { relative_change: a },
        names::COULOMB_FRICTION => Effect::CoulombFriction { state: vel, level: a },
        names::CONSTANT_FORCE => Effect::ConstantForce { state: vel, force: sign * a },
        names::BACKLASH_INERTIA => Effect::BacklashInertia { mass: a, damping: 1.0 },
        names::INPUT_DELAY => Effect::InputDelay { delay: a },
        names::INPUT_SATURATION => Effect::InputSaturation { limit: wmax / (1.0 + a) },
        names::SENSOR_OFFSET => Effect::SensorOffset { offset: vec![sign * a] },
        _ => return None,
    })
}

fn fit_percent(a: &[f64], b: &[f64]) -> f64 {
    let mean = a.iter().sum::<f64>() / a.len() as f64;
    let num = a.iter().zip(b).map(|(x, y)| (x - y).powi(2)).sum::<f64>().sqrt();
    let den = a.iter().map(|x| (x - mean).powi(2)).sum::<f64>().sqrt();
    100.0 * (1.0 - num / den)
}

impl FrictionShape {
    /// The friction library's shape draws (a stream of their own, seeded from the case's
    /// `mix`); the nominal run's scales are set after it.
    fn draw(mix: u64) -> Self {
        let mut rf = ChaCha8Rng::seed_from_u64(mix ^ 0xF41C_7100_0000_0002);
        FrictionShape {
            static_ratio: rf.random_range(1.8..3.0),
            stribeck_frac: rf.random_range(0.05..0.25),
            asym_ratio: rf.random_range(0.2..0.6),
            asym_up: rf.random::<bool>(),
            cog_periods: rf.random_range(3.0..10.0),
            cog_phase: rf.random_range(0.0..TAU),
            v_rms: 0.0,
            pos_range: 0.0,
        }
    }
}

/// The sampling of a case: its period (`None`: 60 samples per natural period), the natural
/// frequency and damping that replace the plant's, what the plant sees of the command, and the
/// AR(1) coefficient of the noise (0 = white).
struct Sampling {
    dt: Option<f64>,
    over: Option<(f64, f64)>,
    drive: Drive,
    noise_rho: f64,
}

/// The sampling of `profile`. The digital and mixed profiles draw from a second stream (the
/// classic stream is untouched; the mixed profile's drive from a third, so that its other draws
/// are the digital profile's with the wider range of sample periods).
fn sampling(profile: Profile, mix: u64) -> Sampling {
    let (lo, hi) = match profile {
        Profile::Classic => return Sampling { dt: None, over: None, drive: Drive::Continuous, noise_rho: 0.0 },
        Profile::Digital => (1e-3f64, 1e-2f64),
        Profile::Mixed => (5e-4f64, 2e-2f64),
    };
    let mut rd = ChaCha8Rng::seed_from_u64(mix ^ 0xD161_7A1D_0000_0001);
    let dt = (rd.random_range(lo.ln()..hi.ln())).exp();
    let spp: f64 = rd.random_range(30.0..100.0);
    let light = rd.random::<bool>();
    let zeta = if light { rd.random_range(0.03..0.1) } else { rd.random_range(0.1..0.7) };
    let noise_rho = if rd.random::<bool>() { rd.random_range(0.5..0.9) } else { 0.0 };
    let drive = match profile {
        Profile::Mixed => match ChaCha8Rng::seed_from_u64(mix ^ 0xD41F_E000_0000_0003).random_range(0..3) {
            0 => Drive::Continuous,
            1 => Drive::Held(InputHold::Zoh),
            _ => Drive::Held(InputHold::Foh),
        },
        _ => Drive::Held(InputHold::Zoh),
    };
    Sampling { dt: Some(dt), over: Some((TAU / (spp * dt), zeta)), drive, noise_rho }
}

/// `ns` samples of measurement noise of standard deviation `std`: white, or AR(1) with
/// coefficient `rho > 0` and the same stationary variance.
fn measurement_noise(rng: &mut ChaCha8Rng, ns: usize, std: f64, rho: f64) -> Vec<f64> {
    let mut noise: Vec<f64> = (0..ns).map(|_| gauss(rng) * std).collect();
    if rho > 0.0 {
        // AR(1) with the same stationary variance: e_k = rho e_{k-1} + sqrt(1 - rho^2) v_k.
        let c = (1.0 - rho * rho).sqrt();
        let mut e = noise[0];
        for v in noise.iter_mut().skip(1) {
            e = rho * e + c * *v;
            *v = e;
        }
    }
    noise
}

/// The magnitude of the concealed effect of `class` at which the nominal model's fit
/// (`fit_at(a)`) drops to `target`: grown until the fit drops below the target, then bisected
/// (`backlash_inertia` capped at half a natural `period`).
fn truth_magnitude(class: &str, fit_at: impl Fn(f64) -> f64, target: f64, period: f64, ystd: f64) -> f64 {
    let mut hi = match class {
        names::INPUT_DELAY => 0.02 * period,
        names::BACKLASH_INERTIA => 0.02 * period,
        names::GAP_WIDTH => 0.5,
        names::INPUT_SATURATION => 0.05,
        _ => 0.02 * ystd,
    };
    let mut lo = 0.0;
    let mut guard = 0;
    let cap = if class == names::BACKLASH_INERTIA { 0.5 * period } else { f64::INFINITY };
    while fit_at(hi) > target && guard < 40 && hi < cap {
        lo = hi;
        hi *= 1.6;
        guard += 1;
    }
    for _ in 0..30 {
        let mid = 0.5 * (lo + hi);
        if fit_at(mid) > target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (0.5 * (lo + hi)).min(cap)
}

/// Generates case number `index` of `class` from `seed` (classic profile).
pub fn generate(class: &'static str, seed: u64, index: usize) -> Case {
    generate_profile(class, seed, index, Profile::Classic)
}

/// Generates case number `index` of `class` from `seed` in `profile`.
pub fn generate_profile(class: &'static str, seed: u64, index: usize, profile: Profile) -> Case {
    generate_classes(&[class], seed, index, profile, forced_signal(), next_requested())
}

/// [`generate_profile`] with the machine's next experiment ([`Case::next`]) whatever
/// `BENCH_NEXT` says.
pub fn generate_with_next(class: &'static str, seed: u64, index: usize, profile: Profile) -> Case {
    generate_classes(&[class], seed, index, profile, forced_signal(), true)
}

/// [`generate_profile`] with the input `input` in place of the drawn one (and of
/// `BENCH_SIGNAL`'s).
pub fn generate_with_input(class: &'static str, seed: u64, index: usize, profile: Profile, input: ForcedInput) -> Case {
    generate_classes(&[class], seed, index, profile, Some(input), next_requested())
}

/// Whether two classes can be concealed in one recording by [`generate_pair`]: distinct, not
/// `none`, not two frictions, and neither a concealed backlash with a change of the nominal's
/// play (gap width, backlash inertia: a concealed backlash means the nominal has no play).
pub fn pair_compatible(a: &str, b: &str) -> bool {
    let friction = |c: &str| c == names::COULOMB_FRICTION || FRICTION_CLASSES.contains(&c);
    let play = |c: &str| c == names::GAP_WIDTH || c == names::BACKLASH_INERTIA;
    a != b
        && a != NONE
        && b != NONE
        && !(friction(a) && friction(b))
        && !((a == names::BACKLASH && play(b)) || (b == names::BACKLASH && play(a)))
        && all_classes().contains(&a)
        && all_classes().contains(&b)
}

/// Every pair of [`CLASSES`] that [`pair_compatible`] allows (each once, in class order).
pub fn pairs() -> Vec<[&'static str; 2]> {
    let mut v = Vec::new();
    for (i, &a) in CLASSES.iter().enumerate() {
        for &b in &CLASSES[i + 1..] {
            if pair_compatible(a, b) {
                v.push([a, b]);
            }
        }
    }
    v
}

/// Generates case number `index` with two concealed effects at once (issue 27 item 4), each
/// of a magnitude that alone drops the nominal fit to its own target in [86, 94] %; the
/// plant, input and noise are drawn as for the first class alone. `None` where the pair is not
/// [`pair_compatible`].
pub fn generate_pair(pair: [&'static str; 2], seed: u64, index: usize, profile: Profile) -> Option<Case> {
    pair_compatible(pair[0], pair[1])
        .then(|| generate_classes(&pair, seed, index, profile, forced_signal(), next_requested()))
}

/// Generates case number `index` concealing every class of `classes` (one, or a pair) from
/// `seed` in `profile`. One class draws exactly what it always did; the second of a pair takes
/// its target and sign from a stream of its own. `input` replaces the drawn input kind; `next`
/// also records the machine's next experiment.
fn generate_classes(
    classes: &[&'static str],
    seed: u64,
    index: usize,
    profile: Profile,
    input: Option<ForcedInput>,
    next: bool,
) -> Case {
    let class = classes[0];
    let mix = case_mix(classes, seed, index);
    let has = |c: &str| classes.contains(&c);
    let mut rng = ChaCha8Rng::seed_from_u64(mix);
    let mut fshape = FrictionShape::draw(mix);
    let Sampling { dt: dig_dt, over, drive, noise_rho } = sampling(profile, mix);
    let n = rng.random_range(2..=4);
    let plant = random_plant(&mut rng, n, over);
    let tau_slow = slowest_time_constant(&plant);
    let period = TAU / plant.omega0;
    let dt = dig_dt.unwrap_or(period / 60.0);
    let duration = (10.0 * tau_slow).max(25.0 * period).min(80.0 * period) * length_factor();
    let ns = (duration / dt) as usize + 1;
    let (signal, sig_name) = random_signal(&mut rng, plant.omega0, duration);
    let (signal, sig_name) = match input {
        Some(f) => forced(f, mix, plant.omega0, duration, dt),
        None => (signal, sig_name),
    };
    let t: Vec<f64> = (0..ns).map(|k| k as f64 * dt).collect();
    let w: Vec<f64> = t.iter().map(|&tk| signal.eval(tk)).collect();
    let wmax = w.iter().map(|v| v.abs()).fold(0.0, f64::max);
    let nominal_has_play = !has(names::BACKLASH);
    let mut plant = plant;
    if has(names::BACKLASH_INERTIA) {
        // Coasting is bounded by the gap: the effect needs a play wide enough to be seen, and
        // its time constant is capped at half a natural period (see the bisection below).
        plant.half_width = rng.random_range(0.15..0.3);
    }
    let mut x0 = vec![0.0; n];
    x0[0] = rng.random_range(-0.3..0.3);
    let sign = if rng.random::<bool>() { 1.0 } else { -1.0 };
    let target: f64 = rng.random_range(86.0..94.0);
    let hw_nom = if nominal_has_play { plant.half_width } else { 0.0 };
    let clean_nom = plant_sim::simulate(&plant, hw_nom, None, &signal, &x0, dt, ns, drive);
    let ystd = {
        let m = clean_nom.iter().sum::<f64>() / ns as f64;
        (clean_nom.iter().map(|v| (v - m).powi(2)).sum::<f64>() / ns as f64).sqrt()
    };
    (fshape.v_rms, fshape.pos_range) = speed_and_range(&clean_nom, dt);
    // The effects' magnitudes are set against the default noise level; the recording carries
    // the same noise scaled to `noise_db` (exactly the default's at -30 dB).
    let noise_std = ystd * 10f64.powf(-30.0 / 20.0);
    let noise = measurement_noise(&mut rng, ns, noise_std, noise_rho);
    let noise_scale = 10f64.powf((noise_db() + 30.0) / 20.0);
    let measure_all = |effs: &[&Effect]| -> Vec<f64> {
        plant_sim::simulate_effects(&plant, hw_nom, effs, &signal, &x0, dt, ns, drive)
            .iter()
            .zip(&noise)
            .map(|(a, b)| a + b)
            .collect()
    };
    let truths =
        true_effects(classes, mix, (target, sign), wmax, plant.vel, &fshape, &measure_all, &clean_nom, period, ystd);
    let truth = truths.first().cloned();
    let machine = Machine { plant: &plant, hw_nom, effs: truths.iter().collect(), x0: &x0, dt, ns, drive };
    let clean = machine.clean(&signal, noise_std * noise_scale);
    let y: Vec<f64> = clean.iter().zip(&noise).map(|(a, b)| a + b * noise_scale).collect();
    let nominal_fit = fit_percent(&y, &clean_nom);
    let name = format!("bench {} #{index} (n = {n})", classes.join("+"));
    let nominal = nominal_system(name, &plant, nominal_has_play, &x0, dt, duration);
    let label = format!("bench-{}-{index}", classes.join("+"));
    let recording = recording_of(&label, &t, &w, &y);
    let next = next.then(|| machine.next_experiment(&label, mix, duration, noise_std * noise_scale, noise_rho));
    let conditions = Conditions { profile, hold: drive.name(), dt, noise_rho, omega0: plant.omega0, zeta: plant.zeta };
    let description = format!(
        "n = {n}, omega0 = {:.2}, zeta = {:.2}, input {sig_name}, {ns} samples, {}, nominal fit {nominal_fit:.1} %",
        plant.omega0,
        plant.zeta,
        conditions.short()
    );
    Case {
        class,
        nominal,
        truth,
        truths,
        classes: classes.to_vec(),
        recording,
        nominal_fit,
        description,
        conditions,
        next,
    }
}

/// The recording `label` of command samples `w` and measured outputs `y` at times `t`.
fn recording_of(label: &str, t: &[f64], w: &[f64], y: &[f64]) -> Recording {
    Recording::from_samples(label, t, w.iter().map(|v| vec![*v]).collect(), y.iter().map(|v| vec![*v]).collect(), None)
}

/// The true machine of a case: the plant, the nominal's play, the concealed effects, the
/// initial state, what the plant sees of the command, and the recording's sampling.
struct Machine<'a> {
    plant: &'a Plant,
    hw_nom: f64,
    effs: Vec<&'a Effect>,
    x0: &'a [f64],
    dt: f64,
    ns: usize,
    drive: Drive,
}

impl Machine<'_> {
    /// The clean output under `signal`. The effects' magnitudes are set on the 20-per-sample
    /// grid; a recording's truth is converged to a tenth of a sigma of any fitted parameter
    /// (white-noise count of samples) for measurement noise of standard deviation `noise_std`
    /// (unless [`converged_truth`] is off).
    fn clean(&self, signal: &Signal, noise_std: f64) -> Vec<f64> {
        let (pl, hw, effs, x0, dt, ns, drive) =
            (self.plant, self.hw_nom, &self.effs, self.x0, self.dt, self.ns, self.drive);
        if converged_truth() {
            let tol = 0.1 * noise_std / (ns as f64).sqrt();
            plant_sim::simulate_converged(pl, hw, effs, signal, x0, dt, ns, drive, tol).0
        } else {
            plant_sim::simulate_effects(pl, hw, effs, signal, x0, dt, ns, drive)
        }
    }

    /// The machine's next experiment ([`NextExperiment`]): an input of the same families drawn
    /// afresh, and new measurement noise of the same standard deviation `noise_std` and AR(1)
    /// colour `rho`, both from a stream of their own (the first recording's draws stay as
    /// they were), over the same `duration`.
    fn next_experiment(&self, label: &str, mix: u64, duration: f64, noise_std: f64, rho: f64) -> NextExperiment {
        let mut rng = ChaCha8Rng::seed_from_u64(mix ^ 0x4E58_7E59_0000_0002);
        let (signal, input) = random_signal(&mut rng, self.plant.omega0, duration);
        let noise = measurement_noise(&mut rng, self.ns, noise_std, rho);
        let t: Vec<f64> = (0..self.ns).map(|k| k as f64 * self.dt).collect();
        let w: Vec<f64> = t.iter().map(|&tk| signal.eval(tk)).collect();
        let clean = self.clean(&signal, noise_std);
        let y: Vec<f64> = clean.iter().zip(&noise).map(|(a, b)| a + b).collect();
        NextExperiment { recording: recording_of(&format!("{label}-next"), &t, &w, &y), clean, input }
    }
}

/// The seed of case `index` of `classes` from `seed`: one class draws what it always did; the
/// second of a pair is mixed in above bit 48.
fn case_mix(classes: &[&'static str], seed: u64, index: usize) -> u64 {
    let class_index = all_classes().iter().position(|c| *c == classes[0]).unwrap_or(0);
    let mut mix = seed ^ (0x9E37_79B9_7F4A_7C15u64.wrapping_mul(index as u64 + 1)) ^ (class_index as u64) << 40;
    if let Some(&second) = classes.get(1) {
        let i2 = all_classes().iter().position(|c| *c == second).unwrap_or(0);
        mix ^= (i2 as u64 + 1) << 48;
    }
    mix
}

/// Each class's true effect, its magnitude set alone so that the nominal model fits the noisy
/// recording to the class's target (the first class's `(target, sign)` as drawn; the second of
/// a pair draws its own from a stream of its own). `measure_all` simulates the plant with the
/// given effects and adds the noise; `clean_nom` is the nominal model's clean output.
#[allow(clippy::too_many_arguments)]
fn true_effects(
    classes: &[&'static str],
    mix: u64,
    (target, sign): (f64, f64),
    wmax: f64,
    vel: usize,
    fshape: &FrictionShape,
    measure_all: &dyn Fn(&[&Effect]) -> Vec<f64>,
    clean_nom: &[f64],
    period: f64,
    ystd: f64,
) -> Vec<Effect> {
    let mut r2 = ChaCha8Rng::seed_from_u64(mix ^ 0x7A1B_0000_0000_0027);
    classes
        .iter()
        .enumerate()
        .filter_map(|(i, &c)| {
            let (target, sign) = if i == 0 {
                (target, sign)
            } else {
                (r2.random_range(86.0..94.0), if r2.random::<bool>() { 1.0 } else { -1.0 })
            };
            let fit_at = |a: f64| {
                let e = effect_at(c, a, sign, wmax, vel, fshape);
                fit_percent(&measure_all(e.iter().collect::<Vec<_>>().as_slice()), clean_nom)
            };
            let a = if c == NONE { 0.0 } else { truth_magnitude(c, fit_at, target, period, ystd) };
            effect_at(c, a, sign, wmax, vel, fshape)
        })
        .collect()
}

/// The slowest time constant of the plant with the play closed (`1 / |max Re eig(A + E C)|`).
fn slowest_time_constant(plant: &Plant) -> f64 {
    let F = &plant.A + &plant.E * &plant.C;
    let mu = F.complex_eigenvalues().iter().map(|c| c.re).fold(f64::NEG_INFINITY, f64::max);
    1.0 / mu.abs()
}

/// The velocity (RMS of the central difference) and position (range) scales of a position
/// record `y` sampled at `dt`.
fn speed_and_range(y: &[f64], dt: f64) -> (f64, f64) {
    let ns = y.len();
    let v_rms =
        ((1..ns - 1).map(|k| ((y[k + 1] - y[k - 1]) / (2.0 * dt)).powi(2)).sum::<f64>() / (ns - 2) as f64).sqrt();
    let range = y.iter().copied().fold(f64::NEG_INFINITY, f64::max) - y.iter().copied().fold(f64::INFINITY, f64::min);
    (v_rms, range)
}

/// The nominal model file of a case: the plant, its play where the nominal has one (else
/// none), the true initial state, and simulation defaults over the record's duration.
fn nominal_system(name: String, plant: &Plant, has_play: bool, x0: &[f64], dt: f64, duration: f64) -> System {
    let theta = if has_play {
        geometry::Shape::Interval(geometry::Interval::symmetric(plant.half_width).expect("positive half-width"))
    } else {
        geometry::Shape::origin(1)
    };
    let x0v = DVector::from_column_slice(x0);
    let z0 = &plant.C * &x0v;
    System::builder()
        .name(name)
        .A(plant.A.clone())
        .B(plant.B.clone())
        .C(plant.C.clone())
        .E(plant.E.clone())
        .theta(theta)
        .input(Input::Sine { amplitudes: vec![1.0], omega: plant.omega0, phase: 0.0 })
        .x0(x0v)
        .z0(z0)
        .sim(SimDefaults { dt, periods: 20, t_end: Some(duration) })
        .build()
        .expect("generated plant is valid")
}

/// A standard normal sample (Box-Muller).
pub(crate) fn gauss(rng: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = rng.random::<f64>().max(1e-300);
    let u2: f64 = rng.random();
    (-2.0 * u1.ln()).sqrt() * (TAU * u2).cos()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn random_steps_change_on_samples_and_dwell_one_to_six_periods() {
        let (w0, dt) = (30.0, 2.3e-3);
        let (Signal::Steps { edges, v }, name) = forced(ForcedInput::Steps, 7, w0, 5.0, dt) else {
            panic!("steps expected")
        };
        assert_eq!(name, "random steps");
        let period = TAU / w0;
        assert!(edges.len() > 3 && *edges.last().unwrap() >= 5.0, "{edges:?}");
        for (i, pair) in edges.windows(2).enumerate() {
            // on the sample grid, computed as the sample times are
            let k = (pair[1] / dt).round() as usize;
            assert_eq!(pair[1], k as f64 * dt);
            let dwell = pair[1] - pair[0];
            assert!(dwell >= period - dt && dwell <= 6.0 * period + dt, "dwell {dwell} of period {period}");
            // the new level from the edge on, the old one just before
            let s = Signal::Steps { edges: edges.clone(), v: v.clone() };
            assert_eq!(s.eval(pair[1]), v[i + 1]);
            assert_eq!(s.eval(pair[1] - 0.5 * dt), v[i]);
        }
        assert!(v.iter().all(|x| (-1.0..=1.0).contains(x)));
    }

    #[test]
    fn the_chirp_sweeps_from_its_low_to_its_high_frequency() {
        let (Signal::Chirp { a, omega_lo, omega_hi, duration }, _) = forced(ForcedInput::Chirp, 7, 30.0, 10.0, 1e-3)
        else {
            panic!("chirp expected")
        };
        assert!(omega_lo < 30.0 * 0.15 && omega_hi > 30.0 * 1.2 && duration == 10.0);
        let s = Signal::Chirp { a: 1.0, omega_lo, omega_hi, duration };
        // the frequency from the time between upward zero crossings, at the start and after
        // the sweep (held at its top)
        let crossings = |t0: f64, t1: f64| -> Vec<f64> {
            let n = ((t1 - t0) / 1e-5) as usize;
            (0..n).map(|i| t0 + i as f64 * 1e-5).filter(|&t| s.eval(t) <= 0.0 && s.eval(t + 1e-5) > 0.0).collect()
        };
        let early = crossings(0.0, 4.0 * TAU / omega_lo);
        let late = crossings(duration, duration + 4.0 * TAU / omega_hi);
        let freq = |c: &[f64]| TAU / (c[1] - c[0]);
        // log sweep: omega(t) = omega_lo (omega_hi / omega_lo)^(t / duration), at the first
        // period's middle
        let mid = 0.5 * (early[0] + early[1]);
        let expected = omega_lo * (omega_hi / omega_lo).powf(mid / duration);
        assert!((freq(&early) / expected - 1.0).abs() < 0.02, "{} vs {expected}", freq(&early));
        assert!((freq(&late) / omega_hi - 1.0).abs() < 1e-3, "{} vs {omega_hi}", freq(&late));
        assert!(a > 0.0 && a <= 1.0);
    }
}
