//! Minimal `beta` of eq. (bet) for a given `lambda` as one SDP with Clarabel PSD cones.
//!
//! For `0 < lambda < |mu|` (eq. (lammu)) solve
//!
//! ```text
//! minimise b  over Pi = Pi^T, b
//! s.t.  -(S(Pi F) + lambda Pi) >= delta I,                               eq. (ALI) with margin
//!       [[Pi, H(Pi)], [H(Pi)^T, b I_p]] >= 0,  H(Pi) = (Pi E - F^T C^T)/2  eqs. (G_H), (bet)
//!       trace(Pi) <= trace_max                                           (compactness)
//! ```
//!
//! By the Schur complement the second LMI is `b >= lambda_max(H^T Pi^{-1} H) = beta` when
//! `Pi > 0`, so the optimum is the smallest `beta` over all `Pi` satisfying (ALI), and
//! `psi` of eq. (phipsi) (increasing in `beta` for fixed `alpha, lambda, gamma`) is then
//! as small as this `lambda` allows. Two PSD cones (orders `n` and `n + p`) and one linear
//! inequality: nothing else (and the inequality only when it is needed, see "Solving").
//!
//! # Normalisation
//! `beta` is **not** homogeneous in `Pi`: `H` is affine in `Pi` (the term `F^T C^T` comes
//! from `|Q|^2`, which has weight 1 in `V = |X|_Pi^2 + |Q|^2`, eq. (V_Gamma)). For
//! `Pi = s Pi_0`,
//! `beta = lambda_max(s E^T Pi_0 E - E^T G - G^T E + G^T Pi_0^{-1} G / s) / 4`, `G = F^T C^T`,
//! which blows up as `s -> 0` (if `C != 0`) and as `s -> inf` (if `E != 0`). So the scale
//! of `Pi` is *determined* by the problem and must not be fixed by a trace or `Pi >= I`
//! normalisation (that would change the optimum). The objective is bounded below by 0, so
//! the SDP is never unbounded; what can fail is *attainment* and *strictness*: with
//! `C = 0` the infimum is approached as `Pi -> 0`, with `E = 0` as `Pi -> inf`, and in
//! general `Pi` may become singular, while eq. (bet) needs `Pi^{-1}`.
//!
//! * Strictness comes from the margin `delta = tol_ali_margin_rel * s_* * |mu|` in (ALI),
//!   where `s_* = ||F^T C^T||_F / ||E||_F` ([`pi_scale`]) is the natural scale of `Pi`
//!   (the minimiser of `beta(s I)` is of this order). Since `F + lambda I` is Hurwitz,
//!   `(F + lambda I)^T Pi + Pi (F + lambda I) <= -2 delta I` implies
//!   `Pi >= 2 delta X > 0`, `X` the solution of the Lyapunov equation with right-hand side
//!   `-I`, and `lambda_min(X) >= 1 / (2 ||F + lambda I||_2)`; so `Pi` is uniformly positive
//!   definite without a separate cone `Pi >= eps I`. The margin is also what lets the
//!   rounded `Pi` pass the rigorous check of (ALI) at the *requested* `lambda`
//!   (no back-off needed in practice). It costs a relative change of `beta` of order
//!   `tol_ali_margin_rel`.
//! * Compactness comes from `trace(Pi) <= n * max_pi_rel * s_*`: inactive on
//!   non-degenerate problems with the default `1e3`; when active (e.g. `E = 0`) the
//!   solution reports it (`trace_bound_active`) and `beta` is the minimum over the bounded
//!   set, still a valid bound.
//!
//! # Solving
//! The SDP is first solved **without** the compactness inequality. That answer is kept only
//! when Clarabel reports `Solved` and its `Pi` satisfies `trace(Pi) <= trace_max`: it is then
//! feasible for the bounded SDP, and a minimiser over the larger set that lies in the smaller
//! one minimises over the smaller one too, so the result is the bounded SDP's optimum (to the
//! same tolerances), not an approximation of it. Otherwise (the bound would be active, as for
//! `E = 0`; `AlmostSolved`; any failure) the full SDP above is solved exactly as stated and
//! its outcome, errors included, is returned; `iterations` then counts both solves.
//!
//! Why: the constant `trace_max` is about `1e3` times the natural scale of the problem, and
//! Clarabel's starting point (the least-squares `s = b - A x`, shifted into the cones by a
//! multiple of the identity proportional to the largest slack) puts every cone about that far
//! from the central path; on the 20 systems of `bench/peers/lmi` the SDP without the bound
//! needs 225 interior-point iterations in all instead of 287. The first solve also switches
//! off Clarabel's iterative refinement of the KKT solves (about a fifth of the time of these
//! small problems). That does not weaken the termination test, which Clarabel applies to the
//! residuals of the problem itself, and a first solve that ends in anything but `Solved` falls
//! back to the full SDP with Clarabel's default settings. An exact change of variables
//! `Pi = T^T P T` with `T` from a Lyapunov solution of `F + lambda I`, and rescaling `b`, gave
//! no gain (BENCHMARKS.md, 2026-11-24).
//!
//! In the rare problems whose `beta` is almost flat along a direction of growing `Pi` (seen
//! mostly for `lambda >= 0.9 |mu|`), the first solve and the full SDP stop at different points
//! within the solver's tolerances, and their `beta` can differ by more than the tolerances
//! suggest (the first solve higher by more than `1e-6` relative in 6 of 799 sweep solves, at
//! most `3.2e-4`, and lower in 1); both are certified bounds.
use crate::error::{LmiError, Result};
use crate::psd_triangle::{sym_from_entries, symmetric_basis, triangular_number};
use crate::sdp::{LmiBuilder, SdpSettings, SdpStatus};
use crate::spectral_abscissa::{check_lambda, check_system, hurwitz_mu};
use crate::verify::{certify, Certificate, VerifySettings};
use nalgebra::DMatrix;

