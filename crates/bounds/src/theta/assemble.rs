//! Assembly of `theta`, eq. (theta), and of every quantity of Theorems 1 and 2 and Section 6
//! for one model, each labelled with its equation and flagged as a verified bound or an
//! estimate ([`crate::report::Quantity`]).
//!
//! Safe directions (NOTES.md): `d`, `||eta_T'||_inf`, `D(C(F Xi_inf + E Theta), {0})` from
//! above (tube quadrature with rigorous remainders, maxima over the unit sphere of
//! sublinear functions certified by conic combination on arcs, `crate::tube::sublinear_max`,
//! or by `geometry::sphere_max` with a valid Lipschitz constant for `p >= 3`); `osc` from below; `alpha`, `lambda`
//! from below and `beta` from above (`lmi` certificate); `R` from above. `theta` is increasing
//! in `R` (the ratio `gamma_1 / gamma_inf` does not depend on `R` and `psi(gamma_inf / R)`
//! increases with `R`), so both `gamma`s are evaluated at the upper bound of `R`: `gamma_inf` is
//! then not itself an upper bound of the true `gamma_inf`, but `theta` is one of the true `theta`.
//! `theta` is verified only if every part is.
use crate::error::BoundsError;
use crate::orbit::{
    packing_bound, partition_bound, partition_bound_local, path_bound, EtaOrbit, OrbitSettings, PackingBound,
};
use crate::report::{BoundKind, Quantity};
use crate::stationary::{rest_set, RestSet, RestSetSettings};
use crate::theta::alpha::{alpha, Alpha};
use crate::theta::psi::Psi;
use crate::theta::speed_profile::SpeedProfile;
use crate::tube::{tube_diameters_with, EngagedHistory, SemigroupData, TubeSettings};
use dynamics::rate::lyapunov_exponent::{measure_rate, RateSettings};
use geometry::{ConvexSet, SphereMaxSettings};
use lmi::{optimise_lambda, LambdaSearchSettings, LmiError};
use model::System;
use nalgebra::DMatrix;
use rounding::{ulp_down_nonzero, ulp_up};

/// Settings of [`assemble`]. All parts have documented defaults; `measure = None` and
/// `stationary = None` skip the two costly optional parts (for sweeps).
#[derive(Debug, Clone)]
pub struct ThetaSettings {
    /// Tube quadrature (eqs. (Xinfsupp), (DXX)). Default [`TubeSettings::default`].
    pub tube: TubeSettings,
    /// Maxima over the unit sphere (eqs. (d), (zinf)) of sublinear functions
    /// ([`crate::tube::sublinear_sphere_max`]). Default: `tol_abs 1e-9`, `tol_rel 1e-6`,
    /// `max_evals 20_000` (the bounds stay valid, only wider, when the budget runs out).
    pub sphere: SphereMaxSettings,
    /// Outer search over `lambda` and the beta SDPs. Default [`LambdaSearchSettings::default`].
    pub lambda: LambdaSearchSettings,
    /// Orbit samples. Default [`OrbitSettings::default`] (2000 intervals).
    pub orbit: OrbitSettings,
    /// Grid points of the (path1) dynamic programme (`O(K^2)`). Default `600`.
    pub path1_points: usize,
    /// p = 1: steps of the engaged-history table over half a period
    /// ([`crate::tube::EngagedHistory`]; two finite-horizon kernels each). `0` disables it.
    /// Default `16`.
    pub engaged_history_steps: usize,
    /// Number of `eps` values of the (path2) packing search. Default `64`.
    pub packing_eps: usize,
    /// Cells of the time-resolved speed profile of `theta_profile` (must divide
    /// `orbit.samples`; otherwise the largest divisor below it is used). Default `400`.
    pub profile_cells: usize,
    /// Every `profile_stride`-th cell boundary is a candidate partition point of the
    /// `theta_profile` dynamic programme (`O((cells/stride)^2)` intervals). Default `4`.
    pub profile_stride: usize,
    /// Stationary set of Theorem 1; `None` skips it. Default `Some(RestSetSettings::default())`.
    pub stationary: Option<RestSetSettings>,
    /// Measured side (pairs of simulated trajectories); `None` skips it. Default:
    /// `dt = 1e-3`, 40 periods, 10 transient, 2 pairs.
    pub measure: Option<RateSettings>,
}

impl Default for ThetaSettings {
    fn default() -> Self {
        Self {
            tube: TubeSettings::default(),
            sphere: SphereMaxSettings { tol_abs: 1e-9, tol_rel: 1e-6, max_evals: 20_000 },
            lambda: LambdaSearchSettings::default(),
            orbit: OrbitSettings::default(),
            path1_points: 600,
            engaged_history_steps: 16,
            packing_eps: 64,
            profile_cells: 400,
            profile_stride: 4,
            stationary: Some(RestSetSettings::default()),
            measure: Some(RateSettings { periods: 40, transient_periods: 10, pairs: 2, ..Default::default() }),
        }
    }
}

impl ThetaSettings {
    /// Cheap settings for sweeps: no measurement, no stationary set.
    pub fn bound_only() -> Self {
        Self { stationary: None, measure: None, ..Default::default() }
    }
}

