//! Hypotheses: the effects of the physics library ([`crate::physics`]) with free parameters,
//! their bounds and starting points, derived from the model's structure and the recording's
//! scales (never from how a benchmark was generated), and the rule that accepts a
//! generalisation over its simpler form.
//!
//! [`candidates`] finds the sites of the model where effects can act ([`Site`]): the play,
//! each velocity state ([`velocity_states`], with its force bound `range(y) / |C F^{-1} e_j|`,
//! its velocity scale and its position state, [`position_velocity_pairs`]), the input and the
//! sensor; [`per_input_candidates`] each input of a model with several. At each site every
//! family of [`physics::FAMILIES`] states its hypotheses; the order (sites first, families
//! second) is the order in which the diagnosis tries them. Each family's file documents its
//! bounds and starts.
//!
//! Starts: the solver screens the starts and iterates the best three.
use crate::physics::{self, Context, Site};
use model::System;

pub use crate::physics::cogging::cogging_scan;
pub use crate::physics::friction::notes as friction_notes;
pub use crate::physics::{Hypothesis, Kind, NominalRun, Scales};

/// Largest held-out SSE ratio of a generalisation against its simpler form
/// ([`simpler_form`]): it must cut the simpler form's held-out error by 7 % (a new effect
/// needs 10 % against the model it extends). Chosen on development seeds between the
/// spurious asymmetry or breakaway fitted to coloured noise (ratios 0.954 and above) and the
/// weakest true ones (0.909-0.922).
pub const NESTED_MAX_CV_RATIO: f64 = 0.93;

/// Largest held-out SSE ratio at which a generalisation is still accepted when it lowers the
/// held-out error in **every** fold (at least [`NESTED_MIN_FOLDS`]): a generalisation fitted to
/// noise raises or lowers each fold's error at random (an extra free parameter rather raises
/// it), so all of five folds lower has probability at most `1/32`. Chosen on development seeds
/// 951-953: true Stribeck and direction-dependent friction under coloured noise gave ratios
/// 0.94-0.98 with every fold lower (0.933-0.994 per fold), spurious ones at most four of five
/// folds lower.
pub const NESTED_CONSISTENT_MAX_CV_RATIO: f64 = 0.99;

/// Fewest folds for the every-fold rule of [`NESTED_CONSISTENT_MAX_CV_RATIO`].
pub const NESTED_MIN_FOLDS: usize = 5;

/// Whether held-out folds support a generalisation over its simpler form ([`simpler_form`]):
/// per-fold held-out SSEs `sse` (generalisation) and `sse_simple`. Accepted when the total
/// ratio is at most [`NESTED_MAX_CV_RATIO`], or at most [`NESTED_CONSISTENT_MAX_CV_RATIO`] with
/// every one of at least [`NESTED_MIN_FOLDS`] folds lower.
pub fn nested_supported(sse: &[f64], sse_simple: &[f64]) -> bool {
    let (a, b): (f64, f64) = (sse.iter().sum(), sse_simple.iter().sum());
    if !b.is_finite() {
        // the simpler form could not be scored on the folds: nothing to prefer it by
        return true;
    }
    if !a.is_finite() || b <= 0.0 || sse.len() != sse_simple.len() {
        return false;
    }
    let ratio = a / b;
    let every_fold = sse.len() >= NESTED_MIN_FOLDS && sse.iter().zip(sse_simple).all(|(x, y)| x < y);
    ratio <= NESTED_MAX_CV_RATIO || (every_fold && ratio <= NESTED_CONSISTENT_MAX_CV_RATIO)
}

/// The simpler single hypothesis that `kind` generalises (nested at some parameter values):
/// Stribeck friction (static level = sliding level) and direction-dependent friction (equal
/// levels) both contain Coulomb friction on the same state. The diagnosis accepts the
/// generalisation only where it also beats the simpler form on held-out folds.
pub fn simpler_form(kind: Kind) -> Option<Kind> {
    kind.simpler_form()
}

/// Velocity-like states: `x_j` such that some other state's derivative is a multiple of
/// `x_j` alone (`A` row `i` has its only non-zero at `j`, `B`, `E` rows `i` zero). When the
/// model has none, every state is a candidate.
pub fn velocity_states(sys: &System) -> Vec<usize> {
    let mut out: Vec<usize> = position_velocity_pairs(sys).iter().map(|&(_, j)| j).collect();
    if out.is_empty() {
        out = (0..sys.n()).collect();
    }
    out.sort();
    out
}

