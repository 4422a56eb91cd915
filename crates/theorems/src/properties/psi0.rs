//! `psi(0) >= 0`, eq. (psilim), for every `Pi` admissible in Section 6: if `Pi > 0` satisfies
//! (ALI) `S(Pi F) <= -lambda Pi` with `lambda > 0`, then `beta = lambda_max(H^T Pi^{-1} H)`,
//! eq. (bet), is at least `alpha lambda`, `alpha` of eq. (alpha); equivalently
//! `psi(0) = sqrt(beta + (alpha - lambda)^2/4) - (alpha + lambda)/2 >= 0`. The paper's case
//! "psi(0) < 0, i.e. alpha > beta / lambda" (after (VV)) is therefore empty
//! (proofs-notes/psi0.md): without strong convexity (`gamma = 0`, polytopes) eq. (theta)
//! certifies nothing.
//!
//! Cases: random Hurwitz `F` (the systems strategy), random `C`; `E` either random or
//! `E = C^T (C C^T)^{-1} K + 0.1 E_r` with `K` positive definite (then `S(C E)` is mostly
//! positive definite, `alpha > 0`, the only case where the claim has content); `lambda` a
//! fraction of `|mu|`; `Pi` the solution of `Pi (F + lambda I) + (F + lambda I)^T Pi = -Q`, `Q`
//! random positive definite (every such `Pi` satisfies (ALI) at `lambda`, and every `Pi`
//! satisfying (ALI) strictly arises this way).
//! Check: `lhs = alpha lambda <= rhs = beta`, both in floating point.
//! Negative control: `alpha lambda <= beta / 4` (a `beta` four times smaller than any
//! admissible `Pi` gives): caught on cases with `alpha > 0`.
//! Tolerance: `1e-9 (|alpha| lambda + beta) + 1e3 eps cond(Pi) |H|^2 / lambda_min(Pi)` for the
//! Lyapunov solve and the eigenvalues.
use super::sets_prelude::*;
use crate::strategies::systems::{system_params, SystemParams, SystemStrategyConfig, MAX_N};
use nalgebra::DMatrix;

pub fn info() -> PropertyInfo {
    PropertyInfo {
        name: "psi0",
        label: "(psilim)",
        title: "psi(0) >= 0, i.e. beta >= alpha lambda, for every Pi satisfying (ALI)",
        default_cases: 5000,
        negative_control: "alpha lambda <= beta / 4",
    }
}

#[derive(Debug, Clone)]
pub struct Psi0Case {
    pub sys: SystemParams,
    /// `E` built from `C` so that `S(C E)` is (mostly) positive definite.
    pub coupled: bool,
    /// Entries of `K` (`p x p` used) and of `L` (`Q = L L^T + 0.05 I`).
    pub k: [f64; MAX_N * MAX_N],
    pub l: [f64; MAX_N * MAX_N],
    /// `lambda = frac |mu|`.
    pub frac: f64,
}

pub fn strategy() -> BoxedStrategy<Psi0Case> {
    let cfg = SystemStrategyConfig { max_p: 4, ..SystemStrategyConfig::default() };
    (
        system_params(&cfg),
        any::<bool>(),
        proptest::array::uniform16(-1.0..=1.0f64),
        proptest::array::uniform16(-1.0..=1.0f64),
        0.02..=0.98f64,
    )
        .prop_map(|(sys, coupled, k, l, frac)| Psi0Case { sys, coupled, k, l, frac })
        .boxed()
}

/// The matrices of one case: `F`, `C`, `E`, `Pi`, `lambda`.
#[derive(Debug, Clone)]
pub struct Psi0Data {
    pub F: DMatrix<f64>,
    pub C: DMatrix<f64>,
    pub E: DMatrix<f64>,
    pub Pi: DMatrix<f64>,
    pub lambda: f64,
}

