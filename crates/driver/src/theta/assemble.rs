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
use crate::error::DriverError;
use crate::orbit::{packing_bound, partition_bound, path_bound, EtaOrbit, OrbitSettings, PackingBound};
use crate::report::{BoundKind, Quantity};
use crate::stationary::{rest_set, RestSet, RestSetSettings};
use crate::theta::alpha::{alpha, Alpha};
use crate::theta::psi::Psi;
use crate::tube::{sublinear_sphere_max, Horizon, TubeKernel, TubeSettings};
use dynamics::rate::lyapunov_exponent::{measure_rate, RateSettings};
use geometry::{ConvexSet, Shape, SphereMaxSettings};
use lmi::{optimise_lambda, LambdaSearchSettings, LmiError};
use model::System;
use nalgebra::DMatrix;
use std::sync::Arc;

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
    /// Number of `eps` values of the (path2) packing search. Default `64`.
    pub packing_eps: usize,
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
            packing_eps: 64,
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
    /// `theta < 0` and verified: a unique periodic regime attracting at rate `theta`.
    pub convergence_guaranteed: bool,
    pub path_bound: f64,
    pub path1_bound: f64,
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
    #[serde(skip)]
    tube_C: Arc<TubeKernel>,
    #[serde(skip)]
    theta_set: Shape,
    #[serde(skip)]
    orbit: Arc<EtaOrbit>,
}

fn sigma_theta_sum(theta: &Shape, v: &[f64]) -> f64 {
    let neg: Vec<f64> = v.iter().map(|x| -x).collect();
    theta.support(v) + theta.support(&neg)
}

/// Computes `theta` and all its parts for `sys`; see the module docs.
///
/// Errors (no answer exists): no period ([`DriverError::NoPeriod`]), `F` not Hurwitz
/// ([`DriverError::NotHurwitz`]), no certified `lambda` ([`DriverError::Lmi`]), tube
/// quadrature budget. Everything else (singular `Phi`, infinite `R`, unverifiable parts) is
/// reported in the result.
pub fn assemble(sys: &System, settings: &ThetaSettings) -> Result<ThetaReport, DriverError> {
    let T = sys.period().ok_or(DriverError::NoPeriod { kind: sys.input.kind() })?;
    let F = sys.F();
    let (C, E) = (&sys.C, &sys.E);
    let p = sys.p();
    let mu = match lmi::hurwitz_mu(&F) {
        Ok(mu) => mu,
        Err(LmiError::NotHurwitz { mu }) => return Err(DriverError::NotHurwitz { mu }),
        Err(e) => return Err(DriverError::Lmi(e)),
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
    let d_theta = theta_set.deviation_from_origin().upper;

    // Tubes C Xi_inf and C F Xi_inf (eqs. (d), (zinf)).
    let tube_C = TubeKernel::new(C, &F, E, &theta_set, Horizon::Infinite, &settings.tube)?;
    let CF = C * &F;
    let tube_CF = TubeKernel::new(&CF, &F, E, &theta_set, Horizon::Infinite, &settings.tube)?;

    // d = max_{|v|=1} sigma_{C Xi_inf + Theta}(v) + sigma_{C Xi_inf + Theta}(-v), eq. (d).
    let lip_d = 2.0 * (tube_C.lipschitz() + d_theta);
    let d_b = sublinear_sphere_max(
        p,
        |v| {
            let neg: Vec<f64> = v.iter().map(|x| -x).collect();
            tube_C.support_upper(v) + tube_C.support_upper(&neg) + sigma_theta_sum(&theta_set, v)
        },
        lip_d,
        &settings.sphere,
    );
    // Lower end: the same maximisation of the quadrature's lower enclosure at the maximiser
    // region is not tracked; report the sampled maximum of the upper function minus its width.
    let d = d_b.upper;
    let d_lower = d_b.lower - 2.0 * (tube_C.remainder_bound() + tube_C.tail_bound());

    // D(C(F Xi_inf + E Theta), {0}) = max_{|v|=1} sigma_{C F Xi_inf}(v) + sigma_Theta(E^T C^T v).
    let CEt = (C * E).transpose();
    let nCE = CEt.iter().map(|x| x * x).sum::<f64>().sqrt();
    let lip_f = tube_CF.lipschitz() + nCE * d_theta * (1.0 + 1e-12);
    let df_b = sublinear_sphere_max(
        p,
        |v| {
            let w = &CEt * nalgebra::DVector::from_column_slice(v);
            tube_CF.support_upper(v) + theta_set.support(w.as_slice())
        },
        lip_f,
        &settings.sphere,
    );
    let d_ftheta = df_b.upper;
    let d_ftheta_lower = df_b.lower - tube_CF.remainder_bound() - tube_CF.tail_bound();

    // Orbit eta_T.
    let orbit = EtaOrbit::new(sys, &settings.orbit)?;
    let osc = orbit.osc;
    let osc_sampled = orbit.osc_sampled();
    let eta_dot_inf = orbit.eta_dot_inf;
    let zdot_bound = eta_dot_inf + d_ftheta;

    // gamma_1, gamma_inf, eqs. (g1), (ginf), at the upper bound of R.
    let strongly_convex = R.is_finite() && R > 0.0;
    let (gamma_1, gamma_inf) =
        if strongly_convex { ((osc - d).max(0.0) / (T * R), zdot_bound / R) } else { (0.0, 0.0) };
    if !strongly_convex {
        notes.push(format!(
            "R = {R}: Theta is not strongly convex, gamma = 0 (the paper's footnote case): theta = psi(0), and convergence is guaranteed only if psi(0) < 0, i.e. alpha > beta / lambda"
        ));
    }
    let kappa = if gamma_inf > 0.0 { (gamma_1 / gamma_inf).clamp(0.0, 1.0) } else { 0.0 };

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
    let d_ok = true; // sphere_max upper bounds with valid Lipschitz constants
    let theta_verified = zero_in_theta && R_verified && al.verified && cert_ok && orbit.verified && d_ok;
    if !orbit.verified {
        notes.push(format!("osc and ||eta_T'||_inf are estimates ({})", orbit.method));
    }

    // Path-length bounds (path), (path1), (path2).
    let idx = orbit.subsample(settings.path1_points);
    let sub: Vec<&[f64]> = idx.iter().map(|&i| orbit.eta[i].as_slice()).collect();
    let all: Vec<&[f64]> = orbit.eta.iter().map(|e| e.as_slice()).collect();
    let path_b = path_bound(osc, d);
    let path1 = partition_bound(&sub, d).max(path_b.min(0.0));
    let path2 = packing_bound(&all[..all.len() - 1], d, osc, settings.packing_eps);

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
        eta_dot_inf,
        d_ftheta,
        d_ftheta_lower,
        zdot_bound,
        gamma_1,
        gamma_inf,
        kappa,
        psi_0,
        psi_inf,
        theta,
        theta_verified,
        convergence_guaranteed: theta_verified && theta < 0.0,
        path_bound: path_b,
        path1_bound: path1,
        path1_grid: sub.len(),
        path2,
        curve,
        stationary,
        measured,
        tube_cells: tube_C.cells(),
        tube_s_max: tube_C.s_max,
        tube_tail: tube_C.tail_bound(),
        notes,
        tube_C: Arc::new(tube_C),
        theta_set,
        orbit: Arc::new(orbit),
    })
}

