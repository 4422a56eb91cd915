//! Assembly of `theta`, eq. (theta), and of every quantity of Theorems 1 and 2 and Section 6
//! for one model, each labelled with its equation and flagged as a verified bound or an
//! estimate ([`crate::report::Quantity`]).
//!
//! [`assemble`] is a list of named stages, in the order of the data flow (each stage needs the
//! ones above it: the lambda search minimises eq. (theta), which needs the gammas):
//! 1. [`plant`]: the period `T`, `F` (eq. (F)), `mu` (eq. (stab)), `R` (eq. (R)), (0inZ);
//! 2. [`tubes`]: the tube diameters `d` and `D(C(F Xi_inf + E Theta),{0})` (eqs. (d), (zinf));
//!    then, beyond the paper, the pinned speed for `p = 1`
//!    ([`crate::beyond_paper::pinned_speed`]);
//! 3. the orbit `eta_T`: `osc` (eq. (mho)) and `||eta_T'||_inf` ([`EtaOrbit`]);
//! 4. [`gammas`]: `gamma_1`, `gamma_inf`, `kappa` (eqs. (g1), (ginf));
//! 5. [`certificate`]: `alpha` (eq. (alpha)) and the certified `Pi`, `lambda`, `beta` of the
//!    lambda search (eqs. (ALI), (bet)) minimising eq. (theta);
//! 6. [`theta`]: `psi` (eq. (phipsi)) and `theta` (eq. (theta)), and whether it is verified;
//! 7. [`path_lengths`]: the path bounds (path), (path1), (path2) of Theorem 2;
//! 8. the bounds beyond the paper, `theta*`, `theta_profile`, `theta_engaged` and the best
//!    verified one ([`crate::beyond_paper::extensions`]);
//! 9. [`stationary`] (Theorem 1) and the [`measured`] side (optional);
//! 10. [`report`]: the [`ThetaReport`].
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
use crate::beyond_paper::{self, Extensions, FromPaper};
use crate::error::BoundsError;
use crate::exponent::alpha::{alpha, Alpha};
use crate::exponent::psi::Psi;
use crate::orbit::{packing_bound, partition_bound, path_bound, EtaOrbit, PackingBound};
use crate::report::{MeasuredSide, ThetaReport};
use crate::settings::ThetaSettings;
use crate::stationary::{rest_set, RestSet};
use crate::tube::{tube_diameters_with, SemigroupData, TubeDiameters, TubeSettings};
use dynamics::rate::lyapunov_exponent::measure_rate;
use geometry::ConvexSet;
use lmi::{optimise_lambda_memo, BetaMemo, LambdaSearch, LmiError};
use model::System;
use nalgebra::DMatrix;
use rounding::{ulp_down_nonzero, ulp_up};

mod memo;
pub use memo::Memo;

/// Computes `theta` and all its parts for `sys`; see the module docs.
///
/// Errors (no answer exists): no period ([`BoundsError::NoPeriod`]), `F` not Hurwitz
/// ([`BoundsError::NotHurwitz`]), no certified `lambda` ([`BoundsError::Lmi`]), tube
/// quadrature budget. Everything else (singular `Phi`, infinite `R`, unverifiable parts) is
/// reported in the result.
pub fn assemble(sys: &System, settings: &ThetaSettings) -> Result<ThetaReport, BoundsError> {
    assemble_memo(sys, settings, &mut Memo::new())
}

