//! Theorem 2: for a `T`-periodic input and `F` Hurwitz, after transients
//! (path) `int_tau^{tau+T} |z'| dt >= (osc - d)_+`, `osc = diam eta_T([0, T])` (eq. (mho)),
//! `d = diam(C Xi_inf + Theta)` (eq. (d)); and
//! (zinf) `limsup |z'| <= ||eta_T'||_inf + D(C(F Xi_inf + E Theta), {0})`.
//!
//! Computation: `eta_T` from `dynamics::periodic::linearised_periodic` (exact for sines, eq.
//! (xT) with its typo corrected); `osc` = largest distance between 1000 samples;
//! `||eta_T'||_inf` = sampled maximum; `d` and `D(...)` as certified upper bounds by
//! `geometry::sphere_max` of support functions, `sigma_{Xi_inf}` by the trapezoid rule (step `0.05`)
//! ([`super::simulation::XiNodes`]). The closed loop is simulated by catching-up
//! (`h = min(T/500, 0.01)`) for a transient of `max(15/|mu|, 2T)` rounded up to whole periods (mu in `[-2, -1]`),
//! then 3 periods are measured: path length per period `sum |Dz|` (minimum over the periods)
//! and speed `max |Dz|/h`.
//! Tolerance (discretisation, first-order scheme): `2%` of the right-hand side.
//! Negative controls: (path) `d` replaced by `0` (the tube ignored); (zinf) the bound halved.
use super::sets_prelude::*;
use super::simulation::{op_norm, simulate, XiNodes};
use crate::strategies::inputs::InputStrategyConfig;
use crate::strategies::systems::{system_params, SystemParams, SystemStrategyConfig};
use dynamics::periodic::linearised::{linearised_periodic, LinearisedSettings};
use geometry::{sphere_max, SphereMaxSettings};

/// Steps per period of the catching-up scheme (capped by [`MAX_DT`]).
pub const STEPS_PER_PERIOD: usize = 500;
/// Largest step.
pub const MAX_DT: f64 = 1e-2;
/// Transient: `TRANSIENT_DECAYS / |mu|` (at least `2 T`), rounded up to whole periods.
pub const TRANSIENT_DECAYS: f64 = 15.0;
/// Quadrature step of `sigma_{Xi_inf}`.
pub const XI_DS: f64 = 5e-2;

/// Backlash sets of the default campaign: the strongly convex kinds whose projection is cheap
/// (ball intersections cost ~50x more per projection in `geometry`; they are covered by
/// [`config_ball_intersection`], run by the `#[ignore]`d test).
pub const THETA_KINDS: [SetKind; 3] = [SetKind::Interval, SetKind::Ball, SetKind::Ellipsoid];

/// Which half of Theorem 2.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    Path,
    Zinf,
}

pub fn info(part: Part) -> PropertyInfo {
    match part {
        Part::Path => PropertyInfo {
            name: "theorem2_path",
            label: "(path)",
            title: "Theorem 2: path of z per period >= (osc(eta_T) - diam(C Xi_inf + Theta))_+",
            default_cases: 2000,
            negative_control: "d replaced by 0",
        },
        Part::Zinf => PropertyInfo {
            name: "theorem2_zinf",
            label: "(zinf)",
            title: "Theorem 2: limsup |z'| <= ||eta_T'||_inf + D(C(F Xi_inf + E Theta), {0})",
            default_cases: 2000,
            negative_control: "bound halved",
        },
    }
}

pub fn config() -> SystemStrategyConfig {
    SystemStrategyConfig {
        mu: (-2.0, -1.0),
        theta: SetStrategyConfig {
            kinds: THETA_KINDS.to_vec(),
            max_cond: 5.0,
            scale_exp: 0.75,
            ..SetStrategyConfig::default()
        },
        input: InputStrategyConfig { amp_exp: (-1.0, 1.3), ..Default::default() },
        ..Default::default()
    }
}

pub fn strategy() -> BoxedStrategy<SystemParams> {
    system_params(&config())
}

/// As [`config`] with ball intersections only.
pub fn config_ball_intersection() -> SystemStrategyConfig {
    let mut c = config();
    c.theta.kinds = vec![SetKind::BallIntersection];
    c
}

/// Every quantity of Theorem 2 for one system, and the measured ones.
#[derive(Debug, Clone)]
pub struct Measured {
    pub osc: f64,
    pub d_upper: f64,
    pub deta_inf: f64,
    pub D_upper: f64,
    /// Minimum over the measured periods of the path length of `z`.
    pub path_min: f64,
    /// Maximum of `|Dz|/h` over the measured periods.
    pub speed_max: f64,
}