/// The measured side: exponent of pairs of trajectories and the backlash motion.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[non_exhaustive]
pub struct MeasuredSide {
    /// Largest measured exponent over the pairs (`(1/2) slope of ln V`).
    pub rate: f64,
    pub ci_low: f64,
    pub ci_high: f64,
    /// Min over periods after the transient of the path length of `z` per period.
    pub path_length_per_period: f64,
    /// Max over periods after the transient of `|z'|`.
    pub limsup_zdot: f64,
    pub periods: usize,
    pub transient_periods: usize,
    pub h: f64,
}

/// Every quantity of the theta computation for one model.
#[derive(Debug, Clone, serde::Serialize)]
#[non_exhaustive]
pub struct ThetaReport {
    pub name: String,
    pub n: usize,
    pub m: usize,
    pub p: usize,
    /// Period `T` of the input.
    pub period: f64,
    /// `mu = max Re eig(F)`, eq. (stab).
    pub mu: f64,
    /// Upper bound of `R`, eq. (R) (`inf` for polytopes).
    pub R: f64,
    pub R_verified: bool,
    /// `0 in Theta`, eq. (0inZ) (assumed by Theorem 2).
    pub zero_in_theta: bool,
    pub alpha: Alpha,
    /// Verified `lambda` and `b_hat >= beta` at the optimum of eq. (theta) over `lambda`.
    pub lambda: f64,
    pub beta: f64,
    pub beta_sdp: f64,
    pub certificate_verified: bool,
    /// The certified `Pi` (rows).
    pub Pi: Vec<Vec<f64>>,
    pub osc: f64,
    /// `osc` from the samples (cross-check of the closed form).
    pub osc_sampled: f64,
    pub orbit_verified: bool,
    pub orbit_method: String,
    /// `d = diam(C Xi_inf + Theta)`, eq. (d): upper bound; `d_lower` is indicative only (best
    /// sampled value of the upper function minus the quadrature remainders), not a bound.
    pub d: f64,
    pub d_lower: f64,
    pub eta_dot_inf: f64,
    /// `D(C(F Xi_inf + E Theta), {0})`, eq. (zinf): upper bound; `d_ftheta_lower` indicative only.
    pub d_ftheta: f64,
    pub d_ftheta_lower: f64,
    /// Both tube diameters `d`, `D(...)` are proven upper bounds (computed by
    /// [`crate::tube::tube_diameters`]).
    pub d_verified: bool,
    /// Right-hand side of (zinf): `||eta_T'||_inf + D(...)`.
    pub zdot_bound: f64,
    pub gamma_1: f64,
    pub gamma_inf: f64,
    /// `kappa = gamma_1 / gamma_inf`.
    pub kappa: f64,
    pub psi_0: f64,
    pub psi_inf: f64,
    pub theta: f64,
    pub theta_verified: bool,
    /// Kinds of the model's `[[effects]]`: physics outside the paper's class (theta is then
    /// computed for the nominal model and is not verified for the model).
    pub effects: Vec<String>,
    /// The best verified bound ([`ThetaReport::theta_best`]) is `< 0`: a unique periodic regime
    /// attracting at that rate.
    pub convergence_guaranteed: bool,
    /// `gamma_1* = max((path), (path1), (path2)) / (T R)` (from below; `>= gamma_1`).
    pub gamma_1_star: f64,
    /// Upper bound of `limsup |z'|` with the backlash side pinned (p = 1,
    /// [`crate::tube::EngagedSpeed`]); `zdot_bound` otherwise. Never above `zdot_bound`.
    pub zdot_star_bound: f64,
    /// `gamma_inf* = zdot_star_bound / R` (from above; `<= gamma_inf`).
    pub gamma_inf_star: f64,
    /// `gamma_1* / gamma_inf*`.
    pub kappa_star: f64,
    /// `theta*`: eq. (theta) with `gamma_1*` (beyond the paper; proofs-notes/theta-star.md),
    /// minimised over the certified `(lambda, b_hat)` of the lambda search.
    pub theta_star: f64,
    pub theta_star_verified: bool,
    /// The certified `(lambda, b_hat)` at which `theta*` is attained.
    pub lambda_star: f64,
    pub beta_star: f64,
    /// `theta_profile`: the chord argument resolved in time (beyond the paper,
    /// [`crate::theta::speed_profile`], proofs-notes/theta-profile.md), `<= theta*` up to the
    /// partition chosen.
    pub theta_profile: f64,
    pub theta_profile_verified: bool,
    /// The certified `lambda` at which `theta_profile` is attained, and the partition size.
    pub lambda_profile: f64,
    pub profile_intervals: usize,
    pub profile_cells: usize,
    /// `theta_engaged` (p = 1): `theta_profile` with speed floors on the cells where the backlash
    /// is provably engaged (beyond the paper, [`crate::theta::speed_profile`],
    /// proofs-notes/theta-engaged.md), `<= theta_profile`. Equal to `theta_profile` and not
    /// verified when `p > 1` or no cell is engaged.
    pub theta_engaged: f64,
    pub theta_engaged_verified: bool,
    /// The certified `lambda` at which `theta_engaged` is attained, and the number of engaged
    /// cells (of `profile_cells`).
    pub lambda_engaged: f64,
    pub engaged_cells: usize,
    /// Which path bound gives `gamma_1*`: `(path)`, `(path1)` or `(path2)`.
    pub path_best_method: &'static str,
    /// The smallest verified bound of the exponent (of `theta`, `theta*`, `theta_profile`,
    /// `theta_engaged`), or `theta` when none is verified.
    pub theta_best: f64,
    /// `"theta"`, `"theta_star"`, `"theta_profile"` or `"theta_engaged"`.
    pub theta_best_method: &'static str,
    pub theta_best_verified: bool,
    pub path_bound: f64,
    pub path1_bound: f64,
    /// (path1) with the step-length-dependent loss `min(d, diam Theta + dt D)` (beyond the paper).
    pub path1_local_bound: f64,
    /// Number of grid points of the (path1) dynamic programme.
    pub path1_grid: usize,
    pub path2: PackingBound,
    /// Certified curve `(lambda, beta, theta)` of the lambda search.
    pub curve: Vec<(f64, f64, f64)>,
    pub stationary: Option<RestSet>,
    pub measured: Option<MeasuredSide>,
    /// Tube quadrature diagnostics: cells, truncation point, tail bound (DXX).
    pub tube_cells: usize,
    pub tube_s_max: f64,
    pub tube_tail: f64,
    pub notes: Vec<String>,
}