/// Settings of the beta SDP.
#[derive(Debug, Clone, PartialEq)]
pub struct BetaSdpSettings {
    /// Interior-point settings. Default [`SdpSettings::default`].
    pub sdp: SdpSettings,
    /// Verification settings. Default [`VerifySettings::default`].
    pub verify: VerifySettings,
    /// Margin of (ALI), `-(S(Pi F) + lambda Pi) >= delta I` with
    /// `delta = tol_ali_margin_rel * s_* * |mu|`, `s_* =` [`pi_scale`]. Default `1e-6`
    /// (with `1e-7` about 2 % of 800 random solves needed a `lambda` back-off; with `1e-6`
    /// one in 800).
    pub tol_ali_margin_rel: f64,
    /// Compactness bound `trace(Pi) <= n * max_pi_rel * s_*`. Default `1e3` (with `1e6`
    /// Clarabel stopped on `InsufficientProgress` on some degenerate problems, e.g.
    /// `beta* = 0` for `n = p = 1`).
    pub max_pi_rel: f64,
}

impl Default for BetaSdpSettings {
    fn default() -> Self {
        Self {
            sdp: SdpSettings::default(),
            verify: VerifySettings::default(),
            tol_ali_margin_rel: 1e-6,
            max_pi_rel: 1e3,
        }
    }
}

impl BetaSdpSettings {
    /// `0 < tol_ali_margin_rel < 1`, `1 <= max_pi_rel < inf`, nested settings valid.
    pub fn validate(&self) -> Result<()> {
        self.sdp.validate()?;
        self.verify.validate()?;
        if !(self.tol_ali_margin_rel > 0.0 && self.tol_ali_margin_rel < 1.0) {
            return Err(LmiError::InvalidSetting { name: "tol_ali_margin_rel", value: self.tol_ali_margin_rel });
        }
        if !(self.max_pi_rel.is_finite() && self.max_pi_rel >= 1.0) {
            return Err(LmiError::InvalidSetting { name: "max_pi_rel", value: self.max_pi_rel });
        }
        Ok(())
    }
}

/// Natural scale `s_* = ||F^T C^T||_F / ||E||_F` of `Pi` (1 when either norm is zero).
pub fn pi_scale(F: &DMatrix<f64>, E: &DMatrix<f64>, C: &DMatrix<f64>) -> f64 {
    let g = (C * F).norm();
    let e = E.norm();
    if g > 0.0 && e > 0.0 && (g / e).is_finite() {
        g / e
    } else {
        1.0
    }
}