impl Psi0Case {
    /// `None` when `C C^T` is too ill-conditioned to build the coupled `E` or the Lyapunov
    /// solve fails (skipped cases).
    pub fn data(&self) -> Option<Psi0Data> {
        let sys = self.sys.build();
        let (n, p) = (sys.n(), sys.p());
        let F = sys.F();
        let C = sys.C.clone();
        let E = if self.coupled {
            let K0 = DMatrix::from_fn(p, p, |i, j| self.k[i * MAX_N + j]);
            let K = &K0 * K0.transpose() + DMatrix::identity(p, p) * 0.1 + (&K0 - K0.transpose()) * 0.5;
            let CCt = &C * C.transpose();
            let inv = CCt.try_inverse()?;
            C.transpose() * inv * K + &sys.E * 0.1
        } else {
            sys.E.clone()
        };
        // F = V J V^{-1}: its eigenvalues' real parts are the strategy's `re`.
        let mu = self.sys.re[..n].iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if !(mu < 0.0) {
            return None;
        }
        let lambda = self.frac * -mu;
        let L = DMatrix::from_fn(n, n, |i, j| self.l[i * MAX_N + j]);
        let Q = &L * L.transpose() + DMatrix::identity(n, n) * 0.05;
        let Fs = &F + DMatrix::identity(n, n) * lambda;
        let Pi = lyapunov(&Fs, &Q)?;
        Some(Psi0Data { F, C, E, Pi, lambda })
    }
}

/// Solves `Pi G + G^T Pi = -Q` (`G` Hurwitz, `n <= 4`) through the Kronecker form; `None` if
/// singular or the result is not positive definite.
pub fn lyapunov(G: &DMatrix<f64>, Q: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let n = G.nrows();
    let I = DMatrix::<f64>::identity(n, n);
    // vec(Pi G) = (G^T kron I) vec(Pi), vec(G^T Pi) = (I kron G^T) vec(Pi) (column-major vec).
    let K = G.transpose().kronecker(&I) + I.kronecker(&G.transpose());
    let rhs = nalgebra::DVector::from_iterator(n * n, Q.iter().map(|q| -q));
    let v = K.lu().solve(&rhs)?;
    let P = DMatrix::from_column_slice(n, n, v.as_slice());
    let P = (&P + P.transpose()) * 0.5;
    let lmin = P.clone().symmetric_eigen().eigenvalues.min();
    (lmin > 0.0).then_some(P)
}

/// `alpha`, `beta` (eq. (bet)) and the tolerance's scale for `Pi`.
pub fn alpha_beta(d: &Psi0Data) -> Option<(f64, f64, f64)> {
    let CE = &d.C * &d.E;
    let alpha = ((&CE + CE.transpose()) * 0.5).symmetric_eigen().eigenvalues.min();
    let H = (&d.Pi * &d.E - d.F.transpose() * d.C.transpose()) * 0.5;
    let eig = d.Pi.clone().symmetric_eigen();
    let (pmin, pmax) = (eig.eigenvalues.min(), eig.eigenvalues.max());
    let Pinv = d.Pi.clone().try_inverse()?;
    let M = H.transpose() * Pinv * &H;
    let beta = ((&M + M.transpose()) * 0.5).symmetric_eigen().eigenvalues.max();
    let scale = (pmax / pmin) * H.norm_squared() / pmin;
    Some((alpha, beta, scale))
}

pub fn eval(case: &Psi0Case, variant: Variant) -> Eval {
    let Some(d) = case.data() else { return Eval::skipped() };
    let Some((alpha, beta, scale)) = alpha_beta(&d) else { return Eval::skipped() };
    if !(alpha.is_finite() && beta.is_finite() && scale.is_finite()) {
        return Eval::skipped();
    }
    let lhs = alpha * d.lambda;
    let rhs = match variant {
        Variant::Claim => beta,
        Variant::NegativeControl => beta / 4.0,
    };
    let tol = 1e-9 * (lhs.abs() + beta) + 1e3 * f64::EPSILON * scale;
    Eval::new(lhs, rhs, tol)
}

pub fn export(case: &Psi0Case, e: &Eval) -> Counterexample {
    let sys = case.sys.build();
    let extra = match case.data() {
        Some(d) => format!("lambda = {:e}, E = {:?}, Pi = {:?}", d.lambda, d.E.as_slice(), d.Pi.as_slice()),
        None => "no data".into(),
    };
    system_counterexample(&sys, e, "psi0", &extra)
}

pub fn property() -> Prop<Psi0Case> {
    Prop { info: info(), strategy, eval, export, max_shrink_iters: 500 }
}
