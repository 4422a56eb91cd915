//! The semigroup `e^{sF}` with proven bounds: short-step and long-time exponentials with their
//! error bounds, the grid bound of `sup ||e^{sF}||` and `int_0^inf ||e^{sF}||` ("the semigroup
//! bound" of proofs-notes/tube-quadrature.md), the tail bound (DXX), and [`SemigroupData`], what
//! every kernel on the same `F` shares.
use super::frob;
use crate::error::BoundsError;
use dynamics::linear::expm::{expm, expm_enclosure, frobenius_up};
use geometry::{ConvexSet, Shape};
use nalgebra::DMatrix;
use rounding::{gamma, mul_up, sqrt_up, UNIT_ROUNDOFF};

/// `h ||F||_F` above which a step of a Hurwitz `F` is taken by squaring ([`exp_long`]) and the
/// semigroup bound uses nested grids ([`semigroup_levels`]); at or below it the computations are
/// those of the short-step formulas (proofs-notes/tube-quadrature.md, "stiff plants").
pub(super) const LONG_STEP: f64 = 2.0;

/// `e^{hF}` for a short step: `(S, e_S)` with `e_S >= ||S - e^{hF}||_2` (the `expm` enclosure of
/// `fl(h F)` plus the perturbation from rounding `h F`).
fn exp_step(F: &DMatrix<f64>, h: f64) -> (DMatrix<f64>, f64) {
    let A = F * h;
    let nA = frobenius_up(&A);
    let dA = UNIT_ROUNDOFF * nA * (1.0 + 4.0 * UNIT_ROUNDOFF);
    let (X, eX) = expm_enclosure(&A);
    let pert = dA * (nA + 2.0 * dA).exp() * (1.0 + 1e-6);
    (X, eX + pert)
}

/// `e^{tF}` for a possibly long time: `(X, err)`, `err >= ||X - e^{tF}||_2`, given
/// `msup >= sup_{[0, t]} ||e^{sF}||_2` (Gronwall for the rounding of `fl(t F)`). For
/// `t ||F||_F > 64` and either `t ||F||_F > 1e4` or an error bound above `1e-8` (stiff
/// plants) the squaring of [`exp_long`] is tried as well and the smaller error kept.
pub(super) fn exp_at(F: &DMatrix<f64>, t: f64, msup: f64) -> (DMatrix<f64>, f64) {
    let A = F * t;
    let (X, eX) = expm_enclosure(&A);
    if t == 0.0 {
        return (X, eX);
    }
    let nA = frobenius_up(&A);
    let eps = UNIT_ROUNDOFF * nA * (1.0 + 4.0 * UNIT_ROUNDOFF) / t.abs();
    let pert = t.abs() * msup * msup * eps * (msup * eps * t.abs()).exp() * (1.0 + 1e-6);
    let err = eX + pert;
    if t > 0.0 && nA > 64.0 && msup.is_finite() && (nA > 1e4 || !(err <= 1e-8)) {
        let (Y, eY) = exp_long(F, t, msup);
        if eY < err {
            return (Y, eY);
        }
    }
    (X, err)
}

