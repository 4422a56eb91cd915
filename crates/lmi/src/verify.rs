//! Rigorous verification of the certificate `(Pi, lambda, b_hat)` of eqs. (ALI), (bet).
//!
//! What is proved, in exact arithmetic about the floating-point numbers handed in
//! (`Pi` is the symmetric matrix defined by the upper triangle of the returned matrix):
//!
//! 1. `Pi > 0`;
//! 2. `-(S(Pi F) + lambda Pi) >= 0`, eq. (ALI);
//! 3. `K = [[Pi, H], [H^T, b_hat I_p]] >= 0` with `H = (Pi E - F^T C^T)/2`, eq. (G_H),
//!    which together with 1. is equivalent (Schur complement) to
//!    `b_hat I - H^T Pi^{-1} H >= 0`, i.e. `beta <= b_hat` in eq. (bet).
//!
//! # Method
//! The matrices of 2. and 3. are formed in floating point together with an entrywise
//! bound `Err` on the rounding error: every entry is a sum of `N` rounded products, so
//! `|fl(s) - s| <= gamma_N sum |terms|`, `gamma_k = k u / (1 - k u)`, `u = 2^-53`
//! (Higham, *Accuracy and Stability*, eq. (3.5)); the bound is doubled to absorb the
//! rounding made while evaluating it. Then `||exact - computed||_2 <= ||Err||_F =: r`.
//!
//! Positive (semi)definiteness of the exact matrix is then proved with Rump's test
//! (S. M. Rump, "Verification of positive definiteness", BIT 46 (2006) 433-452):
//! if floating-point Cholesky of `B = fl(M - t I)` runs to completion, then
//! `R^T R = B + D2` with `|D2_ij| <= g sqrt(b_ii b_jj)`, `g = gamma_{n+1}/(1-gamma_{n+1})`
//! (Demmel's bound), so `||D2||_2 <= g trace(B)`; the shift itself is rounded,
//! `B = M - t I + D1`, `|D1_ii| <= u |m_ii - t|`. Hence
//! `lambda_min(M_exact) >= t - g (1+u)(sum|m_ii| + n t) - u (max|m_ii| + t) - r`, and
//! choosing `t` so that this is `>= shift` proves `lambda_min(M_exact) >= shift`.
//! The constants are doubled, `t` is rounded up by a relative `1e-12`, and an absolute
//! `1e-300 (n+2)^2` covers gradual underflow; matrices with nonzero entries outside
//! `[1e-200, 1e200]` in modulus, or whose factor overflows, are simply *not verified*
//! (never wrongly verified).
//!
//! The Cholesky routine below is the textbook algorithm (no FMA contraction: Rust does
//! not contract `a * b + c`), which is what the error analysis assumes.
//!
//! # The rounded `F`
//! `F = A + E C` (eq. (F)) reaches this module already rounded, `F_hat = fl(A + fl(E C))`. With
//! `VerifySettings::f_from_product` (the default) the three inequalities are proved for *every*
//! `F` in the entrywise enclosure `|F - F_hat| <= r_F`,
//! `r_F = 2 (gamma_1 |F_hat| + gamma_p |E| |C|)` ([`f_enclosure_radius`]; `p` the inner
//! dimension; `|fl(EC) - EC| <= gamma_p |E||C|` for any summation order or FMA use, and the
//! final addition adds `u |A + fl(EC)| <= gamma_1 |F_hat|`), in particular for the exact
//! `A + E C`. The enclosure enters the same entrywise error matrix `Err` as the rounding:
//! `|Delta N| <= (|Pi| r_F + (|Pi| r_F)^T) / 2` in (ALI) and `|Delta H| <= r_F^T |C|^T / 2` in
//! (bet), so the Rump margin covers it.

use crate::error::{LmiError, Result};
use crate::spectral_abscissa::{check_scalar, check_shape, check_system};
use nalgebra::DMatrix;
use rounding::{gamma, UNIT_ROUNDOFF};

/// Absolute slack per matrix entry covering gradual underflow (see module docs).
const UNDERFLOW_SLACK: f64 = 1e-300;

