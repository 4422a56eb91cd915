//! Support functions of the tube cross-sections `L Xi(t)` and `L Xi_inf` (Lemma 2):
//!
//! ```text
//! sigma_{L Xi(t)}(v)   = int_0^t   sigma_Theta(K(s)^T v) ds,   K(s) = L e^{sF} E      (Xsupp)
//! sigma_{L Xi_inf}(v)  = int_0^inf sigma_Theta(K(s)^T v) ds                           (Xinfsupp)
//! ```
//! (`L = I_n` gives `Xi` itself, `L = C` the output tube `C Xi_inf` of eq. (d), `L = C F` the
//! set `C F Xi_inf` of eq. (zinf)), enclosed rigorously up to floating-point rounding.
//!
//! **Quadrature.** On a cell `[m - r, m + r]` write `c(s) = K(s)^T v`. Taylor:
//! `c(m + tau) = c(m) + tau c'(m) + rho(tau)`, `|rho| <= tau^2/2 M2`, with
//! `M2 = ||L F^2 e^{mF}||_F e^{r ||F||_F} ||E||_F |v|` bounding `|c''|` on the cell. As
//! `sigma_Theta` is convex and `D_Theta`-Lipschitz (`D_Theta = D(Theta, {0})`, eq. (DTheta0)):
//! - upper: `int <= r (sigma(c(m) - r c'(m)) + sigma(c(m) + r c'(m))) + D_Theta M2 r^3 / 3`
//!   (the trapezoid rule over-estimates the integral of a convex function);
//! - lower: `int >= 2 r sigma(c(m)) - D_Theta M2 r^3 / 3` (Jensen).
//!
//! The cell width is chosen (and halved, adaptively) until the summed remainders are below
//! `tol_abs / 2`.
//!
//! **Tail, eq. (DXX).** `int_S^inf sigma_Theta(K(s)^T v) ds <= D_Theta |v| ||L e^{SF}||_F ||E||_F
//! int_0^inf ||e^{rF}|| dr`, and `int_0^inf ||e^{rF}|| dr <= tau M / (1 - q)` with
//! `q = ||e^{tau F}||_F < 1` and `M >= max_{[0, tau]} ||e^{rF}||` (grid maximum times
//! `e^{delta ||F||_F}`). `S` is increased until the tail is below `tol_abs / 2`.
use crate::error::BoundsError;
use dynamics::linear::expm::expm;
use geometry::{ConvexSet, Shape};
use nalgebra::DMatrix;

/// Settings of the tube quadrature.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TubeSettings {
    /// Target absolute width (per unit `|v|`) of the enclosure of a support value, half for the
    /// quadrature remainder and half for the tail. Default `1e-5`.
    pub tol_abs: f64,
    /// Maximum number of quadrature cells. Default `400_000`.
    pub max_cells: usize,
}

impl Default for TubeSettings {
    fn default() -> Self {
        Self { tol_abs: 1e-5, max_cells: 400_000 }
    }
}

impl TubeSettings {
    pub fn validate(&self) -> Result<(), BoundsError> {
        if !(self.tol_abs > 0.0 && self.tol_abs.is_finite()) {
            return Err(BoundsError::BadSetting {
                name: "tube.tol_abs",
                value: self.tol_abs,
                reason: "must be positive and finite",
            });
        }
        if self.max_cells < 16 {
            return Err(BoundsError::BadSetting {
                name: "tube.max_cells",
                value: self.max_cells as f64,
                reason: "must be at least 16",
            });
        }
        Ok(())
    }
}

/// The integration horizon: `Xi(t)` (eq. (Xsupp)) or `Xi_inf` (eq. (Xinfsupp)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Horizon {
    Finite(f64),
    Infinite,
}

/// Support function of `Theta` for the quadrature's inner loop. Intersections of discs
/// (`p = 2`) get a fast exact form: the maximiser of `u^T x` is either `c_i + r_i u/|u|` (if it
/// lies in every disc) or one of the precomputed vertices (pairwise circle intersections lying
/// in every disc). Other shapes use their own closed forms.
#[derive(Debug, Clone)]
pub enum ThetaSupport {
    Shape(Shape),
    Discs { centres: Vec<[f64; 2]>, radii: Vec<f64>, vertices: Vec<[f64; 2]> },
}

