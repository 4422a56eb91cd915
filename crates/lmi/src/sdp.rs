//! Thin layer over Clarabel ([`ConicProgram`]: orthants, second-order and PSD cones), and
//! the PSD cones: linear matrix inequalities
//! `M_0 + sum_k x_k M_k >= 0` written directly as rows of `A x + s = b`,
//! `s in PSDTriangleCone` (no modelling layer).
//!
//! Clarabel's form is `min q^T x  s.t.  A x + s = b, s in K`. With
//! `s = svec(M_0 + sum_k x_k M_k)` ([`crate::psd_triangle::svec`]) this gives
//! `b = svec(M_0)` and column `k` of `A` equal to `-svec(M_k)`.

use crate::error::{LmiError, Result};
use crate::psd_triangle::{svec, triangular_number};
pub use crate::status::SdpStatus;
use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SupportedConeT};
use nalgebra::DMatrix;

/// Interior-point settings passed to Clarabel.
#[derive(Debug, Clone, PartialEq)]
pub struct SdpSettings {
    /// Absolute duality-gap tolerance. Default `1e-9`.
    pub tol_gap_abs: f64,
    /// Relative duality-gap tolerance. Default `1e-9`.
    pub tol_gap_rel: f64,
    /// Primal/dual feasibility tolerance. Default `1e-9`.
    pub tol_feas: f64,
    /// Iteration limit; hitting it gives [`LmiError::IterationLimit`]. Default `200`.
    pub max_iter: u32,
    /// Print Clarabel's iteration log. Default `false`.
    pub verbose: bool,
}

impl Default for SdpSettings {
    fn default() -> Self {
        Self { tol_gap_abs: 1e-9, tol_gap_rel: 1e-9, tol_feas: 1e-9, max_iter: 200, verbose: false }
    }
}

impl SdpSettings {
    /// Clarabel's own default tolerances and iteration limit (looser than [`Default`]).
    pub fn clarabel_defaults() -> Self {
        let d = DefaultSettings::<f64>::default();
        Self {
            tol_gap_abs: d.tol_gap_abs,
            tol_gap_rel: d.tol_gap_rel,
            tol_feas: d.tol_feas,
            max_iter: d.max_iter,
            verbose: false,
        }
    }

    /// Check that tolerances are positive and finite and `max_iter >= 1`.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in
            [("tol_gap_abs", self.tol_gap_abs), ("tol_gap_rel", self.tol_gap_rel), ("tol_feas", self.tol_feas)]
        {
            if !(v.is_finite() && v > 0.0) {
                return Err(LmiError::InvalidSetting { name, value: v });
            }
        }
        if self.max_iter == 0 {
            return Err(LmiError::InvalidSetting { name: "max_iter", value: 0.0 });
        }
        Ok(())
    }

    /// Clarabel's settings. `fast` is the variant for a first attempt that may fail without
    /// harm (`beta_sdp`'s solve without the compactness bound): iterative refinement of the
    /// KKT solves off (about a fifth of the time of a small SDP).
    fn to_clarabel(&self, fast: bool) -> DefaultSettings<f64> {
        let d = DefaultSettings::<f64>::default();
        DefaultSettings {
            tol_gap_abs: self.tol_gap_abs,
            tol_gap_rel: self.tol_gap_rel,
            tol_feas: self.tol_feas,
            max_iter: self.max_iter,
            verbose: self.verbose,
            iterative_refinement_enable: !fast && d.iterative_refinement_enable,
            ..d
        }
    }
}

/// Primal solution of a solved SDP.
#[derive(Debug, Clone)]
pub(crate) struct SdpSolution {
    pub x: Vec<f64>,
    pub status: SdpStatus,
    pub iterations: u32,
}

/// The result of [`ConicProgram::solve`], whatever the status: callers decide what a status
/// means for them (the solver status is never dropped).
#[derive(Debug, Clone)]
pub struct ConicOutcome {
    /// Primal variables at termination (meaningful for `Solved` / `AlmostSolved`).
    pub x: Vec<f64>,
    pub status: SdpStatus,
    pub iterations: u32,
}

impl ConicOutcome {
    /// `Solved` or `AlmostSolved`.
    pub fn solved(&self) -> bool {
        matches!(self.status, SdpStatus::Solved | SdpStatus::AlmostSolved)
    }
}

