//! Lemma B, eq. (spec): for `a, b in R` and `g in R^{n x p}`, the largest eigenvalue of
//! `M = [[a I_n, g], [g^T, b I_p]]` (eq. (M)) is `(a + b)/2 + sqrt(||g||^2 + ((a - b)/2)^2)`,
//! `||g||` the operator (spectral) norm.
//!
//! Check: `lambda_max(M)` from faer's dense self-adjoint eigen-solver
//! (`Mat::self_adjoint_eigen`, eigenvalues ascending) against the formula with `||g||` from
//! nalgebra's SVD (an independent code path). Claim: `|formula - eig| <= tol` with
//! `tol = 64 (n + p) eps (|a| + |b| + ||g||_F)` (both are backward stable; the eigenvalue
//! perturbation is at most `||Delta M||`). The slack is `(tol - err)/(tol + err)`.
//! Negative control: the Frobenius norm `||g||_F` instead of the spectral norm (a plausible
//! slip); it differs as soon as `rank g >= 2`.
use super::sets_prelude::*;
use faer::{Mat, Side};
use nalgebra::DMatrix;

pub fn info() -> PropertyInfo {
    PropertyInfo {
        name: "lemma_b",
        label: "(spec)",
        title: "Lemma B: lambda_max([[aI,g],[g^T,bI]]) = (a+b)/2 + sqrt(|g|^2 + ((a-b)/2)^2)",
        default_cases: 5_000,
        negative_control: "Frobenius norm of g instead of the spectral norm",
    }
}

#[derive(Debug, Clone)]
pub struct SpecCase {
    pub n: usize,
    pub p: usize,
    pub a: f64,
    pub b: f64,
    /// `g[i * 4 + j]`, scaled by `10^g_exp`.
    pub g: [f64; 16],
    pub g_exp: f64,
}

pub fn strategy() -> BoxedStrategy<SpecCase> {
    (1..=4usize, 1..=4usize, -10.0..=10.0f64, -10.0..=10.0f64, proptest::array::uniform16(-1.0..=1.0f64), -3.0..=2.0f64)
        .prop_map(|(n, p, a, b, g, g_exp)| SpecCase { n, p, a, b, g, g_exp })
        .boxed()
}

impl SpecCase {
    pub fn g(&self) -> DMatrix<f64> {
        let s = 10f64.powf(self.g_exp);
        DMatrix::from_fn(self.n, self.p, |i, j| s * self.g[i * 4 + j])
    }
}

/// `lambda_max(M)` by faer's dense self-adjoint eigen-decomposition.
pub fn lambda_max_dense(a: f64, b: f64, g: &DMatrix<f64>) -> f64 {
    let (n, p) = (g.nrows(), g.ncols());
    let m = Mat::<f64>::from_fn(n + p, n + p, |i, j| match (i < n, j < n) {
        (true, true) => {
            if i == j {
                a
            } else {
                0.0
            }
        }
        (false, false) => {
            if i == j {
                b
            } else {
                0.0
            }
        }
        (true, false) => g[(i, j - n)],
        (false, true) => g[(j, i - n)],
    });
    match m.self_adjoint_eigen(Side::Lower) {
        Ok(evd) => {
            let s = evd.S().column_vector();
            s[n + p - 1]
        }
        Err(_) => f64::NAN,
    }
}

/// Right-hand side of eq. (spec) with a given norm of `g`.
pub fn lambda_max_formula(a: f64, b: f64, g_norm: f64) -> f64 {
    0.5 * (a + b) + (g_norm * g_norm + 0.25 * (a - b) * (a - b)).sqrt()
}

pub fn eval(case: &SpecCase, variant: Variant) -> Eval {
    let g = case.g();
    let eig = lambda_max_dense(case.a, case.b, &g);
    let gn = match variant {
        Variant::Claim => g.clone().svd(false, false).singular_values.max(),
        Variant::NegativeControl => g.norm(),
    };
    let formula = lambda_max_formula(case.a, case.b, gn);
    let err = (formula - eig).abs();
    let tol = 64.0 * (case.n + case.p) as f64 * f64::EPSILON * (case.a.abs() + case.b.abs() + g.norm());
    Eval::new(err, tol, 0.0)
}

pub fn export(case: &SpecCase, e: &Eval) -> Counterexample {
    let g = case.g();
    let mut root = toml::Table::new();
    root.insert("property".into(), toml::Value::String("lemma_b".into()));
    root.insert("a".into(), toml::Value::Float(case.a));
    root.insert("b".into(), toml::Value::Float(case.b));
    let rows: Vec<toml::Value> = (0..g.nrows())
        .map(|i| toml::Value::Array((0..g.ncols()).map(|j| toml::Value::Float(g[(i, j)])).collect()))
        .collect();
    root.insert("g".into(), toml::Value::Array(rows));
    root.insert("abs_error".into(), toml::Value::Float(e.lhs));
    root.insert("tol".into(), toml::Value::Float(e.rhs));
    Counterexample {
        extension: "toml",
        text: toml::to_string(&root).unwrap_or_default(),
        summary: format!("|formula - eig| = {:.3e} > tol {:.3e} (n = {}, p = {})", e.lhs, e.rhs, case.n, case.p),
    }
}

pub fn property() -> Prop<SpecCase> {
    Prop { info: info(), strategy, eval, export, max_shrink_iters: 2000 }
}