impl ThetaSupport {
    pub fn new(theta: &Shape) -> Self {
        match theta {
            Shape::BallIntersection(bi) if bi.dim() == 2 => {
                let centres: Vec<[f64; 2]> = bi.centres().iter().map(|c| [c[0], c[1]]).collect();
                let radii = bi.radii().to_vec();
                let inside = |x: &[f64; 2], centres: &[[f64; 2]], radii: &[f64]| {
                    centres.iter().zip(radii).all(|(c, r)| {
                        ((x[0] - c[0]).powi(2) + (x[1] - c[1]).powi(2)).sqrt() <= r * (1.0 + 1e-12) + 1e-15
                    })
                };
                let mut vertices = Vec::new();
                for i in 0..centres.len() {
                    for j in i + 1..centres.len() {
                        let (a, b) = (centres[i], centres[j]);
                        let d = ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
                        let (ri, rj) = (radii[i], radii[j]);
                        if d == 0.0 || d > ri + rj || d < (ri - rj).abs() {
                            continue;
                        }
                        let l = (ri * ri - rj * rj + d * d) / (2.0 * d);
                        let h = (ri * ri - l * l).max(0.0).sqrt();
                        let (ex, ey) = ((b[0] - a[0]) / d, (b[1] - a[1]) / d);
                        for sg in [1.0, -1.0] {
                            let x = [a[0] + l * ex - sg * h * ey, a[1] + l * ey + sg * h * ex];
                            if inside(&x, &centres, &radii) {
                                vertices.push(x);
                            }
                        }
                    }
                }
                ThetaSupport::Discs { centres, radii, vertices }
            }
            other => ThetaSupport::Shape(other.clone()),
        }
    }

    #[inline]
    pub fn support(&self, u: &[f64]) -> f64 {
        match self {
            ThetaSupport::Shape(s) => s.support(u),
            ThetaSupport::Discs { centres, radii, vertices } => {
                let nu = (u[0] * u[0] + u[1] * u[1]).sqrt();
                let mut best = f64::NEG_INFINITY;
                for v in vertices {
                    best = best.max(u[0] * v[0] + u[1] * v[1]);
                }
                if nu == 0.0 {
                    return best.max(0.0);
                }
                for (c, r) in centres.iter().zip(radii) {
                    let x = [c[0] + r * u[0] / nu, c[1] + r * u[1] / nu];
                    let ok = centres.iter().zip(radii.iter()).all(|(c2, r2)| {
                        ((x[0] - c2[0]).powi(2) + (x[1] - c2[1]).powi(2)).sqrt() <= r2 * (1.0 + 1e-12) + 1e-15
                    });
                    if ok {
                        best = best.max(u[0] * x[0] + u[1] * x[1]);
                    }
                }
                best
            }
        }
    }
}

fn frob(M: &DMatrix<f64>) -> f64 {
    M.iter().map(|x| x * x).sum::<f64>().sqrt() * (1.0 + 1e-14)
}

/// Precomputed quadrature of `sigma_{L Xi}(v)` for any direction `v in R^r` (`r` = rows of `L`).
/// Thread-safe (immutable after construction), cheap to evaluate for many directions.
#[derive(Debug, Clone)]
pub struct TubeKernel {
    r: usize,
    p: usize,
    theta: ThetaSupport,
    /// Per cell: `(K(m) - r K'(m))^T`, `K(m)^T`, `(K(m) + r K'(m))^T`, each `p x r`, row-major.
    minus: Vec<f64>,
    mid: Vec<f64>,
    plus: Vec<f64>,
    /// Half-width of each cell.
    half: Vec<f64>,
    /// Sum of the Taylor remainders per unit `|v|`.
    remainder: f64,
    /// Tail bound per unit `|v|` (0 for a finite horizon).
    tail: f64,
    /// Upper bound of `int ||K(s)|| ds` (for Lipschitz constants).
    k_l1: f64,
    d_theta: f64,
    zero_in_theta: bool,
    /// Truncation point `S` of the infinite integral (or the finite horizon).
    pub s_max: f64,
    /// Width of the first (smallest) cell; cells grow geometrically with `s`.
    pub h: f64,
}