/// Upper bound of `||P||_2` (proofs-notes/tube-quadrature.md, "stiff plants"): the crude
/// `min(||P||_F, sqrt(||P||_1 ||P||_inf))`, or, when it is proven, `sqrt(t)` with
/// `t = (1 + 1e-7)^2 sigma_est^2` from the computed singular values: Rump's test
/// ([`lmi::verify::proves_lambda_min_at_least`]) proves `t I - P^T P >= 0` for every matrix
/// within `gamma_n ||P||_F^2 + u (t + max G_ii)` of the computed `t I - fl(P^T P)`.
pub(super) fn norm2_up(P: &DMatrix<f64>) -> f64 {
    let n = P.nrows().max(P.ncols());
    let g = 1.0 + 2.0 * gamma(n + 2);
    let col = (0..P.ncols()).map(|j| P.column(j).iter().map(|x| x.abs()).sum::<f64>()).fold(0.0, f64::max) * g;
    let row = (0..P.nrows()).map(|i| P.row(i).iter().map(|x| x.abs()).sum::<f64>()).fold(0.0, f64::max) * g;
    let nf = frobenius_up(P);
    let crude = nf.min(sqrt_up(mul_up(col, row)));
    if !(crude.is_finite() && crude > 0.0) || n == 0 {
        return crude;
    }
    let sigma = P.clone().singular_values().max();
    let t = (sigma * (1.0 + 1e-7)).powi(2);
    if !(t.is_finite() && t > 0.0 && t < crude * crude) {
        return crude;
    }
    let G = P.transpose() * P;
    let gmax = (0..G.nrows()).map(|i| G[(i, i)].abs()).fold(0.0, f64::max);
    let rb = (gamma(P.nrows()) * nf * nf + 2.0 * UNIT_ROUNDOFF * (t + gmax)) * (1.0 + 1e-10);
    let M = DMatrix::<f64>::identity(G.nrows(), G.ncols()) * t - G;
    if lmi::verify::proves_lambda_min_at_least(&M, rb, 0.0) {
        sqrt_up(t).min(crude)
    } else {
        crude
    }
}

/// `e^{tF}` for a long step `t > 0` by squaring (proofs-notes/tube-quadrature.md, "stiff
/// plants"): `t = 2^k h` with `||h F||_F <= 1/2`, `S_0 = ` [`exp_step`]`(F, h)`, then `k`
/// squarings. With `S = E + D`, `E = e^{uF}`: `S^2 - E^2 = S D + D E`, so the error in the
/// 2-norm obeys `e <- e (||S||_2 + min(msup, ||S||_2 + e)) + gamma_n ||S||_F^2` (the
/// product's rounding), given `msup >= sup_{[0, t]} ||e^{sF}||_2`. Returns `(X, e)`, `e >= ||X - e^{tF}||_2` (`+inf` when
/// `t` cannot be halved exactly that far).
pub(super) fn exp_long(F: &DMatrix<f64>, t: f64, msup: f64) -> (DMatrix<f64>, f64) {
    let n = F.nrows();
    let nF = frobenius_up(F);
    let mut h = t;
    let mut k = 0usize;
    while h * nF > 0.5 && k < 2000 {
        h *= 0.5;
        k += 1;
    }
    let (mut S, mut e) = exp_step(F, h);
    if !(h >= 1e-280 && h * nF <= 0.5) {
        return (S, f64::INFINITY);
    }
    let gn = gamma(n);
    for _ in 0..k {
        let nf = frobenius_up(&S);
        let ns = norm2_up(&S);
        e = (e * (ns + msup.min(ns + e)) + gn * nf * nf) * (1.0 + 1e-12);
        S = &S * &S;
    }
    (S, if e.is_finite() { e } else { f64::INFINITY })
}

/// Proven `sup_{[0, tau]} ||e^{sF}||_2` and `||e^{tau F}||_2` (upper bounds) from a grid of
/// `k` steps (`k` a power of two, so `tau / k` is exact): proofs-notes/tube-quadrature.md, "the semigroup bound".
fn semigroup_grid(F: &DMatrix<f64>, tau: f64, k: usize) -> (f64, f64) {
    let n = F.nrows();
    let delta = tau / k as f64;
    let (S, eS) = exp_step(F, delta);
    let nS = frobenius_up(&S);
    let gn = gamma(n);
    let mut P = DMatrix::<f64>::identity(n, n);
    let mut np = vec![frobenius_up(&P)];
    let mut m = vec![np[0]];
    let mut loc: Vec<f64> = vec![0.0];
    for j in 1..=k {
        loc.push(np[j - 1] * (eS + gn * nS));
        P = &P * &S;
        np.push(frobenius_up(&P));
        let d: f64 = (1..=j).map(|i| loc[i] * m[j - i]).sum::<f64>() * (1.0 + 2.0 * gamma(j + 1));
        m.push(np[j] + d);
    }
    let grid_max = m.iter().copied().fold(0.0, f64::max);
    let sup = grid_max * (delta * frobenius_up(F)).exp() * (1.0 + 1e-10);
    (sup, m[k])
}

