//! Labelled quantities: every number of the theta report carries its symbol, the equation
//! label of `strongly-convex-backlash.tex`, the direction in which it bounds the true value,
//! and whether that bound is verified. Each is declared once ([`defs`]); the text table
//! ([`render_table`]), the JSON keys (`ThetaReport::to_json`) and the sweep columns of
//! `moreau sweep` derive from the declarations.
//!
//! The report of one model, [`ThetaReport`], and its JSON are in [`theta_report`].

pub mod theta_report;

pub use theta_report::{MeasuredSide, ThetaReport};

/// How a reported number relates to the true quantity.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BoundKind {
    /// Exact up to floating-point rounding.
    Exact,
    /// An upper bound of the true value.
    Upper,
    /// A lower bound of the true value.
    Lower,
    /// Measured or sampled: no bound claimed.
    Estimate,
}

impl BoundKind {
    pub fn as_str(&self) -> &'static str {
        match self {
            BoundKind::Exact => "exact",
            BoundKind::Upper => "upper bound",
            BoundKind::Lower => "lower bound",
            BoundKind::Estimate => "estimate",
        }
    }
}

/// The declaration of one reported quantity: everything about it that does not depend on
/// the system. Declared once in [`defs`]; the text table, the `--json` keys and the sweep
/// columns are all derived from these declarations.
#[derive(Debug, PartialEq)]
pub struct QuantityDef {
    /// Stable snake_case key: the JSON key of the value and the sweep column name.
    pub key: &'static str,
    /// The paper's symbol in ASCII (text tables).
    pub symbol: &'static str,
    /// The same symbol in LaTeX (sweep tables and figures).
    pub tex: &'static str,
    /// Equation label(s) in the paper.
    pub label: &'static str,
    /// The direction in which the reported number bounds the true value.
    pub kind: BoundKind,
    /// How it is obtained (short; a report may replace it with a more specific note).
    pub how: &'static str,
}

impl QuantityDef {
    /// This quantity with a value and a verified flag computed by the caller.
    pub fn with(&'static self, value: f64, verified: bool) -> Quantity {
        Quantity {
            key: self.key,
            symbol: self.symbol,
            label: self.label,
            equation: crate::equations::numbered(self.label),
            value,
            kind: self.kind,
            verified,
            note: self.how.to_string(),
        }
    }
}

/// Every quantity of the theta report, in report order (module constants, one per quantity).
pub mod defs {
    use super::BoundKind::{self, *};
    use super::QuantityDef;

    const fn q(
        key: &'static str,
        symbol: &'static str,
        tex: &'static str,
        label: &'static str,
        kind: BoundKind,
        how: &'static str,
    ) -> QuantityDef {
        QuantityDef { key, symbol, tex, label, kind, how }
    }

