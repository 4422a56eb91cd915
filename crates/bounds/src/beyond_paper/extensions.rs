//! The bounds beyond the paper, computed from the paper's stages: `theta*` (eq. (theta) with
//! the strongest proven path bound, proofs-notes/theta-star.md), `theta_profile` (the chord
//! argument resolved in time, proofs-notes/theta-profile.md), `theta_engaged` (speed floors
//! where the backlash is provably engaged: p = 1, proofs-notes/theta-engaged.md; balls and
//! ellipsoids in R^2, R^3, proofs-notes/theta-engaged-balls.md) and the best
//! verified one of these and the paper's `theta`.
//!
//! [`extensions`] is a list of named steps: [`speed_profiles`] -> [`speeds_star`] ->
//! [`theta_star`] -> [`theta_profile`] -> [`theta_engaged`] -> [`best`]. [`pinned_speed`] runs
//! earlier, right after the paper's tube stage whose kernels it shares.
use crate::beyond_paper::contact_floors::{contact_floors, Band, ContactGeometry};
use crate::beyond_paper::engaged_speed::{EngagedHistory, EngagedSpeed, HistoryMemo};
use crate::beyond_paper::speed_profile::{ProfileEvidence, SpeedProfile};
use crate::error::BoundsError;
use crate::exponent::psi::Psi;
use crate::orbit::{partition_bound_local, EtaOrbit};
use crate::settings::ThetaSettings;
use crate::tube::{SemigroupData, TubeKernel, TubeSettings};
use geometry::ConvexSet;
use lmi::{optimise_lambda_memo, BetaMemo};
use model::System;
use nalgebra::DMatrix;
use rounding::{ulp_down_nonzero, ulp_up};

/// What the extensions take from the paper's stages (`crate::assemble`).
pub(crate) struct FromPaper<'a> {
    pub sys: &'a System,
    /// `F`, eq. (F).
    pub F: &'a DMatrix<f64>,
    /// Period `T`.
    pub T: f64,
    /// Upper bound of `R`, eq. (R).
    pub R: f64,
    /// `R` finite and positive.
    pub strongly_convex: bool,
    /// The tube kernel of `C F Xi_inf`, the semigroup of `F` and the tube settings it was built with.
    pub tube_CF: &'a TubeKernel,
    pub sg: &'a SemigroupData,
    pub tube: &'a TubeSettings,
    /// `d`, eq. (d), and `D(C(F Xi_inf + E Theta),{0})`, eq. (zinf), from above.
    pub d: f64,
    pub d_ftheta: f64,
    pub orbit: &'a EtaOrbit,
    /// The (path1) grid (indices of orbit samples) and its loss per step.
    pub path_points: &'a [usize],
    pub d_path: f64,
    /// (path), (path1), (path2).
    pub path_bounds: [f64; 3],
    /// Right-hand side of (zinf).
    pub zdot_bound: f64,
    /// `gamma_1`, `gamma_inf`, eqs. (g1), (ginf).
    pub gamma_1: f64,
    pub gamma_inf: f64,
    /// `alpha` from below, eq. (alpha).
    pub alpha: f64,
    /// The certified `(lambda, b_hat)` at the optimum of eq. (theta), and the certified curve.
    pub optimum: (f64, f64),
    pub curve: &'a [(f64, f64, f64)],
    /// The paper's `theta` and whether it is verified.
    pub theta: f64,
    pub theta_verified: bool,
}

/// The pinned speed of the backlash for `p = 1`: `Theta`'s support interval `[lo, hi]` and the
/// engaged history's band at `tau = 0` ([`EngagedSpeed`]).
pub(crate) struct Pinned {
    pub lo_hi: Option<(f64, f64)>,
    pub speed: Option<EngagedSpeed>,
}

