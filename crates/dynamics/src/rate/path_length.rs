//! Path length of the backlash output `z` per period (Thm 2, eq. (path)) and the running
//! maximum of `|z'|` (eq. (zinf)), measured along a catching-up trajectory:
//! `L_j = sum_{k in period j} |z_{k+1} - z_k|`, `|z'| ~ |z_{k+1} - z_k| / h`.
use serde::Serialize;

/// Accumulates per-period path lengths and the maximal speed of `z`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PathStats {
    /// `L_j` for each simulated period `j`.
    pub per_period: Vec<f64>,
    /// Maximal `|z_{k+1} - z_k| / h` in each period.
    pub max_speed_per_period: Vec<f64>,
}

impl PathStats {
    pub fn new() -> Self {
        Self { per_period: Vec::new(), max_speed_per_period: Vec::new() }
    }
    /// Minimum of `L_j` over periods `j >= from`: the measured liminf of the path length.
    pub fn liminf_path_length(&self, from: usize) -> f64 {
        self.per_period.iter().skip(from).copied().fold(f64::INFINITY, f64::min)
    }
    /// Maximum of `|z'|` over periods `j >= from`: the measured limsup of `|z'|`.
    pub fn limsup_speed(&self, from: usize) -> f64 {
        self.max_speed_per_period.iter().skip(from).copied().fold(0.0, f64::max)
    }
}

impl Default for PathStats {
    fn default() -> Self {
        Self::new()
    }
}

/// Observer state for one period.
#[derive(Debug, Clone, Default)]
pub struct PathAccumulator {
    pub length: f64,
    pub max_speed: f64,
    prev: Vec<f64>,
}

impl PathAccumulator {
    pub fn start(z: &[f64]) -> Self {
        Self { length: 0.0, max_speed: 0.0, prev: z.to_vec() }
    }
    #[inline]
    pub fn observe(&mut self, z: &[f64], h: f64) {
        let d = geometry::linalg::dist(z, &self.prev);
        self.length += d;
        self.max_speed = self.max_speed.max(d / h);
        self.prev.copy_from_slice(z);
    }
}
