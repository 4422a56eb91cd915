//! The report of [`crate::assemble()`]: [`ThetaReport`] (every quantity of the theta
//! computation for one model, the paper's and those beyond it) and its renderings: the labelled
//! [`ThetaReport::quantities`] (text table, sweep columns) and [`ThetaReport::to_json`].
use crate::exponent::alpha::Alpha;
use crate::exponent::psi::Psi;
use crate::orbit::PackingBound;
use crate::report::{BoundKind, Quantity};
use crate::stationary::RestSet;

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
    /// The dominant multiplier's exponent from the same pairs
    /// (`dynamics::rate::multipliers`): `[exponent, ci_low, ci_high]`.
    pub multiplier: Option<[f64; 3]>,
    /// The stepping error added to both intervals (`RateSettings::step_check`); `None`: not
    /// estimated, the intervals are the regression's and the blocks' only.
    pub step_error: Option<f64>,
    /// The change at a 100 times smaller separation, added to both intervals too
    /// (`RateSettings::step_check`); `None`: not estimated.
    pub separation_error: Option<f64>,
}

/// The rows of the stationary set's check (eq. (stat1)): `Phi`'s first singular time and the
/// slack.
fn stationary_rows(s: &RestSet) -> Vec<Quantity> {
    use crate::report::defs::*;
    vec![
        PHI_FIRST_SINGULAR
            .with(s.phi.first_singular.unwrap_or(f64::NAN), false)
            .note(format!("min sigma(Phi) on [0,T] = {:.3e}", s.phi.min_sigma)),
        // The grid relaxes (stat1), so its slack bounds the continuous one from below.
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
    ]
}

/// The rows of the measurement (estimates, never verified): the exponent, the dominant
/// multiplier where found, the path length per period and the largest backlash speed.
fn measured_rows(m: &MeasuredSide) -> Vec<Quantity> {
    use crate::report::defs::*;
    let mut q = vec![MEASURED_RATE.with(m.rate, false).note(format!(
        "95% CI [{:.4}, {:.4}], {} periods{}",
        m.ci_low,
        m.ci_high,
        m.periods,
        step_note(m)
    ))];
    if let Some([e, lo, hi]) = m.multiplier {
        q.push(MEASURED_MULTIPLIER.with(e, false).note(format!("95% CI [{lo:.5}, {hi:.5}]{}", step_note(m))));
    }
    q.push(PATH_MEASURED.with(m.path_length_per_period, false));
    q.push(ZDOT_MEASURED.with(m.limsup_zdot, false));
    q
}

/// What a measured interval says about the stepping error.
fn step_note(m: &MeasuredSide) -> String {
    match (m.step_error, m.separation_error) {
        (Some(e), Some(s)) => {
            format!(", step h = {:.2e} (stepping error {e:.1e} and separation error {s:.1e} included)", m.h)
        }
        (Some(e), None) => format!(", step h = {:.2e} (stepping error {e:.1e} included)", m.h),
        _ => format!(", step h = {:.2e} (stepping and separation errors not included: --step-check)", m.h),
    }
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
    /// [`crate::beyond_paper::EngagedSpeed`]); `zdot_bound` otherwise. Never above `zdot_bound`.
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
    /// [`crate::beyond_paper::speed_profile`], proofs-notes/theta-profile.md), `<= theta*` up to the
    /// partition chosen.
    pub theta_profile: f64,
    pub theta_profile_verified: bool,
    /// The certified `lambda` at which `theta_profile` is attained, and the partition size.
    pub lambda_profile: f64,
    pub profile_intervals: usize,
    pub profile_cells: usize,
    /// `theta_engaged`: `theta_profile` with speed floors on the cells where the backlash is
    /// provably engaged (beyond the paper, [`crate::beyond_paper::speed_profile`]; p = 1:
    /// proofs-notes/theta-engaged.md; balls and ellipsoids for p >= 2:
    /// [`crate::beyond_paper::contact_floors`], proofs-notes/theta-engaged-balls.md),
    /// `<= theta_profile`. Equal to `theta_profile` and not verified for other sets with
    /// `p > 1` or when no cell is engaged.
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
    /// The speed profile, partition and certified points `theta_engaged` (or `theta_profile`)
    /// was computed from ([`crate::beyond_paper::ProfileEvidence`]; diagnostics, not rendered).
    #[serde(skip)]
    pub profile_evidence: Option<crate::beyond_paper::ProfileEvidence>,
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
                "no cell provably engaged (p >= 2: balls and ellipsoids only): equals theta_profile".to_string()
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
            q.extend(stationary_rows(s));
        }
        if let Some(m) = &self.measured {
            q.extend(measured_rows(m));
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
        m.insert(
            "measured_multiplier_ci".into(),
            json!(self.measured.as_ref().and_then(|m| m.multiplier).map(|[_, lo, hi]| [f(lo), f(hi)])),
        );
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
