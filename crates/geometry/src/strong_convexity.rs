//! The strong-convexity constant `R` of eq. (R).
use rounding::{gamma, UNIT_ROUNDOFF};

/// `R` of eq. (R): the smallest `r` such that the set is contained in every ball of radius
/// `r` supported at a boundary point by the same hyperplane (equivalently, the smallest `r`
/// such that the set is an intersection of balls of radius `r`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StrongConvexity {
    /// Closed form (ball: radius; ellipsoid with a diagonal matrix: `max a_i^2 / min a_i`; ...),
    /// evaluated with upward rounding where it is not exact: the value is `>= R` and equals `R`
    /// up to one rounding.
    Exact(f64),
    /// Numerical value with a stated absolute error: the true `R` lies in
    /// `[value - error, value + error]`.
    Numerical { value: f64, error: f64 },
    /// Only a proven upper bound is known (e.g. `R(S1 + S2) <= R(S1) + R(S2)`, or an ellipsoid's
    /// `lambda_max / sqrt(lambda_min)` from verified eigenvalue bounds,
    /// [`symmetric_eigen_enclosure`]).
    UpperBound(f64),
    /// Not strongly convex (polytopes): `R = infinity`, the paper's footnote case `gamma = 0`.
    Infinite,
    /// No method to compute `R` for this set (support-function sets in dimension >= 3);
    /// treated as infinite, the safe direction.
    Unknown,
}

impl StrongConvexity {
    /// The value to use where a *larger* `R` is the safe direction (every bound of the
    /// paper divides by `R`): the upper end of what is known.
    pub fn upper(&self) -> f64 {
        match *self {
            Self::Exact(r) | Self::UpperBound(r) => r,
            Self::Numerical { value, error } => value + error,
            Self::Infinite | Self::Unknown => f64::INFINITY,
        }
    }
    /// Best estimate (midpoint for numerical values).
    pub fn estimate(&self) -> f64 {
        match *self {
            Self::Exact(r) | Self::UpperBound(r) => r,
            Self::Numerical { value, .. } => value,
            Self::Infinite | Self::Unknown => f64::INFINITY,
        }
    }
    pub fn is_finite(&self) -> bool {
        self.upper().is_finite()
    }
    /// Whether `upper()` is a proven bound (closed form rounded upward, or an upper bound proved
    /// in the constructing code path, e.g. from verified eigenvalue bounds), as opposed to a
    /// numerical estimate with a heuristic error (`Numerical`, e.g. an ellipsoid whose eigenvalue
    /// enclosure could not be verified).
    pub fn is_verified_upper(&self) -> bool {
        matches!(self, Self::Exact(_) | Self::UpperBound(_))
    }
}

/// Rump's test for positive definiteness (S. M. Rump, "Verification of positive definiteness",
/// BIT 46 (2006) 433-452), the same proof as `lmi::verify::proves_lambda_min_at_least` (geometry
/// cannot depend on `lmi`): returns `true` only if every symmetric matrix within `rounding_bound`
/// (spectral norm) of the symmetric matrix defined by the upper triangle of `m` (row-major
/// `p x p`) has `lambda_min >= shift`.
///
/// If floating-point Cholesky of `B = fl(M - t I)` runs to completion then
/// `lambda_min(M) >= t - g (1+u)(sum|m_ii| + p t) - u (max|m_ii| + t)`, `g = gamma_{p+1} /
/// (1 - gamma_{p+1})` (Demmel's bound on the Cholesky backward error, rounding of the shift);
/// `t` is chosen (with doubled constants) so that this is `>= shift + rounding_bound`.
/// Entries outside `[1e-200, 1e200]` in modulus are never verified.
pub fn proves_lambda_min_at_least(m: &[f64], p: usize, rounding_bound: f64, shift: f64) -> bool {
    if p == 0 || m.len() != p * p || !rounding_bound.is_finite() || rounding_bound < 0.0 || !shift.is_finite() {
        return false;
    }
    let safe = |x: f64| x == 0.0 || (x.is_finite() && x.abs() >= 1e-200 && x.abs() <= 1e200);
    for i in 0..p {
        for j in i..p {
            if !safe(m[i * p + j]) {
                return false;
            }
        }
    }
    let u = UNIT_ROUNDOFF;
    let g1 = gamma(p + 1);
    let g = g1 / (1.0 - g1);
    let d: f64 = (0..p).map(|i| m[i * p + i].abs()).sum();
    let dmax = (0..p).map(|i| m[i * p + i].abs()).fold(0.0, f64::max);
    let pf = p as f64;
    let denom = 1.0 - 2.0 * (g * (1.0 + u) * pf + u);
    if !(denom > 0.5) {
        return false;
    }
    let slack = 1e-300 * (pf + 2.0) * (pf + 2.0);
    let numer = shift + rounding_bound + 2.0 * g * (1.0 + u) * d + 2.0 * u * dmax + slack;
    let t = numer / denom * (1.0 + 1e-12);
    if !t.is_finite() {
        return false;
    }
    // Textbook Cholesky of the upper triangle of B = M - t I (no FMA contraction in Rust).
    let mut r = vec![0.0; p * p];
    for j in 0..p {
        for i in 0..j {
            let mut s = m[i * p + j];
            for k in 0..i {
                s -= r[k * p + i] * r[k * p + j];
            }
            let v = s / r[i * p + i];
            if !v.is_finite() {
                return false;
            }
            r[i * p + j] = v;
        }
        let mut s = m[j * p + j] - t;
        for k in 0..j {
            s -= r[k * p + j] * r[k * p + j];
        }
        if !(s > 0.0) || !s.is_finite() {
            return false;
        }
        r[j * p + j] = s.sqrt();
    }
    true
}

