//! Evaluation of a built [`TubeKernel`]: the upper and lower sums of the quadrature for a
//! direction `v` plus the remainder, tail and floating-point terms (proofs-notes/tube-quadrature.md),
//! and the kernel's diagnostics.
use super::{ThetaSupport, TubeKernel};
use geometry::Shape;
use rounding::{gamma, ulp_up, UNIT_ROUNDOFF};

impl TubeKernel {
    /// Dimension `r` of the directions `v`.
    pub fn dim(&self) -> usize {
        self.r
    }

    /// `sum_j w_j sigma_Theta(M_j^T v)` over the stored matrices (`upper`: each `sigma_Theta`
    /// from above, [`ThetaSupport::support_upper`]; otherwise to nearest).
    fn sum(&self, mats: &[f64], v: &[f64], buf: &mut [f64], upper: bool) -> f64 {
        let (p, r) = (self.p, self.r);
        let mut acc = 0.0;
        for j in 0..self.half.len() {
            let M = &mats[j * p * r..(j + 1) * p * r];
            // M is stored column-major r x p: column i (entries i*r..) is row i of M^T.
            for (i, b) in buf.iter_mut().enumerate() {
                *b = M[i * r..(i + 1) * r].iter().zip(v).map(|(a, x)| a * x).sum();
            }
            let s = if upper { self.theta.support_upper(buf) } else { self.theta.support(buf) };
            acc += self.half[j] * s;
        }
        acc
    }

    /// Enclosure `[lower, upper]` of `sigma_{L Xi}(v)`: `upper` is a proven upper bound, the
    /// floating-point evaluation included (proofs-notes/tube-quadrature.md); `lower` subtracts the same terms but
    /// rests on the stated allowance for `sigma_Theta` evaluated to nearest.
    pub fn support_bounds(&self, v: &[f64]) -> rounding::Enclosure {
        let mut buf = vec![0.0; self.p];
        let nv = geometry::linalg::norm(v) * (1.0 + 2.0 * gamma(self.r + 2));
        let up = self.upper_value(v, nv, &mut buf);
        let lo_tail = if self.zero_in_theta { 0.0 } else { nv * self.tail };
        let lo = 2.0 * self.sum(&self.mid, v, &mut buf, false)
            - nv * (self.remainder + self.rounding_lo) * (1.0 + 8.0 * UNIT_ROUNDOFF)
            - lo_tail;
        rounding::Enclosure::new(lo, up.max(lo))
    }

    /// `(sum_j w_j sup(M_j^T v))` over `minus` and over `plus` in one pass, each accumulated in
    /// the order of [`Self::sum`] (the same values, bit for bit), `sup` monomorphised.
    #[inline]
    fn upper_sums_with(&self, v: &[f64], buf: &mut [f64], sup: impl Fn(&[f64]) -> f64) -> (f64, f64) {
        let (p, r) = (self.p, self.r);
        let (mut am, mut ap) = (0.0, 0.0);
        for (j, &w) in self.half.iter().enumerate() {
            let M = &self.minus[j * p * r..(j + 1) * p * r];
            for (i, b) in buf.iter_mut().enumerate() {
                *b = M[i * r..(i + 1) * r].iter().zip(v).map(|(a, x)| a * x).sum();
            }
            am += w * sup(buf);
            let M = &self.plus[j * p * r..(j + 1) * p * r];
            for (i, b) in buf.iter_mut().enumerate() {
                *b = M[i * r..(i + 1) * r].iter().zip(v).map(|(a, x)| a * x).sum();
            }
            ap += w * sup(buf);
        }
        (am, ap)
    }

    /// The upper sums over `minus` and `plus` with `sigma_Theta` from above: the closed forms of
    /// `geometry::Shape::support_upper` inlined per shape, else [`ThetaSupport::support_upper`].
    fn upper_sums(&self, v: &[f64], buf: &mut [f64]) -> (f64, f64) {
        use geometry::shapes::upper::{ball_support_upper, ellipsoid_support_upper};
        use rounding::mul_up;
        match &self.theta {
            ThetaSupport::Shape(Shape::Interval(i)) => {
                self.upper_sums_with(v, buf, |u| mul_up(u[0], if u[0] >= 0.0 { i.hi } else { i.lo }))
            }
            ThetaSupport::Shape(Shape::Ball(b)) => {
                self.upper_sums_with(v, buf, |u| ball_support_upper(&b.centre, b.radius, u))
            }
            ThetaSupport::Shape(Shape::Ellipsoid(e)) => {
                self.upper_sums_with(v, buf, |u| ellipsoid_support_upper(e.centre(), e.matrix(), u))
            }
            other => self.upper_sums_with(v, buf, |u| other.support_upper(u)),
        }
    }

    /// The proven upper value of [`Self::support_bounds`] (`nv`: `|v|` rounded up as there).
    fn upper_value(&self, v: &[f64], nv: f64, buf: &mut [f64]) -> f64 {
        let (am, ap) = self.upper_sums(v, buf);
        ulp_up(am + ap + nv * (self.remainder + self.tail + self.rounding_up) * (1.0 + 8.0 * UNIT_ROUNDOFF))
    }

    /// Upper bound of `sigma_{L Xi}(v)`: the upper value of [`Self::support_bounds`] (proven,
    /// proofs-notes/tube-quadrature.md) without the lower sum, which only an indication needs.
    pub fn support_upper(&self, v: &[f64]) -> f64 {
        let nv = geometry::linalg::norm(v) * (1.0 + 2.0 * gamma(self.r + 2));
        if self.p <= 8 {
            let mut buf = [0.0; 8];
            self.upper_value(v, nv, &mut buf[..self.p])
        } else {
            self.upper_value(v, nv, &mut vec![0.0; self.p])
        }
    }

    /// Lipschitz constant (in `v`) of [`Self::support_upper`] and of the true support function:
    /// `D_Theta int ||K|| ds` plus the remainder, tail and floating-point terms.
    pub fn lipschitz(&self) -> f64 {
        (self.d_theta * self.k_l1 + self.remainder + self.tail + self.rounding_up) * (1.0 + 1e-10)
    }

    /// Upper bound of `D(L Xi, {0}) = max_{|v|=1} sigma(v)` without a search: `D_Theta int ||K||`.
    pub fn deviation_upper_crude(&self) -> f64 {
        self.lipschitz()
    }

    /// Tail bound of eq. (DXX) per unit `|v|` (0 for a finite horizon).
    pub fn tail_bound(&self) -> f64 {
        self.tail
    }

    /// Summed Taylor remainder per unit `|v|`.
    pub fn remainder_bound(&self) -> f64 {
        self.remainder
    }

    /// Floating-point terms per unit `|v|` added to the upper value (proofs-notes/tube-quadrature.md: matrix
    /// exponentials and products, tiling, the sums, the rounded `F`).
    pub fn rounding_bound(&self) -> f64 {
        self.rounding_up
    }

    /// Number of quadrature cells.
    pub fn cells(&self) -> usize {
        self.half.len()
    }
}