/// One grid of `k` steps `S ~ e^{delta F}` (`e_S >= ||S - e^{delta F}||_2`): the products
/// `P_j = fl(P_{j-1} S)`, their errors `d_j` (propagated through the exact semigroup as in
/// [`semigroup_grid`]) and `m_j = ||P_j||_2 + d_j >= ||e^{j delta F}||_2` (2-norm bounds by
/// [`norm2_up`]). Returns `(max_j m_j, P_k, d_k, m_k)`.
fn grid_walk(S: &DMatrix<f64>, eS: f64, k: usize) -> (f64, DMatrix<f64>, f64, f64) {
    let n = S.nrows();
    let nS = frobenius_up(S);
    let gn = gamma(n);
    let mut P = DMatrix::<f64>::identity(n, n);
    let mut nf = vec![frobenius_up(&P)];
    let mut m = vec![norm2_up(&P)];
    let mut loc: Vec<f64> = vec![0.0];
    let mut d = 0.0;
    for j in 1..=k {
        loc.push(nf[j - 1] * (eS + gn * nS));
        P = &P * S;
        nf.push(frobenius_up(&P));
        d = (1..=j).map(|i| loc[i] * m[j - i]).sum::<f64>() * (1.0 + 2.0 * gamma(j + 1));
        m.push(norm2_up(&P) + d);
    }
    let grid_max = m.iter().copied().fold(0.0, f64::max);
    (grid_max * (1.0 + 1e-12), P, d, m[k] * (1.0 + 1e-12))
}

/// The semigroup bound of a stiff `F` (`tau / 256 ||F||_F > 1/2`; proofs-notes/
/// tube-quadrature.md, "stiff plants"): nested grids of 256 steps, `delta_0 = tau / 256`,
/// `delta_{l+1} = delta_l / 256` until `delta_L ||F||_F <= 1/2`. From the bottom:
/// `sup_{[0, delta_L]} ||e^{sF}|| <= e^{delta_L ||F||_F}`; the grid of level `l` (steps
/// `e^{delta_l F}`, the end product of the level below with its error) gives
/// `sup_{[0, 256 delta_l]} <= max_j m_j sup_{[0, delta_l]}` (`e^{(j delta + u) F} =
/// e^{j delta F} e^{uF}`). Returns `(sup_{[0, tau]}, q >= ||e^{tau F}||_2)`.
fn semigroup_levels(F: &DMatrix<f64>, tau: f64) -> (f64, f64) {
    let nF = frobenius_up(F);
    let mut deltas = vec![tau / 256.0];
    while deltas[deltas.len() - 1] * nF > 0.5 && deltas.len() < 12 {
        let d = deltas[deltas.len() - 1] / 256.0;
        deltas.push(d);
    }
    let dL = deltas[deltas.len() - 1];
    let mut sup = (dL * nF).exp() * (1.0 + 1e-10);
    let (mut S, mut eS) = exp_step(F, dL);
    let mut q = f64::INFINITY;
    for _ in 0..deltas.len() {
        let (gmax, P, d, mk) = grid_walk(&S, eS, 256);
        sup = gmax * sup * (1.0 + 1e-12);
        S = P;
        eS = d;
        q = mk;
    }
    if !(sup.is_finite() && q.is_finite()) {
        return (f64::INFINITY, f64::INFINITY);
    }
    (sup, q)
}