/// Position-velocity pairs `(i, j)`: `x_i' = a x_j` alone (`A` row `i` has its only non-zero
/// at `j`, `B`, `E` rows `i` zero), one per velocity state `j`.
pub fn position_velocity_pairs(sys: &System) -> Vec<(usize, usize)> {
    let n = sys.n();
    let mut out = Vec::new();
    for i in 0..n {
        let nz: Vec<usize> = (0..n).filter(|&j| sys.A[(i, j)] != 0.0).collect();
        let b0 = (0..sys.m()).all(|j| sys.B[(i, j)] == 0.0) && (0..sys.p()).all(|j| sys.E[(i, j)] == 0.0);
        if nz.len() == 1 && nz[0] != i && b0 && !out.iter().any(|&(_, j)| j == nz[0]) {
            out.push((i, nz[0]));
        }
    }
    out
}

/// Static gain `|C F^{-1} e_j|` from a force on state `j` to `y` (None if `F` is singular or
/// the gain vanishes).
fn static_gain(sys: &System, j: usize) -> Option<f64> {
    let Finv = sys.F().try_inverse()?;
    let g = (&sys.C * Finv.column(j)).norm();
    (g > 1e-12).then_some(g)
}

/// The velocity states of `sys` as sites: force bound `range(y) / |C F^{-1} e_j|` (else
/// `max|w| max|B_j|`), velocity scale the state's RMS over the nominal run (else
/// `range(y) / tau_slow`), and the position state of a position-velocity pair.
fn velocity_sites(sys: &System, s: &Scales) -> Vec<Site> {
    let yr = s.y_range_max();
    let pairs = position_velocity_pairs(sys);
    velocity_states(sys)
        .into_iter()
        .map(|j| {
            let fs = static_gain(sys, j).map(|g| yr / g).unwrap_or_else(|| s.w_absmax * sys.B.row(j).amax()).max(1e-12);
            let velocity_scale = s
                .state_rms
                .get(j)
                .copied()
                .filter(|v| *v > 0.0 && v.is_finite())
                .unwrap_or_else(|| yr / s.tau_slow.max(1e-12));
            let position_state = pairs.iter().find(|&&(_, v)| v == j).map(|&(pos, _)| pos);
            Site::Velocity { state: j, force_bound: fs, velocity_scale, position_state }
        })
        .collect()
}

/// All single-effect hypotheses applicable to `sys`: the library's families at the play, each
/// velocity state, the input and the sensor, in that order.
pub fn candidates(sys: &System, s: &Scales) -> Vec<Hypothesis> {
    candidates_in(sys, s, None)
}

/// [`candidates`] narrowed to `library` (labels or names, [`physics::in_library`]; `None`:
/// all), without the work of stating the others.
pub fn candidates_in(sys: &System, s: &Scales, library: Option<&[String]>) -> Vec<Hypothesis> {
    let mut sites = vec![Site::Play];
    sites.extend(velocity_sites(sys, s));
    sites.extend([Site::Input, Site::Sensor]);
    physics::hypotheses_at(&sites, &Context { sys, scales: s, library })
}

/// Per-input hypotheses for a model with `m > 1` inputs (none for `m = 1`): the library's
/// families at each input alone ([`physics::input_ops`]), `w` the recorded input (flat
/// `k * m + j`).
pub fn per_input_candidates(sys: &System, s: &Scales, w: &[f64]) -> Vec<Hypothesis> {
    let m = sys.m();
    if m < 2 {
        return vec![];
    }
    let n = w.len() / m;
    let sites: Vec<Site> = (0..m)
        .map(|j| {
            let absmax = (0..n).map(|k| w[k * m + j].abs()).fold(0.0, f64::max).max(1e-12);
            let range = s.w_range.get(j).copied().unwrap_or(absmax).max(1e-12);
            Site::OneInput { input: j, absmax, range }
        })
        .collect();
    physics::hypotheses_at(&sites, &Context { sys, scales: s, library: None })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nested_generalisation_needs_a_large_gain_or_every_fold_lower() {
        let simple = [1.0; 5];
        // a large gain passes even with one fold worse
        assert!(nested_supported(&[0.8, 0.8, 0.8, 0.9, 1.05], &simple));
        // a small gain in every fold (a true breakaway under coloured noise, seed 951) passes
        assert!(nested_supported(&[0.933, 0.933, 0.945, 0.953, 0.933], &simple));
        // negative controls: the same small mean gain with one fold worse (a fit to noise, seed
        // 953), a consistent but negligible gain, too few folds for the every-fold rule
        assert!(!nested_supported(&[0.972, 0.897, 0.948, 1.056, 0.982], &simple));
        assert!(!nested_supported(&[0.995; 5], &simple));
        assert!(!nested_supported(&[0.95; 4], &[1.0; 4]));
        // an unscorable generalisation never passes; an unscorable simpler form is no rival
        assert!(!nested_supported(&[f64::INFINITY, 0.5, 0.5, 0.5, 0.5], &simple));
        assert!(nested_supported(&[0.9; 5], &[f64::INFINITY; 5]));
    }
}
