//! `[signals]` of a model file as a domain type: units of the recorded signals and the
//! reference input of a tracking loop, for reports (read and written by
//! [`crate::model_file`]).

/// `[signals]`: units of the recorded outputs and inputs, for reports (empty: unitless).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Signals {
    /// One unit per output (`y = "m"` gives every output the same unit).
    pub y: Vec<String>,
    /// One unit per input.
    pub w: Vec<String>,
    /// Unit of time (`""` when not stated).
    pub t: String,
    /// For each output, the input (0-based) that is its reference in a tracking loop (`w1` in
    /// the file is `0`); empty when not stated. `diagnose` then also reports the fit of the
    /// tracking error `w_ref - y`.
    pub reference: Vec<usize>,
}

impl Signals {
    /// Unit of output `i` (`""` when not stated).
    pub fn y_unit(&self, i: usize) -> &str {
        self.y.get(i).map_or("", |s| s.as_str())
    }
    /// Unit of input `j` (`""` when not stated).
    pub fn w_unit(&self, j: usize) -> &str {
        self.w.get(j).map_or("", |s| s.as_str())
    }
    pub fn is_empty(&self) -> bool {
        self.y.is_empty() && self.w.is_empty() && self.t.is_empty() && self.reference.is_empty()
    }

    /// The common unit of all outputs (`""` when not stated or when they differ).
    pub fn y_common_unit(&self) -> &str {
        match self.y.first() {
            Some(u) if self.y.iter().all(|v| v == u) => u,
            _ => "",
        }
    }
}
