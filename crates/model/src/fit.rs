//! `[fit]` of a model file as a domain type: the nominal parameters `moreau diagnose` may
//! refit ([`FitSpec`], [`FreeParam`] naming an entry `plant.X[row][col]` of a
//! [`PlantMatrix`], or a parameter of `[parameters]`) and the refits recorded in a fitted model ([`FitRecord`]).
//!
//! Reading and writing a parameter's value in a [`crate::System`] (`FreeParam::get`, `set`,
//! `System::plant_matrix`) lives with the system in [`crate::system`], which holds a
//! [`FitSpec`]; the TOML form is read and written by [`crate::model_file`].

/// The plant matrix a freed nominal parameter lives in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlantMatrix {
    A,
    B,
    C,
    E,
}

impl PlantMatrix {
    pub fn name(&self) -> &'static str {
        match self {
            PlantMatrix::A => "A",
            PlantMatrix::B => "B",
            PlantMatrix::C => "C",
            PlantMatrix::E => "E",
        }
    }
}

/// One nominal parameter freed by `[fit] free`: an entry `plant.X[row][col]` (0-based) or a
/// named parameter of `[parameters]`, with optional bounds `[fit.bounds]`.
#[derive(Debug, Clone, PartialEq)]
pub struct FreeParam {
    /// Canonical name, e.g. `plant.A[1][1]` or `M`.
    pub name: String,
    pub target: FreeTarget,
    /// `(lower, upper)`, the nominal value inside.
    pub bounds: Option<(f64, f64)>,
}

/// What a freed parameter moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FreeTarget {
    /// One entry of a plant matrix.
    Entry { matrix: PlantMatrix, row: usize, col: usize },
    /// The parameter of `[parameters]` named [`FreeParam::name`], and with it every number
    /// written as an expression of it.
    Parameter,
}

impl FreeParam {
    /// The entry `plant.X[row][col]`, named canonically.
    pub fn entry(matrix: PlantMatrix, row: usize, col: usize) -> Self {
        Self {
            name: format!("plant.{}[{row}][{col}]", matrix.name()),
            target: FreeTarget::Entry { matrix, row, col },
            bounds: None,
        }
    }
}

/// A grey-box refit recorded in a fitted model (`[fit.result."plant.A[1][1]"]`): the value
/// of the model file it was fitted from, the fitted value (the one in `[plant]`) and its
/// 1-sigma uncertainty (`NaN`, and not written, where not identifiable), and its correlation
/// with each other refitted parameter (`correlation = { M = 0.93 }`: the fit's statistical
/// correlation, Gauss-Newton). Informational: nothing reads it back into the dynamics.
#[derive(Debug, Clone, PartialEq)]
pub struct FitRecord {
    pub name: String,
    pub nominal: f64,
    pub value: f64,
    pub std: f64,
    /// `(other parameter's name, correlation in [-1, 1])`; empty where not computed.
    pub correlation: Vec<(String, f64)>,
}

/// `[fit]`: the nominal parameters `moreau diagnose` may refit (empty: none).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FitSpec {
    pub free: Vec<FreeParam>,
    pub result: Vec<FitRecord>,
}

impl FitSpec {
    pub fn is_empty(&self) -> bool {
        self.free.is_empty() && self.result.is_empty()
    }
}

/// `plant.X[i][j]` -> `(X, i, j)`; `None` when malformed.
pub fn parse_param_name(s: &str) -> Option<(PlantMatrix, usize, usize)> {
    let rest = s.trim().strip_prefix("plant.")?;
    let mut ch = rest.chars();
    let mat = match ch.next()? {
        'A' => PlantMatrix::A,
        'B' => PlantMatrix::B,
        'C' => PlantMatrix::C,
        'E' => PlantMatrix::E,
        _ => return None,
    };
    let rest = ch.as_str().strip_prefix('[')?;
    let (i, rest) = rest.split_once(']')?;
    let rest = rest.strip_prefix('[')?;
    let (j, rest) = rest.split_once(']')?;
    if !rest.is_empty() {
        return None;
    }
    let idx = |v: &str| -> Option<usize> {
        (!v.is_empty() && v.chars().all(|c| c.is_ascii_digit())).then(|| v.parse().ok()).flatten()
    };
    Some((mat, idx(i)?, idx(j)?))
}