fn in_safe_range(x: f64) -> bool {
    x == 0.0 || (x.is_finite() && x.abs() >= 1e-200 && x.abs() <= 1e200)
}

/// Textbook Cholesky `B = R^T R` on the upper triangle of `B`; `false` when a pivot is
/// not positive or anything is non-finite.
fn cholesky_runs_to_completion(B: &DMatrix<f64>) -> bool {
    let n = B.nrows();
    let mut R = DMatrix::<f64>::zeros(n, n);
    for j in 0..n {
        // Off-diagonal entries of column j: r_ij = (b_ij - sum_{k<i} r_ki r_kj) / r_ii.
        for i in 0..j {
            let mut s = B[(i, j)];
            for k in 0..i {
                s -= R[(k, i)] * R[(k, j)];
            }
            let r = s / R[(i, i)];
            if !r.is_finite() {
                return false;
            }
            R[(i, j)] = r;
        }
        let mut s = B[(j, j)];
        for k in 0..j {
            s -= R[(k, j)] * R[(k, j)];
        }
        if !(s > 0.0) || !s.is_finite() {
            return false;
        }
        R[(j, j)] = s.sqrt();
    }
    true
}

/// Rump's test: returns `true` only if **every** symmetric matrix `M_exact` with
/// `||M_exact - S||_2 <= rounding_bound` has `lambda_min(M_exact) >= shift`, where `S` is
/// the symmetric matrix defined by the upper triangle of `M`. `false` means "not proved"
/// (the matrix may still be PSD).
pub fn proves_lambda_min_at_least(M: &DMatrix<f64>, rounding_bound: f64, shift: f64) -> bool {
    let n = M.nrows();
    if n == 0 || M.ncols() != n || !rounding_bound.is_finite() || rounding_bound < 0.0 || !shift.is_finite() {
        return false;
    }
    for j in 0..n {
        for i in 0..=j {
            if !in_safe_range(M[(i, j)]) {
                return false;
            }
        }
    }
    let u = UNIT_ROUNDOFF;
    let g1 = gamma(n + 1);
    let g = g1 / (1.0 - g1);
    let D: f64 = (0..n).map(|i| M[(i, i)].abs()).sum();
    let dmax = (0..n).map(|i| M[(i, i)].abs()).fold(0.0, f64::max);
    let nf = n as f64;
    let denom = 1.0 - 2.0 * (g * (1.0 + u) * nf + u);
    if !(denom > 0.5) {
        return false;
    }
    let slack = UNDERFLOW_SLACK * (nf + 2.0) * (nf + 2.0);
    let numer = shift + rounding_bound + 2.0 * g * (1.0 + u) * D + 2.0 * u * dmax + slack;
    let t = numer / denom * (1.0 + 1e-12);
    if !t.is_finite() {
        return false;
    }
    let mut B = DMatrix::<f64>::zeros(n, n);
    for j in 0..n {
        for i in 0..j {
            B[(i, j)] = M[(i, j)];
        }
        B[(j, j)] = M[(j, j)] - t;
    }
    cholesky_runs_to_completion(&B)
}

/// Verified lower bound on `lambda_min` for one matrix inequality.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Margin {
    /// `true` when `lambda_min(exact matrix) >= lower_bound >= 0` was proved.
    pub verified: bool,
    /// Proved lower bound on the smallest eigenvalue of the exact matrix (`NaN` when not
    /// verified). The margin by which the inequality holds.
    pub lower_bound: f64,
    /// Floating-point estimate of the smallest eigenvalue of the computed matrix.
    pub estimate: f64,
    /// Bound `r` on `||exact - computed||_2` from forming the matrix.
    pub rounding_bound: f64,
}

fn lambda_min_estimate(M: &DMatrix<f64>) -> f64 {
    let S = (M + M.transpose()) * 0.5;
    S.symmetric_eigen().eigenvalues.iter().copied().fold(f64::INFINITY, f64::min)
}