/// [`assemble()`] with what reports of one plant share taken from and added to `memo` ([`Memo`]:
/// the beta SDPs, the engaged history): models that share `F`, `E`, `C` (the same plant under
/// other inputs, amplitudes or frequencies, a scaled Theta) solve each `lambda` once. The report
/// is the one [`assemble()`] gives, bit for bit.
pub fn assemble_memo(sys: &System, settings: &ThetaSettings, memo: &mut Memo) -> Result<ThetaReport, BoundsError> {
    let mut notes = Vec::new();
    let plant = plant(sys, &mut notes)?;
    let tubes = tubes(sys, &plant.F, settings)?;
    let pinned = beyond_paper::pinned_speed(sys, &plant.F, &tubes.diam.tube_CF, &tubes.sg, &tubes.tube)?;
    let orbit = EtaOrbit::new(sys, &settings.orbit)?;
    let gammas = gammas(&plant, &tubes, &orbit, &mut notes);
    // one memo for the lambda searches of theta, theta* and theta_engaged (lmi::beta_memo)
    let cert = certificate(sys, &plant.F, &gammas, settings, &mut memo.beta, &mut notes)?;
    let theta = theta(sys, &plant, &tubes, &orbit, &cert, &gammas, &mut notes);
    let paths = path_lengths(&orbit, tubes.d, settings);
    let ext = beyond_paper::extensions(
        &FromPaper {
            sys,
            F: &plant.F,
            T: plant.T,
            R: plant.R,
            strongly_convex: gammas.strongly_convex,
            tube_CF: &tubes.diam.tube_CF,
            sg: &tubes.sg,
            tube: &tubes.tube,
            d: tubes.d,
            d_ftheta: tubes.d_ftheta,
            orbit: &orbit,
            path_points: &paths.idx,
            d_path: paths.d_path,
            path_bounds: [paths.path, paths.path1, paths.path2.value],
            zdot_bound: gammas.zdot_bound,
            gamma_1: gammas.gamma_1,
            gamma_inf: gammas.gamma_inf,
            alpha: cert.alpha.lower,
            optimum: (cert.search.optimum.value.lambda, cert.search.optimum.value.beta),
            curve: &cert.curve,
            theta: theta.theta,
            theta_verified: theta.verified,
        },
        &pinned,
        settings,
        (&mut memo.beta, &mut memo.history),
        &mut notes,
    );
    let stationary = stationary(sys, settings, &mut notes);
    let measured = measured(sys, settings, &cert, &theta.effects, &mut notes);
    compare_measured(measured.as_ref(), theta.theta, &ext, &mut notes);
    Ok(report(sys, plant, tubes, orbit, gammas, cert, theta, paths, ext, stationary, measured, notes))
}

/// Stage 1: what the system gives directly.
struct Plant {
    /// Period `T` of the input.
    T: f64,
    /// `F = A + E C`, eq. (F).
    F: DMatrix<f64>,
    p: usize,
    /// `mu = max Re eig(F)`, eq. (stab).
    mu: f64,
    /// `0 in Theta`, eq. (0inZ).
    zero_in_theta: bool,
    /// Upper bound of `R`, eq. (R).
    R: f64,
    R_verified: bool,
}

/// Stage 1: `T`, `F`, `mu` (an error when `F` is not Hurwitz), (0inZ), `R`.
fn plant(sys: &System, notes: &mut Vec<String>) -> Result<Plant, BoundsError> {
    let T = sys.period().ok_or(BoundsError::NoPeriod { kind: sys.input.kind() })?;
    let F = sys.F();
    let p = sys.p();
    let mu = match lmi::hurwitz_mu(&F) {
        Ok(mu) => mu,
        Err(LmiError::NotHurwitz { mu }) => return Err(BoundsError::NotHurwitz { mu }),
        Err(e) => return Err(BoundsError::Lmi(e)),
    };
    let zero_in_theta = sys.theta.contains(&vec![0.0; p], 0.0);
    if !zero_in_theta {
        notes.push("0 is not in Theta: assumption (0inZ) of Theorem 2 fails, theta is not a verified bound".into());
    }
    let sc = sys.theta.strong_convexity();
    let R = sc.upper();
    // R = inf is trivially a valid upper bound (polytopes: gamma = 0).
    let R_verified = sc.is_verified_upper() || R == f64::INFINITY;
    Ok(Plant { T, F, p, mu, zero_in_theta, R, R_verified })
}

/// Stage 2: the tubes `C Xi_inf`, `C F Xi_inf` and their diameters.
struct Tubes {
    /// The quadrature settings with the radius of the enclosure of `F`.
    tube: TubeSettings,
    /// One semigroup of `F` for every tube kernel of this report (the tube diameters and, for
    /// p = 1, the engaged history).
    sg: SemigroupData,
    diam: TubeDiameters,
    /// `d`, eq. (d): upper bound; `d_lower` indicative only.
    d: f64,
    d_lower: f64,
    /// `D(C(F Xi_inf + E Theta), {0})`, eq. (zinf): upper bound; `d_ftheta_lower` indicative only.
    d_ftheta: f64,
    d_ftheta_lower: f64,
    verified: bool,
}