/// Proven bounds of the semigroup of a Hurwitz `F`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExpNormBounds {
    /// `>= sup_{s >= 0} ||e^{sF}||_2`.
    pub sup: f64,
    /// `>= int_0^inf ||e^{sF}||_2 ds`.
    pub integral: f64,
}

/// Bound `int_0^inf ||e^{rF}|| dr <= tau M / (1 - q)` (see the proofs-notes/tube-quadrature.md).
pub fn exp_norm_integral(F: &DMatrix<f64>) -> Result<f64, BoundsError> {
    Ok(exp_norm_bounds(F)?.integral)
}

/// [`ExpNormBounds`]: `tau` doubles from `1 / |mu|` until the floating-point `||e^{tau F}||_F`
/// is below `1/2`; then a 256-step grid on `[0, tau]` proves `M >= sup_{[0,tau]} ||e^{rF}||`
/// and `q >= ||e^{tau F}||` (proofs-notes/tube-quadrature.md) and, when `q < 1/2`, `sup_{s>=0} ||e^{sF}|| <= M`,
/// `int_0^inf ||e^{rF}|| dr <= tau M / (1 - q)`.
pub fn exp_norm_bounds(F: &DMatrix<f64>) -> Result<ExpNormBounds, BoundsError> {
    exp_norm_bounds_mu(F, lmi::spectral_abscissa(F).map_err(BoundsError::Lmi))
}

/// [`exp_norm_bounds`] given the spectral abscissa of `F` (or the error computing it).
fn exp_norm_bounds_mu(F: &DMatrix<f64>, mu: Result<f64, BoundsError>) -> Result<ExpNormBounds, BoundsError> {
    let mu = mu?;
    if mu >= 0.0 {
        return Err(BoundsError::NotHurwitz { mu });
    }
    let mut tau = 1.0 / -mu;
    let nF = frob(F);
    for _ in 0..40 {
        let q_est = frob(&expm(&(F * tau)));
        if q_est < 0.5 {
            let (sup, q) = if tau / 256.0 * nF > 0.5 { semigroup_levels(F, tau) } else { semigroup_grid(F, tau, 256) };
            if q < 0.5 {
                return Ok(ExpNormBounds { sup, integral: tau * sup / (1.0 - q) * (1.0 + 1e-10) });
            }
        }
        tau *= 2.0;
    }
    Err(BoundsError::NoTailBound { tau_max: tau })
}

/// Proven `sup_{[0, t]} ||e^{sF}||_2` for any `F` (the semigroup bound of a Hurwitz `F`, else a
/// grid on `[0, t (1 + 2^-20)]` with `max(256, t ||F||)` steps, a power of two, at most 4096).
pub(super) fn exp_sup_on(F: &DMatrix<f64>, t: f64, bounds: &Result<ExpNormBounds, BoundsError>) -> f64 {
    if let Ok(b) = bounds {
        return b.sup;
    }
    let t = t * (1.0 + 2f64.powi(-20));
    let mut k = 256usize;
    while (k as f64) < t * frob(F) && k < 4096 {
        k *= 2;
    }
    semigroup_grid(F, t, k).0
}

/// Eq. (DXX): `D(Xi_inf, Xi(t)) <= D(Theta, {0}) ||E|| int_t^inf ||e^{sF}|| ds`, bounded by
/// `D_Theta ||E||_F ||e^{tF}||_F int_0^inf ||e^{rF}|| dr` (see [`exp_norm_integral`]), with the
/// rounding of `e^{tF}` bounded (proofs-notes/tube-quadrature.md).
pub fn dxx_bound(F: &DMatrix<f64>, E: &DMatrix<f64>, theta: &Shape, t: f64) -> Result<f64, BoundsError> {
    let b = exp_norm_bounds(F)?;
    let (X, err) = exp_at(F, t, b.sup);
    Ok(theta.deviation_from_origin().upper * frob(E) * (frob(&X) + err) * b.integral * (1.0 + 1e-10))
}