/// Optimal point of the beta SDP (floating point, not yet verified).
#[derive(Debug, Clone, PartialEq)]
pub struct BetaSdpSolution {
    /// Requested `lambda`.
    pub lambda: f64,
    /// Margin `delta` with which (ALI) was imposed.
    pub ali_margin: f64,
    /// `Pi` (symmetric).
    pub Pi: DMatrix<f64>,
    /// Optimal value `b` = minimal `beta` of eq. (bet) (to solver accuracy).
    pub beta: f64,
    /// `mu` of eq. (stab).
    pub mu: f64,
    /// The bound `trace(Pi) <= trace_max` used, `trace_max = n * max_pi_rel * s_*`.
    pub trace_max: f64,
    /// `trace(Pi)` is within 1 % of `trace_max` (the compactness bound is active).
    pub trace_bound_active: bool,
    /// `lambda_min(Pi)` (floating point).
    pub lambda_min_pi: f64,
    /// Solver status (`Solved` or `AlmostSolved`).
    pub status: SdpStatus,
    /// Interior-point iterations (of both solves when the full SDP was needed, module docs).
    pub iterations: u32,
}

/// Solver solution together with its rigorous [`Certificate`].
#[derive(Debug, Clone, PartialEq)]
pub struct CertifiedBeta {
    /// SDP solution.
    pub solution: BetaSdpSolution,
    /// Verified `(lambda, b_hat)` for `solution.Pi`.
    pub certificate: Certificate,
}

/// Solve the beta SDP (module docs) at `lambda`.
///
/// Errors: input validation ([`LmiError::DimensionMismatch`], [`LmiError::NonFinite`],
/// [`LmiError::Empty`]), [`LmiError::NotHurwitz`], [`LmiError::LambdaOutOfRange`],
/// solver outcomes ([`LmiError::Infeasible`], [`LmiError::Unbounded`],
/// [`LmiError::IterationLimit`], [`LmiError::SolverFailed`]).
pub fn solve_beta_sdp(
    F: &DMatrix<f64>,
    E: &DMatrix<f64>,
    C: &DMatrix<f64>,
    lambda: f64,
    settings: &BetaSdpSettings,
) -> Result<BetaSdpSolution> {
    let mu = validate_problem(F, E, C, lambda, settings)?;
    solve_checked(F, E, C, lambda, mu, settings)
}

/// Validates settings, dimensions and finiteness, `F` Hurwitz and `lambda in (0, |mu|)`;
/// returns `mu`.
fn validate_problem(
    F: &DMatrix<f64>,
    E: &DMatrix<f64>,
    C: &DMatrix<f64>,
    lambda: f64,
    settings: &BetaSdpSettings,
) -> Result<f64> {
    settings.validate()?;
    check_system(F, E, C)?;
    let mu = hurwitz_mu(F)?;
    check_lambda(lambda, mu)?;
    Ok(mu)
}

/// [`solve_beta_sdp`] followed by [`certify`]; [`LmiError::NotVerified`] when no proof
/// could be obtained. With the default [`VerifySettings::f_from_product`] the certificate holds
/// for every `F` in the entrywise enclosure of `fl(A + fl(E C))`
/// ([`crate::verify::f_enclosure_radius`]), so the exact `A + E C` is covered.
pub fn certified_beta(
    F: &DMatrix<f64>,
    E: &DMatrix<f64>,
    C: &DMatrix<f64>,
    lambda: f64,
    settings: &BetaSdpSettings,
) -> Result<CertifiedBeta> {
    let mu = validate_problem(F, E, C, lambda, settings)?;
    certified_checked(F, E, C, lambda, mu, settings)
}

pub(crate) fn certified_checked(
    F: &DMatrix<f64>,
    E: &DMatrix<f64>,
    C: &DMatrix<f64>,
    lambda: f64,
    mu: f64,
    settings: &BetaSdpSettings,
) -> Result<CertifiedBeta> {
    let solution = solve_checked(F, E, C, lambda, mu, settings)?;
    let certificate = certify(F, E, C, &solution.Pi, lambda, solution.beta.max(0.0), &settings.verify)?;
    if !certificate.verified {
        return Err(LmiError::NotVerified { lambda, b_hat: certificate.b_hat });
    }
    Ok(CertifiedBeta { solution, certificate })
}