/// Stage 2: tubes `C Xi_inf` and `C F Xi_inf` and their diameters (eqs. (d), (zinf)).
fn tubes(sys: &System, F: &DMatrix<f64>, settings: &ThetaSettings) -> Result<Tubes, BoundsError> {
    let (C, E) = (&sys.C, &sys.E);
    // (issue 15) the tube covers every F in the enclosure of fl(A + fl(E C)).
    let tube =
        TubeSettings { f_radius: lmi::verify::f_enclosure_radius(F, E, C).norm() * (1.0 + 1e-10), ..settings.tube };
    let sg = SemigroupData::new(F);
    let d_theta = sys.theta.deviation_from_origin().upper;
    let diam = tube_diameters_with(C, F, E, &sys.theta, d_theta, &sg, &tube, &settings.sphere)?;
    let (d, d_lower) = (diam.d.upper, diam.d.lower);
    let (d_ftheta, d_ftheta_lower) = (diam.d_ftheta.upper, diam.d_ftheta.lower);
    let verified = diam.verified;
    Ok(Tubes { tube, sg, diam, d, d_lower, d_ftheta, d_ftheta_lower, verified })
}

/// Stage 4: the speeds of the backlash, eqs. (g1), (ginf).
struct Gammas {
    /// `R` finite and positive (otherwise gamma = 0, the paper's footnote case).
    strongly_convex: bool,
    /// Right-hand side of (zinf): `||eta_T'||_inf + D(...)`.
    zdot_bound: f64,
    gamma_1: f64,
    gamma_inf: f64,
    /// `kappa = gamma_1 / gamma_inf`.
    kappa: f64,
}

/// Stage 4: `gamma_1`, `gamma_inf`, eqs. (g1), (ginf), at the upper bound of R.
fn gammas(plant: &Plant, tubes: &Tubes, orbit: &EtaOrbit, notes: &mut Vec<String>) -> Gammas {
    let (T, R, d) = (plant.T, plant.R, tubes.d);
    let osc = orbit.osc;
    let zdot_bound = orbit.eta_dot_inf + tubes.d_ftheta;
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
    Gammas { strongly_convex, zdot_bound, gamma_1, gamma_inf, kappa }
}

/// Stage 5: `alpha` and the certified `(Pi, lambda, beta)`.
struct Cert {
    alpha: Alpha,
    search: LambdaSearch,
    /// Certified curve `(lambda, beta, theta)` of the lambda search.
    curve: Vec<(f64, f64, f64)>,
}

/// Stage 5: `alpha`, eq. (alpha), and the lambda search (eqs. (ALI), (bet), (theta)).
fn certificate(
    sys: &System,
    F: &DMatrix<f64>,
    gammas: &Gammas,
    settings: &ThetaSettings,
    memo: &mut BetaMemo,
    notes: &mut Vec<String>,
) -> Result<Cert, BoundsError> {
    let (C, E) = (&sys.C, &sys.E);
    let (gamma_1, gamma_inf) = (gammas.gamma_1, gammas.gamma_inf);
    let al = alpha(C, E);
    let a_low = al.lower;
    let psi = |l: f64, b: f64| Psi { alpha: a_low, lambda: l, beta: b }.theta(gamma_1, gamma_inf);
    let mut search = optimise_lambda_memo(F, E, C, psi, &settings.lambda, memo);
    // Stiff plants (issue 29 item 1): with ||F|| 1e3-1e4 times |mu| the solver's Pi often
    // satisfies (ALI) with too small a margin to be proven; the search is repeated with the
    // margin imposed in the SDP raised to 1e-3, then 1e-2 (relative), which only enlarges the
    // certified beta (every certificate is verified as before).
    for margin in [1e-3, 1e-2] {
        if !matches!(search, Err(LmiError::NoCertificate { .. })) || settings.lambda.beta.tol_ali_margin_rel >= margin {
            break;
        }
        let mut retry = settings.lambda.clone();
        retry.beta.tol_ali_margin_rel = margin;
        search = optimise_lambda_memo(F, E, C, psi, &retry, memo);
        if search.is_ok() {
            notes.push(format!(
                "lambda search: no certificate with the default (ALI) margin; certified with the margin raised to {margin:e} (stiff F: a larger beta)"
            ));
        }
    }
    let search = search?;
    let curve: Vec<(f64, f64, f64)> =
        search.curve.iter().filter_map(|c| c.value.as_ref().ok().map(|v| (v.lambda, v.beta, v.theta))).collect();
    if !search.gaps.is_empty() {
        notes.push(format!(
            "lambda search: {} of {} evaluations failed (gaps in the curve)",
            search.gaps.len(),
            search.curve.len()
        ));
    }
    Ok(Cert { alpha: al, search, curve })
}