/// How much `int_0^inf ||e^{s F_exact}||` can exceed the proven integral `I` of the computed
/// `F` when `||F_exact - F|| <= eps`: `eps I^2 / (1 - eps I)` (the perturbation series of the
/// resolvent); `+inf` where `eps I >= 1/2`.
pub fn perturbed_integral_excess(integral: f64, eps: f64) -> f64 {
    if eps * integral < 0.5 {
        eps * integral * integral / (1.0 - eps * integral)
    } else {
        f64::INFINITY
    }
}

/// What every kernel with the same `F` (resp. the same `Theta`) computes first: the spectral
/// abscissa of `F`, its proven semigroup bounds ([`exp_norm_bounds`]) and `D(Theta, {0})` from
/// above. Computed once by a caller that builds several kernels (the Theorem 2 and Lemma 2
/// checks of the campaign, [`crate::tube::tube_diameters`]) and handed to
/// [`TubeKernel::with_shared`]: the kernels are the same, bit for bit, as [`TubeKernel::new`]'s.
/// It also memoises the short-step exponentials `exp_step(F, h)` (with their error bounds) by
/// the exact bits of `h`: a finite-horizon kernel uses one step for every block, and kernels on
/// the same `F` (the checkpoints of Lemma 2, `C Xi_inf` and `C F Xi_inf`) start with the same
/// steps.
#[derive(Debug)]
pub struct SemigroupData {
    pub(super) f: DMatrix<f64>,
    pub(super) mu: Result<f64, BoundsError>,
    pub(super) bounds: Result<ExpNormBounds, BoundsError>,
    steps: std::sync::Mutex<Vec<(u64, DMatrix<f64>, f64)>>,
}

impl SemigroupData {
    /// The proven semigroup bounds of `F` (`sup ||e^{sF}||`, `int_0^inf ||e^{sF}||`), when `F`
    /// is Hurwitz and they were proven.
    pub fn exp_norm(&self) -> Option<ExpNormBounds> {
        self.bounds.as_ref().ok().cloned()
    }
}

/// Most memoised steps per [`SemigroupData`].
const STEP_MEMO: usize = 64;

impl Clone for SemigroupData {
    fn clone(&self) -> Self {
        let steps = self.steps.lock().map(|v| v.clone()).unwrap_or_default();
        Self {
            f: self.f.clone(),
            mu: self.mu.clone(),
            bounds: self.bounds.clone(),
            steps: std::sync::Mutex::new(steps),
        }
    }
}

impl SemigroupData {
    /// Spectral abscissa and [`exp_norm_bounds`] of `F`.
    pub fn new(F: &DMatrix<f64>) -> Self {
        let mu = lmi::spectral_abscissa(F).map_err(BoundsError::Lmi);
        let bounds = exp_norm_bounds_mu(F, mu.clone());
        Self { f: F.clone(), mu, bounds, steps: std::sync::Mutex::new(Vec::new()) }
    }
    /// `exp_step(F, h)`, memoised (the same value, bit for bit: a deterministic function of
    /// `F` and `h`).
    pub(super) fn exp_step(&self, h: f64) -> (DMatrix<f64>, f64) {
        let key = h.to_bits();
        if let Ok(v) = self.steps.lock() {
            if let Some((_, S, e)) = v.iter().find(|(k, _, _)| *k == key) {
                return (S.clone(), *e);
            }
        }
        let r = match &self.bounds {
            Ok(b) if h * frobenius_up(&self.f) > LONG_STEP => exp_long(&self.f, h, b.sup),
            _ => exp_step(&self.f, h),
        };
        if let Ok(mut v) = self.steps.lock() {
            if v.len() < STEP_MEMO {
                v.push((key, r.0.clone(), r.1));
            }
        }
        r
    }
    /// The proven bounds of `e^{sF}` (or why they could not be proven).
    pub fn bounds(&self) -> &Result<ExpNormBounds, BoundsError> {
        &self.bounds
    }
}