/// Proven enclosure of the extreme eigenvalues of a symmetric matrix: `lambda_min >= min_lower`
/// and `lambda_max <= max_upper`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EigenEnclosure {
    pub min_lower: f64,
    pub max_upper: f64,
    /// The matrix is diagonal, so the bounds are its exact eigenvalues.
    pub exact: bool,
}

/// Verified bounds of `lambda_min` and `lambda_max` of the symmetric matrix `m` (row-major
/// `p x p`, upper triangle used) around floating-point estimates `min_approx <= max_approx`.
///
/// A diagonal matrix gives its diagonal (exact). Otherwise `lambda_min >= s` is proved by
/// [`proves_lambda_min_at_least`] on `M` for `s = min_approx - eps scale` and
/// `lambda_max <= s'` on `fl(s' I - M)` (its diagonal rounding, `u |s' - m_ii|` per entry, is the
/// rounding bound) for `s' = max_approx + eps scale`, `scale = max(|min_approx|, |max_approx|)`,
/// with `eps = 1e-15, 1e-14, ..., 1e-8` tried in turn. `None` when no proof is found (the
/// estimates are wrong or the matrix is too ill-conditioned): a wrong claim is never verified.
pub fn symmetric_eigen_enclosure(m: &[f64], p: usize, min_approx: f64, max_approx: f64) -> Option<EigenEnclosure> {
    if p == 0 || m.len() != p * p || !(min_approx.is_finite() && max_approx.is_finite()) {
        return None;
    }
    let diagonal = (0..p).all(|i| (0..p).all(|j| i == j || (m[i * p + j] == 0.0 && m[j * p + i] == 0.0)));
    if diagonal {
        let d = (0..p).map(|i| m[i * p + i]);
        let lo = d.clone().fold(f64::INFINITY, f64::min);
        let hi = d.fold(f64::NEG_INFINITY, f64::max);
        return (lo.is_finite() && hi.is_finite()).then_some(EigenEnclosure {
            min_lower: lo,
            max_upper: hi,
            exact: true,
        });
    }
    let scale = min_approx.abs().max(max_approx.abs());
    if !(scale > 0.0) {
        return None;
    }
    let eps = [1e-15, 1e-14, 1e-13, 1e-12, 1e-11, 1e-10, 1e-9, 1e-8];
    let min_lower = eps.iter().map(|e| min_approx - e * scale).find(|&s| proves_lambda_min_at_least(m, p, 0.0, s))?;
    let max_upper = eps.iter().map(|e| max_approx + e * scale).find(|&s| {
        let mut b = vec![0.0; p * p];
        let mut diag2 = 0.0;
        for i in 0..p {
            for j in 0..p {
                b[i * p + j] = if i == j { s - m[i * p + i] } else { -m[i * p + j] };
            }
            diag2 += b[i * p + i] * b[i * p + i];
        }
        // |fl(s - m_ii) - (s - m_ii)| <= u |fl(s - m_ii)| / (1 - u); doubled.
        let r = 2.0 * UNIT_ROUNDOFF * diag2.sqrt() * (1.0 + 1e-10);
        proves_lambda_min_at_least(&b, p, r, 0.0)
    })?;
    Some(EigenEnclosure { min_lower, max_upper, exact: false })
}

impl std::fmt::Display for StrongConvexity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Self::Exact(r) => write!(f, "{r} (exact)"),
            Self::Numerical { value, error } => write!(f, "{value} +- {error:.1e} (numerical)"),
            Self::UpperBound(r) => write!(f, "<= {r}"),
            Self::Infinite => write!(f, "infinite (not strongly convex)"),
            Self::Unknown => write!(f, "unknown (treated as infinite)"),
        }
    }
}