/// Computes `theta` and all its parts for `sys`; see the module docs.
///
/// Errors (no answer exists): no period ([`BoundsError::NoPeriod`]), `F` not Hurwitz
/// ([`BoundsError::NotHurwitz`]), no certified `lambda` ([`BoundsError::Lmi`]), tube
/// quadrature budget. Everything else (singular `Phi`, infinite `R`, unverifiable parts) is
/// reported in the result.
pub fn assemble(sys: &System, settings: &ThetaSettings) -> Result<ThetaReport, BoundsError> {
    let T = sys.period().ok_or(BoundsError::NoPeriod { kind: sys.input.kind() })?;
    let F = sys.F();
    let (C, E) = (&sys.C, &sys.E);
    let p = sys.p();
    let mu = match lmi::hurwitz_mu(&F) {
        Ok(mu) => mu,
        Err(LmiError::NotHurwitz { mu }) => return Err(BoundsError::NotHurwitz { mu }),
        Err(e) => return Err(BoundsError::Lmi(e)),
    };
    let mut notes = Vec::new();
    let theta_set = sys.theta.clone();
    let zero_in_theta = theta_set.contains(&vec![0.0; p], 0.0);
    if !zero_in_theta {
        notes.push("0 is not in Theta: assumption (0inZ) of Theorem 2 fails, theta is not a verified bound".into());
    }
    let sc = theta_set.strong_convexity();
    let R = sc.upper();
    // R = inf is trivially a valid upper bound (polytopes: gamma = 0).
    let R_verified = sc.is_verified_upper() || R == f64::INFINITY;

    // Tubes C Xi_inf and C F Xi_inf and their diameters (eqs. (d), (zinf)).
    // (issue 15) the tube covers every F in the enclosure of fl(A + fl(E C)).
    let tube = crate::tube::TubeSettings {
        f_radius: lmi::verify::f_enclosure_radius(&F, E, C).norm() * (1.0 + 1e-10),
        ..settings.tube
    };
    // One semigroup of F for every tube kernel of this report (the tube diameters and, for
    // p = 1, the engaged history).
    let sg = SemigroupData::new(&F);
    let d_theta = theta_set.deviation_from_origin().upper;
    let diam = tube_diameters_with(C, &F, E, &theta_set, d_theta, &sg, &tube, &settings.sphere)?;
    let (d, d_lower) = (diam.d.upper, diam.d.lower);
    let (d_ftheta, d_ftheta_lower) = (diam.d_ftheta.upper, diam.d_ftheta.lower);
    let d_ok = diam.verified;
    // p = 1: Theta = [lo, hi]; (zinf) with the backlash side pinned (beyond the paper,
    // tube::engaged_speed): the engaged history's band at tau = 0.
    // (support values from above: exact for an interval, an enclosing interval for any other
    // set in R^1)
    let lo_hi = (p == 1).then(|| (-theta_set.support_upper(&[-1.0]), theta_set.support_upper(&[1.0])));
    let engaged_speed = match lo_hi {
        Some((lo, hi)) => {
            EngagedHistory::new(&diam.tube_CF, C, &F, E, (lo, hi), &sg, &tube, 1.0, 0)?.map(|h| h.pinned(lo, hi))
        }
        None => None,
    };
    let tube_C = diam.tube_C;

    // Orbit eta_T.
    let orbit = EtaOrbit::new(sys, &settings.orbit)?;
    let osc = orbit.osc;
    let osc_sampled = orbit.osc_sampled();
    let eta_dot_inf = orbit.eta_dot_inf;
    let zdot_bound = eta_dot_inf + d_ftheta;
    let zdot_star = engaged_speed.map_or(zdot_bound, |es| es.zdot_bound(eta_dot_inf).min(zdot_bound));

    // gamma_1, gamma_inf, eqs. (g1), (ginf), at the upper bound of R.
    let strongly_convex = R.is_finite() && R > 0.0;
    // (issue 15) rounded safely: gamma_1 down, gamma_inf up (theta increases with gamma_inf), by
    // 8u relative on top of the <= 3 roundings of each formula.
    let (gamma_1, gamma_inf) = if strongly_convex {
        (
            ulp_down_nonzero((osc - d).max(0.0) / (T * R) * (1.0 - 4.0 * f64::EPSILON)),
            ulp_up(zdot_bound / R * (1.0 + 4.0 * f64::EPSILON)),
        )
    } else {
        (0.0, 0.0)
    };
    if !strongly_convex {
        notes.push(format!(
            "R = {R}: Theta is not strongly convex, gamma = 0 (the paper's footnote case): theta = psi(0) >= 0 for every admissible Pi (proofs-notes/psi0.md), so eq. (theta) cannot certify convergence here"
        ));
    }
    let kappa = if gamma_inf > 0.0 { ulp_down_nonzero(gamma_1 / gamma_inf).clamp(0.0, 1.0) } else { 0.0 };

    // alpha, eq. (alpha), and the lambda search (eqs. (ALI), (bet), (theta)).
    let al = alpha(C, E);
    let a_low = al.lower;
    let search = optimise_lambda(
        &F,
        E,
        C,
        |l, b| Psi { alpha: a_low, lambda: l, beta: b }.theta(gamma_1, gamma_inf),
        &settings.lambda,
    )?;
    let opt = &search.optimum;
    let psi = Psi { alpha: a_low, lambda: opt.value.lambda, beta: opt.value.beta };
    let psi_0 = psi.at_zero();
    let psi_inf = psi.eval(gamma_inf);
    let theta = psi.theta(gamma_1, gamma_inf);
    let curve: Vec<(f64, f64, f64)> =
        search.curve.iter().filter_map(|c| c.value.as_ref().ok().map(|v| (v.lambda, v.beta, v.theta))).collect();
    if !search.gaps.is_empty() {
        notes.push(format!(
            "lambda search: {} of {} evaluations failed (gaps in the curve)",
            search.gaps.len(),
            search.curve.len()
        ));
    }
    let cert_ok = opt.certificate.verified;
    // Effects (friction, inertia, delay, ...) are outside the paper's class: theta below is the
    // nominal model's and proves nothing about the model with effects.
    let effects: Vec<String> = sys.effects.list.iter().map(|e| e.kind().to_string()).collect();
    if !effects.is_empty() {
        notes.push(format!(
            "the model has effects outside the paper's class ({}): theta is computed for the nominal model without them and is NOT a certificate for this model (with friction or inertia a continuum of stationary regimes can exist)",
            effects.join(", ")
        ));
    }
    let theta_verified =
        zero_in_theta && R_verified && al.verified && cert_ok && orbit.verified && d_ok && effects.is_empty();
    if !orbit.verified {
        notes.push(format!("osc and ||eta_T'||_inf are estimates ({})", orbit.method));
    }

    // Path-length bounds (path), (path1), (path2).
    let idx = orbit.subsample(settings.path1_points);
    let sub: Vec<&[f64]> = idx.iter().map(|&i| orbit.eta[i].as_slice()).collect();
    let all: Vec<&[f64]> = orbit.eta.iter().map(|e| e.as_slice()).collect();
    let path_b = path_bound(osc, d);
    // The closed-form samples lie within rel_margin * rho of the orbit (rho = osc / (2 (1 - margin))
    // <= osc): each distance between two samples is within 2 rel_margin osc of the true one, so
    // the partition sums use a loss d + 2 rel_margin osc (0 for exact or grid samples).
    let d_path = d + 2.0 * orbit.rel_margin * osc * (1.0 + 1e-12);
    let path1 = partition_bound(&sub, d_path).max(path_b.min(0.0));
    let path2 = packing_bound(&all[..all.len() - 1], d_path, osc, settings.packing_eps);
    // (path1) with the loss min(d, diam(Theta) + dt D(C(F Xi_inf + E Theta),{0})) per step of
    // length dt (proofs-notes/theta-star.md): the same partitions, a smaller loss on short steps.
    let sub_t: Vec<f64> = idx.iter().map(|&i| orbit.t[i]).collect();
    let diam_theta = theta_set.diameter().upper;
    let diam_path = diam_theta + 2.0 * orbit.rel_margin * osc * (1.0 + 1e-12);
    let path_local = partition_bound_local(&sub, &sub_t, d_path, diam_path, d_ftheta).max(path1);

    // Speed profile per cell (theta_profile, theta_engaged), built before theta* because its
    // largest ceiling also bounds limsup |z'|.
    let cells = largest_divisor_at_most(orbit.t.len() - 1, settings.profile_cells.max(1));
    let profile = match (strongly_convex, orbit.eta_dot_cells(cells)) {
        (true, Some((edot, nodes))) => {
            let prof = SpeedProfile::new(T, nodes, &edot, d_ftheta, d, R);
            // p = 1: the signed speed bounds (tube::engaged_speed) lower the cells' ceilings
            match (&engaged_speed, orbit.deta_cells_scalar(cells)) {
                (Some(es), Some((low, high))) => Some(prof.with_signed_speed(&low, &high, es)),
                _ => Some(prof),
            }
        }
        _ => None,
    };
    // theta_engaged (beyond the paper, p = 1): the profile with speed floors where the backlash
    // is provably engaged (the output has moved monotonically by Theta's width), partition by
    // dynamic programming again (the floors change which intervals matter), then the best
    // certified (lambda, b_hat) of the curve (proofs-notes/theta-engaged.md).
    let engaged = match (&profile, orbit.deta_cells_scalar(cells), lo_hi) {
        (Some(prof), Some((low, high)), Some((lo, hi))) => {
            let width = (hi - lo) * (1.0 + 1e-12);
            let prof = prof.clone().with_floors(&low, &high, d_ftheta, width);
            // the engaged history narrows the band of z' - eta_T' on engaged cells
            // (tube::EngagedHistory; proofs-notes/theta-engaged.md), tabulated on
            // tau_j = j T / (2 history_steps) up to the longest engaged history of the profile
            let oldest = prof.engaged_age.iter().flatten().map(|&(_, a)| a).max().unwrap_or(0) as f64 * prof.h;
            let steps = settings.engaged_history_steps;
            let dtau = T / (2.0 * steps.max(1) as f64);
            let needed = ((oldest / dtau).floor() as usize).min(steps);
            let history = if needed > 0 {
                EngagedHistory::new(&diam.tube_CF, C, &F, E, (lo, hi), &sg, &tube, dtau, needed).unwrap_or_else(|e| {
                    notes.push(format!("engaged history not computed: {e}"));
                    None
                })
            } else {
                None
            };
            let prof = match &history {
                Some(h) => prof.with_history(&low, &high, h, lo, hi),
                None => prof,
            };
            (prof.engaged_cells() > 0 && width.is_finite()).then_some(prof)
        }
        _ => None,
    };
    // theta_profile uses the engaged profile's ceilings (valid at every time of their cells)
    // without its floors.
    let profile = match &engaged {
        Some(e) => {
            let mut prof = e.clone();
            prof.floor.iter_mut().for_each(|f| *f = 0.0);
            Some(prof)
        }
        None => profile,
    };
    // theta* (beyond eq. (g1)): the chord argument of eq. (theta) with gamma_1 from the
    // strongest proven path bound. Over a window of k periods the path of z is at least
    // k S - (one wrap-around term), S any cyclic partition sum (path1) or packing sum (path2),
    // so the long-run mean of |z'|/R is at least S / (T R): the same chord (psiup) then gives
    // theta* (proofs-notes/theta-star.md). Each (lambda, b_hat) of the certified curve gives a
    // valid theta*; the best is kept.
    let (path_best, path_best_method) =
        [(path_b, "(path)"), (path1, "(path1)"), (path2.value, "(path2)"), (path_local, "(path1-local)")]
            .into_iter()
            .fold((0.0f64, "(path)"), |a, b| if b.0 > a.0 { b } else { a });
    // Rounding of the sums of distances (at most 2000 terms, each within a few ulps): a relative
    // margin far above it.
    let path_safe = path_best * (1.0 - 1e-10);
    let gamma_1_star = if strongly_convex { ulp_down_nonzero(path_safe / (T * R)).max(gamma_1) } else { 0.0 };
    // gamma_inf*: the pinned speed bound, or the profile's largest cell ceiling if lower
    let max_cell_speed = profile.as_ref().map_or(f64::INFINITY, |p| p.max_speed());
    let (zdot_star, gamma_inf_star) = if strongly_convex {
        let zdot_star = zdot_star.min(ulp_up(max_cell_speed * R * (1.0 + 4.0 * f64::EPSILON)));
        (zdot_star, ulp_up(zdot_star / R * (1.0 + 4.0 * f64::EPSILON)).min(gamma_inf).min(max_cell_speed))
    } else {
        (zdot_star, 0.0)
    };
    let kappa_star =
        if gamma_inf_star > 0.0 { ulp_down_nonzero(gamma_1_star / gamma_inf_star).clamp(0.0, 1.0) } else { 0.0 };
    // Certified (lambda, b_hat) points for theta*: the paper's curve, plus a second lambda search
    // with theta* as its objective when gamma_1* > gamma_1 (theta*'s best lambda differs from
    // theta's); every point is a verified certificate, so the minimum over all is a bound.
    let mut star_points: Vec<(f64, f64)> = curve.iter().map(|&(l, b, _)| (l, b)).collect();
    if strongly_convex && (gamma_1_star > gamma_1 || gamma_inf_star < gamma_inf) {
        match optimise_lambda(
            &F,
            E,
            C,
            |l, b| Psi { alpha: a_low, lambda: l, beta: b }.theta(gamma_1_star, gamma_inf_star),
            &settings.lambda,
        ) {
            Ok(s2) => {
                star_points.extend(s2.curve.iter().filter_map(|c| c.value.as_ref().ok().map(|v| (v.lambda, v.beta))))
            }
            Err(e) => notes.push(format!("second lambda search (for theta*) failed: {e}")),
        }
    }
    let (theta_star, lambda_star, beta_star) = star_points
        .iter()
        .map(|&(l, b)| (Psi { alpha: a_low, lambda: l, beta: b }.theta(gamma_1_star, gamma_inf_star), l, b))
        .fold((theta, opt.value.lambda, opt.value.beta), |a, c| if c.0 < a.0 { c } else { a });
    // The same proof obligations as theta (the path bounds use the same d and orbit samples).
    let theta_star_verified = theta_verified;

    // (theta_profile, its certified (lambda, b_hat), partition size)
    let (theta_profile, (lambda_profile, beta_profile), profile_intervals) = match &profile {
        Some(prof) => {
            let nodes = prof
                .best_partition(&Psi { alpha: a_low, lambda: lambda_star, beta: beta_star }, settings.profile_stride);
            let (v, at) = best_certified_point(prof, &nodes, a_low, &star_points);
            (v.min(theta_star), if v <= theta_star { at } else { (lambda_star, beta_star) }, nodes.len() - 1)
        }
        None => (theta_star, (lambda_star, beta_star), 0),
    };
    let theta_profile_verified = theta_verified && profile.is_some();

    let (theta_engaged, lambda_engaged, engaged_cells) = match &engaged {
        Some(prof) => {
            let nodes = prof.best_partition(
                &Psi { alpha: a_low, lambda: lambda_profile, beta: beta_profile },
                settings.profile_stride,
            );
            // the floors weigh psi at high speeds more than the chords do: a lambda search of
            // its own (every point a verified certificate, as for theta*)
            let mut points = star_points.clone();
            match optimise_lambda(
                &F,
                E,
                C,
                |l, b| prof.bound(&Psi { alpha: a_low, lambda: l, beta: b }, &nodes),
                &settings.lambda,
            ) {
                Ok(s3) => {
                    points.extend(s3.curve.iter().filter_map(|c| c.value.as_ref().ok().map(|v| (v.lambda, v.beta))))
                }
                Err(e) => notes.push(format!("third lambda search (for theta_engaged) failed: {e}")),
            }
            let (v, (l, _)) = best_certified_point(prof, &nodes, a_low, &points);
            (v.min(theta_profile), if v <= theta_profile { l } else { lambda_profile }, prof.engaged_cells())
        }
        None => (theta_profile, lambda_profile, 0),
    };
    let theta_engaged_verified = theta_profile_verified && engaged.is_some();
    let candidates = [
        (theta, "theta", theta_verified),
        (theta_star, "theta_star", theta_star_verified),
        (theta_profile, "theta_profile", theta_profile_verified),
        (theta_engaged, "theta_engaged", theta_engaged_verified),
    ];
    let (theta_best, theta_best_method, theta_best_verified) = candidates
        .iter()
        .filter(|c| c.2)
        .fold(None, |a: Option<(f64, &'static str, bool)>, c| match a {
            Some(b) if b.0 <= c.0 => Some(b),
            _ => Some(*c),
        })
        .unwrap_or((theta, "theta", theta_verified));

    // Stationary set (Theorem 1).
    let stationary = match &settings.stationary {
        Some(st) => match rest_set(sys, st) {
            Ok(r) => {
                if let Some(t) = r.phi.first_singular {
                    notes.push(format!("Phi(t) is singular at t = {t:.6} in [0, T]: Theorem 1's representation (stat1) fails there; R(T) is computed from (zin) instead"));
                }
                Some(r)
            }
            Err(e) => {
                notes.push(format!("stationary set not computed: {e}"));
                None
            }
        },
        None => None,
    };

    // Measured side.
    let measured = match &settings.measure {
        Some(_) if !effects.is_empty() => {
            notes.push("measured side not computed: the rate measurement simulates the paper's class only, and the model has effects".into());
            None
        }
        Some(ms) => {
            let mut ms = ms.clone();
            ms.pi = Some(opt.certificate.Pi.clone());
            match measure_rate(sys, &ms, None) {
                Ok(r) => Some(MeasuredSide {
                    rate: r.exponent,
                    ci_low: r.ci_low,
                    ci_high: r.ci_high,
                    path_length_per_period: r.path_length_per_period,
                    limsup_zdot: r.limsup_z_speed,
                    periods: r.periods,
                    transient_periods: r.transient_periods,
                    h: r.h,
                }),
                Err(e) => {
                    notes.push(format!("measured side not computed: {e}"));
                    None
                }
            }
        }
        None => None,
    };
    if let Some(m) = &measured {
        if theta < 0.0 && m.rate > theta {
            notes.push(format!("measured exponent {:.4} exceeds theta {:.4}: the bound is violated (or the measurement has not converged)", m.rate, theta));
        }
        if theta_best < 0.0 && m.rate > theta_best && theta_best < theta {
            notes.push(format!("measured exponent {:.4} exceeds {theta_best_method} {:.4}: the bound is violated (or the measurement has not converged)", m.rate, theta_best));
        }
    }

    let Pi: Vec<Vec<f64>> =
        (0..opt.certificate.Pi.nrows()).map(|i| opt.certificate.Pi.row(i).iter().copied().collect()).collect();
    Ok(ThetaReport {
        name: sys.name.clone(),
        n: sys.n(),
        m: sys.m(),
        p,
        period: T,
        mu,
        R,
        R_verified,
        zero_in_theta,
        alpha: al,
        lambda: opt.value.lambda,
        beta: opt.value.beta,
        beta_sdp: opt.value.beta_sdp,
        certificate_verified: cert_ok,
        Pi,
        osc,
        osc_sampled,
        orbit_verified: orbit.verified,
        orbit_method: orbit.method.to_string(),
        d,
        d_lower,
        d_verified: d_ok,
        eta_dot_inf,
        d_ftheta,
        d_ftheta_lower,
        zdot_bound,
        zdot_star_bound: zdot_star,
        gamma_inf_star,
        gamma_1,
        gamma_inf,
        kappa,
        psi_0,
        psi_inf,
        theta,
        theta_verified,
        effects,
        convergence_guaranteed: theta_best_verified && theta_best < 0.0,
        gamma_1_star,
        kappa_star,
        theta_star,
        theta_star_verified,
        lambda_star,
        beta_star,
        path_best_method,
        theta_best,
        theta_best_method,
        theta_best_verified,
        theta_profile,
        theta_profile_verified,
        lambda_profile,
        profile_intervals,
        profile_cells: if profile.is_some() { cells } else { 0 },
        theta_engaged,
        theta_engaged_verified,
        lambda_engaged,
        engaged_cells,
        path_bound: path_b,
        path1_bound: path1,
        path1_local_bound: path_local,
        path1_grid: sub.len(),
        path2,
        curve,
        stationary,
        measured,
        tube_cells: tube_C.cells(),
        tube_s_max: tube_C.s_max,
        tube_tail: tube_C.tail_bound(),
        notes,
    })
}