/// Prove `M_exact >= 0` for all `M_exact` within `rounding_bound` of `M` (upper triangle),
/// and find the largest proved lower bound on `lambda_min` among `{0.99, 0.5, 0} x estimate`.
pub fn psd_margin(M: &DMatrix<f64>, rounding_bound: f64) -> Margin {
    let estimate = lambda_min_estimate(M);
    let mut candidates = vec![];
    if estimate > 0.0 {
        candidates.extend([0.99 * estimate, 0.5 * estimate]);
    }
    candidates.push(0.0);
    for c in candidates {
        if proves_lambda_min_at_least(M, rounding_bound, c) {
            return Margin { verified: true, lower_bound: c, estimate, rounding_bound };
        }
    }
    Margin { verified: false, lower_bound: f64::NAN, estimate, rounding_bound }
}

fn frobenius(ErrB: &DMatrix<f64>) -> f64 {
    ErrB.iter().map(|e| e * e).sum::<f64>().sqrt() * (1.0 + 1e-10)
}

/// The symmetric matrix defined by the upper triangle of `Pi` (what is certified).
pub fn symmetrize_upper(Pi: &DMatrix<f64>) -> DMatrix<f64> {
    let n = Pi.nrows();
    DMatrix::from_fn(n, n, |i, j| if i <= j { Pi[(i, j)] } else { Pi[(j, i)] })
}

/// Entrywise radius `r_F = 2 (gamma_1 |F_hat| + gamma_p |E| |C|)` of an enclosure of the exact
/// `F = A + E C` around `F_hat = fl(A + fl(E C))` (module docs, "The rounded `F`"). It does not
/// depend on `A`. The evaluation of the bound itself is covered by the factor 2.
pub fn f_enclosure_radius(F: &DMatrix<f64>, E: &DMatrix<f64>, C: &DMatrix<f64>) -> DMatrix<f64> {
    let p = E.ncols();
    let (g1, gp) = (gamma(1), gamma(p.max(1)));
    DMatrix::from_fn(F.nrows(), F.ncols(), |i, j| {
        let ec: f64 = (0..p).map(|k| (E[(i, k)] * C[(k, j)]).abs()).sum();
        2.0 * (g1 * F[(i, j)].abs() + gp * ec) + UNDERFLOW_SLACK
    })
}

/// `N = -(S(Pi F) + lambda Pi)` of eq. (ALI), computed in floating point, with
/// `r >= ||N_exact - N||_2`. `Pi` must be symmetric. `F` is taken as exact; see
/// [`lyapunov_matrix_enclosed`] for an `F` known only up to an entrywise radius.
pub fn lyapunov_matrix(F: &DMatrix<f64>, Pi: &DMatrix<f64>, lambda: f64) -> (DMatrix<f64>, f64) {
    lyapunov_matrix_enclosed(F, None, Pi, lambda)
}

/// `(|Pi| r_F)_ij` (the perturbation of `Pi F` over the enclosure), rounded up by the factor
/// `1 + 2 gamma_{n+1}`.
fn abs_pi_times(Pi: &DMatrix<f64>, Fr: &DMatrix<f64>) -> DMatrix<f64> {
    let n = Pi.nrows();
    let g = 1.0 + 2.0 * gamma(n + 1);
    DMatrix::from_fn(n, Fr.ncols(), |i, j| (0..n).map(|k| Pi[(i, k)].abs() * Fr[(k, j)]).sum::<f64>() * g)
}

/// [`lyapunov_matrix`] for every `F` with `|F - F_hat| <= Fr` entrywise (`Fr = None`: exact `F`):
/// `r >= sup ||N_exact(F) - N||_2` over the enclosure.
pub fn lyapunov_matrix_enclosed(
    F: &DMatrix<f64>,
    Fr: Option<&DMatrix<f64>>,
    Pi: &DMatrix<f64>,
    lambda: f64,
) -> (DMatrix<f64>, f64) {
    let n = F.nrows();
    let PFr = Fr.map(|Fr| abs_pi_times(Pi, Fr));
    let gN = 2.0 * gamma(2 * n + 1);
    let mut N = DMatrix::zeros(n, n);
    let mut ErrB = DMatrix::zeros(n, n);
    for j in 0..n {
        for i in 0..=j {
            let mut s = 0.0;
            let mut a = 0.0;
            for k in 0..n {
                let t1 = (-0.5 * Pi[(i, k)]) * F[(k, j)];
                let t2 = (-0.5 * Pi[(j, k)]) * F[(k, i)];
                s += t1;
                s += t2;
                a += t1.abs() + t2.abs();
            }
            let t3 = -lambda * Pi[(i, j)];
            s += t3;
            a += t3.abs();
            let mut e = gN * a + UNDERFLOW_SLACK * (2 * n + 2) as f64;
            if let Some(P) = &PFr {
                e += 0.5 * (P[(i, j)] + P[(j, i)]) * (1.0 + 4.0 * UNIT_ROUNDOFF);
            }
            N[(i, j)] = s;
            N[(j, i)] = s;
            ErrB[(i, j)] = e;
            ErrB[(j, i)] = e;
        }
    }
    (N, frobenius(&ErrB))
}

