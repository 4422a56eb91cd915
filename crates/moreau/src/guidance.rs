//! Design guidance when `moreau theta` certifies nothing: which term of eq. (theta) blocks, how
//! the best verified bound moves with the input's amplitude and frequency and with Theta's
//! scale, and the smallest amplitude that certifies (found by bisection, each reported point
//! itself certified by a full bound computation).
//!
//! What blocks. `theta* = (1 - kappa*) psi(0) + kappa* psi(gamma_inf)` (eq. (theta) with the
//! strongest path bound) is negative iff `psi(gamma_inf) < 0` and
//! `kappa* > kappa_needed = psi(0) / (psi(0) - psi(gamma_inf))`. `psi(0) >= 0` always
//! (proofs-notes/psi0.md), so the backlash must move: `kappa*` (path per period against the top
//! speed) is the lever, the coupling (`beta` against `lambda`) sets the bar. For a sine input,
//! as the amplitude grows `kappa*` tends to at most `2/pi` (the path of two half swings against
//! the top speed of an ellipse) and `psi(gamma_inf)` to `-lambda`, so a large enough amplitude
//! certifies when `(1 - 2/pi) psi(0) - (2/pi) lambda < 0` at some certified `(lambda, b_hat)`.
use crate::sweep::axis::{apply_all, Parameter};
use bounds::report::fmt_value as v;
use bounds::{assemble_memo, Memo, Psi, ThetaReport, ThetaSettings};
use model::{Input, System};
use std::cell::RefCell;

/// Settings of [`guidance`].
#[derive(Debug, Clone)]
pub struct GuidanceSettings {
    /// Relative step of the finite differences (`x -> x e^{+-h}`). Default `ln 1.1`.
    pub step: f64,
    /// Largest amplitude factor tried. Default `4096`.
    pub max_factor: f64,
    /// Bisection steps after bracketing. Default `10`.
    pub bisection_steps: usize,
}

impl Default for GuidanceSettings {
    fn default() -> Self {
        Self { step: 1.1f64.ln(), max_factor: 4096.0, bisection_steps: 10 }
    }
}

/// `d theta_best / d ln x` by central differences.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Sensitivity {
    /// `input.amplitude`, `input.omega` or `theta.scale`.
    pub parameter: &'static str,
    pub derivative: f64,
}

/// The smallest amplitude factor found that certifies.
#[derive(Debug, Clone, serde::Serialize)]
pub struct AmplitudeSearch {
    /// Every amplitude multiplied by `factor`.
    pub factor: f64,
    pub amplitudes: Vec<f64>,
    /// The best verified bound there and its method.
    pub theta_best: f64,
    pub method: &'static str,
    /// Largest factor tried that does not certify (the bracket's lower end).
    pub below: f64,
    pub evaluations: usize,
}

/// Design guidance for one model (see the module docs).
#[derive(Debug, Clone, serde::Serialize)]
pub struct Guidance {
    pub kappa_star: f64,
    /// `psi(0) / (psi(0) - psi(gamma_inf))`, or `inf` when `psi(gamma_inf) >= 0`.
    pub kappa_needed: f64,
    /// What blocks, in words.
    pub blocking: String,
    /// `min over the certified curve of (1 - 2/pi) psi(0) - (2/pi) lambda` (sine inputs): the
    /// limit of `theta*` for large amplitudes.
    pub large_amplitude_limit: Option<f64>,
    pub sensitivities: Vec<Sensitivity>,
    pub amplitude: Option<AmplitudeSearch>,
    pub notes: Vec<String>,
}

/// The bound computations of the guidance: every model varies the input or Theta, never `F`, `E`,
/// `C`, so one memo serves their lambda searches (bounds::assemble_memo).
struct Bounds<'m>(RefCell<&'m mut Memo>);

impl Bounds<'_> {
    fn report(&self, sys: &System) -> Option<ThetaReport> {
        assemble_memo(sys, &ThetaSettings::bound_only(), &mut self.0.borrow_mut()).ok()
    }

    fn certifies(&self, sys: &System) -> Option<(f64, &'static str)> {
        let r = self.report(sys)?;
        Some((r.theta_best, r.theta_best_method)).filter(|(t, _)| r.theta_best_verified && *t < 0.0)
    }
}

fn amplitudes(sys: &System) -> Option<&[f64]> {
    sys.input.wave().map(|(amplitudes, _, _)| amplitudes)
}

