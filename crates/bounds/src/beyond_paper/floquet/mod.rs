//! A verified enclosure of the periodic regime (p = 1, `Theta = [lo, hi]` (or a ball or an
//! ellipsoid in R^1, faces enclosed), sine input) and of
//! its Floquet exponent `ln rho(M) / T` (the local convergence exponent of trajectories near
//! the regime), with no simulation in the claim (proofs-notes/floquet-enclosure.md).
//!
//! Pipeline ([`floquet_enclosure`]), one stage per module:
//! 1. [`phases`]: the switching structure read from a simulated regime (a hypothesis);
//! 2. [`period_map`]: Newton on the multiple-shooting form of the period map, then the
//!    Krawczyk test on a box around the result: exactly one zero in the box;
//! 3. [`switching`]: the phase conditions over the box (transversal contacts and releases,
//!    `q` inside `Theta` while resting, `y'` pushing while engaged): the zero is the regime and
//!    its phase sequence is the one assumed;
//! 4. [`monodromy`]: saltation matrices and phase exponentials, the spectral radius enclosed.
//!
//! The flows of the phases are matrix exponentials of the plant augmented by the sine's
//! exosystem ([`flow`]), in interval arithmetic with outward rounding ([`rounding::Ival`],
//! [`imat`]). `verified` is true only when every stage proved its part; otherwise the reason
//! says which failed, and the exponent (if any) is a floating-point estimate.
// `!(x > 0.0)` is deliberate (true for NaN, which must never pass); index loops mirror the
// formulas; the failure carries the partial result on purpose.
#![allow(clippy::neg_cmp_op_on_partial_ord, clippy::needless_range_loop, clippy::result_large_err)]

pub mod flow;
pub mod imat;
pub mod monodromy;
pub mod period_map;
pub mod phases;
pub mod switching;

use flow::{Face, Generators, PhaseKind};
use geometry::Shape;
use model::{Input, System};
use period_map::{KrawczykVerdict, Shooting};
pub use phases::PhaseStructure;
pub use rounding::Ival;
use serde::Serialize;

/// Settings of the enclosure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FloquetSettings {
    /// Most periods simulated to find the regime's structure. Default `400`.
    pub max_periods: usize,
    /// Relative radii tried for the Krawczyk box, smallest first. Default `[1e-10, 1e-8, 1e-6]`.
    pub box_radii: [f64; 3],
    /// Most Newton iterations. Default `40`.
    pub max_newton: usize,
}

impl Default for FloquetSettings {
    fn default() -> Self {
        Self { max_periods: 400, box_radii: [1e-10, 1e-8, 1e-6], max_newton: 40 }
    }
}

impl FloquetSettings {
    pub fn validate(&self) -> Result<(), FloquetError> {
        if self.max_periods == 0 {
            return Err(FloquetError::BadSetting { name: "max_periods", value: 0.0 });
        }
        if let Some(r) = self.box_radii.iter().find(|r| !(**r > 0.0 && **r < 1.0)) {
            return Err(FloquetError::BadSetting { name: "box_radii", value: *r });
        }
        Ok(())
    }
}

