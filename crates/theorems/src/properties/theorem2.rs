//! Theorem 2: for a `T`-periodic input and `F` Hurwitz, after transients
//! (path) `int_tau^{tau+T} |z'| dt >= (osc - d)_+`, `osc = diam eta_T([0, T])` (eq. (mho)),
//! `d = diam(C Xi_inf + Theta)` (eq. (d)); and
//! (zinf) `limsup |z'| <= ||eta_T'||_inf + D(C(F Xi_inf + E Theta), {0})`.
//!
//! Computation: `eta_T` in closed form for sines ([`orbit_samples`]: the phasor of
//! `bounds::orbit::EtaOrbit`), else from `dynamics::periodic::linearised_periodic` (eq. (xT)
//! with its typo corrected); `osc` = largest distance between 1001 samples;
//! `||eta_T'||_inf` = sampled maximum; `d` and `D(...)` as certified upper bounds by the
//! production code of `moreau theta`, `bounds::tube::tube_diameters` (certified quadrature of
//! `sigma_{C Xi_inf}`, `sigma_{C F Xi_inf}`, sphere maxima of sublinear functions). The closed loop is simulated by catching-up
//! (`h = min(T/2000, 0.0025)`) for a transient of `max(15/|mu|, 2T)` rounded up to whole periods (mu in `[-2, -1]`),
//! then 3 periods are measured: path length per period `sum |Dz|` (minimum over the periods)
//! and speed `max |Dz|/h`.
//! Tolerance (discretisation, first-order scheme): `2%` of the right-hand side. The scheme's
//! `max |Dz|/h` overshoots the continuous speed by O(h); the step is chosen on a measured case
//! (`proofs-notes/theorem2-zinf.md`, "Step").
//! Negative controls: (path) `d` replaced by `0` (the tube ignored); (zinf) the bound halved.
use super::sets_prelude::*;
use super::simulation::simulate;
use crate::strategies::inputs::InputStrategyConfig;
use crate::strategies::systems::{system_params, SystemParams, SystemStrategyConfig};
use bounds::orbit::{EtaOrbit, OrbitSettings};
use bounds::tube::{tube_diameters_with, SemigroupData, TubeSettings};
use dynamics::periodic::linearised::{linearised_periodic, LinearisedPeriodic, LinearisedSettings};
use geometry::SphereMaxSettings;

/// Sample intervals of `eta_T` over one period (for `osc` and `||eta_T'||_inf`).
pub const ORBIT_SAMPLES: usize = 1000;
/// Steps per period of the catching-up scheme (capped by [`MAX_DT`]).
pub const STEPS_PER_PERIOD: usize = 2000;
/// Largest step.
pub const MAX_DT: f64 = 2.5e-3;
/// Transient: `TRANSIENT_DECAYS / |mu|` (at least `2 T`), rounded up to whole periods.
pub const TRANSIENT_DECAYS: f64 = 15.0;
/// Tolerance of the tube quadrature relative to `D(Theta, {0})` (the enclosures stay rigorous;
/// only their width depends on it).
pub const TUBE_TOL_REL: f64 = 1e-4;

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
    let lin = orbit_samples(sys)?;
    let osc = lin.osc_lower();
    let deta_inf = lin.deta_inf_sampled();
    // d and D(...) by the production kernels of `bounds` (the numbers `moreau theta` prints),
    // at a tolerance matched to the 2 % allowance of the check. `D(Theta, {0})` (a sphere
    // maximum for an ellipsoid) and the semigroup bounds of `F` are computed once and shared
    // by both kernels (`tube_diameters_with`: the same numbers as `tube_diameters`).
    let d_theta = sys.theta.deviation_from_origin().upper;
    let tube = TubeSettings { tol_abs: TUBE_TOL_REL * d_theta.max(f64::MIN_POSITIVE), ..TubeSettings::default() };
    let st = SphereMaxSettings { tol_abs: 1e-9, tol_rel: 1e-3, max_evals: 2_000 };
    let F = sys.F();
    let sg = SemigroupData::new(&F);
    let diam = tube_diameters_with(&sys.C, &F, &sys.E, &sys.theta, d_theta, &sg, &tube, &st).ok()?;
    let (d_upper, D_upper) = (diam.d.upper, diam.d_ftheta.upper);
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

/// Samples of `eta_T` and `eta_T'` at `t_k = k T / ORBIT_SAMPLES`, `k = 0..=ORBIT_SAMPLES`.
/// Sine input: the closed form of `bounds::orbit::EtaOrbit` (`eta_T = P sin + Q cos` from the
/// phasor `(i omega I - F)^{-1} B a`, one complex solve; the same grid and the same samples up
/// to rounding as the matrix exponentials of `linearised_periodic`, which cost ~1,000 `expm`
/// per case), used when its rounding margin `16 n cond eps` is below `1e-3` (`verified`);
/// otherwise, and for other inputs, `dynamics::periodic::linearised_periodic` as before.
/// `None` when neither applies (resonant period).
pub fn orbit_samples(sys: &model::System) -> Option<LinearisedPeriodic> {
    if let model::Input::Sine { .. } = sys.input {
        if let Ok(o) = EtaOrbit::new(sys, &OrbitSettings { samples: ORBIT_SAMPLES }) {
            let finite = o.eta.iter().chain(&o.deta).all(|v| v.iter().all(|x| x.is_finite()));
            if o.verified && finite {
                return Some(LinearisedPeriodic {
                    period: o.period,
                    t: o.t,
                    xi: Vec::new(),
                    dxi: Vec::new(),
                    eta: o.eta,
                    deta: o.deta,
                    exact: true,
                });
            }
        }
    }
    linearised_periodic(sys, &LinearisedSettings { samples: ORBIT_SAMPLES, substeps: 8 }).ok()
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

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::strategy::ValueTree;
    use proptest::test_runner::TestRunner;

    /// The closed-form samples agree with the exponentials of `linearised_periodic` (the
    /// previous computation) on random systems of the campaign, and give the same `osc` and
    /// `||eta_T'||` up to rounding.
    #[test]
    fn closed_form_orbit_matches_linearised_periodic() {
        let strat = strategy();
        let mut runner = TestRunner::deterministic();
        for _ in 0..40 {
            let sys = strat.new_tree(&mut runner).unwrap().current().build();
            let a = orbit_samples(&sys).expect("sine input");
            let b = linearised_periodic(&sys, &LinearisedSettings { samples: ORBIT_SAMPLES, substeps: 8 }).unwrap();
            let scale = 1.0 + b.osc_lower() + b.deta_inf_sampled();
            for (x, y) in a.eta.iter().zip(&b.eta).chain(a.deta.iter().zip(&b.deta)) {
                assert!(dist(x, y) <= 1e-9 * scale, "{x:?} vs {y:?}");
            }
            assert!((a.osc_lower() - b.osc_lower()).abs() <= 1e-9 * scale);
            assert!((a.deta_inf_sampled() - b.deta_inf_sampled()).abs() <= 1e-9 * scale);
        }
    }
}
