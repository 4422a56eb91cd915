//! The set of `T`-stationary initial conditions of the backlash output, eqs. (stat), (stat1):
//! `R(T) = {z : Phi(t) z in C x_*(t) + Theta for all t in [0, T]}` (eq. (zin), equivalent to
//! (stat1) where `Phi` is invertible and meaningful everywhere), with `x_*` of eq. (xz0) the
//! response of the open loop (no feedback) from the model's `x0`.
//!
//! On a grid `t_k = k T / K` the constraints are relaxed by a common slack `s` and
//! `min s` is solved: `R_grid = {z : Phi(t_k) z - C x_*(t_k) in Theta (+ s)}`; `s* > 0` means the
//! grid set is empty and hence so is `R(T)` (which is contained in it).
//! - `p = 1`, interval `Theta`: exact intersection of intervals (verified up to the accuracy of
//!   `x_*`, see `margin_rel`);
//! - otherwise a second-order cone program in Clarabel: balls, ellipsoids and intersections of
//!   balls are second-order cones, polytopes linear inequalities (`s*` is the solver's value:
//!   an estimate).
//!
//! When the grid set is nonempty, its most interior point is simulated (catching-up scheme,
//! `sim_dt`) and `z` is confirmed to stay at rest over `[0, T]`.
use crate::error::BoundsError;
use dynamics::integrators::catching_up::CatchingUpSettings;
use dynamics::linear::expm::t_psi;
use dynamics::linear::step_map::{InputHold, SystemStepMap};
use geometry::{ConvexSet, Shape};
use lmi::{ConicProgram, SdpSettings};
use model::System;
use nalgebra::{DMatrix, DVector};

use super::phi::{scan_phi, PhiScan};

/// Settings of the stationary-set computation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RestSetSettings {
    /// Grid intervals over `[0, T]`. Default `400`.
    pub grid: usize,
    /// Sub-steps per grid interval for `x_*` (first-order hold). Default `16`.
    pub substeps: usize,
    /// `Phi(t)` counts as singular when its smallest singular value is below this. Default `1e-10`.
    pub tol_sigma: f64,
    /// Emptiness (p = 1) is reported as verified when the gap exceeds
    /// `margin_rel (1 + |z|)` (covers the discretisation error of `x_*`). Default `1e-6`.
    pub margin_rel: f64,
    /// Step of the confirming simulation. Default `1e-3`.
    pub sim_dt: f64,
    /// `z` counts as at rest when it moves less than this. Default `1e-9`.
    pub tol_rest: f64,
}

impl Default for RestSetSettings {
    fn default() -> Self {
        Self { grid: 400, substeps: 16, tol_sigma: 1e-10, margin_rel: 1e-6, sim_dt: 1e-3, tol_rest: 1e-9 }
    }
}

/// Result of [`rest_set`].
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[non_exhaustive]
pub struct RestSet {
    pub period: f64,
    /// Scan of `Phi` (Theorem 1's hypothesis).
    pub phi: PhiScan,
    /// `Some(true)`: `R(T)` is empty; `Some(false)`: a point was found; `None`: undecided.
    pub empty: Option<bool>,
    /// True when emptiness is proven (p = 1 exact intervals) or non-emptiness is confirmed
    /// by simulation.
    pub verified: bool,
    /// Optimal slack `s*` (`> 0`: empty).
    pub slack: f64,
    /// A point of the grid set (most interior), if nonempty.
    pub point: Option<Vec<f64>>,
    /// Largest `|z(t) - z(0)|` along the confirming simulation.
    pub max_drift: Option<f64>,
    pub method: &'static str,
}

/// Open-loop response `x_*(t_k)` of eq. (xz0) on the grid (first-order hold of `w`).
fn open_loop(sys: &System, T: f64, K: usize, sub: usize) -> Result<Vec<DVector<f64>>, BoundsError> {
    let n = sys.n();
    let hs = T / (K * sub) as f64;
    let map = SystemStepMap::new(&sys.A, &sys.B, &DMatrix::zeros(n, sys.p()), hs, InputHold::Foh)?;
    let m = sys.m();
    let (mut w0, mut w1) = (vec![0.0; m], vec![0.0; m]);
    let mut x = sys.x0.clone();
    let mut out = vec![x.clone()];
    for k in 0..K {
        for j in 0..sub {
            let t0 = (k * sub + j) as f64 * hs;
            sys.input.eval(t0, &mut w0);
            sys.input.eval(t0 + hs, &mut w1);
            let a = DVector::from_column_slice(&w0);
            let b = DVector::from_column_slice(&w1);
            x = &map.phi * &x + &map.g1B * &a + &map.g2B * (b - &a);
        }
        out.push(x.clone());
    }
    Ok(out)
}