impl ThetaReport {
    /// `psi` of eq. (phipsi) at the certified `(alpha_lower, lambda, b_hat)`.
    pub fn psi(&self) -> Psi {
        Psi { alpha: self.alpha.lower, lambda: self.lambda, beta: self.beta }
    }

    /// The labelled quantities in report order ([`crate::report::defs::ALL`]; the stationary
    /// and measured ones only when computed).
    pub fn quantities(&self) -> Vec<Quantity> {
        use crate::report::defs::*;
        let r_ok = self.R_verified;
        let cert = self.certificate_verified;
        let orb = self.orbit_verified;
        let psi_ok = self.alpha.verified && cert;
        let mut q = vec![
            PERIOD.with(self.period, self.period.is_finite() && self.period > 0.0),
            MU.with(self.mu, false),
            R.with(self.R, r_ok),
            ALPHA.with(self.alpha.lower, self.alpha.verified),
            LAMBDA.with(self.lambda, cert),
            BETA.with(self.beta, cert),
            OSC.with(self.osc, orb).note(self.orbit_method.clone()),
            D.with(self.d, self.d_verified),
            ETA_DOT_INF.with(self.eta_dot_inf, orb),
            D_FTHETA.with(self.d_ftheta, self.d_verified),
            ZDOT_BOUND.with(self.zdot_bound, orb && self.d_verified),
            GAMMA_1.with(self.gamma_1, orb && r_ok && self.d_verified),
            GAMMA_INF.with(self.gamma_inf, orb && r_ok && self.d_verified),
            KAPPA.with(self.kappa, orb && self.d_verified),
            PSI_0.with(self.psi_0, psi_ok),
            PSI_INF.with(self.psi_inf, psi_ok),
            PSI_LIMIT.with(-self.lambda, cert),
            THETA.with(self.theta, self.theta_verified),
            GAMMA_1_STAR
                .with(self.gamma_1_star, orb && r_ok && self.d_verified)
                .note(format!("{} / (T R), R upper", self.path_best_method)),
            ZDOT_STAR.with(self.zdot_star_bound, orb && self.d_verified).note(if self.p == 1 {
                "backlash side pinned; largest cell ceiling with the engaged history".to_string()
            } else {
                "= (zinf) (the side is pinned only for p = 1)".to_string()
            }),
            GAMMA_INF_STAR.with(self.gamma_inf_star, orb && r_ok && self.d_verified),
            THETA_STAR
                .with(self.theta_star, self.theta_star_verified)
                .note(format!("eq. (theta) with gamma_1*, gamma_inf*, at lambda = {:.6}", self.lambda_star)),
            THETA_PROFILE.with(self.theta_profile, self.theta_profile_verified).note(format!(
                "time-resolved chord: {} cells, {} intervals, lambda = {:.6}",
                self.profile_cells, self.profile_intervals, self.lambda_profile
            )),
            THETA_ENGAGED.with(self.theta_engaged, self.theta_engaged_verified).note(if self.engaged_cells > 0 {
                format!(
                    "speed floors on {} of {} cells where the backlash is engaged, lambda = {:.6}",
                    self.engaged_cells, self.profile_cells, self.lambda_engaged
                )
            } else if self.p == 1 {
                "no cell provably engaged: equals theta_profile".to_string()
            } else {
                "p = 1 only: equals theta_profile".to_string()
            }),
            PATH_BOUND.with(self.path_bound, orb && self.d_verified),
            PATH1_BOUND
                .with(self.path1_bound, orb && self.d_verified)
                .note(format!("dynamic programming over a {}-point grid", self.path1_grid)),
            PATH1_LOCAL_BOUND
                .with(self.path1_local_bound, orb && self.d_verified)
                .note(format!("loss min(d, diam Theta + dt D) per step, {}-point grid", self.path1_grid)),
            PATH2_BOUND
                .with(self.path2.value, orb && self.d_verified)
                .note(format!("greedy packing, eps = {:.4}, N = {}", self.path2.eps, self.path2.count)),
        ];
        if let Some(s) = &self.stationary {
            q.push(
                PHI_FIRST_SINGULAR
                    .with(s.phi.first_singular.unwrap_or(f64::NAN), false)
                    .note(format!("min sigma(Phi) on [0,T] = {:.3e}", s.phi.min_sigma)),
            );
            // The grid relaxes (stat1), so its slack bounds the continuous one from below.
            q.push(
                STATIONARY_SLACK
                    .with(s.slack, s.verified)
                    .kind(if s.verified { BoundKind::Lower } else { BoundKind::Estimate })
                    .note(format!(
                        "{} -> {}",
                        s.method,
                        match s.empty {
                            Some(true) => "empty",
                            Some(false) => "nonempty",
                            None => "undecided",
                        }
                    )),
            );
        }
        if let Some(m) = &self.measured {
            q.push(
                MEASURED_RATE
                    .with(m.rate, false)
                    .note(format!("95% CI [{:.4}, {:.4}], {} periods", m.ci_low, m.ci_high, m.periods)),
            );
            q.push(PATH_MEASURED.with(m.path_length_per_period, false));
            q.push(ZDOT_MEASURED.with(m.limsup_zdot, false));
        }
        q
    }