/// `H = (Pi E - F^T C^T)/2` of eq. (G_H), computed in floating point.
pub fn h_matrix(F: &DMatrix<f64>, E: &DMatrix<f64>, C: &DMatrix<f64>, Pi: &DMatrix<f64>) -> DMatrix<f64> {
    (Pi * E - F.transpose() * C.transpose()) * 0.5
}

/// `K = [[Pi, H], [H^T, b I_p]]` (eq. (bet) via the Schur complement), computed in
/// floating point, with `r >= ||K_exact - K||_2` (only the `H` blocks carry rounding). `F` is
/// taken as exact; see [`schur_block_enclosed`].
pub fn schur_block(
    F: &DMatrix<f64>,
    E: &DMatrix<f64>,
    C: &DMatrix<f64>,
    Pi: &DMatrix<f64>,
    b: f64,
) -> (DMatrix<f64>, f64) {
    schur_block_enclosed(F, None, E, C, Pi, b)
}

/// [`schur_block`] for every `F` with `|F - F_hat| <= Fr` entrywise (`Fr = None`: exact `F`):
/// `H` moves by at most `(r_F^T |C|^T)_ij / 2` per entry.
pub fn schur_block_enclosed(
    F: &DMatrix<f64>,
    Fr: Option<&DMatrix<f64>>,
    E: &DMatrix<f64>,
    C: &DMatrix<f64>,
    Pi: &DMatrix<f64>,
    b: f64,
) -> (DMatrix<f64>, f64) {
    let n = F.nrows();
    let p = E.ncols();
    let gN = 2.0 * gamma(2 * n);
    let mut K = DMatrix::zeros(n + p, n + p);
    let mut ErrB = DMatrix::zeros(n + p, n + p);
    K.view_mut((0, 0), (n, n)).copy_from(Pi);
    for j in 0..p {
        K[(n + j, n + j)] = b;
        for i in 0..n {
            let mut s = 0.0;
            let mut a = 0.0;
            for k in 0..n {
                let t1 = (0.5 * Pi[(i, k)]) * E[(k, j)];
                let t2 = (-0.5 * F[(k, i)]) * C[(j, k)];
                s += t1;
                s += t2;
                a += t1.abs() + t2.abs();
            }
            let mut e = gN * a + UNDERFLOW_SLACK * (2 * n + 1) as f64;
            if let Some(Fr) = Fr {
                let d: f64 = (0..n).map(|k| Fr[(k, i)] * C[(j, k)].abs()).sum();
                e += 0.5 * d * (1.0 + 2.0 * gamma(n + 1));
            }
            K[(i, n + j)] = s;
            K[(n + j, i)] = s;
            ErrB[(i, n + j)] = e;
            ErrB[(n + j, i)] = e;
        }
    }
    (K, frobenius(&ErrB))
}

/// Floating-point estimate of `beta = lambda_max(H^T Pi^{-1} H)`, eq. (bet)
/// (`+inf` when `Pi` is not numerically positive definite).
pub fn beta_estimate(F: &DMatrix<f64>, E: &DMatrix<f64>, C: &DMatrix<f64>, Pi: &DMatrix<f64>) -> f64 {
    let H = h_matrix(F, E, C, Pi);
    match Pi.clone().cholesky() {
        Some(ch) => {
            let X = ch.l().solve_lower_triangular(&H).unwrap_or_else(|| H.clone() * f64::INFINITY);
            let M = X.transpose() * X;
            M.symmetric_eigen().eigenvalues.iter().copied().fold(f64::NEG_INFINITY, f64::max)
        }
        None => f64::INFINITY,
    }
}