pub(crate) fn solve_checked(
    F: &DMatrix<f64>,
    E: &DMatrix<f64>,
    C: &DMatrix<f64>,
    lambda: f64,
    mu: f64,
    settings: &BetaSdpSettings,
) -> Result<BetaSdpSolution> {
    let n = F.nrows();
    let p = E.ncols();
    let m = triangular_number(n);
    let scale = pi_scale(F, E, C);
    let delta = settings.tol_ali_margin_rel * scale * -mu;
    let trace_max = n as f64 * settings.max_pi_rel * scale;
    let basis = symmetric_basis(n);
    let nvar = m + 1; // [entries of Pi, b]
    let I_n = DMatrix::<f64>::identity(n, n);

    // -(S(Pi F) + lambda Pi) - delta I >= 0, eq. (ALI) with margin
    let ali_0 = &I_n * -delta;
    let ali_k: Vec<Option<DMatrix<f64>>> = basis
        .iter()
        .map(|B| {
            let BF = B * F;
            Some(-((&BF + BF.transpose()) * 0.5 + B * lambda))
        })
        .chain(std::iter::once(None))
        .collect();
    // [[Pi, H], [H^T, b I]] >= 0 with H = (Pi E - F^T C^T)/2, eq. (bet)
    let G = F.transpose() * C.transpose();
    let mut bet_0 = DMatrix::<f64>::zeros(n + p, n + p);
    bet_0.view_mut((0, n), (n, p)).copy_from(&(&G * -0.5));
    bet_0.view_mut((n, 0), (p, n)).copy_from(&(G.transpose() * -0.5));
    let mut bet_k: Vec<Option<DMatrix<f64>>> = basis
        .iter()
        .map(|B| {
            let mut K = DMatrix::<f64>::zeros(n + p, n + p);
            K.view_mut((0, 0), (n, n)).copy_from(B);
            let BE = B * E * 0.5;
            K.view_mut((0, n), (n, p)).copy_from(&BE);
            K.view_mut((n, 0), (p, n)).copy_from(&BE.transpose());
            Some(K)
        })
        .collect();
    let mut Kb = DMatrix::<f64>::zeros(n + p, n + p);
    for j in 0..p {
        Kb[(n + j, n + j)] = 1.0;
    }
    bet_k.push(Some(Kb));
    let mut q = vec![0.0; nvar];
    q[m] = 1.0;

    // First attempt without the compactness bound, accepted only when it is `Solved` and its
    // `Pi` satisfies `trace(Pi) <= trace_max` (module docs, "Solving").
    let mut relaxed = LmiBuilder::new(nvar);
    relaxed.add_psd(&ali_0, &ali_k);
    relaxed.add_psd(&bet_0, &bet_k);
    let mut first_iterations = 0;
    if let Ok(out) = relaxed.solve_fast(&q, &settings.sdp) {
        first_iterations = out.iterations;
        if out.status == SdpStatus::Solved {
            let Pi = sym_from_entries(&out.x[..m], n);
            if Pi.trace() <= trace_max {
                return Ok(solution(Pi, out.x[m], out.status, out.iterations, lambda, delta, mu, trace_max));
            }
        }
    }

    // The full SDP with the compactness bound trace_max - trace(Pi) >= 0 (a 1 x 1 cone).
    let mut bld = LmiBuilder::new(nvar);
    bld.add_psd(&ali_0, &ali_k);
    let tr_k: Vec<Option<DMatrix<f64>>> =
        basis.iter().map(|B| Some(DMatrix::from_element(1, 1, -B.trace()))).chain(std::iter::once(None)).collect();
    bld.add_psd(&DMatrix::from_element(1, 1, trace_max), &tr_k);
    bld.add_psd(&bet_0, &bet_k);
    let sol = bld.solve(&q, &settings.sdp, lambda)?;
    let Pi = sym_from_entries(&sol.x[..m], n);
    Ok(solution(Pi, sol.x[m], sol.status, first_iterations + sol.iterations, lambda, delta, mu, trace_max))
}