/// Computes `R(T)` for the model's period `T`, see the module docs.
pub fn rest_set(sys: &System, settings: &RestSetSettings) -> Result<RestSet, BoundsError> {
    let T = sys.period().ok_or(BoundsError::NoPeriod { kind: sys.input.kind() })?;
    if settings.grid < 2 || settings.substeps == 0 {
        return Err(BoundsError::BadSetting {
            name: "stationary.grid",
            value: settings.grid as f64,
            reason: "grid >= 2 and substeps >= 1",
        });
    }
    let K = settings.grid;
    let p = sys.p();
    let phi_scan = scan_phi(&sys.A, &sys.C, &sys.E, T, K, settings.tol_sigma);
    let xs = open_loop(sys, T, K, settings.substeps)?;
    let mut Phis = Vec::with_capacity(K + 1);
    let mut cs = Vec::with_capacity(K + 1);
    for (k, x) in xs.iter().enumerate() {
        let t = T * k as f64 / K as f64;
        Phis.push(DMatrix::identity(p, p) - &sys.C * t_psi(&sys.A, t) * &sys.E);
        cs.push(&sys.C * x);
    }
    let (empty, verified, slack, point, method) = match &sys.theta {
        Shape::Interval(iv) => {
            let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
            let mut impossible = false;
            for (P, c) in Phis.iter().zip(&cs) {
                let f = P[(0, 0)];
                let (a, b) = (iv.lo + c[0], iv.hi + c[0]);
                if f > 0.0 {
                    lo = lo.max(a / f);
                    hi = hi.min(b / f);
                } else if f < 0.0 {
                    lo = lo.max(b / f);
                    hi = hi.min(a / f);
                } else if !(a <= 0.0 && 0.0 <= b) {
                    impossible = true;
                }
            }
            let gap = lo - hi;
            let margin = settings.margin_rel * (1.0 + lo.abs().min(hi.abs()));
            if impossible || gap > 0.0 {
                (
                    Some(true),
                    impossible || gap > margin,
                    gap,
                    None,
                    "exact intersection of intervals on the grid (p = 1)",
                )
            } else {
                (
                    Some(false),
                    false,
                    gap,
                    Some(vec![0.5 * (lo + hi)]),
                    "exact intersection of intervals on the grid (p = 1)",
                )
            }
        }
        theta => {
            let (s, z) = socp(theta, &Phis, &cs)?;
            if s > 0.0 {
                (
                    Some(true),
                    false,
                    s,
                    None,
                    "second-order cone program (Clarabel) on the grid; emptiness from the solver's optimum (estimate)",
                )
            } else {
                (Some(false), false, s, Some(z), "second-order cone program (Clarabel) on the grid")
            }
        }
    };
    let mut out = RestSet { period: T, phi: phi_scan, empty, verified, slack, point, max_drift: None, method };
    if let Some(z) = out.point.clone() {
        let drift = confirm_at_rest(sys, &z, settings.sim_dt)?;
        out.max_drift = Some(drift);
        out.verified = drift <= settings.tol_rest;
        if !out.verified {
            // The grid point did not stay at rest: the grid relaxation was too coarse.
            out.empty = None;
        }
    }
    Ok(out)
}

/// Simulates the closed loop from `(sys.x0, z)` over one period (catching-up scheme, step
/// `<= dt`) and returns `max_t |z(t) - z|`: zero (to rounding) iff `z` stays at rest.
pub fn confirm_at_rest(sys: &System, z: &[f64], dt: f64) -> Result<f64, BoundsError> {
    let T = sys.period().ok_or(BoundsError::NoPeriod { kind: sys.input.kind() })?;
    let mut s2 = sys.clone();
    s2.z0 = DVector::from_column_slice(z);
    let (N, h) = dynamics::periodic::steps_per_period(T, dt)?;
    let traj =
        dynamics::trajectory::simulate_catching_up(&s2, &CatchingUpSettings { dt: h, hold: InputHold::Foh }, N, 1)?;
    let mut drift = 0.0f64;
    for i in 0..traj.len() {
        drift = drift.max(geometry::linalg::dist(traj.z_at(i), z));
    }
    Ok(drift)
}