/// Largest `lambda` with `-(S(Pi F) + lambda Pi) >= 0` in floating point: the smallest
/// generalised eigenvalue of `(-S(Pi F), Pi)`; `NaN` when `Pi` is not numerically PD.
pub fn lambda_of_pi(F: &DMatrix<f64>, Pi: &DMatrix<f64>) -> f64 {
    let PF = Pi * F;
    let S = -(&PF + PF.transpose()) * 0.5;
    match Pi.clone().cholesky() {
        Some(ch) => {
            let L = ch.l();
            let Y = match L.solve_lower_triangular(&S) {
                Some(Y) => Y,
                None => return f64::NAN,
            };
            let Z = match L.solve_lower_triangular(&Y.transpose()) {
                Some(Z) => Z,
                None => return f64::NAN,
            };
            lambda_min_estimate(&Z)
        }
        None => f64::NAN,
    }
}

/// How far [`certify`] may move `lambda` down and `b_hat` up to obtain a proof.
#[derive(Debug, Clone, PartialEq)]
pub struct VerifySettings {
    /// First relative back-off of `lambda` below `min(lambda, lambda(Pi))`; multiplied by 4
    /// at each further attempt. Default `1e-12`.
    pub tol_backoff_rel: f64,
    /// First relative inflation of `b_hat` above `max(b, beta(Pi))`; multiplied by 4 at
    /// each further attempt. Default `1e-12`.
    pub tol_inflate_rel: f64,
    /// Maximum number of back-off / inflation attempts each. Default `24`
    /// (`4^24 * 1e-12 ~ 0.28` relative at most).
    pub max_adjust_steps: usize,
    /// `F` was computed as `fl(A + fl(E C))`: prove the inequalities for every `F` in the
    /// enclosure of [`f_enclosure_radius`] (module docs, "The rounded `F`"). `false` treats the
    /// `F` handed in as exact. Default `true`.
    pub f_from_product: bool,
}

impl Default for VerifySettings {
    fn default() -> Self {
        Self { tol_backoff_rel: 1e-12, tol_inflate_rel: 1e-12, max_adjust_steps: 24, f_from_product: true }
    }
}

impl VerifySettings {
    /// Positive finite tolerances.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [("tol_backoff_rel", self.tol_backoff_rel), ("tol_inflate_rel", self.tol_inflate_rel)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(LmiError::InvalidSetting { name, value: v });
            }
        }
        Ok(())
    }
}

/// A checked certificate for eqs. (ALI) and (bet).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Certificate {
    /// All three inequalities proved.
    pub verified: bool,
    /// The `lambda` that was asked for.
    pub lambda_requested: f64,
    /// The `lambda` for which (ALI) is proved (`<= lambda_requested`; smaller only when
    /// the solver's `Pi` violated (ALI) by rounding and `lambda` had to be backed off).
    pub lambda: f64,
    /// The `b` that was asked for (e.g. the SDP optimum).
    pub b_requested: f64,
    /// Proved upper bound on `beta` of eq. (bet) (`>= b_requested`).
    pub b_hat: f64,
    /// Floating-point estimate of `beta(Pi)`.
    pub beta_estimate: f64,
    /// `Pi > 0`.
    pub pi_positive: Margin,
    /// `-(S(Pi F) + lambda Pi) >= 0`, eq. (ALI), at `lambda`.
    pub lyapunov: Margin,
    /// `[[Pi, H], [H^T, b_hat I]] >= 0`, eq. (bet), at `b_hat`.
    pub schur: Margin,
    /// The certified matrix (symmetric, from the upper triangle of the input).
    pub Pi: DMatrix<f64>,
    /// Frobenius norm of the entrywise radius `r_F` of the enclosure of `F` that the
    /// certificate covers (0 when `F` was taken as exact).
    #[serde(default)]
    pub f_radius: f64,
}