impl ThetaReport {
    /// `psi` of eq. (phipsi) at the certified `(alpha_lower, lambda, b_hat)`.
    pub fn psi(&self) -> Psi {
        Psi { alpha: self.alpha.lower, lambda: self.lambda, beta: self.beta }
    }

    /// Enclosure of the support function of `C Xi_inf` (eq. (Xinfsupp) with `u = C^T v`).
    pub fn tube_support(&self, v: &[f64]) -> geometry::Bounds {
        self.tube_C.support_bounds(v)
    }

    /// Upper bound of the support function of `C Xi_inf + Theta` (the cross-section of the
    /// tube of Fig. loop around `eta_T`).
    pub fn tube_theta_support_upper(&self, v: &[f64]) -> f64 {
        self.tube_C.support_upper(v) + self.theta_set.support(v)
    }

    /// The orbit `eta_T` (samples, closed-form `osc`, `||eta_T'||`).
    pub fn orbit(&self) -> &EtaOrbit {
        &self.orbit
    }

    /// The labelled quantities in report order.
    pub fn quantities(&self) -> Vec<Quantity> {
        use BoundKind::*;
        let r_ok = self.R_verified;
        let mut q = vec![
            Quantity::new("period", "T", "(xT)", self.period, Exact, true, "period of the input"),
            Quantity::new("mu", "mu", "(stab)", self.mu, Estimate, false, "max Re eig(F), F = A + E C (Schur form)"),
            Quantity::new("r", "R", "(R)", self.R, Upper, r_ok, "strong convexity constant of Theta"),
            Quantity::new(
                "alpha",
                "alpha",
                "(alpha)",
                self.alpha.lower,
                Lower,
                self.alpha.verified,
                "lambda_min(S(C E)), Rump's test",
            ),
            Quantity::new(
                "lambda",
                "lambda",
                "(lammu),(ALI)",
                self.lambda,
                Lower,
                self.certificate_verified,
                "verified decay rate of the certificate",
            ),
            Quantity::new(
                "beta",
                "beta",
                "(bet)",
                self.beta,
                Upper,
                self.certificate_verified,
                "b_hat >= lambda_max(H^T Pi^-1 H), SDP + verification",
            ),
            Quantity::new("osc", "osc", "(mho),(osc)", self.osc, Lower, self.orbit_verified, self.orbit_method.clone()),
            Quantity::new(
                "d",
                "d",
                "(d),(Xinfsupp)",
                self.d,
                Upper,
                true,
                "tube quadrature + tail (DXX), certified sphere max",
            ),
            Quantity::new(
                "eta_dot_inf",
                "||eta_T'||_inf",
                "(zinf)",
                self.eta_dot_inf,
                Upper,
                self.orbit_verified,
                "max speed of the linearised orbit",
            ),
            Quantity::new(
                "d_ftheta",
                "D(C(F Xi_inf + E Theta),{0})",
                "(zinf)",
                self.d_ftheta,
                Upper,
                true,
                "tube quadrature + certified sphere max",
            ),
            Quantity::new(
                "zdot_bound",
                "limsup |z'| <=",
                "(zinf)",
                self.zdot_bound,
                Upper,
                self.orbit_verified,
                "||eta_T'||_inf + D(...)",
            ),
            Quantity::new(
                "gamma_1",
                "gamma_1",
                "(g1)",
                self.gamma_1,
                Lower,
                self.orbit_verified && r_ok,
                "(osc - d)_+ / (T R), R upper",
            ),
            Quantity::new(
                "gamma_inf",
                "gamma_inf",
                "(ginf)",
                self.gamma_inf,
                Upper,
                self.orbit_verified && r_ok,
                "(||eta_T'|| + D(...)) / R at R upper (safe for theta)",
            ),
            Quantity::new(
                "psi_0",
                "psi(0)",
                "(psilim)",
                self.psi_0,
                Upper,
                self.alpha.verified && self.certificate_verified,
                "at (alpha, lambda) lower, beta upper",
            ),
            Quantity::new(
                "psi_inf",
                "psi(gamma_inf)",
                "(phipsi)",
                self.psi_inf,
                Upper,
                self.alpha.verified && self.certificate_verified,
                "at gamma_inf (R upper)",
            ),
            Quantity::new(
                "psi_limit",
                "-lambda",
                "(psilim)",
                -self.lambda,
                Exact,
                self.certificate_verified,
                "limit of psi at infinity",
            ),
            Quantity::new(
                "theta",
                "theta",
                "(theta)",
                self.theta,
                Upper,
                self.theta_verified,
                "psi(0) - (gamma_1/gamma_inf)(psi(0) - psi(gamma_inf))",
            ),
            Quantity::new(
                "path_bound",
                "(osc - d)_+",
                "(path)",
                self.path_bound,
                Lower,
                self.orbit_verified,
                "liminf path length of z per period",
            ),
            Quantity::new(
                "path1_bound",
                "sup_partitions",
                "(path1)",
                self.path1_bound,
                Lower,
                self.orbit_verified,
                format!("dynamic programming over a {}-point grid", self.path1_grid),
            ),
            Quantity::new(
                "path2_bound",
                "sup_eps (2eps-d)N_eps",
                "(path2)",
                self.path2.value,
                Lower,
                self.orbit_verified,
                format!("greedy packing, eps = {:.4}, N = {}", self.path2.eps, self.path2.count),
            ),
        ];
        if let Some(s) = &self.stationary {
            q.push(Quantity::new(
                "phi_first_singular",
                "first t with Phi(t) singular",
                "(Phi)",
                s.phi.first_singular.unwrap_or(f64::NAN),
                Estimate,
                false,
                format!("min sigma(Phi) on [0,T] = {:.3e}", s.phi.min_sigma),
            ));
            q.push(Quantity::new(
                "stationary_slack",
                "R(T) slack s*",
                "(stat1)",
                s.slack,
                // The grid relaxes (stat1), so its slack bounds the continuous one from below.
                if s.verified { Lower } else { Estimate },
                s.verified,
                format!(
                    "{} -> {}",
                    s.method,
                    match s.empty {
                        Some(true) => "empty",
                        Some(false) => "nonempty",
                        None => "undecided",
                    }
                ),
            ));
        }
        if let Some(m) = &self.measured {
            q.push(Quantity::new(
                "measured_rate",
                "measured exponent",
                "(VV)",
                m.rate,
                Estimate,
                false,
                format!("95% CI [{:.4}, {:.4}], {} periods", m.ci_low, m.ci_high, m.periods),
            ));
            q.push(Quantity::new(
                "path_measured",
                "measured path/period",
                "(path)",
                m.path_length_per_period,
                Estimate,
                false,
                "min over periods after the transient",
            ));
            q.push(Quantity::new(
                "zdot_measured",
                "measured limsup |z'|",
                "(zinf)",
                m.limsup_zdot,
                Estimate,
                false,
                "max over periods after the transient",
            ));
        }
        q
    }