/// Stage 6: eq. (theta) at the optimum.
struct Theta {
    psi_0: f64,
    psi_inf: f64,
    theta: f64,
    verified: bool,
    /// Kinds of the model's `[[effects]]` (physics outside the paper's class).
    effects: Vec<String>,
}

/// Stage 6: `psi(0)`, `psi(gamma_inf)` (eq. (phipsi)) and `theta` (eq. (theta)) at the
/// certified optimum; verified when every part is.
fn theta(
    sys: &System,
    plant: &Plant,
    tubes: &Tubes,
    orbit: &EtaOrbit,
    cert: &Cert,
    gammas: &Gammas,
    notes: &mut Vec<String>,
) -> Theta {
    let opt = &cert.search.optimum;
    let psi = Psi { alpha: cert.alpha.lower, lambda: opt.value.lambda, beta: opt.value.beta };
    let psi_0 = psi.at_zero();
    let psi_inf = psi.eval(gammas.gamma_inf);
    let theta = psi.theta(gammas.gamma_1, gammas.gamma_inf);
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
    let verified = plant.zero_in_theta
        && plant.R_verified
        && cert.alpha.verified
        && cert_ok
        && orbit.verified
        && tubes.verified
        && effects.is_empty();
    if !orbit.verified {
        notes.push(format!("osc and ||eta_T'||_inf are estimates ({})", orbit.method));
    }
    Theta { psi_0, psi_inf, theta, verified, effects }
}

/// Stage 7: the path-length bounds of Theorem 2.
struct PathLengths {
    /// Indices of the orbit samples on the (path1) grid.
    idx: Vec<usize>,
    /// The loss per step of the partition sums: `d` plus the samples' distance to the orbit.
    d_path: f64,
    path: f64,
    path1: f64,
    path2: PackingBound,
}

/// Stage 7: path-length bounds (path), (path1), (path2).
fn path_lengths(orbit: &EtaOrbit, d: f64, settings: &ThetaSettings) -> PathLengths {
    let osc = orbit.osc;
    let idx = orbit.subsample(settings.path1_points);
    let sub: Vec<&[f64]> = idx.iter().map(|&i| orbit.eta[i].as_slice()).collect();
    let all: Vec<&[f64]> = orbit.eta.iter().map(|e| e.as_slice()).collect();
    let path = path_bound(osc, d);
    // The closed-form samples lie within rel_margin * rho of the orbit (rho = osc / (2 (1 - margin))
    // <= osc): each distance between two samples is within 2 rel_margin osc of the true one, so
    // the partition sums use a loss d + 2 rel_margin osc (0 for exact or grid samples).
    let d_path = d + 2.0 * orbit.rel_margin * osc * (1.0 + 1e-12);
    let path1 = partition_bound(&sub, d_path).max(path.min(0.0));
    let path2 = packing_bound(&all[..all.len() - 1], d_path, osc, settings.packing_eps);
    PathLengths { idx, d_path, path, path1, path2 }
}

/// Stage 9: the stationary set of Theorem 1 (`None` when skipped or failed, with a note).
fn stationary(sys: &System, settings: &ThetaSettings, notes: &mut Vec<String>) -> Option<RestSet> {
    match &settings.stationary {
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
    }
}

/// Stage 9: the measured side (pairs of simulated trajectories with the certified `Pi`);
/// `None` when skipped, failed, or the model has effects.
fn measured(
    sys: &System,
    settings: &ThetaSettings,
    cert: &Cert,
    effects: &[String],
    notes: &mut Vec<String>,
) -> Option<MeasuredSide> {
    match &settings.measure {
        Some(_) if !effects.is_empty() => {
            notes.push("measured side not computed: the rate measurement simulates the paper's class only, and the model has effects".into());
            None
        }
        Some(ms) => {
            let mut ms = ms.clone();
            ms.pi = Some(cert.search.optimum.certificate.Pi.clone());
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
                    multiplier: r.multiplier.map(|u| [u.exponent, u.ci_low, u.ci_high]),
                    step_error: r.step_error,
                    separation_error: r.separation_error,
                }),
                Err(e) => {
                    notes.push(format!("measured side not computed: {e}"));
                    None
                }
            }
        }
        None => None,
    }
}

