//! Two-sided enclosures of a real quantity.

/// A real number known to lie in `[lower, upper]`. `lower == upper` means exact (up to
/// rounding in the closed form that produced it).
///
/// Named `Enclosure` (it was `geometry::Bounds`) so that it does not collide with the crate
/// `bounds`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Enclosure {
    pub lower: f64,
    pub upper: f64,
}

impl Enclosure {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accessors() {
        let e = Enclosure::new(1.0, 3.0);
        assert_eq!((e.width(), e.mid(), e.is_exact()), (2.0, 2.0, false));
        assert!(Enclosure::exact(0.5).is_exact());
    }
}