fn check_inputs(
    F: &DMatrix<f64>,
    E: &DMatrix<f64>,
    C: &DMatrix<f64>,
    Pi: &DMatrix<f64>,
    lambda: f64,
    b: f64,
) -> Result<()> {
    let (n, _) = check_system(F, E, C)?;
    check_shape("Pi", Pi, (n, n))?;
    crate::spectral_abscissa::check_finite("Pi", Pi)?;
    check_scalar("lambda", lambda)?;
    check_scalar("b", b)?;
    Ok(())
}

/// The enclosure radius of `F` that [`certify`] covers under `settings`.
fn f_radius_for(F: &DMatrix<f64>, E: &DMatrix<f64>, C: &DMatrix<f64>, f_from_product: bool) -> Option<DMatrix<f64>> {
    f_from_product.then(|| f_enclosure_radius(F, E, C))
}

fn frobenius_opt(Fr: &Option<DMatrix<f64>>) -> f64 {
    Fr.as_ref().map_or(0.0, |r| r.iter().map(|e| e * e).sum::<f64>().sqrt())
}

/// Check the three inequalities exactly at the given `lambda` and `b_hat` (no adjustment), for
/// every `F` in the enclosure of `fl(A + fl(E C))` ([`f_enclosure_radius`]).
pub fn check_certificate(
    F: &DMatrix<f64>,
    E: &DMatrix<f64>,
    C: &DMatrix<f64>,
    Pi: &DMatrix<f64>,
    lambda: f64,
    b_hat: f64,
) -> Result<Certificate> {
    check_certificate_with(F, E, C, Pi, lambda, b_hat, true)
}

/// [`check_certificate`] with the choice of [`VerifySettings::f_from_product`]: `false` takes `F`
/// as exact.
pub fn check_certificate_with(
    F: &DMatrix<f64>,
    E: &DMatrix<f64>,
    C: &DMatrix<f64>,
    Pi: &DMatrix<f64>,
    lambda: f64,
    b_hat: f64,
    f_from_product: bool,
) -> Result<Certificate> {
    check_inputs(F, E, C, Pi, lambda, b_hat)?;
    let Fr = f_radius_for(F, E, C, f_from_product);
    let Pi = symmetrize_upper(Pi);
    let pi_positive = psd_margin(&Pi, 0.0);
    let pi_positive = Margin { verified: pi_positive.verified && pi_positive.lower_bound > 0.0, ..pi_positive };
    let (N, rN) = lyapunov_matrix_enclosed(F, Fr.as_ref(), &Pi, lambda);
    let lyapunov = psd_margin(&N, rN);
    let (K, rK) = schur_block_enclosed(F, Fr.as_ref(), E, C, &Pi, b_hat);
    let schur = psd_margin(&K, rK);
    Ok(Certificate {
        f_radius: frobenius_opt(&Fr),
        verified: pi_positive.verified && lyapunov.verified && schur.verified,
        lambda_requested: lambda,
        lambda,
        b_requested: b_hat,
        b_hat,
        beta_estimate: beta_estimate(F, E, C, &Pi),
        pi_positive,
        lyapunov,
        schur,
        Pi,
    })
}