fn solution(
    Pi: DMatrix<f64>,
    beta: f64,
    status: SdpStatus,
    iterations: u32,
    lambda: f64,
    ali_margin: f64,
    mu: f64,
    trace_max: f64,
) -> BetaSdpSolution {
    let lambda_min_pi = Pi.clone().symmetric_eigen().eigenvalues.iter().copied().fold(f64::INFINITY, f64::min);
    BetaSdpSolution {
        lambda,
        ali_margin,
        beta,
        trace_bound_active: Pi.trace() >= 0.99 * trace_max,
        Pi,
        mu,
        trace_max,
        lambda_min_pi,
        status,
        iterations,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::{paper_example, random_hurwitz_system};
    use crate::verify::{beta_estimate, check_certificate, lambda_of_pi};
    use approx::assert_relative_eq;

    /// Scalar case n = p = 1, F = -f, E = e, C = c: (ALI) is lambda <= f, and
    /// beta(pi) = (pi e + f c)^2 / (4 pi) is minimised at pi = f|c|/|e| (if e c > 0 the
    /// minimum over pi > 0 of (pi e + f c)^2/(4 pi) is e f c, at pi = f c / e).
    #[test]
    fn scalar_case_closed_form() {
        let (f, e, c) = (2.0, 0.5, 3.0);
        let F = DMatrix::from_element(1, 1, -f);
        let E = DMatrix::from_element(1, 1, e);
        let C = DMatrix::from_element(1, 1, c);
        let sol = solve_beta_sdp(&F, &E, &C, 1.0, &BetaSdpSettings::default()).unwrap();
        // H = (pi e + f c)/2 since F^T C^T = -f c. beta(pi) = pi/16 + 3/2 + 9/pi here, so
        // beta(12 (1 + r)) - 3 ~ 0.75 r^2: a relative gap of 1e-9 fixes pi only to
        // r ~ sqrt(4e-9) ~ 6e-5 (the first solve, module docs, stops at r = 2.4e-5).
        assert_relative_eq!(sol.Pi[(0, 0)], f * c / e, max_relative = 1e-4);
        assert_relative_eq!(sol.beta, e * f * c, max_relative = 1e-7);
        assert!(!sol.trace_bound_active && sol.lambda_min_pi > 0.0);
    }

    #[test]
    fn paper_example_certifies_and_matches_beta_of_pi() {
        let (F, E, C) = paper_example();
        let cb = certified_beta(&F, &E, &C, 0.15, &BetaSdpSettings::default()).unwrap();
        let cert = &cb.certificate;
        assert!(cert.verified);
        assert_eq!(cert.lambda, 0.15, "no back-off expected with the default margin");
        assert!(cb.solution.lambda_min_pi > 0.0 && !cb.solution.trace_bound_active);
        assert_relative_eq!(cert.b_hat, cb.solution.beta, max_relative = 1e-6);
        assert_relative_eq!(beta_estimate(&F, &E, &C, &cb.solution.Pi), cb.solution.beta, max_relative = 1e-6);
        assert!(lambda_of_pi(&F, &cb.solution.Pi) >= 0.15 * (1.0 - 1e-9));
    }

    /// The SDP optimum is not beaten by Lyapunov-equation solutions Pi_t = t P,
    /// (F + lambda I)^T P + P (F + lambda I) = -I, which are feasible for every t > 0.
    #[test]
    fn optimum_beats_scaled_lyapunov_solutions() {
        for seed in 0..4u64 {
            let (F, E, C) = random_hurwitz_system(seed, 3 + (seed as usize % 2), 1 + (seed as usize % 2));
            let mu = hurwitz_mu(&F).unwrap();
            let lambda = 0.5 * -mu;
            let cb = certified_beta(&F, &E, &C, lambda, &BetaSdpSettings::default()).unwrap();
            let n = F.nrows();
            let Fl = &F + DMatrix::<f64>::identity(n, n) * lambda;
            // Kronecker solve of the Lyapunov equation.
            let I = DMatrix::<f64>::identity(n, n);
            let K = Fl.transpose().kronecker(&I) + I.kronecker(&Fl.transpose());
            let rhs = -DMatrix::<f64>::identity(n, n);
            let vecP = K.lu().solve(&nalgebra::DVector::from_column_slice(rhs.as_slice())).unwrap();
            let P = DMatrix::from_column_slice(n, n, vecP.as_slice());
            let P = (&P + P.transpose()) * 0.5;
            for t in [0.01, 0.1, 1.0, 10.0, 100.0] {
                let b = beta_estimate(&F, &E, &C, &(&P * t));
                assert!(cb.certificate.b_hat <= b * (1.0 + 1e-6), "seed {seed} t {t}: {} > {b}", cb.certificate.b_hat);
            }
        }
    }

    #[test]
    fn negative_controls_perturbed_pi_and_underestimated_b() {
        let (F, E, C) = random_hurwitz_system(11, 4, 2);
        let mu = hurwitz_mu(&F).unwrap();
        // lambda close to |mu| so that (ALI) is tight.
        let lambda = 0.9 * -mu;
        let cb = certified_beta(&F, &E, &C, lambda, &BetaSdpSettings::default()).unwrap();
        assert!(cb.certificate.verified);
        let Pi = &cb.certificate.Pi;
        // Perturb Pi along the eigenvector of the tight (ALI) direction: rejected.
        let PF = Pi * &F;
        let N = -((&PF + PF.transpose()) * 0.5 + Pi * lambda);
        let eig = N.symmetric_eigen();
        let k = eig.eigenvalues.imin();
        let v = eig.eigenvectors.column(k).into_owned();
        let mut worst: Option<bool> = None;
        for sgn in [1.0, -1.0] {
            let Pp = Pi + (&v * v.transpose()) * (sgn * 1e-3 * Pi.norm());
            let c = check_certificate(&F, &E, &C, &Pp, lambda, cb.certificate.b_hat * 10.0).unwrap();
            worst = Some(worst.unwrap_or(true) && c.lyapunov.verified);
        }
        assert_eq!(worst, Some(false), "a perturbation of the tight Pi must break (ALI)");
        // Underestimated b_hat is rejected.
        let c = check_certificate(&F, &E, &C, Pi, cb.certificate.lambda, cb.solution.beta * (1.0 - 1e-4)).unwrap();
        assert!(!c.schur.verified && !c.verified);
        // And the certified one passes the plain check.
        let c = check_certificate(&F, &E, &C, Pi, cb.certificate.lambda, cb.certificate.b_hat).unwrap();
        assert!(c.verified);
    }

    #[test]
    fn bad_input_is_an_error_value() {
        let (F, E, C) = paper_example();
        let s = BetaSdpSettings::default();
        assert!(matches!(
            solve_beta_sdp(&F, &E, &C, 0.3, &s),
            Err(LmiError::LambdaOutOfRange { lambda, mu }) if lambda == 0.3 && (mu + 0.3).abs() < 1e-12
        ));
        assert!(matches!(solve_beta_sdp(&F, &E, &C, -0.1, &s), Err(LmiError::LambdaOutOfRange { .. })));
        assert!(matches!(solve_beta_sdp(&F, &E, &C, f64::NAN, &s), Err(LmiError::NonFinite { what: "lambda", .. })));
        let Fu = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -1.0, 0.6]);
        assert!(
            matches!(solve_beta_sdp(&Fu, &E, &C, 0.1, &s), Err(LmiError::NotHurwitz { mu }) if (mu - 0.3).abs() < 1e-12)
        );
        let Cbad = DMatrix::zeros(2, 2);
        assert!(matches!(
            solve_beta_sdp(&F, &E, &Cbad, 0.1, &s),
            Err(LmiError::DimensionMismatch { what: "C", expected: (1, 2), found: (2, 2) })
        ));
        let mut En = E.clone();
        En[(1, 0)] = f64::INFINITY;
        assert!(matches!(
            solve_beta_sdp(&F, &En, &C, 0.1, &s),
            Err(LmiError::NonFinite { what: "E", row: 1, col: 0, .. })
        ));
        let it = BetaSdpSettings { sdp: SdpSettings { max_iter: 2, ..Default::default() }, ..Default::default() };
        assert!(matches!(solve_beta_sdp(&F, &E, &C, 0.1, &it), Err(LmiError::IterationLimit { max_iter: 2, .. })));
        let bad = BetaSdpSettings { max_pi_rel: 0.5, ..Default::default() };
        assert!(matches!(
            solve_beta_sdp(&F, &E, &C, 0.1, &bad),
            Err(LmiError::InvalidSetting { name: "max_pi_rel", .. })
        ));
    }

    /// Degenerate C = 0: beta = lambda_max(E^T Pi E)/4 -> 0 as Pi -> 0; the (ALI) margin
    /// keeps Pi positive definite and the certificate valid.
    #[test]
    fn degenerate_c_zero_keeps_pi_positive() {
        let (F, E, _) = paper_example();
        let C = DMatrix::zeros(1, 2);
        let cb = certified_beta(&F, &E, &C, 0.1, &BetaSdpSettings::default()).unwrap();
        assert!(cb.certificate.verified && cb.certificate.pi_positive.lower_bound > 0.0);
        assert!(cb.solution.lambda_min_pi > 0.0 && cb.certificate.b_hat < 1e-6);
    }

    /// Degenerate coupling E = 0: the infimum is approached as Pi -> inf; the upper
    /// normalisation bound becomes active and is reported, and the certificate is valid.
    #[test]
    fn degenerate_e_zero_reports_active_bound() {
        let (F, _, C) = paper_example();
        let E = DMatrix::zeros(2, 1);
        let cb = certified_beta(&F, &E, &C, 0.1, &BetaSdpSettings::default()).unwrap();
        assert!(cb.solution.trace_bound_active);
        assert!(cb.certificate.verified);
        // beta ~ |C F|^2 / (4 lambda_max(Pi)) with trace(Pi) ~ trace_max = 2e3 here.
        assert!(cb.certificate.b_hat < 1e-3);
    }
}