/// p = 1: Theta = [lo, hi]; (zinf) with the backlash side pinned (beyond_paper::engaged_speed): the
/// engaged history's band at tau = 0.
pub(crate) fn pinned_speed(
    sys: &System,
    F: &DMatrix<f64>,
    tube_CF: &TubeKernel,
    sg: &SemigroupData,
    tube: &TubeSettings,
) -> Result<Pinned, BoundsError> {
    // (support values from above: exact for an interval, an enclosing interval for any other
    // set in R^1)
    let lo_hi = (sys.p() == 1).then(|| (-sys.theta.support_upper(&[-1.0]), sys.theta.support_upper(&[1.0])));
    let speed = match lo_hi {
        Some((lo, hi)) => {
            EngagedHistory::new(tube_CF, &sys.C, F, &sys.E, (lo, hi), sg, tube, 1.0, 0)?.map(|h| h.pinned(lo, hi))
        }
        None => None,
    };
    Ok(Pinned { lo_hi, speed })
}

/// Every bound beyond the paper (see the fields of [`crate::ThetaReport`] of the same names).
pub(crate) struct Extensions {
    pub path_local: f64,
    pub path_best_method: &'static str,
    pub gamma_1_star: f64,
    pub zdot_star: f64,
    pub gamma_inf_star: f64,
    pub kappa_star: f64,
    pub theta_star: f64,
    pub theta_star_verified: bool,
    pub lambda_star: f64,
    pub beta_star: f64,
    pub theta_profile: f64,
    pub theta_profile_verified: bool,
    pub lambda_profile: f64,
    pub profile_intervals: usize,
    pub profile_cells: usize,
    pub theta_engaged: f64,
    pub theta_engaged_verified: bool,
    pub lambda_engaged: f64,
    pub engaged_cells: usize,
    pub theta_best: f64,
    pub theta_best_method: &'static str,
    pub theta_best_verified: bool,
    /// The profile, partition and points of `theta_engaged` (of `theta_profile` when no cell is
    /// engaged).
    pub evidence: Option<ProfileEvidence>,
}

/// `theta*`, `theta_profile`, `theta_engaged` and the best verified bound.
pub(crate) fn extensions(
    paper: &FromPaper,
    pinned: &Pinned,
    settings: &ThetaSettings,
    (betas, histories): (&mut BetaMemo, &mut HistoryMemo),
    notes: &mut Vec<String>,
) -> Extensions {
    let profiles = speed_profiles(paper, pinned, settings, histories, notes);
    let speeds = speeds_star(paper, pinned, profiles.profile.as_ref());
    let star = theta_star(paper, &speeds, settings, betas, notes);
    let profile = theta_profile(paper, &profiles, &star, settings);
    let engaged = theta_engaged(paper, &profiles, &star, &profile, settings, betas, notes);
    let (theta_best, theta_best_method, theta_best_verified) = best(paper, &star, &profile, &engaged);
    let evidence = engaged.evidence.or(profile.evidence);
    Extensions {
        path_local: speeds.path_local,
        path_best_method: speeds.path_best_method,
        gamma_1_star: speeds.gamma_1_star,
        zdot_star: speeds.zdot_star,
        gamma_inf_star: speeds.gamma_inf_star,
        kappa_star: speeds.kappa_star,
        theta_star: star.theta,
        theta_star_verified: star.verified,
        lambda_star: star.lambda,
        beta_star: star.beta,
        theta_profile: profile.theta,
        theta_profile_verified: profile.verified,
        lambda_profile: profile.lambda,
        profile_intervals: profile.intervals,
        profile_cells: if profiles.profile.is_some() { profiles.cells } else { 0 },
        theta_engaged: engaged.theta,
        theta_engaged_verified: engaged.verified,
        lambda_engaged: engaged.lambda,
        engaged_cells: engaged.cells,
        theta_best,
        theta_best_method,
        theta_best_verified,
        evidence,
    }
}

/// The speed profile per cell, without and with the engaged floors.
struct Profiles {
    /// Cells of the profile (a divisor of the orbit's intervals).
    cells: usize,
    /// The profile of `theta_profile` (the engaged profile's ceilings without its floors when
    /// there is one).
    profile: Option<SpeedProfile>,
    /// The profile of `theta_engaged` (p = 1, or a ball or an ellipsoid for p >= 2; some cell engaged).
    engaged: Option<SpeedProfile>,
}