pub fn measure(sys: &model::System) -> Option<Measured> {
    let T = sys.period()?;
    let mu = sys.mu();
    if !(mu < 0.0) {
        return None;
    }
    let lin = linearised_periodic(sys, &LinearisedSettings { samples: 1000, substeps: 8 }).ok()?;
    let osc = lin.osc_lower();
    let deta_inf = lin.deta_inf_sampled();
    let p = sys.p();
    let xi = XiNodes::new(sys, XI_DS, 200.0);
    let d_theta = sys.theta.deviation_from_origin().upper;
    let d_xi = d_theta * op_norm(&sys.E) * xi.int_norm; // >= D(Xi_inf, {0}), eq. (DXX)
    let Ct = sys.C.transpose();
    let st = SphereMaxSettings { tol_abs: 1e-9, tol_rel: 1e-2, max_evals: 400 };
    let cn = op_norm(&sys.C);
    let xi_c = xi.mapped(&Ct);
    let sig_cxi = |u: &[f64]| xi_c.support(&sys.theta, u);
    let d_upper = sphere_max(
        p,
        |u| {
            let m: Vec<f64> = u.iter().map(|x| -x).collect();
            sig_cxi(u) + sig_cxi(&m) + sys.theta.support(u) + sys.theta.support(&m)
        },
        2.0 * (cn * d_xi + d_theta),
        &st,
    )
    .upper;
    let FtCt = sys.F().transpose() * &Ct;
    let EtCt = sys.E.transpose() * &Ct;
    let xi_f = xi.mapped(&FtCt);
    let D_upper = sphere_max(
        p,
        |u| {
            let v = nalgebra::DVector::from_column_slice(u);
            xi_f.support(&sys.theta, u) + sys.theta.support((&EtCt * &v).as_slice())
        },
        op_norm(&FtCt) * d_xi + op_norm(&EtCt) * d_theta,
        &st,
    )
    .upper;
    let dt = (T / STEPS_PER_PERIOD as f64).min(MAX_DT);
    let spp = (T / dt).round().max(1.0) as usize;
    let dt = T / spp as f64;
    let transient_periods = ((TRANSIENT_DECAYS / mu.abs()).max(2.0 * T) / T).ceil() as usize;
    let mut x: Vec<f64> = sys.x0.iter().copied().collect();
    let mut z: Vec<f64> = sys.z0.iter().copied().collect();
    if !simulate(sys, dt, 0.0, &mut x, &mut z, transient_periods * spp, |_, _, _| {}) {
        return None;
    }
    let mut path_min = f64::INFINITY;
    let mut speed_max: f64 = 0.0;
    for k in 0..3 {
        let t0 = (transient_periods + k) as f64 * T;
        let mut prev = z.clone();
        let mut len = 0.0;
        simulate(sys, dt, t0, &mut x, &mut z, spp, |_, _, zz| {
            let s = dist(zz, &prev);
            len += s;
            speed_max = speed_max.max(s / dt);
            prev.copy_from_slice(zz);
        });
        path_min = path_min.min(len);
    }
    Some(Measured { osc, d_upper, deta_inf, D_upper, path_min, speed_max })
}

pub fn eval_part(sp: &SystemParams, part: Part, variant: Variant) -> Eval {
    let sys = sp.build();
    let Some(m) = measure(&sys) else { return Eval::skipped() };
    match (part, variant) {
        (Part::Path, v) => {
            let d = if v == Variant::Claim { m.d_upper } else { 0.0 };
            let bound = (m.osc - d).max(0.0);
            // claim: bound <= path
            Eval::new(bound, m.path_min, 0.02 * bound + 1e-12)
        }
        (Part::Zinf, v) => {
            let k = if v == Variant::Claim { 1.0 } else { 0.5 };
            let bound = k * (m.deta_inf + m.D_upper);
            Eval::new(m.speed_max, bound, 0.02 * bound + 1e-12)
        }
    }
}

pub fn eval_path(sp: &SystemParams, variant: Variant) -> Eval {
    eval_part(sp, Part::Path, variant)
}
pub fn eval_zinf(sp: &SystemParams, variant: Variant) -> Eval {
    eval_part(sp, Part::Zinf, variant)
}

fn export_path(sp: &SystemParams, e: &Eval) -> Counterexample {
    system_counterexample(&sp.build(), e, "theorem2_path", "lhs = (osc - d)_+, rhs = min path length of z per period")
}
fn export_zinf(sp: &SystemParams, e: &Eval) -> Counterexample {
    system_counterexample(&sp.build(), e, "theorem2_zinf", "lhs = max |z'| after transients, rhs = ||eta_T'|| + D(...)")
}

pub fn property_path() -> Prop<SystemParams> {
    Prop { info: info(Part::Path), strategy, eval: eval_path, export: export_path, max_shrink_iters: 60 }
}
pub fn property_zinf() -> Prop<SystemParams> {
    Prop { info: info(Part::Zinf), strategy, eval: eval_zinf, export: export_zinf, max_shrink_iters: 60 }
}