/// Stage 9: a note when the measured exponent exceeds `theta` or the best verified bound.
fn compare_measured(measured: Option<&MeasuredSide>, theta: f64, ext: &Extensions, notes: &mut Vec<String>) {
    let (theta_best, theta_best_method) = (ext.theta_best, ext.theta_best_method);
    if let Some(m) = measured {
        if theta < 0.0 && m.rate > theta {
            notes.push(format!("measured exponent {:.4} exceeds theta {:.4}: the bound is violated (or the measurement has not converged)", m.rate, theta));
        }
        if theta_best < 0.0 && m.rate > theta_best && theta_best < theta {
            notes.push(format!("measured exponent {:.4} exceeds {theta_best_method} {:.4}: the bound is violated (or the measurement has not converged)", m.rate, theta_best));
        }
    }
}

/// Stage 10: every stage's results in one [`ThetaReport`].
#[allow(clippy::too_many_arguments)]
fn report(
    sys: &System,
    plant: Plant,
    tubes: Tubes,
    orbit: EtaOrbit,
    gammas: Gammas,
    cert: Cert,
    theta: Theta,
    paths: PathLengths,
    ext: Extensions,
    stationary: Option<RestSet>,
    measured: Option<MeasuredSide>,
    notes: Vec<String>,
) -> ThetaReport {
    let opt = &cert.search.optimum;
    let Pi: Vec<Vec<f64>> =
        (0..opt.certificate.Pi.nrows()).map(|i| opt.certificate.Pi.row(i).iter().copied().collect()).collect();
    let tube_C = &tubes.diam.tube_C;
    ThetaReport {
        name: sys.name.clone(),
        n: sys.n(),
        m: sys.m(),
        p: plant.p,
        period: plant.T,
        mu: plant.mu,
        R: plant.R,
        R_verified: plant.R_verified,
        zero_in_theta: plant.zero_in_theta,
        alpha: cert.alpha,
        lambda: opt.value.lambda,
        beta: opt.value.beta,
        beta_sdp: opt.value.beta_sdp,
        certificate_verified: opt.certificate.verified,
        Pi,
        osc: orbit.osc,
        osc_sampled: orbit.osc_sampled(),
        orbit_verified: orbit.verified,
        orbit_method: orbit.method.to_string(),
        d: tubes.d,
        d_lower: tubes.d_lower,
        d_verified: tubes.verified,
        eta_dot_inf: orbit.eta_dot_inf,
        d_ftheta: tubes.d_ftheta,
        d_ftheta_lower: tubes.d_ftheta_lower,
        zdot_bound: gammas.zdot_bound,
        zdot_star_bound: ext.zdot_star,
        gamma_inf_star: ext.gamma_inf_star,
        gamma_1: gammas.gamma_1,
        gamma_inf: gammas.gamma_inf,
        kappa: gammas.kappa,
        psi_0: theta.psi_0,
        psi_inf: theta.psi_inf,
        theta: theta.theta,
        theta_verified: theta.verified,
        effects: theta.effects,
        convergence_guaranteed: ext.theta_best_verified && ext.theta_best < 0.0,
        gamma_1_star: ext.gamma_1_star,
        kappa_star: ext.kappa_star,
        theta_star: ext.theta_star,
        theta_star_verified: ext.theta_star_verified,
        lambda_star: ext.lambda_star,
        beta_star: ext.beta_star,
        path_best_method: ext.path_best_method,
        theta_best: ext.theta_best,
        theta_best_method: ext.theta_best_method,
        theta_best_verified: ext.theta_best_verified,
        theta_profile: ext.theta_profile,
        theta_profile_verified: ext.theta_profile_verified,
        lambda_profile: ext.lambda_profile,
        profile_intervals: ext.profile_intervals,
        profile_cells: ext.profile_cells,
        theta_engaged: ext.theta_engaged,
        theta_engaged_verified: ext.theta_engaged_verified,
        lambda_engaged: ext.lambda_engaged,
        engaged_cells: ext.engaged_cells,
        path_bound: paths.path,
        path1_bound: paths.path1,
        path1_local_bound: ext.path_local,
        path1_grid: paths.idx.len(),
        path2: paths.path2,
        curve: cert.curve,
        stationary,
        measured,
        tube_cells: tube_C.cells(),
        tube_s_max: tube_C.s_max,
        tube_tail: tube_C.tail_bound(),
        notes,
        profile_evidence: ext.evidence,
    }
}