/// `min s` s.t. `Phi_k z - c_k in Theta + s` (cone form per shape). Variables `(z, s)`.
fn socp(theta: &Shape, Phis: &[DMatrix<f64>], cs: &[DVector<f64>]) -> Result<(f64, Vec<f64>), BoundsError> {
    let p = theta.dim();
    let nv = p + 1;
    let mut prog = ConicProgram::new(nv);
    // s >= -big (keeps the problem bounded).
    let big = 1e3 * (1.0 + theta.deviation_from_origin().upper);
    let mut r0 = vec![0.0; nv];
    r0[p] = -1.0;
    prog.add_nonnegative(&[(r0, big)]);
    // SOC ||W (Phi z - c - centre)|| <= rad + s:  s_cone = [rad + s; W (Phi z - c - centre)]
    let soc =
        |W: &DMatrix<f64>, centre: &[f64], rad: f64, P: &DMatrix<f64>, c: &DVector<f64>, prog: &mut ConicProgram| {
            let mut rows = Vec::with_capacity(W.nrows() + 1);
            let mut r = vec![0.0; nv];
            r[p] = -1.0;
            rows.push((r, rad));
            let WP = W * P;
            let off = W * (c + DVector::from_column_slice(centre));
            for i in 0..W.nrows() {
                let mut r = vec![0.0; nv];
                for j in 0..p {
                    r[j] = -WP[(i, j)];
                }
                rows.push((r, -off[i]));
            }
            prog.add_second_order(&rows);
        };
    let I = DMatrix::<f64>::identity(p, p);
    for (P, c) in Phis.iter().zip(cs) {
        match theta {
            Shape::Ball(bl) => soc(&I, &bl.centre, bl.radius, P, c, &mut prog),
            Shape::BallIntersection(bi) => {
                for (ctr, rad) in bi.centres().iter().zip(bi.radii()) {
                    soc(&I, ctr, *rad, P, c, &mut prog);
                }
            }
            Shape::Ellipsoid(el) => {
                let M = DMatrix::from_row_slice(p, p, el.matrix());
                let L =
                    M.cholesky().ok_or(BoundsError::ConicData { what: "ellipsoid matrix is not positive definite" })?;
                let W = L.l().try_inverse().ok_or(BoundsError::ConicData { what: "ellipsoid factor is singular" })?;
                soc(&W, el.centre(), 1.0, P, c, &mut prog);
            }
            Shape::Polytope(pt) => {
                // n_i^T (Phi z - c) <= o_i + s  <=>  o_i + n_i^T c - n_i^T Phi z + s >= 0
                let mut rows = Vec::with_capacity(pt.normals().len());
                for (nrm, o) in pt.normals().iter().zip(pt.offsets()) {
                    let nv_ = DVector::from_column_slice(nrm);
                    let nP = nv_.transpose() * P;
                    let mut r = vec![0.0; nv];
                    for j in 0..p {
                        r[j] = nP[(0, j)];
                    }
                    r[p] = -1.0;
                    rows.push((r, o + nv_.dot(c)));
                }
                prog.add_nonnegative(&rows);
            }
            Shape::Interval(iv) => {
                // (p = 1 handled exactly by the caller; kept for completeness)
                let mut rows = Vec::with_capacity(2);
                for (sgn, bound) in [(1.0, iv.hi), (-1.0, -iv.lo)] {
                    let mut r = vec![0.0; nv];
                    r[0] = sgn * P[(0, 0)];
                    r[p] = -1.0;
                    rows.push((r, bound + sgn * c[0]));
                }
                prog.add_nonnegative(&rows);
            }
        }
    }
    let mut q = vec![0.0; nv];
    q[p] = 1.0;
    let out = prog
        .solve(&q, &SdpSettings::clarabel_defaults())
        .map_err(|_| BoundsError::ConicData { what: "Clarabel rejected the problem data" })?;
    if out.solved() {
        Ok((out.x[p], out.x[..p].to_vec()))
    } else {
        Err(BoundsError::ConicSolver { status: out.status })
    }
}