    pub const PERIOD: QuantityDef = q("period", "T", "$T$", "(xT)", Exact, "period of the input");
    pub const MU: QuantityDef = q("mu", "mu", "$\\mu$", "(stab)", Estimate, "max Re eig(F), F = A + E C (Schur form)");
    pub const R: QuantityDef = q("r", "R", "$R$", "(R)", Upper, "strong convexity constant of Theta");
    pub const ALPHA: QuantityDef =
        q("alpha", "alpha", "$\\alpha$", "(alpha)", Lower, "lambda_min(S(C E)), Rump's test");
    pub const LAMBDA: QuantityDef =
        q("lambda", "lambda", "$\\lambda$", "(lammu),(ALI)", Lower, "verified decay rate of the certificate");
    pub const BETA: QuantityDef =
        q("beta", "beta", "$\\beta$", "(bet)", Upper, "b_hat >= lambda_max(H^T Pi^-1 H), SDP + verification");
    pub const OSC: QuantityDef = q("osc", "osc", "$\\mathrm{osc}$", "(mho),(osc)", Lower, "diameter of eta_T");
    pub const D: QuantityDef =
        q("d", "d", "$d$", "(d),(Xinfsupp)", Upper, "tube quadrature + tail (DXX), certified sphere max");
    pub const ETA_DOT_INF: QuantityDef = q(
        "eta_dot_inf",
        "||eta_T'||_inf",
        "$\\|\\dot\\eta_T\\|_\\infty$",
        "(zinf)",
        Upper,
        "max speed of the linearised orbit",
    );
    pub const D_FTHETA: QuantityDef =
        q("d_ftheta", "D(C(F Xi_inf + E Theta),{0})", "$D$", "(zinf)", Upper, "tube quadrature + certified sphere max");
    pub const ZDOT_BOUND: QuantityDef =
        q("zdot_bound", "limsup |z'| <=", "$\\limsup|\\dot z|$", "(zinf)", Upper, "||eta_T'||_inf + D(...)");
    pub const GAMMA_1: QuantityDef =
        q("gamma_1", "gamma_1", "$\\gamma_1$", "(g1)", Lower, "(osc - d)_+ / (T R), R upper");
    pub const GAMMA_INF: QuantityDef = q(
        "gamma_inf",
        "gamma_inf",
        "$\\gamma_\\infty$",
        "(ginf)",
        Upper,
        "(||eta_T'|| + D(...)) / R at R upper (safe for theta)",
    );
    pub const KAPPA: QuantityDef = q(
        "kappa",
        "gamma_1/gamma_inf",
        "$\\gamma_1/\\gamma_\\infty$",
        "(theta)",
        Lower,
        "weight of psi(gamma_inf) in theta (independent of R)",
    );
    pub const PSI_0: QuantityDef =
        q("psi_0", "psi(0)", "$\\psi(0)$", "(psilim)", Upper, "at (alpha, lambda) lower, beta upper");
    pub const PSI_INF: QuantityDef =
        q("psi_inf", "psi(gamma_inf)", "$\\psi(\\gamma_\\infty)$", "(phipsi)", Upper, "at gamma_inf (R upper)");
    pub const PSI_LIMIT: QuantityDef =
        q("psi_limit", "-lambda", "$-\\lambda$", "(psilim)", Exact, "limit of psi at infinity");
    pub const THETA: QuantityDef =
        q("theta", "theta", "$\\theta$", "(theta)", Upper, "psi(0) - (gamma_1/gamma_inf)(psi(0) - psi(gamma_inf))");
    pub const GAMMA_1_STAR: QuantityDef = q(
        "gamma_1_star",
        "gamma_1*",
        "$\\gamma_1^*$",
        "(g1),(path1)",
        Lower,
        "max((path), (path1), (path1-local), (path2)) / (T R), R upper",
    );
    pub const ZDOT_STAR: QuantityDef = q(
        "zdot_star_bound",
        "limsup |z'| <= (p = 1)",
        "$\\dot z^*_{\\max}$",
        "(zinf)",
        Upper,
        "limsup |z'| with the backlash side pinned and its engaged history (p = 1; beyond the paper, proofs-notes/theta-star.md)",
    );
    pub const GAMMA_INF_STAR: QuantityDef =
        q("gamma_inf_star", "gamma_inf*", "$\\gamma_\\infty^*$", "(ginf)", Upper, "min(zdot bounds) / R, R upper");
    pub const THETA_STAR: QuantityDef = q(
        "theta_star",
        "theta*",
        "$\\theta^*$",
        "(theta),(path1)",
        Upper,
        "eq. (theta) with gamma_1* (beyond the paper, proofs-notes/theta-star.md)",
    );
    pub const THETA_PROFILE: QuantityDef = q(
        "theta_profile",
        "theta_profile",
        "$\\theta_{\\mathrm{prof}}$",
        "(theta),(ydot),(diffs1)",
        Upper,
        "chord of eq. (theta) per cell of a speed profile (beyond the paper, proofs-notes/theta-profile.md)",
    );
    pub const THETA_ENGAGED: QuantityDef = q(
        "theta_engaged",
        "theta_engaged",
        "$\\theta_{\\mathrm{eng}}$",
        "(theta),(ydot),(diffs1)",
        Upper,
        "theta_profile with speed floors where the backlash is engaged, p = 1 or a ball or an ellipsoid in R^2, R^3 (beyond the paper, proofs-notes/theta-engaged.md, theta-engaged-balls.md)",
    );
    pub const PATH_BOUND: QuantityDef =
        q("path_bound", "(osc - d)_+", "$(\\mathrm{osc}-d)_+$", "(path)", Lower, "liminf path length of z per period");
    pub const PATH1_BOUND: QuantityDef =
        q("path1_bound", "sup_partitions", "(path1)", "(path1)", Lower, "dynamic programming over a grid");
    pub const PATH1_LOCAL_BOUND: QuantityDef = q(
        "path1_local_bound",
        "sup_partitions, local loss",
        "(path1-local)",
        "(path1),(zinf)",
        Lower,
        "(path1) with the loss min(d, diam Theta + dt D) per step (beyond the paper)",
    );
    pub const PATH2_BOUND: QuantityDef =
        q("path2_bound", "sup_eps (2eps-d)N_eps", "(path2)", "(path2)", Lower, "greedy packing");
    pub const PHI_FIRST_SINGULAR: QuantityDef = q(
        "phi_first_singular",
        "first t with Phi(t) singular",
        "$t_\\Phi$",
        "(Phi)",
        Estimate,
        "scan of sigma_min(Phi) on [0, T]",
    );
    pub const STATIONARY_SLACK: QuantityDef = q(
        "stationary_slack",
        "R(T) slack s*",
        "$s^*$",
        "(stat1)",
        Lower,
        "grid relaxation of (stat1): bounds the continuous slack from below",
    );
    pub const MEASURED_RATE: QuantityDef =
        q("measured_rate", "measured exponent", "measured", "(VV)", Estimate, "pairs of simulated trajectories");
    pub const MEASURED_MULTIPLIER: QuantityDef = q(
        "measured_multiplier",
        "measured ln rho / T",
        "$\\ln\\rho/T$",
        "(Floquet)",
        Estimate,
        "dominant multiplier of a linear map fitted to the pairs' differences at period ends",
    );
    pub const PATH_MEASURED: QuantityDef =
        q("path_measured", "measured path/period", "path", "(path)", Estimate, "min over periods after the transient");
    pub const ZDOT_MEASURED: QuantityDef = q(
        "zdot_measured",
        "measured limsup |z'|",
        "$|\\dot z|_{\\max}$",
        "(zinf)",
        Estimate,
        "max over periods after the transient",
    );