/// Speed profile per cell (theta_profile, theta_engaged), built before theta* because its
/// largest ceiling also bounds limsup |z'|.
fn speed_profiles(
    paper: &FromPaper,
    pinned: &Pinned,
    settings: &ThetaSettings,
    histories: &mut HistoryMemo,
    notes: &mut Vec<String>,
) -> Profiles {
    let (T, R, d, d_ftheta, orbit) = (paper.T, paper.R, paper.d, paper.d_ftheta, paper.orbit);
    let cells = largest_divisor_at_most(orbit.t.len() - 1, settings.profile_cells.max(1));
    let profile = match (paper.strongly_convex, orbit.eta_dot_cells(cells)) {
        (true, Some((edot, nodes))) => {
            let prof = SpeedProfile::new(T, nodes, &edot, d_ftheta, d, R);
            // p = 1: the signed speed bounds (beyond_paper::engaged_speed) lower the cells' ceilings
            match (&pinned.speed, orbit.deta_cells_scalar(cells)) {
                (Some(es), Some((low, high))) => Some(prof.with_signed_speed(&low, &high, es)),
                _ => Some(prof),
            }
        }
        _ => None,
    };
    // theta_engaged (p = 1): the profile with speed floors where the backlash is provably
    // engaged (the output has moved monotonically by Theta's width), partition by dynamic
    // programming again (the floors change which intervals matter), then the best certified
    // (lambda, b_hat) of the curve (proofs-notes/theta-engaged.md).
    let engaged = match (&profile, orbit.deta_cells_scalar(cells), pinned.lo_hi) {
        (Some(prof), Some((low, high)), Some((lo, hi))) => {
            let width = (hi - lo) * (1.0 + 1e-12);
            // diam(C Xi_inf) = d - (hi - lo) for p = 1 (the diameter of a sum of intervals), from
            // above: hi - lo are support values rounded outward by a few ulps at most
            let dev_diam = ((d - (hi - lo) * (1.0 - 1e-10)) * (1.0 + 1e-12)).max(0.0);
            let prof = prof.clone().with_floors_tube(&low, &high, d_ftheta, width, dev_diam);
            // the engaged history narrows the band of z' - eta_T' on engaged cells
            // (beyond_paper::EngagedHistory; proofs-notes/theta-engaged.md), tabulated on
            // tau_j = j T / (2 history_steps) up to the longest engaged history of the profile
            let oldest = prof.engaged_age.iter().flatten().map(|&(_, a)| a).max().unwrap_or(0) as f64 * prof.h;
            let steps = settings.engaged_history_steps;
            let dtau = T / (2.0 * steps.max(1) as f64);
            let needed = ((oldest / dtau).floor() as usize).min(steps);
            let history = if needed > 0 {
                let sys = paper.sys;
                histories
                    .history(paper.tube_CF, &sys.C, paper.F, &sys.E, (lo, hi), paper.sg, paper.tube, dtau, needed)
                    .unwrap_or_else(|e| {
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
            // runs continue while the engaged band keeps the backlash moving (proofs-notes/theta-engaged.md,
            // "Continued engagement")
            let prof = prof.with_continued_runs(&low, &high, history.as_ref(), lo, hi);
            (prof.engaged_cells() > 0 && width.is_finite()).then_some(prof)
        }
        // p >= 2, a ball or an ellipsoid: floors from the normal component of y' at the contact
        // point (beyond_paper::contact_floors; proofs-notes/theta-engaged-balls.md)
        (Some(prof), None, None) => contact_profile(paper, prof, cells),
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
    Profiles { cells, profile, engaged }
}

/// The profile with the contact floors of a ball or an ellipsoid (`p >= 2`, closed-form orbit):
/// `None` when the set has no proven curvature radii or no cell is engaged.
fn contact_profile(paper: &FromPaper, prof: &SpeedProfile, cells: usize) -> Option<SpeedProfile> {
    if paper.sys.p() < 2 || !paper.strongly_convex {
        return None;
    }
    let sys = paper.sys;
    let geo = ContactGeometry::of(&sys.theta, paper.R)?;
    let band = Band::new(paper.tube_CF, &sys.C, paper.F, &sys.E, &sys.theta, paper.sg, paper.tube, paper.d_ftheta);
    let floors = contact_floors(paper.orbit, cells, paper.d_ftheta, &|u| band.support_upper(u), &geo)?;
    let prof = prof.clone().with_speed_ceilings(&floors.ceiling).with_speed_floors(&floors.floor);
    (prof.engaged_cells() > 0).then_some(prof)
}

/// The speeds of `theta*`: `gamma_1*` from the strongest path bound, `gamma_inf*` from the
/// pinned speed or the profile's largest cell ceiling.
struct SpeedsStar {
    /// (path1) with the step-length-dependent loss.
    path_local: f64,
    path_best_method: &'static str,
    gamma_1_star: f64,
    zdot_star: f64,
    gamma_inf_star: f64,
    kappa_star: f64,
}

/// `gamma_1*`, `limsup |z'|` from above with the side pinned, `gamma_inf*`, `kappa*`.
fn speeds_star(paper: &FromPaper, pinned: &Pinned, profile: Option<&SpeedProfile>) -> SpeedsStar {
    let (T, R, orbit, gamma_1, gamma_inf) = (paper.T, paper.R, paper.orbit, paper.gamma_1, paper.gamma_inf);
    let osc = orbit.osc;
    let [path_b, path1, path2] = paper.path_bounds;
    // (path1) with the loss min(d, diam(Theta) + dt D(C(F Xi_inf + E Theta),{0})) per step of
    // length dt (proofs-notes/theta-star.md): the same partitions, a smaller loss on short steps.
    let sub: Vec<&[f64]> = paper.path_points.iter().map(|&i| orbit.eta[i].as_slice()).collect();
    let sub_t: Vec<f64> = paper.path_points.iter().map(|&i| orbit.t[i]).collect();
    let diam_theta = paper.sys.theta.diameter().upper;
    let diam_path = diam_theta + 2.0 * orbit.rel_margin * osc * (1.0 + 1e-12);
    let path_local = partition_bound_local(&sub, &sub_t, paper.d_path, diam_path, paper.d_ftheta).max(path1);
    // theta* (beyond eq. (g1)): the chord argument of eq. (theta) with gamma_1 from the
    // strongest proven path bound. Over a window of k periods the path of z is at least
    // k S - (one wrap-around term), S any cyclic partition sum (path1) or packing sum (path2),
    // so the long-run mean of |z'|/R is at least S / (T R): the same chord (psiup) then gives
    // theta* (proofs-notes/theta-star.md). Each (lambda, b_hat) of the certified curve gives a
    // valid theta*; the best is kept.
    let (path_best, path_best_method) =
        [(path_b, "(path)"), (path1, "(path1)"), (path2, "(path2)"), (path_local, "(path1-local)")]
            .into_iter()
            .fold((0.0f64, "(path)"), |a, b| if b.0 > a.0 { b } else { a });
    // Rounding of the sums of distances (at most 2000 terms, each within a few ulps): a relative
    // margin far above it.
    let path_safe = path_best * (1.0 - 1e-10);
    let strongly_convex = paper.strongly_convex;
    let gamma_1_star = if strongly_convex { ulp_down_nonzero(path_safe / (T * R)).max(gamma_1) } else { 0.0 };
    let zdot_bound = paper.zdot_bound;
    let zdot_star = pinned.speed.map_or(zdot_bound, |es| es.zdot_bound(orbit.eta_dot_inf).min(zdot_bound));
    // gamma_inf*: the pinned speed bound, or the profile's largest cell ceiling if lower
    let max_cell_speed = profile.map_or(f64::INFINITY, |p| p.max_speed());
    let (zdot_star, gamma_inf_star) = if strongly_convex {
        let zdot_star = zdot_star.min(ulp_up(max_cell_speed * R * (1.0 + 4.0 * f64::EPSILON)));
        (zdot_star, ulp_up(zdot_star / R * (1.0 + 4.0 * f64::EPSILON)).min(gamma_inf).min(max_cell_speed))
    } else {
        (zdot_star, 0.0)
    };
    let kappa_star =
        if gamma_inf_star > 0.0 { ulp_down_nonzero(gamma_1_star / gamma_inf_star).clamp(0.0, 1.0) } else { 0.0 };
    SpeedsStar { path_local, path_best_method, gamma_1_star, zdot_star, gamma_inf_star, kappa_star }
}

/// `theta*` and the certified points it was minimised over.
struct Star {
    theta: f64,
    verified: bool,
    lambda: f64,
    beta: f64,
    /// Certified `(lambda, b_hat)` points: the paper's curve and the second lambda search.
    points: Vec<(f64, f64)>,
}

/// `theta*`: eq. (theta) with `gamma_1*`, `gamma_inf*`, minimised over certified points.
fn theta_star(
    paper: &FromPaper,
    speeds: &SpeedsStar,
    settings: &ThetaSettings,
    memo: &mut BetaMemo,
    notes: &mut Vec<String>,
) -> Star {
    let (a_low, gamma_1, gamma_inf) = (paper.alpha, paper.gamma_1, paper.gamma_inf);
    let (gamma_1_star, gamma_inf_star) = (speeds.gamma_1_star, speeds.gamma_inf_star);
    let sys = paper.sys;
    // Certified (lambda, b_hat) points for theta*: the paper's curve, plus a second lambda search
    // with theta* as its objective when gamma_1* > gamma_1 (theta*'s best lambda differs from
    // theta's); every point is a verified certificate, so the minimum over all is a bound.
    let mut star_points: Vec<(f64, f64)> = paper.curve.iter().map(|&(l, b, _)| (l, b)).collect();
    if paper.strongly_convex && (gamma_1_star > gamma_1 || gamma_inf_star < gamma_inf) {
        match optimise_lambda_memo(
            paper.F,
            &sys.E,
            &sys.C,
            |l, b| Psi { alpha: a_low, lambda: l, beta: b }.theta(gamma_1_star, gamma_inf_star),
            &settings.lambda,
            memo,
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
        .fold((paper.theta, paper.optimum.0, paper.optimum.1), |a, c| if c.0 < a.0 { c } else { a });
    // The same proof obligations as theta (the path bounds use the same d and orbit samples).
    Star {
        theta: theta_star,
        verified: paper.theta_verified,
        lambda: lambda_star,
        beta: beta_star,
        points: star_points,
    }
}

/// `theta_profile`, its certified `(lambda, b_hat)` and partition size.
struct ProfileBound {
    theta: f64,
    verified: bool,
    lambda: f64,
    beta: f64,
    intervals: usize,
    evidence: Option<ProfileEvidence>,
}

/// `theta_profile`: the best partition of the speed profile at `theta*`'s point, then the best
/// certified point (never above `theta*`).
fn theta_profile(paper: &FromPaper, profiles: &Profiles, star: &Star, settings: &ThetaSettings) -> ProfileBound {
    let a_low = paper.alpha;
    let (theta_star, lambda_star, beta_star) = (star.theta, star.lambda, star.beta);
    let (theta_profile, (lambda_profile, beta_profile), profile_intervals, evidence) = match &profiles.profile {
        Some(prof) => {
            let nodes = prof
                .best_partition(&Psi { alpha: a_low, lambda: lambda_star, beta: beta_star }, settings.profile_stride);
            let (v, at) = best_certified_point(prof, &nodes, a_low, &star.points);
            let intervals = nodes.len() - 1;
            let evidence = ProfileEvidence { profile: prof.clone(), nodes, alpha: a_low, points: star.points.clone() };
            (v.min(theta_star), if v <= theta_star { at } else { (lambda_star, beta_star) }, intervals, Some(evidence))
        }
        None => (theta_star, (lambda_star, beta_star), 0, None),
    };
    ProfileBound {
        theta: theta_profile,
        verified: paper.theta_verified && profiles.profile.is_some(),
        lambda: lambda_profile,
        beta: beta_profile,
        intervals: profile_intervals,
        evidence,
    }
}

/// `theta_engaged`, its certified `lambda` and the number of engaged cells.
struct EngagedBound {
    theta: f64,
    verified: bool,
    lambda: f64,
    cells: usize,
    evidence: Option<ProfileEvidence>,
}

/// `theta_engaged`: the engaged profile's best partition and a lambda search of its own
/// (never above `theta_profile`).
fn theta_engaged(
    paper: &FromPaper,
    profiles: &Profiles,
    star: &Star,
    profile: &ProfileBound,
    settings: &ThetaSettings,
    memo: &mut BetaMemo,
    notes: &mut Vec<String>,
) -> EngagedBound {
    let a_low = paper.alpha;
    let sys = paper.sys;
    let (theta_profile, lambda_profile, beta_profile) = (profile.theta, profile.lambda, profile.beta);
    let (theta_engaged, lambda_engaged, engaged_cells, evidence) = match &profiles.engaged {
        Some(prof) => {
            let nodes = prof.best_partition(
                &Psi { alpha: a_low, lambda: lambda_profile, beta: beta_profile },
                settings.profile_stride,
            );
            // the floors weigh psi at high speeds more than the chords do: a lambda search of
            // its own (every point a verified certificate, as for theta*)
            let mut points = star.points.clone();
            match optimise_lambda_memo(
                paper.F,
                &sys.E,
                &sys.C,
                |l, b| prof.bound(&Psi { alpha: a_low, lambda: l, beta: b }, &nodes),
                &settings.lambda,
                memo,
            ) {
                Ok(s3) => {
                    points.extend(s3.curve.iter().filter_map(|c| c.value.as_ref().ok().map(|v| (v.lambda, v.beta))))
                }
                Err(e) => notes.push(format!("third lambda search (for theta_engaged) failed: {e}")),
            }
            let (v, (l, _)) = best_certified_point(prof, &nodes, a_low, &points);
            let evidence = ProfileEvidence { profile: prof.clone(), nodes, alpha: a_low, points };
            (
                v.min(theta_profile),
                if v <= theta_profile { l } else { lambda_profile },
                prof.engaged_cells(),
                Some(evidence),
            )
        }
        None => (theta_profile, lambda_profile, 0, None),
    };
    EngagedBound {
        theta: theta_engaged,
        verified: profile.verified && profiles.engaged.is_some(),
        lambda: lambda_engaged,
        cells: engaged_cells,
        evidence,
    }
}

/// The smallest verified bound of `theta`, `theta*`, `theta_profile`, `theta_engaged` (the
/// first one on ties), or `theta` when none is verified.
fn best(paper: &FromPaper, star: &Star, profile: &ProfileBound, engaged: &EngagedBound) -> (f64, &'static str, bool) {
    let (theta, theta_verified) = (paper.theta, paper.theta_verified);
    let candidates = [
        (theta, "theta", theta_verified),
        (star.theta, "theta_star", star.verified),
        (profile.theta, "theta_profile", profile.verified),
        (engaged.theta, "theta_engaged", engaged.verified),
    ];
    candidates
        .iter()
        .filter(|c| c.2)
        .fold(None, |a: Option<(f64, &'static str, bool)>, c| match a {
            Some(b) if b.0 <= c.0 => Some(b),
            _ => Some(*c),
        })
        .unwrap_or((theta, "theta", theta_verified))
}

/// The largest divisor of `k` that is at most `at_most` (at least 1).
fn largest_divisor_at_most(k: usize, at_most: usize) -> usize {
    (1..=at_most.min(k).max(1)).rev().find(|&d| k.is_multiple_of(d)).unwrap_or(1)
}

/// The smallest bound of `prof` with partition `nodes` over the certified `(lambda, b_hat)`
/// points, and the point attaining it (`(inf, (NaN, NaN))` without points).
fn best_certified_point(prof: &SpeedProfile, nodes: &[usize], alpha: f64, points: &[(f64, f64)]) -> (f64, (f64, f64)) {
    points
        .iter()
        .map(|&(l, b)| (prof.bound(&Psi { alpha, lambda: l, beta: b }, nodes), (l, b)))
        .fold((f64::INFINITY, (f64::NAN, f64::NAN)), |a, c| if c.0 < a.0 { c } else { a })
}
