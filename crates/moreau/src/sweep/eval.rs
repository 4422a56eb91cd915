//! Evaluation of one sweep point: the [`Evaluator`] trait, so that the sweep machinery can be
//! driven by theta (see `sweep::theta_eval`) or by any cheap stand-in (tests).
use model::System;

/// What a column holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColumnKind {
    Number,
    /// `true` / `false` (e.g. "theta verified").
    Flag,
    Text,
}

impl ColumnKind {
    pub fn as_str(self) -> &'static str {
        match self {
            ColumnKind::Number => "number",
            ColumnKind::Flag => "flag",
            ColumnKind::Text => "text",
        }
    }
    pub fn parse(s: &str) -> Option<Self> {
        Some(match s {
            "number" => ColumnKind::Number,
            "flag" => ColumnKind::Flag,
            "text" => ColumnKind::Text,
            _ => return None,
        })
    }
}

/// One output column.
#[derive(Debug, Clone, PartialEq)]
pub struct Column {
    /// Machine name (CSV header, JSON key), e.g. `theta`.
    pub name: String,
    /// LaTeX header, e.g. `$\theta$`.
    pub latex: String,
    pub kind: ColumnKind,
}

impl Column {
    pub fn number(name: &str, latex: &str) -> Self {
        Self { name: name.into(), latex: latex.into(), kind: ColumnKind::Number }
    }
    pub fn flag(name: &str, latex: &str) -> Self {
        Self { name: name.into(), latex: latex.into(), kind: ColumnKind::Flag }
    }
    pub fn text(name: &str, latex: &str) -> Self {
        Self { name: name.into(), latex: latex.into(), kind: ColumnKind::Text }
    }
}

/// One value of a point.
#[derive(Debug, Clone, PartialEq)]
pub enum Cell {
    Num(f64),
    Flag(bool),
    Text(String),
    /// Not computed (e.g. the point failed).
    Empty,
}

/// Error of one point: recorded in the point's `status`, the sweep goes on.
pub type PointError = Box<dyn std::error::Error + Send + Sync>;

/// Computes the columns of one sweep point. Must be deterministic (the same system gives the
/// same cells bit for bit, whatever the thread), so that tables do not depend on the thread
/// count.
pub trait Evaluator: Sync {
    /// Identifies the method and its settings; part of the spec hash, so that resumed runs and
    /// merged shards never mix results of different methods.
    fn fingerprint(&self) -> String;
    /// The columns, in order; [`Evaluator::evaluate`] returns one cell per column.
    fn columns(&self) -> Vec<Column>;
    fn evaluate(&self, sys: &System) -> Result<Vec<Cell>, PointError>;
}

/// An evaluator from a closure (stand-ins in tests, quick experiments).
pub struct FnEvaluator<F> {
    pub fingerprint: String,
    pub columns: Vec<Column>,
    pub f: F,
}

impl<F> Evaluator for FnEvaluator<F>
where
    F: Fn(&System) -> Result<Vec<Cell>, PointError> + Sync,
{
    fn fingerprint(&self) -> String {
        self.fingerprint.clone()
    }
    fn columns(&self) -> Vec<Column> {
        self.columns.clone()
    }
    fn evaluate(&self, sys: &System) -> Result<Vec<Cell>, PointError> {
        (self.f)(sys)
    }
}