    /// All of them, in report order.
    pub const ALL: [&QuantityDef; 34] = [
        &PERIOD,
        &MU,
        &R,
        &ALPHA,
        &LAMBDA,
        &BETA,
        &OSC,
        &D,
        &ETA_DOT_INF,
        &D_FTHETA,
        &ZDOT_BOUND,
        &GAMMA_1,
        &GAMMA_INF,
        &KAPPA,
        &PSI_0,
        &PSI_INF,
        &PSI_LIMIT,
        &THETA,
        &GAMMA_1_STAR,
        &ZDOT_STAR,
        &GAMMA_INF_STAR,
        &THETA_STAR,
        &THETA_PROFILE,
        &THETA_ENGAGED,
        &PATH_BOUND,
        &PATH1_BOUND,
        &PATH1_LOCAL_BOUND,
        &PATH2_BOUND,
        &PHI_FIRST_SINGULAR,
        &STATIONARY_SLACK,
        &MEASURED_RATE,
        &MEASURED_MULTIPLIER,
        &PATH_MEASURED,
        &ZDOT_MEASURED,
    ];

    /// The declaration with this key.
    pub fn by_key(key: &str) -> Option<&'static QuantityDef> {
        ALL.iter().copied().find(|d| d.key == key)
    }
}

/// One labelled number: a [`QuantityDef`] with its value for one system.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[non_exhaustive]
pub struct Quantity {
    /// Stable snake_case key (also the JSON key of the value).
    pub key: &'static str,
    /// The paper's symbol in ASCII.
    pub symbol: &'static str,
    /// Equation label(s) in the paper's source.
    pub label: &'static str,
    /// The same equations by their printed numbers (`(84),(56)`; [`crate::equations`]).
    pub equation: String,
    pub value: f64,
    pub kind: BoundKind,
    /// True when the bound in `kind` is proven (up to floating-point rounding of closed forms).
    pub verified: bool,
    /// How it was obtained (short).
    pub note: String,
}