/// Bound `int_0^inf ||e^{rF}|| dr <= tau M / (1 - q)` (see the module docs).
pub fn exp_norm_integral(F: &DMatrix<f64>) -> Result<f64, BoundsError> {
    let nF = frob(F);
    let mu = lmi::spectral_abscissa(F).map_err(BoundsError::Lmi)?;
    if mu >= 0.0 {
        return Err(BoundsError::NotHurwitz { mu });
    }
    let mut tau = 1.0 / -mu;
    for _ in 0..40 {
        let q = frob(&expm(&(F * tau)));
        if q < 0.5 {
            // M = max over a grid of [0, tau] of ||e^{rF}||_F, times e^{delta ||F||}.
            let k = 256usize;
            let delta = tau / k as f64;
            let step = expm(&(F * delta));
            let mut P = DMatrix::<f64>::identity(F.nrows(), F.nrows());
            let mut M = frob(&P);
            for _ in 0..k {
                P = &P * &step;
                M = M.max(frob(&P));
            }
            M *= (delta * nF).exp() * (1.0 + 1e-10);
            return Ok(tau * M / (1.0 - q));
        }
        tau *= 2.0;
    }
    Err(BoundsError::NoTailBound { tau_max: tau })
}

/// Eq. (DXX): `D(Xi_inf, Xi(t)) <= D(Theta, {0}) ||E|| int_t^inf ||e^{sF}|| ds`, bounded by
/// `D_Theta ||E||_F ||e^{tF}||_F int_0^inf ||e^{rF}|| dr` (see [`exp_norm_integral`]).
pub fn dxx_bound(F: &DMatrix<f64>, E: &DMatrix<f64>, theta: &Shape, t: f64) -> Result<f64, BoundsError> {
    let i_inf = exp_norm_integral(F)?;
    Ok(theta.deviation_from_origin().upper * frob(E) * frob(&expm(&(F * t))) * i_inf)
}