/// Certify `(Pi, lambda, b)`, backing `lambda` off and inflating `b` minimally (geometric
/// steps from [`VerifySettings`]) until eqs. (ALI) and (bet) are proved.
///
/// Returns the certificate; `verified == false` when the attempts are exhausted or
/// `Pi > 0` cannot be proved. `lambda` is never increased and `b_hat >= b`.
pub fn certify(
    F: &DMatrix<f64>,
    E: &DMatrix<f64>,
    C: &DMatrix<f64>,
    Pi: &DMatrix<f64>,
    lambda: f64,
    b: f64,
    settings: &VerifySettings,
) -> Result<Certificate> {
    settings.validate()?;
    check_inputs(F, E, C, Pi, lambda, b)?;
    let Fr = f_radius_for(F, E, C, settings.f_from_product);
    let Fr_ref = Fr.as_ref();
    let Pi = symmetrize_upper(Pi);
    let n = Pi.nrows();
    let pi_positive = psd_margin(&Pi, 0.0);
    let pi_ok = pi_positive.verified && pi_positive.lower_bound > 0.0;
    let pi_positive = Margin { verified: pi_ok, ..pi_positive };

    // (ALI): lambda first as asked, then backed off below the floating-point lambda(Pi).
    let (N, rN) = lyapunov_matrix_enclosed(F, Fr_ref, &Pi, lambda);
    let mut lyapunov = psd_margin(&N, rN);
    let mut lambda_v = lambda;
    if !lyapunov.verified {
        let lp = lambda_of_pi(F, &Pi);
        let start = if lp.is_finite() { lp.min(lambda) } else { lambda };
        let mut step = settings.tol_backoff_rel * lambda.abs().max(f64::MIN_POSITIVE);
        for _ in 0..settings.max_adjust_steps {
            let l = start - step;
            step *= 4.0;
            if !(l > 0.0) {
                break;
            }
            let (N, rN) = lyapunov_matrix_enclosed(F, Fr_ref, &Pi, l);
            let m = psd_margin(&N, rN);
            if m.verified {
                lyapunov = m;
                lambda_v = l;
                break;
            }
        }
    }

    // (bet): b as asked, then inflated above the floating-point beta(Pi).
    let beta_est = beta_estimate(F, E, C, &Pi);
    let (K, rK) = schur_block_enclosed(F, Fr_ref, E, C, &Pi, b);
    let mut schur = psd_margin(&K, rK);
    let mut b_hat = b;
    if !schur.verified && beta_est.is_finite() {
        let start = b.max(beta_est);
        let base = start.max(n as f64 * UNIT_ROUNDOFF * Pi.trace().abs());
        let mut step = settings.tol_inflate_rel * base;
        for _ in 0..settings.max_adjust_steps {
            let bb = start + step;
            step *= 4.0;
            let (K, rK) = schur_block_enclosed(F, Fr_ref, E, C, &Pi, bb);
            let m = psd_margin(&K, rK);
            if m.verified {
                schur = m;
                b_hat = bb;
                break;
            }
        }
    }
    Ok(Certificate {
        f_radius: frobenius_opt(&Fr),
        verified: pi_ok && lyapunov.verified && schur.verified,
        lambda_requested: lambda,
        lambda: lambda_v,
        b_requested: b,
        b_hat,
        beta_estimate: beta_est,
        pi_positive,
        lyapunov,
        schur,
        Pi,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn random_orthogonal(n: usize, seed: u64) -> DMatrix<f64> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let A = DMatrix::from_fn(n, n, |_, _| rng.random_range(-1.0..1.0));
        A.qr().q()
    }

    fn with_spectrum(eigs: &[f64], seed: u64) -> DMatrix<f64> {
        let n = eigs.len();
        let Q = random_orthogonal(n, seed);
        let D = DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(eigs));
        let M = &Q * D * Q.transpose();
        symmetrize_upper(&M)
    }

    #[test]
    fn pd_matrix_is_verified_with_margin() {
        let M = with_spectrum(&[1e-10, 1.0, 2.0, 3.0], 1);
        assert!(proves_lambda_min_at_least(&M, 0.0, 0.0));
        let m = psd_margin(&with_spectrum(&[0.5, 1.0, 2.0], 2), 0.0);
        assert!(m.verified);
        assert_relative_eq!(m.estimate, 0.5, epsilon = 1e-12);
        assert!(m.lower_bound > 0.49 && m.lower_bound <= 0.5);
    }

    #[test]
    fn negative_control_eigenvalue_minus_1e_minus_14_rejected() {
        for seed in 0..10 {
            let M = with_spectrum(&[-1e-14, 1.0, 2.0, 3.0], seed);
            assert!(!proves_lambda_min_at_least(&M, 0.0, 0.0), "seed {seed}");
            assert!(!psd_margin(&M, 0.0).verified);
        }
        // Exactly diagonal: the exact eigenvalue is -1e-14.
        let D = DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(&[1.0, -1e-14, 2.0]));
        assert!(!proves_lambda_min_at_least(&D, 0.0, 0.0));
        // A singular PSD matrix cannot be proved positive definite either.
        let Z = DMatrix::from_diagonal(&nalgebra::DVector::from_column_slice(&[1.0, 0.0]));
        assert!(!proves_lambda_min_at_least(&Z, 0.0, 0.0));
    }

    #[test]
    fn rounding_bound_and_shift_are_honoured() {
        let M = with_spectrum(&[0.1, 1.0, 2.0], 3);
        assert!(proves_lambda_min_at_least(&M, 0.05, 0.0));
        assert!(!proves_lambda_min_at_least(&M, 0.11, 0.0));
        assert!(proves_lambda_min_at_least(&M, 0.0, 0.09));
        assert!(!proves_lambda_min_at_least(&M, 0.0, 0.11));
        // NaN / huge entries: not verified.
        let mut Mn = M.clone();
        Mn[(0, 1)] = f64::NAN;
        assert!(!proves_lambda_min_at_least(&Mn, 0.0, 0.0));
        let mut Mh = M.clone();
        Mh[(0, 0)] = 1e250;
        assert!(!proves_lambda_min_at_least(&Mh, 0.0, 0.0));
    }

    /// F = -I: Pi = I satisfies (ALI) for lambda <= 1 with margin 1 - lambda.
    #[test]
    fn lyapunov_check_and_negative_control() {
        let F = -DMatrix::<f64>::identity(3, 3);
        let E = DMatrix::from_row_slice(3, 1, &[1.0, 0.0, 0.0]);
        let C = DMatrix::from_row_slice(1, 3, &[0.0, 1.0, 0.0]);
        let Pi = DMatrix::<f64>::identity(3, 3);
        // H = (E - F^T C^T)/2 = (e1 + e2)/2, beta = |H|^2 = 1/2.
        let cert = check_certificate(&F, &E, &C, &Pi, 0.5, 0.5 + 1e-12).unwrap();
        assert!(cert.verified, "{cert:?}");
        assert!(cert.lyapunov.lower_bound > 0.49);
        assert_relative_eq!(cert.beta_estimate, 0.5, epsilon = 1e-14);
        // Underestimated b_hat is rejected.
        let low = check_certificate(&F, &E, &C, &Pi, 0.5, 0.5 - 1e-9).unwrap();
        assert!(!low.schur.verified && !low.verified);
        // Pi = I violates (ALI) for a strongly non-normal F: S(F) has eigenvalue 4.
        let F2 = DMatrix::from_row_slice(2, 2, &[-1.0, 10.0, 0.0, -1.0]);
        let E2 = DMatrix::from_row_slice(2, 1, &[1.0, 0.0]);
        let C2 = DMatrix::from_row_slice(1, 2, &[1.0, 0.0]);
        let bad = check_certificate(&F2, &E2, &C2, &DMatrix::identity(2, 2), 0.5, 100.0).unwrap();
        assert!(!bad.lyapunov.verified && !bad.verified);
    }

    #[test]
    fn certify_backs_off_lambda_and_inflates_b_minimally() {
        let F = -DMatrix::<f64>::identity(2, 2);
        let E = DMatrix::from_row_slice(2, 1, &[1.0, 0.0]);
        let C = DMatrix::from_row_slice(1, 2, &[0.0, 1.0]);
        // Pi = (1 + 1e-9) I has lambda(Pi) = 1 exactly, so lambda = 1 is on the boundary:
        // ask for 1 - 1e-15 (margin below the rounding) and for b slightly too small.
        let Pi = DMatrix::<f64>::identity(2, 2) * (1.0 + 1e-9);
        let beta = beta_estimate(&F, &E, &C, &Pi);
        let cert = certify(&F, &E, &C, &Pi, 1.0 - 1e-15, beta * (1.0 - 1e-6), &VerifySettings::default()).unwrap();
        assert!(cert.verified, "{cert:?}");
        assert!(cert.lambda < 1.0 - 1e-15 && cert.lambda > 1.0 - 1e-9);
        assert!(cert.b_hat >= beta && cert.b_hat < beta * (1.0 + 1e-8));
        // With a Pi that is not positive definite nothing is verified.
        let Pbad = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, -1e-3]);
        let c2 = certify(&F, &E, &C, &Pbad, 0.5, 1.0, &VerifySettings::default()).unwrap();
        assert!(!c2.verified && !c2.pi_positive.verified);
    }
}