impl Quantity {
    /// Replaces the default note of the declaration.
    pub fn note(mut self, note: impl Into<String>) -> Self {
        self.note = note.into();
        self
    }
    /// Replaces the declared kind (e.g. a lower bound that could not be proven is an estimate).
    pub fn kind(mut self, kind: BoundKind) -> Self {
        self.kind = kind;
        self
    }
}

/// Formats `v` compactly for the readable report.
pub fn fmt_value(v: f64) -> String {
    if v.is_nan() {
        "n/a".into()
    } else if v.is_infinite() {
        if v > 0.0 {
            "inf".into()
        } else {
            "-inf".into()
        }
    } else if v == 0.0 || (v.abs() >= 1e-3 && v.abs() < 1e5) {
        format!("{v:.6}")
    } else {
        format!("{v:.4e}")
    }
}

/// A plain-text table: symbol, equation number(s) as printed in the paper, source label(s),
/// value, kind, verified, how.
pub fn render_table(rows: &[Quantity]) -> String {
    let mut s = String::new();
    let w_sym = rows.iter().map(|q| q.symbol.len()).max().unwrap_or(6).max(6);
    let w_eq = rows.iter().map(|q| q.equation.len()).max().unwrap_or(3).max(3);
    let w_lab = rows.iter().map(|q| q.label.len()).max().unwrap_or(5).max(5);
    s.push_str(&format!(
        "{:<w_sym$}  {:<w_eq$}  {:<w_lab$}  {:>14}  {:<12}  {:<8}  {}\n",
        "symbol", "eq.", "label", "value", "kind", "verified", "how"
    ));
    for q in rows {
        s.push_str(&format!(
            "{:<w_sym$}  {:<w_eq$}  {:<w_lab$}  {:>14}  {:<12}  {:<8}  {}\n",
            q.symbol,
            q.equation,
            q.label,
            fmt_value(q.value),
            q.kind.as_str(),
            if q.verified { "yes" } else { "no" },
            q.note
        ));
    }
    s
}