/// A linear conic program `min q^T x  s.t.  A x + s = b,  s in K` in Clarabel's form,
/// assembled block by block: nonnegative orthants and second-order cones from dense rows
/// (Theorem 1's set, eq. (stat1)), PSD cones from matrix pencils `M_0 + sum_k x_k M_k`
/// (eqs. (ALI), (bet)). The only Clarabel wrapper of the workspace.
#[derive(Debug, Clone)]
pub struct ConicProgram {
    nvar: usize,
    /// Column-wise nonzeros (row, value) of `A`.
    cols: Vec<Vec<(usize, f64)>>,
    b: Vec<f64>,
    cones: Vec<SupportedConeT<f64>>,
}

impl ConicProgram {
    pub fn new(nvar: usize) -> Self {
        Self { nvar, cols: vec![Vec::new(); nvar], b: Vec::new(), cones: Vec::new() }
    }

    /// Number of variables.
    pub fn nvar(&self) -> usize {
        self.nvar
    }

    fn push_dense_rows(&mut self, rows: &[(Vec<f64>, f64)]) {
        for (r, bi) in rows {
            debug_assert_eq!(r.len(), self.nvar);
            let row = self.b.len();
            for (k, &v) in r.iter().enumerate() {
                if v != 0.0 {
                    self.cols[k].push((row, v));
                }
            }
            self.b.push(*bi);
        }
    }

    /// `b_i - a_i^T x >= 0` for each dense row `(a_i, b_i)`.
    pub fn add_nonnegative(&mut self, rows: &[(Vec<f64>, f64)]) {
        if rows.is_empty() {
            return;
        }
        self.push_dense_rows(rows);
        self.cones.push(SupportedConeT::NonnegativeConeT(rows.len()));
    }

    /// `(b_0 - a_0^T x, ..., b_k - a_k^T x)` in the second-order cone (first entry the norm
    /// bound).
    pub fn add_second_order(&mut self, rows: &[(Vec<f64>, f64)]) {
        self.push_dense_rows(rows);
        self.cones.push(SupportedConeT::SecondOrderConeT(rows.len()));
    }

    /// `M0 + sum_k x_k Mk[k] >= 0`; `Mk[k] = None` means variable `k` does not enter.
    pub fn add_psd(&mut self, M0: &DMatrix<f64>, Mk: &[Option<DMatrix<f64>>]) {
        debug_assert_eq!(Mk.len(), self.nvar);
        let d = M0.nrows();
        let row0 = self.b.len();
        self.b.extend(svec(M0));
        for (k, M) in Mk.iter().enumerate() {
            if let Some(M) = M {
                for (r, v) in svec(M).into_iter().enumerate() {
                    if v != 0.0 {
                        self.cols[k].push((row0 + r, -v));
                    }
                }
            }
        }
        debug_assert_eq!(self.b.len(), row0 + triangular_number(d));
        self.cones.push(SupportedConeT::PSDTriangleConeT(d));
    }

    /// `min q^T x` subject to the accumulated constraints. `Err` only when Clarabel rejects
    /// the data; every termination status is returned in the outcome.
    pub fn solve(&self, q: &[f64], settings: &SdpSettings) -> Result<ConicOutcome> {
        self.solve_with(q, settings, false)
    }

    /// [`ConicProgram::solve`], with Clarabel's settings for a first attempt when `fast`
    /// (`SdpSettings::to_clarabel`).
    pub(crate) fn solve_with(&self, q: &[f64], settings: &SdpSettings, fast: bool) -> Result<ConicOutcome> {
        let m = self.b.len();
        let n = self.nvar;
        let mut colptr = Vec::with_capacity(n + 1);
        let mut rowval = Vec::new();
        let mut nzval = Vec::new();
        colptr.push(0);
        // Rows are appended in increasing order, so each column is already sorted (CSC).
        for col in &self.cols {
            for &(r, v) in col {
                rowval.push(r);
                nzval.push(v);
            }
            colptr.push(rowval.len());
        }
        let A = CscMatrix::new(m, n, colptr, rowval, nzval);
        let P = CscMatrix::zeros((n, n));
        let mut solver = DefaultSolver::new(&P, q, &A, &self.b, &self.cones, settings.to_clarabel(fast))
            .map_err(|_| LmiError::SetupRejected { rows: m, cols: n })?;
        solver.solve();
        let sol = &solver.solution;
        Ok(ConicOutcome { x: sol.x.clone(), status: SdpStatus::from(sol.status), iterations: sol.iterations })
    }
}