impl TubeKernel {
    /// Builds the quadrature of `sigma_{L Xi}` for `K(s) = L e^{sF} E` and the set `theta`.
    pub fn new(
        L: &DMatrix<f64>,
        F: &DMatrix<f64>,
        E: &DMatrix<f64>,
        theta: &Shape,
        horizon: Horizon,
        settings: &TubeSettings,
    ) -> Result<Self, BoundsError> {
        settings.validate()?;
        let p = E.ncols();
        let r = L.nrows();
        let d_theta = theta.deviation_from_origin().upper;
        let zero_in_theta = theta.contains(&vec![0.0; p], 0.0);
        let nF = frob(F);
        let nE = frob(E);
        let LF = L * F;
        let LF2 = &LF * F;
        let tol = settings.tol_abs;
        // Truncation point.
        let (s_max, tail_unit) = match horizon {
            Horizon::Finite(t) => {
                if !(t >= 0.0 && t.is_finite()) {
                    return Err(BoundsError::BadSetting {
                        name: "horizon",
                        value: t,
                        reason: "must be finite and >= 0",
                    });
                }
                (t, 0.0)
            }
            Horizon::Infinite => {
                let i_inf = exp_norm_integral(F)?;
                let mu = lmi::spectral_abscissa(F).map_err(BoundsError::Lmi)?;
                let mut S = 8.0 / -mu;
                let mut tail;
                loop {
                    tail = d_theta * frob(&(L * expm(&(F * S)))) * nE * i_inf;
                    if tail <= 0.5 * tol || S > 1e6 / -mu {
                        break;
                    }
                    S *= 1.25;
                }
                (S, tail)
            }
        };
        // Cell widths: graded as h(s) = h0 e^{grade s} (the remainder per cell decays like
        // e^{mu s} h^3), capped at 1 / ||F||; h0 shrinks (remainder ~ h0^2) until the summed
        // remainders are below tol / 2. The grading only affects efficiency, not rigour.
        let grade = match horizon {
            Horizon::Infinite => (-lmi::spectral_abscissa(F).map_err(BoundsError::Lmi)?).max(0.0) / 3.0,
            Horizon::Finite(_) => 0.0,
        };
        let h_cap = 1.0 / nF.max(1e-300);
        let mut h0 = (0.05_f64).min(0.5 * h_cap);
        loop {
            let k = Self::build(
                L,
                &LF,
                &LF2,
                F,
                E,
                theta,
                s_max,
                h0,
                grade,
                h_cap,
                d_theta,
                nF,
                nE,
                r,
                p,
                settings.max_cells,
            );
            let Some(k) = k else {
                return Err(BoundsError::QuadratureBudget {
                    error_bound: f64::INFINITY,
                    tol,
                    nodes: settings.max_cells,
                });
            };
            if k.remainder <= 0.5 * tol || k.cells() == 0 {
                return Ok(Self { tail: tail_unit, zero_in_theta, s_max, ..k });
            }
            h0 /= (k.remainder / (0.4 * tol)).sqrt().max(1.5);
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn build(
        L: &DMatrix<f64>,
        LF: &DMatrix<f64>,
        LF2: &DMatrix<f64>,
        F: &DMatrix<f64>,
        E: &DMatrix<f64>,
        theta: &Shape,
        s_max: f64,
        h0: f64,
        grade: f64,
        h_cap: f64,
        d_theta: f64,
        nF: f64,
        nE: f64,
        r: usize,
        p: usize,
        max_cells: usize,
    ) -> Option<Self> {
        const BLOCK: usize = 32;
        let mut minus = Vec::new();
        let mut mid = Vec::new();
        let mut plus = Vec::new();
        let mut half = Vec::new();
        let mut remainder = 0.0;
        let mut k_l1 = 0.0;
        let push_t = |buf: &mut Vec<f64>, M: &DMatrix<f64>| {
            // M is r x p; store M^T (p x r) row-major, i.e. M column-major.
            buf.extend(M.iter().copied());
        };
        let mut sb = 0.0;
        let mut h_first = f64::NAN;
        while sb < s_max {
            let mut hb = (h0 * (grade * sb).exp()).min(h_cap).max(h0);
            let mut count = BLOCK;
            if sb + BLOCK as f64 * hb >= s_max {
                count = (((s_max - sb) / hb).ceil() as usize).max(1);
                hb = (s_max - sb) / count as f64;
            }
            if h_first.is_nan() {
                h_first = hb;
            }
            if half.len() + count > max_cells {
                return None;
            }
            let rr = 0.5 * hb;
            let grow = (rr * nF).exp();
            let step = expm(&(F * hb));
            let mut P = expm(&(F * (sb + rr)));
            for j in 0..count {
                if j > 0 {
                    P = &P * &step;
                }
                let PE = &P * E;
                let K = L * &PE;
                let K1 = LF * &PE;
                let M2 = frob(&(LF2 * &P)) * grow * nE;
                let Km = &K - &K1 * rr;
                let Kp = &K + &K1 * rr;
                push_t(&mut minus, &Km);
                push_t(&mut mid, &K);
                push_t(&mut plus, &Kp);
                half.push(rr);
                remainder += d_theta * M2 * rr * rr * rr / 3.0;
                k_l1 += 2.0 * rr * (frob(&K) + rr * frob(&K1) + 0.5 * rr * rr * M2);
            }
            sb += count as f64 * hb;
            if count < BLOCK {
                break;
            }
        }
        let h = if h_first.is_nan() { 0.0 } else { h_first };
        Some(Self {
            r,
            p,
            theta: ThetaSupport::new(theta),
            minus,
            mid,
            plus,
            half,
            remainder: remainder * (1.0 + 1e-10),
            tail: 0.0,
            k_l1,
            d_theta,
            zero_in_theta: true,
            s_max,
            h,
        })
    }

    /// Dimension `r` of the directions `v`.
    pub fn dim(&self) -> usize {
        self.r
    }

    /// `sum_j w_j sigma_Theta(M_j^T v)` over the stored matrices.
    fn sum(&self, mats: &[f64], v: &[f64], buf: &mut [f64]) -> f64 {
        let (p, r) = (self.p, self.r);
        let mut acc = 0.0;
        for j in 0..self.half.len() {
            let M = &mats[j * p * r..(j + 1) * p * r];
            // M is stored column-major r x p: column i (entries i*r..) is row i of M^T.
            for (i, b) in buf.iter_mut().enumerate() {
                *b = M[i * r..(i + 1) * r].iter().zip(v).map(|(a, x)| a * x).sum();
            }
            acc += self.half[j] * self.theta.support(buf);
        }
        acc
    }

    /// Rigorous enclosure `[lower, upper]` of `sigma_{L Xi}(v)` (up to rounding).
    pub fn support_bounds(&self, v: &[f64]) -> geometry::Bounds {
        let mut buf = vec![0.0; self.p];
        let nv = geometry::linalg::norm(v);
        let up =
            self.sum(&self.minus, v, &mut buf) + self.sum(&self.plus, v, &mut buf) + nv * (self.remainder + self.tail);
        let lo_tail = if self.zero_in_theta { 0.0 } else { nv * self.tail };
        let lo = 2.0 * self.sum(&self.mid, v, &mut buf) - nv * self.remainder - lo_tail;
        geometry::Bounds::new(lo, up.max(lo))
    }

    /// Upper bound of `sigma_{L Xi}(v)`.
    pub fn support_upper(&self, v: &[f64]) -> f64 {
        self.support_bounds(v).upper
    }

    /// Lipschitz constant (in `v`) of [`Self::support_upper`] and of the true support function:
    /// `D_Theta int ||K|| ds` plus the remainder and tail terms.
    pub fn lipschitz(&self) -> f64 {
        (self.d_theta * self.k_l1 + self.remainder + self.tail) * (1.0 + 1e-10)
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

    /// Number of quadrature cells.
    pub fn cells(&self) -> usize {
        self.half.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dxx_bounds_the_hausdorff_gap_between_xi_t_and_xi_inf() {
        let F = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -1.0, -0.6]);
        let E = DMatrix::from_row_slice(2, 1, &[0.0, 1.0]);
        let theta = Shape::Interval(geometry::Interval::symmetric(0.1).unwrap());
        let I = DMatrix::<f64>::identity(2, 2);
        let st = TubeSettings { tol_abs: 1e-7, ..Default::default() };
        let kinf = TubeKernel::new(&I, &F, &E, &theta, Horizon::Infinite, &st).unwrap();
        for t in [1.0, 5.0, 15.0] {
            let kt = TubeKernel::new(&I, &F, &E, &theta, Horizon::Finite(t), &st).unwrap();
            let bound = dxx_bound(&F, &E, &theta, t).unwrap();
            let mut gap = 0.0f64;
            for k in 0..64 {
                let a = std::f64::consts::TAU * k as f64 / 64.0;
                let u = [a.cos(), a.sin()];
                gap = gap.max(kinf.support_bounds(&u).lower - kt.support_upper(&u));
            }
            assert!(gap <= bound, "t = {t}: gap {gap} > (DXX) {bound}");
            assert!(gap > 0.0 || t > 10.0);
            // Negative control: a rate faster than mu (e^{-t} instead of e^{-0.3 t}) is violated.
            if t == 5.0 {
                assert!(gap > 0.1 * (-t).exp(), "{gap}");
            }
        }
    }

    #[test]
    fn fast_disc_intersection_support_matches_geometry() {
        let lens = geometry::BallIntersection::new(vec![vec![-0.15, 0.0], vec![0.15, 0.0]], vec![0.2, 0.2]).unwrap();
        let three = geometry::BallIntersection::new(
            vec![vec![0.0, 0.0], vec![0.3, 0.1], vec![0.1, -0.25]],
            vec![0.3, 0.35, 0.4],
        )
        .unwrap();
        for bi in [lens, three] {
            let shape = Shape::BallIntersection(bi);
            let fast = ThetaSupport::new(&shape);
            assert!(matches!(fast, ThetaSupport::Discs { .. }));
            for k in 0..720 {
                let a = std::f64::consts::TAU * k as f64 / 720.0 + 0.001;
                let u = [2.0 * a.cos(), 2.0 * a.sin()];
                let (x, y) = (fast.support(&u), shape.support(&u));
                assert!((x - y).abs() <= 1e-12 * (1.0 + y.abs()), "{a}: {x} vs {y}");
            }
        }
        // Negative control: dropping the vertices breaks the support at the lens' tips.
        let shape = Shape::BallIntersection(
            geometry::BallIntersection::new(vec![vec![-0.15, 0.0], vec![0.15, 0.0]], vec![0.2, 0.2]).unwrap(),
        );
        if let ThetaSupport::Discs { centres, radii, .. } = ThetaSupport::new(&shape) {
            let broken = ThetaSupport::Discs { centres, radii, vertices: vec![] };
            assert!((broken.support(&[0.0, 1.0]) - shape.support(&[0.0, 1.0])).abs() > 1e-3);
        }
    }
}