fn with_amplitude_factor(sys: &System, f: f64) -> Option<System> {
    let a = amplitudes(sys)?.to_vec();
    let params: Vec<Parameter> = (0..a.len()).map(|k| Parameter::InputAmplitude { component: Some(k) }).collect();
    let settings: Vec<(&Parameter, f64)> = params.iter().zip(&a).map(|(p, v)| (p, v * f)).collect();
    apply_all(sys, &settings).ok()
}

fn with(sys: &System, p: Parameter, value: f64) -> Option<System> {
    apply_all(sys, &[(&p, value)]).ok()
}

/// Guidance for `sys` whose report is `rep` (meant for reports without a certificate; it
/// also runs on certified ones). `memo` may hold what `rep`'s own computation left
/// (bounds::Memo): every bound computed here is for the same `F`, `E`, `C`.
pub fn guidance(sys: &System, rep: &ThetaReport, s: &GuidanceSettings, memo: &mut Memo) -> Guidance {
    let bounds = Bounds(RefCell::new(memo));
    let mut notes = Vec::new();
    let psi = Psi { alpha: rep.alpha.lower, lambda: rep.lambda_star, beta: rep.beta_star };
    let (p0, pinf) = (psi.at_zero(), psi.eval(rep.gamma_inf));
    let kappa_needed = if pinf < 0.0 { p0 / (p0 - pinf) } else { f64::INFINITY };
    let blocking = blocking_reason(rep, p0, pinf, kappa_needed);
    let large_amplitude_limit = large_amplitude_limit(sys, rep);
    let sensitivities = sensitivities(sys, s, &bounds, &mut notes);
    let amplitude = if rep.R.is_finite() && amplitudes(sys).is_some() && rep.effects.is_empty() {
        amplitude_search(sys, s, &bounds, &mut notes)
    } else {
        None
    };
    Guidance {
        kappa_star: rep.kappa_star,
        kappa_needed,
        blocking,
        large_amplitude_limit,
        sensitivities,
        amplitude,
        notes,
    }
}

/// What stands between the report and a certificate (`p0 = psi(0)`, `pinf = psi(gamma_inf)`,
/// `kappa_needed` the least `kappa*` that makes `theta*` negative).
fn blocking_reason(rep: &ThetaReport, p0: f64, pinf: f64, kappa_needed: f64) -> String {
    if !rep.R.is_finite() {
        "Theta is not strongly convex (R infinite): gamma = 0 and theta = psi(0) >= 0 for every admissible Pi; no bound of this kind can certify (proofs-notes/psi0.md)".to_string()
    } else if pinf >= 0.0 {
        format!(
            "psi(gamma_inf) = {} >= 0: even the top backlash speed the bound allows (gamma_inf = {}) does not make psi negative; the coupling (beta = {} against lambda = {}) needs faster motion (amplitude, omega) or a more curved Theta (smaller R)",
            v(pinf), v(rep.gamma_inf), v(rep.beta_star), v(rep.lambda_star)
        )
    } else if rep.kappa_star < kappa_needed {
        format!(
            "the backlash moves too little per period against its top speed: kappa* = {} (path bound / (T R gamma_inf)) but theta* < 0 needs kappa* > psi(0)/(psi(0) - psi(gamma_inf)) = {} (psi(0) = {}, set by beta = {} against lambda = {})",
            v(rep.kappa_star), v(kappa_needed), v(p0), v(rep.beta_star), v(rep.lambda_star)
        )
    } else {
        "theta* < 0 at these values; the best bound is certified".to_string()
    }
}

/// Under a sine input with Theta strongly convex: the least over the report's curve of
/// `(1 - 2/pi) psi(0) - (2/pi) lambda`, the limit of theta at large amplitude.
fn large_amplitude_limit(sys: &System, rep: &ThetaReport) -> Option<f64> {
    match (&sys.input, rep.R.is_finite()) {
        (Input::Sine { .. }, true) => {
            let k = 2.0 / std::f64::consts::PI;
            rep.curve
                .iter()
                .map(|&(l, b, _)| {
                    let p = Psi { alpha: rep.alpha.lower, lambda: l, beta: b };
                    (1.0 - k) * p.at_zero() - k * l
                })
                .reduce(f64::min)
        }
        _ => None,
    }
}

