//! Is an input missing from the model? A recording may carry columns the model does not use
//! ([`crate::Recording::extra`]). If the nominal residual follows one of them through the
//! plant's dynamics, the honest diagnosis is "input X is missing from the model", not an
//! effect fitted to stand in for it (a pulse train left out of the model was once "explained"
//! as a constant force equal to its mean).
//!
//! Test: the column `u` is fed through the linearised nominal loop (`F = A + E C`, no play,
//! no effects, zero initial state, the diagnosis' input hold) on each state in turn,
//! `g_i = C (s I - F)^{-1} e_i u`; the weighted nominal residual on the estimation segment is
//! regressed on the `n` responses by least squares. The share of its energy so explained is
//! compared with the share the best hypothesis of the library explains: the column is
//! reported missing when it explains at least [`MISSING_SHARE`] and more than the best
//! hypothesis by [`MISSING_MARGIN`]. Columns that are monotone (time stamps, sample
//! counters) or constant are not inputs and are skipped.
use dynamics::extended::{ExtendedModel, InputHold};
use model::{Input, System};
use nalgebra::{DMatrix, DVector};
use serde::Serialize;

/// Share of the nominal residual's energy a column must explain to be reported missing.
pub const MISSING_SHARE: f64 = 0.5;
/// ... and by how much more than the best hypothesis of the library.
pub const MISSING_MARGIN: f64 = 0.1;

/// The check of one extra column.
#[derive(Debug, Clone, Serialize)]
pub struct MissingInput {
    pub column: String,
    /// Share of the weighted nominal residual energy (estimation segment) explained by the
    /// column through the nominal dynamics.
    pub explained: f64,
    /// Share explained by the best hypothesis of the library (`1 - SSE / SSE_nominal`).
    pub best_hypothesis_explained: f64,
    pub best_hypothesis: String,
    /// Whether the column is reported as an input missing from the model.
    pub missing: bool,
}

fn monotone_or_constant(u: &[f64]) -> bool {
    let inc = u.windows(2).all(|p| p[1] >= p[0]);
    let dec = u.windows(2).all(|p| p[1] <= p[0]);
    inc || dec
}

/// Share of `e` (flat `k * p + i`, first `k_est` samples, weighted per output by `weights`)
/// explained by `u` through the linearised nominal loop of `sys`; `None` for a skipped column
/// or a failed simulation.
#[allow(clippy::too_many_arguments)]
pub fn explained_share(
    sys: &System,
    u: &[f64],
    e: &[f64],
    weights: &[f64],
    k_est: usize,
    dt: f64,
    substeps: usize,
    hold: InputHold,
) -> Option<f64> {
    if monotone_or_constant(u) {
        return None;
    }
    let (n, p) = (sys.n(), sys.p());
    let mut lin = sys.clone();
    lin.input = Input::Zero { m: 1 };
    lin.theta = geometry::Shape::origin(p);
    lin.effects = Default::default();
    let rows = k_est * p;
    let mut G = DMatrix::zeros(rows, n);
    for i in 0..n {
        lin.B = DMatrix::zeros(n, 1);
        lin.B[(i, 0)] = 1.0;
        let ext = ExtendedModel::new(&lin, &[], dt, substeps).ok()?.with_hold(hold);
        let o = ext.simulate(&u[..k_est], dt, &vec![0.0; n]);
        if !o.finite {
            return None;
        }
        for r in 0..rows {
            G[(r, i)] = o.y[r] * weights[r % p];
        }
    }
    let ev = DVector::from_iterator(rows, (0..rows).map(|r| e[r] * weights[r % p]));
    let e2 = ev.norm_squared();
    if e2 <= 0.0 {
        return None;
    }
    // Least squares by the SVD (columns may be nearly dependent).
    let svd = G.clone().svd(true, true);
    let b = svd.solve(&ev, 1e-10).ok()?;
    let r = &ev - &G * b;
    Some((1.0 - r.norm_squared() / e2).clamp(0.0, 1.0))
}
