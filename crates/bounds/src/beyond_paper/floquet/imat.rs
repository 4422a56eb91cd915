//! Small dense interval matrices (row-major `Vec<Ival>`), the linear algebra of the verified
//! pipeline: every product and sum rounds outward ([`rounding::Ival`]), so an `IMat` computed
//! from enclosures encloses the exact result. Vectors are `n x 1` matrices.
use nalgebra::DMatrix;
use rounding::Ival;

#[derive(Debug, Clone, PartialEq)]
pub struct IMat {
    pub rows: usize,
    pub cols: usize,
    pub d: Vec<Ival>,
}

impl IMat {
    pub fn zeros(rows: usize, cols: usize) -> Self {
        Self { rows, cols, d: vec![Ival::point(0.0); rows * cols] }
    }
    pub fn identity(n: usize) -> Self {
        let mut m = Self::zeros(n, n);
        for i in 0..n {
            m.d[i * n + i] = Ival::point(1.0);
        }
        m
    }
    /// The point matrix (exact).
    pub fn from_f64(a: &DMatrix<f64>) -> Self {
        let mut m = Self::zeros(a.nrows(), a.ncols());
        for i in 0..a.nrows() {
            for j in 0..a.ncols() {
                m.d[i * a.ncols() + j] = Ival::point(a[(i, j)]);
            }
        }
        m
    }
    /// The column vector of the given intervals.
    pub fn column(v: &[Ival]) -> Self {
        Self { rows: v.len(), cols: 1, d: v.to_vec() }
    }
    #[inline]
    pub fn at(&self, i: usize, j: usize) -> Ival {
        self.d[i * self.cols + j]
    }
    #[inline]
    pub fn set(&mut self, i: usize, j: usize, v: Ival) {
        self.d[i * self.cols + j] = v;
    }
    /// Every entry widened by `[-r, r]` (`r >= 0`, an entrywise error bound).
    pub fn inflate(&self, r: f64) -> Self {
        Self { rows: self.rows, cols: self.cols, d: self.d.iter().map(|x| x.add(Ival::sym(r))).collect() }
    }
    pub fn mul(&self, o: &IMat) -> IMat {
        assert_eq!(self.cols, o.rows, "IMat::mul shapes");
        let mut m = IMat::zeros(self.rows, o.cols);
        for i in 0..self.rows {
            for j in 0..o.cols {
                let mut s = Ival::point(0.0);
                for k in 0..self.cols {
                    s = s.add(self.at(i, k).mul(o.at(k, j)));
                }
                m.set(i, j, s);
            }
        }
        m
    }
    pub fn add(&self, o: &IMat) -> IMat {
        Self { rows: self.rows, cols: self.cols, d: self.d.iter().zip(&o.d).map(|(a, b)| a.add(*b)).collect() }
    }
    pub fn sub(&self, o: &IMat) -> IMat {
        Self { rows: self.rows, cols: self.cols, d: self.d.iter().zip(&o.d).map(|(a, b)| a.sub(*b)).collect() }
    }
    pub fn scale(&self, s: Ival) -> IMat {
        Self { rows: self.rows, cols: self.cols, d: self.d.iter().map(|a| a.mul(s)).collect() }
    }
    /// Rows `r0..r0+nr`, columns `c0..c0+nc`.
    pub fn block(&self, r0: usize, c0: usize, nr: usize, nc: usize) -> IMat {
        let mut m = IMat::zeros(nr, nc);
        for i in 0..nr {
            for j in 0..nc {
                m.set(i, j, self.at(r0 + i, c0 + j));
            }
        }
        m
    }
    /// The matrix of midpoints.
    pub fn mid(&self) -> DMatrix<f64> {
        DMatrix::from_fn(self.rows, self.cols, |i, j| self.at(i, j).mid())
    }
    /// Largest entry width (rounded up).
    pub fn max_width(&self) -> f64 {
        self.d.iter().map(|x| x.width()).fold(0.0, f64::max)
    }
    /// Every entry finite and ordered.
    pub fn is_valid(&self) -> bool {
        self.d.iter().all(|x| x.is_valid())
    }
    /// `row . self` for a point row vector (`row.len() == self.rows`, `self` a column).
    pub fn dot_row(&self, row: &[f64]) -> Ival {
        debug_assert_eq!(self.cols, 1);
        row.iter().zip(&self.d).fold(Ival::point(0.0), |s, (r, x)| s.add(x.scale(*r)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn products_enclose_the_point_product_and_widths_add() {
        let a = DMatrix::from_row_slice(2, 2, &[0.1, 0.2, 0.3, 0.7]);
        let b = DMatrix::from_row_slice(2, 2, &[1.0 / 3.0, -0.2, 0.25, 0.9]);
        let p = IMat::from_f64(&a).mul(&IMat::from_f64(&b));
        let q = &a * &b;
        for i in 0..2 {
            for j in 0..2 {
                assert!(p.at(i, j).contains(q[(i, j)]));
            }
        }
        assert!(p.max_width() < 1e-15);
        let w = IMat::from_f64(&a).inflate(1e-3).mul(&IMat::from_f64(&b));
        assert!(w.max_width() > 1e-3, "an inflated factor widens the product");
    }
}
