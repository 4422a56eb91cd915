//! The strong-convexity constant `R` of eq. (R).

/// `R` of eq. (R): the smallest `r` such that the set is contained in every ball of radius
/// `r` supported at a boundary point by the same hyperplane (equivalently, the smallest `r`
/// such that the set is an intersection of balls of radius `r`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StrongConvexity {
    /// Closed form (ball: radius; ellipsoid: `max a_i^2 / min a_i`; ...).
    Exact(f64),
    /// Numerical value with a stated absolute error: the true `R` lies in
    /// `[value - error, value + error]`.
    Numerical { value: f64, error: f64 },
    /// Only an upper bound is known (e.g. `R(S1 + S2) <= R(S1) + R(S2)`).
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
    /// Whether `upper()` is a proven bound (closed form or stated upper bound), as opposed to
    /// a numerical estimate with a heuristic error.
    pub fn is_verified_upper(&self) -> bool {
        matches!(self, Self::Exact(_) | Self::UpperBound(_))
    }
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
