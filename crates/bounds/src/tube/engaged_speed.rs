//! (zinf) for `p = 1` with the backlash's side pinned (beyond the paper;
//! proofs-notes/theta-star.md, "The speed bound").
//!
//! Eq. (zinf) bounds `|z'| <= ||eta_T'||_inf + D(C(F Xi_inf + E Theta),{0})`, taking the
//! backlash's offset `v = z - y` anywhere in `Theta`. For `p = 1`, `Theta = [lo, hi]`, the
//! sweeping process moves `z` only from a face: `z' > 0` forces `z = y + lo`, `z' < 0` forces
//! `z = y + hi` (the interval `y + Theta` pushes `z` from behind). With `x = xi_T + dev`,
//! `y' = eta_T' + C F dev + C E v` and `dev` in `Xi_inf` (asymptotically), so wherever `z` moves
//! (`z' = y'` there):
//!
//! ```text
//! z' > 0:   eta_T' - (s(-1) - CE lo) <= z' <= eta_T' + s(+1) + CE lo
//! z' < 0:   eta_T' - s(-1) - CE hi   <= z' <= eta_T' + (s(+1) + CE hi)
//! ```
//!
//! with `s(+-1) = sigma_{C F Xi_inf}(+-1)`. The ceilings are never above `D` (which takes the worst
//! `v` in `Theta` for either sign); they are lower by `CE (hi - lo)` when `CE > 0`. The floors
//! hold only while the backlash is engaged (`theta_engaged` decides where).
use crate::tube::TubeKernel;

/// Offsets of the signed speed of `z` for `p = 1` (module docs), each an upper bound.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct EngagedSpeed {
    /// `z' <= eta_T' + ceil_up` wherever `z' > 0`.
    pub ceil_up: f64,
    /// `-z' <= -eta_T' + ceil_down` wherever `z' < 0`.
    pub ceil_down: f64,
    /// `z' >= eta_T' - floor_up` wherever `z' > 0`.
    pub floor_up: f64,
    /// `-z' >= -eta_T' - floor_down` wherever `z' < 0`.
    pub floor_down: f64,
}

impl EngagedSpeed {
    /// `tube_CF`: the kernel of `sigma_{C F Xi_inf}` (as for `D`), `C` (1 x n), `E` (n x 1) and
    /// `Theta = [lo, hi]`. `None` unless `p = 1` and every value is finite.
    pub fn new(
        tube_CF: &TubeKernel,
        C: &nalgebra::DMatrix<f64>,
        E: &nalgebra::DMatrix<f64>,
        lo: f64,
        hi: f64,
    ) -> Option<Self> {
        if C.nrows() != 1 || E.ncols() != 1 || C.ncols() != E.nrows() || !(lo <= 0.0 && 0.0 <= hi) {
            return None;
        }
        let n = C.ncols();
        // CE = sum C_i E_i with its rounding error (at most n u sum |C_i E_i| / (1 - n u)).
        let ce = (0..n).map(|i| C[(0, i)] * E[(i, 0)]).sum::<f64>();
        let ce_err = 2.0 * (n as f64 + 1.0) * f64::EPSILON * (0..n).map(|i| (C[(0, i)] * E[(i, 0)]).abs()).sum::<f64>();
        let s_up = tube_CF.support_upper(&[1.0]);
        let s_down = tube_CF.support_upper(&[-1.0]);
        // a + ce m, rounded up: the product's own rounding and ce's error times |m|.
        let add = |a: f64, m: f64| up(a + ce * m + ce_err * m.abs() + 2.0 * f64::EPSILON * ((ce * m).abs() + a.abs()));
        let out = Self {
            ceil_up: add(s_up, lo),
            ceil_down: add(s_down, -hi),
            floor_up: add(s_down, -lo),
            floor_down: add(s_up, hi),
        };
        [out.ceil_up, out.ceil_down, out.floor_up, out.floor_down].iter().all(|x| x.is_finite()).then_some(out)
    }