/// Accumulates PSD constraints `M_0 + sum_k x_k M_k >= 0` (a [`ConicProgram`] whose failures
/// are mapped to the errors of eqs. (ALI), (bet)).
pub(crate) struct LmiBuilder(ConicProgram);

impl LmiBuilder {
    pub fn new(nvar: usize) -> Self {
        Self(ConicProgram::new(nvar))
    }

    /// Add `M0 + sum_k x_k Mk[k] >= 0`; `Mk[k] = None` means variable `k` does not enter.
    pub fn add_psd(&mut self, M0: &DMatrix<f64>, Mk: &[Option<DMatrix<f64>>]) {
        self.0.add_psd(M0, Mk)
    }

    /// The raw outcome of `min q^T x` (no error mapping) with the `fast` settings of
    /// `SdpSettings::to_clarabel`: for a first attempt whose failure is not an error
    /// (`beta_sdp`'s solve without the compactness bound).
    pub fn solve_fast(&self, q: &[f64], settings: &SdpSettings) -> Result<ConicOutcome> {
        self.0.solve_with(q, settings, true)
    }

    /// `min q^T x` subject to the accumulated constraints.
    pub fn solve(self, q: &[f64], settings: &SdpSettings, lambda: f64) -> Result<SdpSolution> {
        let out = self.0.solve(q, settings)?;
        let status = out.status;
        match status {
            SdpStatus::Solved | SdpStatus::AlmostSolved => {
                Ok(SdpSolution { x: out.x, status, iterations: out.iterations })
            }
            SdpStatus::PrimalInfeasible => Err(LmiError::Infeasible { lambda, status }),
            SdpStatus::DualInfeasible => Err(LmiError::Unbounded { lambda, status }),
            SdpStatus::MaxIterations => Err(LmiError::IterationLimit { lambda, max_iter: settings.max_iter }),
            _ => Err(LmiError::SolverFailed { lambda, status }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// End-to-end check of the svec convention through Clarabel itself:
    /// `min <Cm, X>` s.t. `trace X = 1`, `X >= 0` has value `lambda_min(Cm)`, and the
    /// minimiser is the corresponding eigenprojector. A wrong off-diagonal scaling
    /// gives a different value.
    #[test]
    fn clarabel_psd_cone_convention_end_to_end() {
        let Cm = DMatrix::from_row_slice(3, 3, &[2.0, 1.0, 0.5, 1.0, 3.0, -1.0, 0.5, -1.0, 1.5]);
        let basis = crate::psd_triangle::symmetric_basis(3);
        let nvar = basis.len();
        let mut bld = LmiBuilder::new(nvar);
        // X >= 0
        bld.add_psd(&DMatrix::zeros(3, 3), &basis.iter().cloned().map(Some).collect::<Vec<_>>());
        // trace X = 1 as two 1x1 PSD cones: trace X - 1 >= 0 and 1 - trace X >= 0.
        let tr = |B: &DMatrix<f64>| DMatrix::from_element(1, 1, B.trace());
        bld.add_psd(&DMatrix::from_element(1, 1, -1.0), &basis.iter().map(|B| Some(tr(B))).collect::<Vec<_>>());
        bld.add_psd(&DMatrix::from_element(1, 1, 1.0), &basis.iter().map(|B| Some(-tr(B))).collect::<Vec<_>>());
        let q: Vec<f64> = basis.iter().map(|B| (B * &Cm).trace()).collect();
        let sol = bld.solve(&q, &SdpSettings::default(), 0.0).expect("solvable");
        let lmin = Cm.clone().symmetric_eigen().eigenvalues.min();
        assert_relative_eq!(q.iter().zip(&sol.x).map(|(a, b)| a * b).sum::<f64>(), lmin, epsilon = 1e-7);
    }

    #[test]
    fn settings_validate_rejects_bad_values() {
        assert!(SdpSettings::default().validate().is_ok());
        let s = SdpSettings { tol_feas: f64::NAN, ..Default::default() };
        assert!(matches!(s.validate(), Err(LmiError::InvalidSetting { name: "tol_feas", .. })));
        let s = SdpSettings { max_iter: 0, ..Default::default() };
        assert!(matches!(s.validate(), Err(LmiError::InvalidSetting { name: "max_iter", .. })));
    }
}