/// Why no enclosure could be attempted or proven.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FloquetError {
    #[error("the Floquet enclosure needs p = 1 and Theta an interval (or a ball or ellipsoid in R^1), got p = {p}, Theta = {theta}")]
    Unsupported { p: usize, theta: String },
    #[error("the Floquet enclosure needs a sine input, got {kind}")]
    UnsupportedInput { kind: &'static str },
    #[error("the Floquet enclosure needs the paper's model (no [[effects]])")]
    Effects,
    #[error("setting `{name}` = {value} is out of range")]
    BadSetting { name: &'static str, value: f64 },
    #[error("simulation failed: {what}")]
    Simulation { what: String },
    #[error("no periodic regime found in {periods} periods")]
    NoRegime { periods: usize },
    #[error("the regime never engages the backlash (no isolated regime: z is a free constant)")]
    NoContact,
    #[error("Newton's method on the period map did not converge for the assumed phase sequence")]
    Newton,
    #[error("Krawczyk test inconclusive on every box tried")]
    KrawczykInconclusive,
    #[error("refuted: the period map has no zero in the box (Krawczyk, coordinate {coordinate})")]
    NoZeroInBox { coordinate: usize },
    #[error("phase {phase}: {what}")]
    Phase { phase: usize, what: &'static str },
    #[error("spectral enclosure failed: {what}")]
    Spectrum { what: &'static str },
}

/// The enclosure and how far it is proven.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FloquetEnclosure {
    /// `ln rho(M) / T` enclosed (when `verified`), else `[estimate, estimate]` or NaN.
    pub floquet_exponent: [f64; 2],
    /// Floating-point estimate of the exponent (the midpoint monodromy's).
    pub estimate: f64,
    /// The spectral radius of the monodromy (largest Floquet multiplier modulus) enclosed.
    pub multiplier: [f64; 2],
    /// Every stage proved its part.
    pub verified: bool,
    /// Why not verified (None when verified).
    pub reason: Option<String>,
    /// The phase sequence from the section (the last continues the first).
    pub phases: Vec<PhaseKind>,
    /// Enclosures of the phase durations.
    pub durations: Vec<[f64; 2]>,
    /// Enclosure of the regime's `(x, z)` at the section.
    pub section_state: Vec<[f64; 2]>,
    /// The section's input phase `omega t_0 + phase`, in quarter turns.
    pub section_quarter: usize,
}

impl FloquetEnclosure {
    fn failed(e: &FloquetError) -> Self {
        Self {
            floquet_exponent: [f64::NAN; 2],
            estimate: f64::NAN,
            multiplier: [f64::NAN; 2],
            verified: false,
            reason: Some(e.to_string()),
            phases: vec![],
            durations: vec![],
            section_state: vec![],
            section_quarter: 0,
        }
    }
    /// Relative width of the exponent's enclosure.
    pub fn relative_width(&self) -> f64 {
        Ival::new(self.floquet_exponent[0], self.floquet_exponent[1]).relative_width()
    }
}

/// The model's data the enclosure needs: `(lo, hi, a, omega, phase)`, the faces of `Theta`
/// enclosed.
fn supported(sys: &System) -> Result<(Ival, Ival, Vec<f64>, f64, f64), FloquetError> {
    if !sys.effects.list.is_empty() {
        return Err(FloquetError::Effects);
    }
    let (lo, hi) = faces(&sys.theta)
        .ok_or_else(|| FloquetError::Unsupported { p: sys.p(), theta: geometry::ConvexSet::describe(&sys.theta) })?;
    match &sys.input {
        Input::Sine { amplitudes, omega, phase } if *omega > 0.0 => Ok((lo, hi, amplitudes.clone(), *omega, *phase)),
        other => Err(FloquetError::UnsupportedInput { kind: other.kind() }),
    }
}

/// `Theta = [lo, hi]` in R^1 with its faces enclosed: an interval exactly, a ball or an
/// ellipsoid as `c -+ r` (`r` the radius, or the square root of the 1 x 1 shape matrix) in
/// interval arithmetic. `None` for other sets, `p != 1` or faces not provably apart.
fn faces(theta: &Shape) -> Option<(Ival, Ival)> {
    if geometry::ConvexSet::dim(theta) != 1 {
        return None;
    }
    let (lo, hi) = match theta {
        Shape::Interval(iv) => (Ival::point(iv.lo), Ival::point(iv.hi)),
        Shape::Ball(b) => {
            let (c, r) = (Ival::point(b.centre[0]), Ival::point(b.radius));
            (c.sub(r), c.add(r))
        }
        Shape::Ellipsoid(e) => {
            let (c, r) = (Ival::point(e.centre()[0]), Ival::point(e.matrix()[0]).sqrt());
            (c.sub(r), c.add(r))
        }
        _ => return None,
    };
    (lo.is_valid() && hi.is_valid() && lo.hi < hi.lo).then_some((lo, hi))
}

fn generators(sys: &System) -> Result<(Generators, f64, f64), FloquetError> {
    let (lo, hi, a, omega, phase) = supported(sys)?;
    Ok((Generators::new(&sys.A, &sys.B, &a, &sys.C, &sys.E, lo, hi, omega), omega, phase))
}

/// Whether the enclosure applies to `sys` (p = 1, `Theta` a set in R^1 with enclosed faces (an
/// interval, a ball or an ellipsoid), sine input, no
/// `[[effects]]`); elsewhere [`floquet_enclosure`] returns the reason.
pub fn applies(sys: &System) -> bool {
    supported(sys).is_ok()
}

/// The whole pipeline: structure from simulation, then the proof. Never panics; a failure of
/// a stage is the result's `reason`.
pub fn floquet_enclosure(sys: &System, settings: &FloquetSettings) -> FloquetEnclosure {
    match structure(sys, settings) {
        Ok(st) => enclose_structure(sys, &st, settings),
        Err(e) => FloquetEnclosure::failed(&e),
    }
}

/// Stage 1 alone: the phase structure read from a simulation.
pub fn structure(sys: &System, settings: &FloquetSettings) -> Result<PhaseStructure, FloquetError> {
    settings.validate()?;
    let (lo, hi, _, omega, phase) = supported(sys)?;
    phases::simulate_structure(sys, lo.mid(), hi.mid(), omega, phase, settings.max_periods)
}

/// Stages 2 to 4 for a given (hypothetical) phase structure.
pub fn enclose_structure(sys: &System, st: &PhaseStructure, settings: &FloquetSettings) -> FloquetEnclosure {
    match prove(sys, st, settings) {
        Ok(r) => r,
        Err((e, partial)) => {
            let mut r = partial.unwrap_or_else(|| FloquetEnclosure::failed(&e));
            r.verified = false;
            r.reason = Some(e.to_string());
            r
        }
    }
}

type Failure = (FloquetError, Option<FloquetEnclosure>);

fn prove(sys: &System, st: &PhaseStructure, settings: &FloquetSettings) -> Result<FloquetEnclosure, Failure> {
    settings.validate().map_err(|e| (e, None))?;
    let (g, _, _) = generators(sys).map_err(|e| (e, None))?;
    let sh = Shooting::new(&g, st.kinds.clone(), st.section_sc());
    let u0: Vec<f64> = st.x0.iter().copied().chain([st.z0]).chain(st.durations.iter().copied()).collect();
    let uhat = sh.newton(&u0, settings.max_newton).ok_or((FloquetError::Newton, None))?;
    // the estimate at the Newton point (reported even when the proof fails)
    let point: Vec<Ival> = uhat.iter().map(|v| Ival::point(*v)).collect();
    let ev0 = sh.evaluate(&point, false).ok_or((FloquetError::Newton, None))?;
    let M0 = monodromy::monodromy(&ev0.flows, &st.kinds, &g.C);
    if !M0.is_valid() {
        // (an eigen-solver on a non-finite matrix need not return)
        return Err((FloquetError::Spectrum { what: "non-finite monodromy" }, None));
    }
    let T = sh.T;
    let rho0 = M0.mid().complex_eigenvalues().iter().map(|z| z.norm()).fold(0.0, f64::max);
    let estimate = rho0.ln() / T.mid();
    let mut partial = FloquetEnclosure {
        floquet_exponent: [estimate; 2],
        estimate,
        multiplier: [rho0; 2],
        verified: false,
        reason: None,
        phases: st.kinds.clone(),
        durations: ev0.durations.iter().map(|h| [h.mid(); 2]).collect(),
        section_state: uhat[..=g.n].iter().map(|v| [*v; 2]).collect(),
        section_quarter: st.quarter,
    };
    let mut last = FloquetError::KrawczykInconclusive;
    let mut boxed = None;
    for rel in settings.box_radii {
        let r: Vec<f64> = uhat.iter().map(|v| rel * (1.0 + v.abs())).collect();
        match sh.krawczyk(&uhat, &r) {
            Some(KrawczykVerdict::Unique(K)) => {
                boxed = Some(K);
                break;
            }
            Some(KrawczykVerdict::NoZero { coordinate }) => last = FloquetError::NoZeroInBox { coordinate },
            _ => {}
        }
    }
    let Some(K) = boxed else { return Err((last, Some(partial))) };
    let ev = sh.evaluate(&K, false).ok_or((FloquetError::Newton, None))?;
    partial.durations = ev.durations.iter().map(|h| [h.lo, h.hi]).collect();
    partial.section_state = K[..=g.n].iter().map(|v| [v.lo, v.hi]).collect();
    switching::check_phases(&g, &st.kinds, &ev)
        .map_err(|f| (FloquetError::Phase { phase: f.phase, what: f.what }, Some(partial.clone())))?;
    let M = monodromy::MonodromyEnclosure::new(&g, &st.kinds, &ev.durations, &ev.flows);
    let (rho, _) = monodromy::spectral_radius(&M).map_err(|f| {
        let what = match f {
            monodromy::SpectrumFailure::EigenvectorsIllConditioned => "eigenvectors ill-conditioned",
            monodromy::SpectrumFailure::NonFinite => "non-finite monodromy",
        };
        (FloquetError::Spectrum { what }, Some(partial.clone()))
    })?;
    if !(rho.lo > 0.0) {
        return Err((FloquetError::Spectrum { what: "spectral radius not bounded away from 0" }, Some(partial)));
    }
    let ex = rho.ln().div(T);
    partial.floquet_exponent = [ex.lo, ex.hi];
    partial.multiplier = [rho.lo, rho.hi];
    partial.verified = true;
    Ok(partial)
}

/// The face a phase kind engages, if any.
pub fn face_of(kind: PhaseKind) -> Option<Face> {
    match kind {
        PhaseKind::Engaged(f) => Some(f),
        PhaseKind::Resting => None,
    }
}

#[cfg(test)]
mod tests;