    /// `limsup |z'| <= ||eta_T'||_inf + max(ceil_up, ceil_down)` (at least `0`), from above.
    pub fn zdot_bound(&self, eta_dot_inf: f64) -> f64 {
        up((eta_dot_inf + self.ceil_up.max(self.ceil_down)).max(0.0))
    }
}

/// Rounds up by a relative `4u` and an absolute `MIN_POSITIVE` (one sum of a few terms).
fn up(x: f64) -> f64 {
    if x.is_finite() {
        x + 4.0 * f64::EPSILON * x.abs() + f64::MIN_POSITIVE
    } else {
        x
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tube::{Horizon, TubeSettings};
    use geometry::{ConvexSet, Interval, Shape};
    use nalgebra::DMatrix;

    fn kernel(C: &DMatrix<f64>, F: &DMatrix<f64>, E: &DMatrix<f64>, theta: &Shape) -> TubeKernel {
        TubeKernel::new(&(C * F), F, E, theta, Horizon::Infinite, &TubeSettings::default()).unwrap()
    }

    /// The ceilings never exceed D (which allows any v in Theta); with CE > 0 they are lower
    /// by CE (hi - lo), with CE = 0 (worked example) equal to D's terms.
    #[test]
    fn ceilings_against_d() {
        let F = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -1.0, -0.6]);
        let theta = Shape::Interval(Interval::new(-0.1, 0.2).unwrap());
        for (C, E, ce) in [
            (DMatrix::from_row_slice(1, 2, &[1.0, 0.0]), DMatrix::from_row_slice(2, 1, &[0.0, 1.0]), 0.0),
            (DMatrix::from_row_slice(1, 2, &[1.0, 0.5]), DMatrix::from_row_slice(2, 1, &[0.0, 1.0]), 0.5),
            (DMatrix::from_row_slice(1, 2, &[1.0, -0.5]), DMatrix::from_row_slice(2, 1, &[0.0, 1.0]), -0.5),
        ] {
            let k = kernel(&C, &F, &E, &theta);
            let s = EngagedSpeed::new(&k, &C, &E, -0.1, 0.2).unwrap();
            let (su, sd) = (k.support_upper(&[1.0]), k.support_upper(&[-1.0]));
            // D's two terms: s(u) + sigma_Theta(CE u)
            let d = (su + theta.support(&[ce])).max(sd + theta.support(&[-ce]));
            let ceil = s.ceil_up.max(s.ceil_down);
            assert!(ceil <= d * (1.0 + 1e-12) + 1e-15, "ce {ce}: ceiling {ceil} above D {d}");
            if ce > 0.0 {
                assert!(s.ceil_up <= su + ce * 0.2 - ce * 0.3 + 1e-12, "ce {ce}: {}", s.ceil_up);
            } else {
                assert!((ceil - d).abs() <= 1e-12 * d.abs().max(1.0), "ce {ce}: {ceil} vs {d}");
            }
            // negative control: the floors are not ceilings (floor_up allows z' below eta' - s(-1))
            assert!(s.floor_up >= sd - ce * (-0.1) - 1e-12);
        }
    }

    #[test]
    fn rejects_p_2_and_zero_outside() {
        let F = DMatrix::from_row_slice(2, 2, &[-1.0, 0.0, 0.0, -2.0]);
        let C = DMatrix::identity(2, 2);
        let E = DMatrix::identity(2, 2);
        let theta = Shape::Interval(Interval::new(-0.1, 0.2).unwrap());
        let C1 = DMatrix::from_row_slice(1, 2, &[1.0, 0.0]);
        let E1 = DMatrix::from_row_slice(2, 1, &[1.0, 0.0]);
        let k = kernel(&C1, &F, &E1, &theta);
        assert!(EngagedSpeed::new(&k, &C, &E, -0.1, 0.2).is_none());
        assert!(EngagedSpeed::new(&k, &C1, &E1, 0.1, 0.2).is_none(), "0 not in Theta");
        assert!(EngagedSpeed::new(&k, &C1, &E1, -0.1, 0.2).is_some());
    }
}