    /// JSON object with stable snake_case keys (see the README of `moreau theta`).
    pub fn to_json(&self) -> serde_json::Value {
        use serde_json::json;
        let f = |v: f64| if v.is_finite() { json!(v) } else { serde_json::Value::Null };
        let quantities: Vec<serde_json::Value> =
            self.quantities().iter().map(|q| serde_json::to_value(q).unwrap_or_default()).collect();
        let mut m = serde_json::Map::new();
        m.insert("name".into(), json!(self.name));
        m.insert("n".into(), json!(self.n));
        m.insert("m".into(), json!(self.m));
        m.insert("p".into(), json!(self.p));
        m.insert("period".into(), json!(f(self.period)));
        m.insert("mu".into(), json!(f(self.mu)));
        m.insert("r".into(), json!(f(self.R)));
        m.insert("r_verified".into(), json!(self.R_verified));
        m.insert("alpha".into(), json!(f(self.alpha.lower)));
        m.insert("alpha_verified".into(), json!(self.alpha.verified));
        m.insert("lambda".into(), json!(f(self.lambda)));
        m.insert("beta".into(), json!(f(self.beta)));
        m.insert("certificate_verified".into(), json!(self.certificate_verified));
        m.insert("pi".into(), json!(self.Pi));
        m.insert("osc".into(), json!(f(self.osc)));
        m.insert("orbit_verified".into(), json!(self.orbit_verified));
        m.insert("d".into(), json!(f(self.d)));
        m.insert("eta_dot_inf".into(), json!(f(self.eta_dot_inf)));
        m.insert("d_ftheta".into(), json!(f(self.d_ftheta)));
        m.insert("zdot_bound".into(), json!(f(self.zdot_bound)));
        m.insert("gamma_1".into(), json!(f(self.gamma_1)));
        m.insert("gamma_inf".into(), json!(f(self.gamma_inf)));
        m.insert("kappa".into(), json!(f(self.kappa)));
        m.insert("psi_0".into(), json!(f(self.psi_0)));
        m.insert("psi_inf".into(), json!(f(self.psi_inf)));
        m.insert("psi_limit".into(), json!(f(-self.lambda)));
        m.insert("theta".into(), json!(f(self.theta)));
        m.insert("theta_verified".into(), json!(self.theta_verified));
        m.insert("convergence_guaranteed".into(), json!(self.convergence_guaranteed));
        m.insert("measured_rate".into(), json!(self.measured.as_ref().map(|m| f(m.rate))));
        m.insert("measured_rate_ci".into(), json!(self.measured.as_ref().map(|m| [f(m.ci_low), f(m.ci_high)])));
        m.insert("path_bound".into(), json!(f(self.path_bound)));
        m.insert("path1_bound".into(), json!(f(self.path1_bound)));
        m.insert("path2_bound".into(), json!(f(self.path2.value)));
        m.insert("path_measured".into(), json!(self.measured.as_ref().map(|m| f(m.path_length_per_period))));
        m.insert("zdot_measured".into(), json!(self.measured.as_ref().map(|m| f(m.limsup_zdot))));
        m.insert("stationary_set_empty".into(), json!(self.stationary.as_ref().and_then(|s| s.empty)));
        m.insert("stationary_verified".into(), json!(self.stationary.as_ref().map(|s| s.verified)));
        m.insert("stationary_point".into(), json!(self.stationary.as_ref().and_then(|s| s.point.clone())));
        m.insert("phi_first_singular".into(), json!(self.stationary.as_ref().and_then(|s| s.phi.first_singular)));
        m.insert("tube_cells".into(), json!(self.tube_cells));
        m.insert("tube_tail_dxx".into(), json!(f(self.tube_tail)));
        m.insert("lambda_curve".into(), json!(self.curve));
        m.insert("notes".into(), json!(self.notes));
        m.insert("quantities".into(), json!(quantities));
        serde_json::Value::Object(m)
    }
}

/// `F` of eq. (F) (convenience re-export for callers holding only the report's system).
pub fn linearised_matrix(sys: &System) -> DMatrix<f64> {
    sys.F()
}
