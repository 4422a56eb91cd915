//! Grey-box refit: nominal parameters freed by the model file's `[fit] free` (entries of
//! `A`, `B`, `C`, `E`), fitted jointly with the effects of a hypothesis.
//!
//! Coordinates: the solver works on `value / scale` with `scale = |nominal|` (or, for a zero
//! nominal, half the width of its bounds, else the largest entry of its matrix, else 1), so a
//! unit step is a relative change; user bounds are kept by projection. Each evaluation builds
//! the modified system (a copy without the model's input) and its exact step maps (`F = A + E C`
//! changes with the parameters), so the exact discretisation and the hold stay as for the
//! nominal.
use model::model_file::{FreeParam, FreeTarget};
use model::{Input, System};

/// The freed nominal parameters of a diagnosis.
#[derive(Debug, Clone)]
pub struct FreeNominal {
    pub params: Vec<FreeParam>,
    /// Values in the model file.
    pub nominal: Vec<f64>,
    /// Solver scales (see the module documentation).
    pub scale: Vec<f64>,
    /// The model without its input (cheap to copy per evaluation).
    base: System,
}

impl FreeNominal {
    /// The parameters `sys.fit.free` (`None` when the model frees none).
    pub fn of(sys: &System) -> Option<Self> {
        if sys.fit.free.is_empty() {
            return None;
        }
        let params = sys.fit.free.clone();
        let nominal: Vec<f64> = params.iter().map(|f| f.get(sys)).collect();
        let amax = |f: &FreeParam| match f.target {
            FreeTarget::Entry { matrix, .. } => sys.plant_matrix(matrix).amax(),
            FreeTarget::Parameter => 0.0,
        };
        let scale = params
            .iter()
            .zip(&nominal)
            .map(|(f, v)| {
                if v.abs() > 0.0 {
                    v.abs()
                } else if let Some((lo, hi)) = f.bounds {
                    0.5 * (hi - lo)
                } else if amax(f) > 0.0 {
                    amax(f)
                } else {
                    1.0
                }
            })
            .collect();
        let mut base = sys.clone();
        base.input = Input::Zero { m: sys.m() };
        Some(Self { params, nominal, scale, base })
    }
    pub fn k(&self) -> usize {
        self.params.len()
    }
    pub fn names(&self) -> Vec<String> {
        self.params.iter().map(|p| p.name.clone()).collect()
    }
    /// The model (without its input) at parameter values `v` (`None` where an expression of
    /// a named parameter leaves its range, e.g. a negative friction level).
    pub fn system_at(&self, v: &[f64]) -> Option<System> {
        self.apply(&self.base, v).ok()
    }
    /// `sys` (with its input) at parameter values `v` (the named parameters set in one pass); an
    /// error where an expression of a named parameter leaves its range.
    pub fn apply(&self, sys: &System, v: &[f64]) -> Result<System, model::ModelError> {
        let mut s = sys.clone();
        let mut named: Vec<(&str, f64)> = Vec::new();
        for (p, x) in self.params.iter().zip(v) {
            match p.target {
                FreeTarget::Parameter => named.push((p.name.as_str(), *x)),
                FreeTarget::Entry { .. } => p.set(&mut s, *x)?,
            }
        }
        if !named.is_empty() {
            s.set_parameters(&named)?;
        }
        Ok(s)
    }
    /// Solver coordinates of the bounds (`-inf`, `inf` where unbounded).
    pub fn bounds_scaled(&self) -> (Vec<f64>, Vec<f64>) {
        self.params
            .iter()
            .zip(&self.scale)
            .map(|(p, s)| p.bounds.map_or((f64::NEG_INFINITY, f64::INFINITY), |(lo, hi)| (lo / s, hi / s)))
            .unzip()
    }
}

/// The freed parameters of one problem and the values they take when not fitted (the start
/// of a fit, and the values a simulation of an already fitted hypothesis uses).
#[derive(Debug, Clone)]
pub struct Refit<'a> {
    pub free: &'a FreeNominal,
    pub values: Vec<f64>,
}
