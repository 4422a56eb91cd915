//! Two-sided enclosures of a real quantity.

/// A real number known to lie in `[lower, upper]`. `lower == upper` means exact (up to
/// rounding in the closed form that produced it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bounds {
    pub lower: f64,
    pub upper: f64,
}

impl Bounds {
    pub fn exact(v: f64) -> Self {
        Self { lower: v, upper: v }
    }
    pub fn new(lower: f64, upper: f64) -> Self {
        Self { lower, upper }
    }
    pub fn is_exact(&self) -> bool {
        self.lower == self.upper
    }
    pub fn width(&self) -> f64 {
        self.upper - self.lower
    }
    pub fn mid(&self) -> f64 {
        0.5 * (self.lower + self.upper)
    }
}