/// What a reader should take from each quantity, in plain words (`moreau theta --explain`).
/// Every key of [`defs::ALL`] has an entry (a test checks it).
pub fn glossary(key: &str) -> Option<&'static str> {
    Some(match key {
        "period" => "T, the period of the input w. Everything below is per period or per unit time.",
        "mu" => "mu, the largest real part of the eigenvalues of F = A + E C (the loop linearised with the backlash moving with its input). Theorem 2 needs mu < 0; the certified decay rate lambda lies in (0, |mu|).",
        "r" => "R, the strong-convexity constant of Theta: Theta is an intersection of balls of radius R (an interval or a ball: its half-width or radius). Small R = strongly curved; R = inf (a polytope) means no certificate of this kind can exist.",
        "alpha" => "alpha, the smallest eigenvalue of the symmetric part of C E: how the backlash output feeds back into its own input. It enters psi; often 0.",
        "lambda" => "lambda, the decay rate of the Lyapunov matrix Pi found by semidefinite programming and proven by a rounding-aware check (Rump's test): Pi F + F^T Pi <= -2 lambda Pi.",
        "beta" => "beta, the coupling between the plant and the backlash seen through Pi (an upper bound b_hat proven for the same Pi). psi(0) >= 0 always; beta sets how large it is.",
        "osc" => "osc, the diameter of the periodic output eta_T of the linearised loop (closed form for sine inputs): how far the backlash input swings over a period.",
        "d" => "d, the diameter of C Xi_inf + Theta: how far the backlash output can sit from eta_T once transients are gone. The backlash must move at least osc - d per period.",
        "eta_dot_inf" => "The largest speed of eta_T over a period.",
        "d_ftheta" => "The largest extra speed the tube adds to the backlash input (D(C(F Xi_inf + E Theta), {0})). With the previous row it bounds |z'| from above.",
        "zdot_bound" => "An upper bound of the backlash speed |z'| after transients, Theorem 2's (zinf). Compare with the measured limsup |z'| below.",
        "gamma_1" => "gamma_1, the paper's lower bound of the mean backlash speed per period divided by R, from (osc - d)_+.",
        "gamma_inf" => "gamma_inf, the upper bound of the backlash speed divided by R. The chord of psi over [0, gamma_inf] gives theta.",
        "kappa" => "kappa = gamma_1 / gamma_inf in [0, 1]: the weight of psi(gamma_inf) in theta. theta < 0 needs kappa > psi(0) / (psi(0) - psi(gamma_inf)).",
        "psi_0" => "psi(0), the growth rate the Lyapunov bound allows while the backlash rests. Always >= 0 (proven), so convergence comes only from backlash motion.",
        "psi_inf" => "psi(gamma_inf), the decay rate the bound allows while the backlash moves at its top speed.",
        "psi_limit" => "-lambda, the limit of psi at infinite speed: no bound of this kind goes below it.",
        "theta" => "theta, the paper's bound of the exponential rate at which any two trajectories approach each other. theta < 0 and verified: a unique periodic regime attracts every trajectory at least at this rate. theta >= 0: a valid bound, no convergence guaranteed.",
        "gamma_1_star" => "gamma_1*, gamma_1 from the strongest proven path bound per period ((path1) or (path2) instead of (path)).",
        "zdot_star_bound" => "An upper bound of the backlash speed |z'| after transients that uses which side of Theta the backlash is pushed from (p = 1: z' > 0 only with z = y + min Theta) and, where the backlash is provably engaged, for how long; never above (zinf). Equal to (zinf) for p >= 2.",
        "gamma_inf_star" => "gamma_inf*, the smaller speed bound divided by R: the chord of theta* ends there.",
        "theta_star" => "theta*, eq. (theta) with gamma_1*, gamma_inf* and the best certified (lambda, beta): a proven bound beyond the paper (proofs-notes/theta-star.md).",
        "theta_profile" => "theta_profile, the chord of theta applied cell by cell of the speed bound |eta_T'(t)| + D, with path bounds per interval: a proven bound beyond the paper, never above theta* (proofs-notes/theta-profile.md).",
        "theta_engaged" => "theta_engaged, theta_profile with a floor on the backlash speed where the output has provably moved monotonically by Theta's width, so the backlash is engaged and moves with it (p = 1): a proven bound beyond the paper, never above theta_profile (proofs-notes/theta-engaged.md).",
        "path_bound" => "(path), the paper's lower bound of the backlash path per period: (osc - d)_+.",
        "path1_bound" => "(path1), the path bound over a partition of the period (sum of (|eta_T jumps| - d)_+), computed on a grid: at least (path).",
        "path1_local_bound" => "(path1) where a short step loses only diam(Theta) + (step length) D instead of d (the tube moves at most at speed D): at least (path1).",
        "path2_bound" => "(path2), the path bound from a packing of the orbit by balls of radius eps > d/2.",
        "phi_first_singular" => "The first time in [0, T] at which Theorem 1's matrix Phi(t) = I - t C Psi(tA) E is singular (none: Theorem 1's representation holds on the whole period).",
        "stationary_slack" => "Theorem 1: slack of the SDP deciding whether some initial state stays at rest for a whole period (the stationary set R(T)); > 0 means R(T) is empty.",
        "measured_rate" => "The measured exponent: half the slope of ln V along simulated pairs of trajectories, with its 95 % interval. A verified bound must lie above it.",
        "measured_multiplier" => "The measured dominant Floquet multiplier of the periodic regime, ln rho / T: the map between the pairs' differences at the ends of the periods fitted by least squares, its largest eigenvalue's modulus rho. Unlike the slope of ln V it does not wobble when the slowest multipliers are a complex pair. A measurement, not a proof: compare with floquet_exponent.",
        "path_measured" => "The measured path length of the backlash output per period (compare with the path bounds).",
        "zdot_measured" => "The measured limsup of the backlash speed |z'| (compare with the (zinf) bound).",
        _ => return None,
    })
}