    /// The quantity with this key, if it was computed.
    pub fn quantity(&self, key: &str) -> Option<Quantity> {
        self.quantities().into_iter().find(|q| q.key == key)
    }

    /// JSON object with stable snake_case keys (see the README of `moreau theta`): one key per
    /// declared quantity ([`crate::report::defs::ALL`]; `null` when not computed or not
    /// finite), the verified flags, the system's sizes, `Pi`, the lambda curve, notes, and the
    /// full `quantities` list.
    pub fn to_json(&self) -> serde_json::Value {
        use serde_json::json;
        let f = |v: f64| if v.is_finite() { json!(v) } else { serde_json::Value::Null };
        let quantities = self.quantities();
        let mut m = serde_json::Map::new();
        m.insert("name".into(), json!(self.name));
        m.insert("n".into(), json!(self.n));
        m.insert("m".into(), json!(self.m));
        m.insert("p".into(), json!(self.p));
        for def in crate::report::defs::ALL {
            let v = quantities.iter().find(|q| q.key == def.key).map(|q| f(q.value)).unwrap_or(serde_json::Value::Null);
            m.insert(def.key.into(), v);
        }
        m.insert("r_verified".into(), json!(self.R_verified));
        m.insert("alpha_verified".into(), json!(self.alpha.verified));
        m.insert("certificate_verified".into(), json!(self.certificate_verified));
        m.insert("orbit_verified".into(), json!(self.orbit_verified));
        m.insert("d_verified".into(), json!(self.d_verified));
        m.insert("theta_verified".into(), json!(self.theta_verified));
        m.insert("theta_star_verified".into(), json!(self.theta_star_verified));
        m.insert("theta_profile_verified".into(), json!(self.theta_profile_verified));
        m.insert("theta_engaged_verified".into(), json!(self.theta_engaged_verified));
        m.insert("theta_best".into(), json!(f(self.theta_best)));
        m.insert("theta_best_method".into(), json!(self.theta_best_method));
        m.insert("theta_best_verified".into(), json!(self.theta_best_verified));
        m.insert("kappa_star".into(), json!(f(self.kappa_star)));
        m.insert("convergence_guaranteed".into(), json!(self.convergence_guaranteed));
        m.insert("effects".into(), json!(self.effects));
        m.insert("pi".into(), json!(self.Pi));
        m.insert("measured_rate_ci".into(), json!(self.measured.as_ref().map(|m| [f(m.ci_low), f(m.ci_high)])));
        m.insert("stationary_set_empty".into(), json!(self.stationary.as_ref().and_then(|s| s.empty)));
        m.insert("stationary_verified".into(), json!(self.stationary.as_ref().map(|s| s.verified)));
        m.insert("stationary_point".into(), json!(self.stationary.as_ref().and_then(|s| s.point.clone())));
        m.insert("tube_cells".into(), json!(self.tube_cells));
        m.insert("tube_tail_dxx".into(), json!(f(self.tube_tail)));
        m.insert("lambda_curve".into(), json!(self.curve));
        m.insert("notes".into(), json!(self.notes));
        let qs: Vec<serde_json::Value> =
            quantities.iter().map(|q| serde_json::to_value(q).unwrap_or_default()).collect();
        m.insert("quantities".into(), json!(qs));
        serde_json::Value::Object(m)
    }
}

/// The largest divisor of `k` that is at most `at_most` (at least 1).
fn largest_divisor_at_most(k: usize, at_most: usize) -> usize {
    (1..=at_most.min(k).max(1)).rev().find(|&d| k.is_multiple_of(d)).unwrap_or(1)
}

/// `F` of eq. (F) (convenience re-export for callers holding only the report's system).
pub fn linearised_matrix(sys: &System) -> DMatrix<f64> {
    sys.F()
}

/// The smallest bound of `prof` with partition `nodes` over the certified `(lambda, b_hat)`
/// points, and the point attaining it (`(inf, (NaN, NaN))` without points).
fn best_certified_point(prof: &SpeedProfile, nodes: &[usize], alpha: f64, points: &[(f64, f64)]) -> (f64, (f64, f64)) {
    points
        .iter()
        .map(|&(l, b)| (prof.bound(&Psi { alpha, lambda: l, beta: b }, nodes), (l, b)))
        .fold((f64::INFINITY, (f64::NAN, f64::NAN)), |a, c| if c.0 < a.0 { c } else { a })
}