/// Sensitivities of the best verified bound (or of theta when none is verified) to the input's
/// amplitude and frequency and to Theta's scale: central differences in the logarithm.
fn sensitivities(sys: &System, s: &GuidanceSettings, bounds: &Bounds, notes: &mut Vec<String>) -> Vec<Sensitivity> {
    let mut sensitivities = Vec::new();
    let value = |sys: &System| bounds.report(sys).map(|r| r.theta_best);
    let h = s.step;
    let (up, dn) = (h.exp(), (-h).exp());
    let mut push = |name: &'static str, a: Option<System>, b: Option<System>| {
        if let (Some(a), Some(b)) = (a.as_ref().and_then(value), b.as_ref().and_then(value)) {
            sensitivities.push(Sensitivity { parameter: name, derivative: (a - b) / (2.0 * h) });
        }
    };
    if amplitudes(sys).is_some() {
        push("input.amplitude", with_amplitude_factor(sys, up), with_amplitude_factor(sys, dn));
        if let Some((_, omega, _)) = sys.input.wave() {
            push(
                "input.omega",
                with(sys, Parameter::InputOmega, omega * up),
                with(sys, Parameter::InputOmega, omega * dn),
            );
        }
    } else {
        notes.push("the input is not a sine, square wave or multisine: amplitude and frequency are not varied".into());
    }
    push("theta.scale", with(sys, Parameter::ThetaScale, up), with(sys, Parameter::ThetaScale, dn));
    sensitivities
}

/// Smallest amplitude factor that certifies: bracketed by doubling (or, already certified, by
/// halving), then bisected in the logarithm. `None` for an input without amplitudes.
fn amplitude_search(
    sys: &System,
    s: &GuidanceSettings,
    bounds: &Bounds,
    notes: &mut Vec<String>,
) -> Option<AmplitudeSearch> {
    let base = amplitudes(sys)?.to_vec();
    let mut evaluations = 0;
    let mut eval = |f: f64| {
        evaluations += 1;
        with_amplitude_factor(sys, f).as_ref().and_then(|s| bounds.certifies(s))
    };
    let (mut lo, mut hi) = (1.0f64, None);
    if let Some(v) = bounds.certifies(sys) {
        notes.push(
            "already certified: the amplitude search looks for the smallest factor <= 1 that still certifies".into(),
        );
        let mut f = 1.0;
        hi = Some((1.0, v));
        lo = f64::NAN;
        while f > 1.0 / s.max_factor {
            f *= 0.5;
            match eval(f) {
                Some(v) => hi = Some((f, v)),
                None => {
                    lo = f;
                    break;
                }
            }
        }
        if lo.is_nan() {
            notes.push(format!("every factor down to 1/{} certifies", s.max_factor));
            hi = None;
        }
    } else {
        let mut f = 1.0;
        while f < s.max_factor {
            f *= 2.0;
            match eval(f) {
                Some(v) => {
                    hi = Some((f, v));
                    break;
                }
                None => lo = f,
            }
        }
    }
    let Some(mut best) = hi else {
        if !lo.is_nan() {
            notes.push(format!("no amplitude factor up to {} certifies", s.max_factor));
        }
        return None;
    };
    for _ in 0..s.bisection_steps {
        let mid = (lo * best.0).sqrt();
        match eval(mid) {
            Some(v) => best = (mid, v),
            None => lo = mid,
        }
    }
    let a = base.iter().map(|x| x * best.0).collect();
    Some(AmplitudeSearch {
        factor: best.0,
        amplitudes: a,
        theta_best: best.1 .0,
        method: best.1 .1,
        below: lo,
        evaluations,
    })
}

impl Guidance {
    /// Readable lines (printed under the verdict).
    pub fn render(&self) -> String {
        let mut s = String::from("Design guidance:\n");
        s.push_str(&format!("  what blocks: {}\n", self.blocking));
        if let Some(l) = self.large_amplitude_limit {
            s.push_str(&format!(
                "  large amplitudes: theta* tends to (1 - 2/pi) psi(0) - (2/pi) lambda = {} at best ({})\n",
                v(l),
                if l < 0.0 { "a large enough amplitude certifies" } else { "no amplitude certifies through theta*" }
            ));
        }
        if !self.sensitivities.is_empty() {
            let parts: Vec<String> =
                self.sensitivities.iter().map(|x| format!("{} {}", x.parameter, v(x.derivative))).collect();
            s.push_str(&format!("  d theta_best / d ln(x), +-10 %: {}\n", parts.join(", ")));
        }
        if let Some(a) = &self.amplitude {
            s.push_str(&format!(
                "  smallest amplitude that certifies: x {} (amplitudes {}) gives {} = {} (verified); x {} does not ({} bound computations)\n",
                v(a.factor),
                a.amplitudes.iter().map(|x| v(*x)).collect::<Vec<_>>().join(", "),
                a.method,
                v(a.theta_best),
                v(a.below),
                a.evaluations
            ));
        }
        for n in &self.notes {
            s.push_str(&format!("  note: {n}\n"));
        }
        s
    }
}
