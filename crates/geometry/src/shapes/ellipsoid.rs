//! Ellipsoid `{x : (x - c)^T M^{-1} (x - c) <= 1}` with a symmetric positive definite shape
//! matrix `M`; its semi-axes are `a_i = sqrt(eig_i(M))`.
use super::{check_finite, fmt_vec};
use crate::linalg::norm;
use crate::strong_convexity::{symmetric_eigen_enclosure, EigenEnclosure};
use crate::{ConvexSet, Enclosure, GeometryError, StrongConvexity};
use nalgebra::DMatrix;
use rounding::{div_up, sqrt_down, sqrt_up};

/// Largest dimension handled without allocation in the projection.
pub const MAX_DIM: usize = 16;

/// Ellipsoid with centre `c` and shape matrix `M` (SPD). Support function
/// `sigma(u) = c^T u + sqrt(u^T M u)`; strong-convexity constant `R = max a_i^2 / min a_i`
/// (eq. (R), NOTES.md), bounded from above with verified bounds of the extreme eigenvalues of `M`
/// (exact for a diagonal `M`; Rump's Cholesky test otherwise,
/// [`crate::strong_convexity::symmetric_eigen_enclosure`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Ellipsoid {
    centre: Vec<f64>,
    /// Shape matrix, row-major.
    m: Vec<f64>,
    /// Eigenvalues of `M` (= squared semi-axes), ascending.
    lam: Vec<f64>,
    /// Eigenvectors of `M`, row-major `v[i * p + k]` = component `i` of eigenvector `k`.
    v: Vec<f64>,
    /// `M^{-1}`, row-major.
    m_inv: Vec<f64>,
    /// Proven enclosure of `lambda_min(M)` from below and `lambda_max(M)` from above (`None` when
    /// the verification failed: `R` is then only a numerical estimate).
    enclosure: Option<EigenEnclosure>,
    /// [`ConvexSet::deviation_from_origin`] once computed (a sphere maximum for an off-centre
    /// ellipsoid; asked for several times per system by `model` and the tube kernels of
    /// `bounds`). A function of the fields above, which never change after construction.
    deviation: DeviationCache,
}

/// Memo of a deterministic function of the ellipsoid: ignored by `==`.
#[derive(Debug, Clone, Default)]
struct DeviationCache(std::sync::OnceLock<Enclosure>);

impl PartialEq for DeviationCache {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl Ellipsoid {
    /// Builds the ellipsoid from its centre and shape matrix (rows). Checks dimensions,
    /// finiteness, symmetry (to `1e-12` relative) and positive definiteness.
    pub fn new(centre: Vec<f64>, matrix: &DMatrix<f64>) -> Result<Self, GeometryError> {
        let p = centre.len();
        if p == 0 || p > MAX_DIM {
            return Err(GeometryError::UnsupportedDimension { max: MAX_DIM, got: p });
        }
        if matrix.nrows() != p || matrix.ncols() != p {
            return Err(GeometryError::DimensionMismatch {
                what: "ellipsoid matrix (rows x cols vs centre length)",
                expected: p,
                got: if matrix.nrows() != p { matrix.nrows() } else { matrix.ncols() },
            });
        }
        check_finite("ellipsoid centre", &centre)?;
        check_finite("ellipsoid matrix entry", matrix.as_slice())?;
        let scale = matrix.amax().max(f64::MIN_POSITIVE);
        let asym = (matrix - matrix.transpose()).amax();
        if asym > 1e-12 * scale {
            return Err(GeometryError::NotSymmetric { asymmetry: asym });
        }
        let sym = (matrix + matrix.transpose()) * 0.5;
        let eig = nalgebra::SymmetricEigen::new(sym.clone());
        let mut order: Vec<usize> = (0..p).collect();
        order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
        let lam: Vec<f64> = order.iter().map(|&k| eig.eigenvalues[k]).collect();
        if !(lam[0] > 0.0) {
            return Err(GeometryError::NotPositiveDefinite { min_eig: lam[0] });
        }
        let mut v = vec![0.0; p * p];
        for (kk, &k) in order.iter().enumerate() {
            for i in 0..p {
                v[i * p + kk] = eig.eigenvectors[(i, k)];
            }
        }
        let mut m_inv = vec![0.0; p * p];
        for i in 0..p {
            for j in 0..p {
                m_inv[i * p + j] = (0..p).map(|k| v[i * p + k] * v[j * p + k] / lam[k]).sum();
            }
        }
        let m: Vec<f64> = (0..p * p).map(|ij| sym[(ij / p, ij % p)]).collect();
        let enclosure = symmetric_eigen_enclosure(&m, p, lam[0], lam[p - 1]);
        Ok(Self { centre, m, lam, v, m_inv, enclosure, deviation: DeviationCache::default() })
    }

    /// Axis-aligned ellipsoid with the given semi-axes.
    pub fn axis_aligned(centre: Vec<f64>, semi_axes: &[f64]) -> Result<Self, GeometryError> {
        check_finite("ellipsoid semi-axis", semi_axes)?;
        let m =
            DMatrix::from_diagonal(&nalgebra::DVector::from_iterator(semi_axes.len(), semi_axes.iter().map(|a| a * a)));
        Self::new(centre, &m)
    }

    pub fn centre(&self) -> &[f64] {
        &self.centre
    }
    /// Semi-axes `a_i = sqrt(eig_i(M))`, ascending.
    pub fn semi_axes(&self) -> Vec<f64> {
        self.lam.iter().map(|l| l.sqrt()).collect()
    }
    /// Shape matrix `M` (row-major).
    pub fn matrix(&self) -> &[f64] {
        &self.m
    }
    /// Proven bounds `lambda_min(M) >= min_lower`, `lambda_max(M) <= max_upper` (`None` when the
    /// verification failed).
    pub fn eigen_enclosure(&self) -> Option<EigenEnclosure> {
        self.enclosure
    }
    /// Upper bound of the longest semi-axis `a_max = sqrt(lambda_max(M))`: proven when the eigenvalue
    /// enclosure is verified, otherwise the estimate with a relative `1e-8` added.
    fn a_max_upper(&self) -> f64 {
        match self.enclosure {
            Some(e) => sqrt_up(e.max_upper),
            None => self.lam[self.lam.len() - 1].sqrt() * (1.0 + 1e-8),
        }
    }

    /// Coordinates of `x - c` in the eigenbasis.
    #[inline]
    fn to_axes(&self, x: &[f64], y: &mut [f64]) {
        let p = self.centre.len();
        for k in 0..p {
            let mut s = 0.0;
            for i in 0..p {
                s += self.v[i * p + k] * (x[i] - self.centre[i]);
            }
            y[k] = s;
        }
    }
    #[inline]
    fn to_world(&self, y: &[f64], out: &mut [f64]) {
        let p = self.centre.len();
        for i in 0..p {
            let mut s = self.centre[i];
            for k in 0..p {
                s += self.v[i * p + k] * y[k];
            }
            out[i] = s;
        }
    }

    /// `psi(t) = sum_i lam_i y_i^2 / (lam_i + t)^2`, the squared `M^{-1}`-norm of the
    /// stationary point `u(t)_i = lam_i y_i / (lam_i + t)` of the secular equation.
    #[inline]
    fn psi(&self, y: &[f64], t: f64) -> (f64, f64) {
        let mut f = 0.0;
        let mut df = 0.0;
        for k in 0..y.len() {
            let l = self.lam[k];
            let d = 1.0 / (l + t);
            let w = l * y[k] * y[k] * d * d;
            f += w;
            df -= 2.0 * w * d;
        }
        (f, df)
    }

    /// Root `t > 0` of the secular equation `psi(t) = 1` for a point outside: safeguarded
    /// Newton on `1/sqrt(psi(t)) - 1` (nearly linear in `t`), bisection fallback on the
    /// bracket `[0, sqrt(lam_max) |y|]`.
    fn secular_root(&self, y: &[f64]) -> f64 {
        let mut lo = 0.0;
        let mut hi = self.lam[self.lam.len() - 1].sqrt() * norm(y);
        let mut t = 0.0;
        for _ in 0..100 {
            let (f, df) = self.psi(y, t);
            let g = 1.0 / f.sqrt() - 1.0;
            if g < 0.0 {
                lo = t;
            } else {
                hi = t;
            }
            if g == 0.0 || hi - lo <= 4.0 * f64::EPSILON * hi {
                break;
            }
            let dg = -0.5 * df / (f * f.sqrt());
            let mut tn = t - g / dg;
            if !(tn > lo && tn < hi) {
                tn = 0.5 * (lo + hi);
            }
            if (tn - t).abs() <= 2.0 * f64::EPSILON * tn.abs() {
                t = tn;
                break;
            }
            t = tn;
        }
        t
    }
}

impl Ellipsoid {
    /// `D(E, {0})` by its definition (see [`ConvexSet::deviation_from_origin`]), not memoised.
    fn deviation_from_origin_uncached(&self) -> Enclosure {
        let up = self.a_max_upper();
        let cn = norm(&self.centre);
        if cn == 0.0 {
            return Enclosure::new(self.lam[self.lam.len() - 1].sqrt().min(up), up);
        }
        crate::sphere_max(self.dim(), |u| self.support(u), (cn + up) * (1.0 + 1e-12), &Default::default())
    }
}

impl ConvexSet for Ellipsoid {
    fn dim(&self) -> usize {
        self.centre.len()
    }
    fn support(&self, u: &[f64]) -> f64 {
        let p = self.dim();
        let mut q = 0.0;
        for i in 0..p {
            for j in 0..p {
                q += u[i] * self.m[i * p + j] * u[j];
            }
        }
        crate::linalg::dot(&self.centre, u) + q.max(0.0).sqrt()
    }
    fn support_point(&self, u: &[f64], out: &mut [f64]) {
        let p = self.dim();
        let mut mu = [0.0; MAX_DIM];
        let mut q = 0.0;
        for i in 0..p {
            mu[i] = (0..p).map(|j| self.m[i * p + j] * u[j]).sum();
            q += u[i] * mu[i];
        }
        let s = if q > 0.0 { 1.0 / q.sqrt() } else { 0.0 };
        for i in 0..p {
            out[i] = self.centre[i] + s * mu[i];
        }
    }
    /// Metric projection by a safeguarded Newton iteration on the secular equation in the
    /// eigenbasis of `M` (no general-purpose QP): relative accuracy ~1e-15 on `t`.
    fn project(&self, x: &[f64], out: &mut [f64]) {
        let p = self.dim();
        let mut y = [0.0; MAX_DIM];
        self.to_axes(x, &mut y[..p]);
        let (f0, _) = self.psi(&y[..p], 0.0);
        if f0 <= 1.0 {
            out.copy_from_slice(x);
            return;
        }
        let t = self.secular_root(&y[..p]);
        let mut u = [0.0; MAX_DIM];
        for k in 0..p {
            u[k] = self.lam[k] * y[k] / (self.lam[k] + t);
        }
        self.to_world(&u[..p], out);
    }
    fn contains(&self, x: &[f64], tol: f64) -> bool {
        let p = self.dim();
        let mut y = [0.0; MAX_DIM];
        self.to_axes(x, &mut y[..p]);
        let (f0, _) = self.psi(&y[..p], 0.0);
        if f0 <= 1.0 {
            return true;
        }
        let mut proj = [0.0; MAX_DIM];
        self.project(x, &mut proj[..p]);
        crate::linalg::dist(x, &proj[..p]) <= tol
    }
    /// Nearest boundary point from an interior point: the root of `psi(t) = 1` in
    /// `(-lam_min, 0]` (bisection to machine precision), with the "hard case" (no component
    /// along the shortest axis) handled in closed form.
    fn dist_to_boundary(&self, x: &[f64]) -> f64 {
        let p = self.dim();
        let mut y = [0.0; MAX_DIM];
        self.to_axes(x, &mut y[..p]);
        let y = &y[..p];
        if self.psi(y, 0.0).0 >= 1.0 {
            return 0.0;
        }
        let lmin = self.lam[0];
        let group: Vec<bool> = self.lam.iter().map(|&l| l <= lmin * (1.0 + 1e-12)).collect();
        let mut u = [0.0; MAX_DIM];
        // hard case test: psi restricted to the other axes at t = -lam_min
        let y_min2: f64 = (0..p).filter(|&k| group[k]).map(|k| y[k] * y[k]).sum();
        let rest: f64 =
            (0..p).filter(|&k| !group[k]).map(|k| self.lam[k] * y[k] * y[k] / (self.lam[k] - lmin).powi(2)).sum();
        let lo_eff = -lmin * (1.0 - 1e-13);
        if y_min2 <= (1e-13 * lmin).powi(2) && rest <= 1.0 {
            // hard case: u on the other axes from the formula, rest of the unit norm along the
            // shortest axis (direction of y's component if any, else the first axis of the group)
            let mut along = 0.0;
            for k in 0..p {
                if group[k] {
                    u[k] = 0.0;
                } else {
                    u[k] = self.lam[k] * y[k] / (self.lam[k] - lmin);
                    along += u[k] * u[k] / self.lam[k];
                }
            }
            let first = (0..p).find(|&k| group[k]).unwrap();
            let s = if y[first] < 0.0 { -1.0 } else { 1.0 };
            u[first] = s * (lmin * (1.0 - along).max(0.0)).sqrt();
            return crate::linalg::dist(&u[..p], y);
        }
        let (mut lo, mut hi) = (lo_eff, 0.0f64);
        if self.psi(y, lo).0 < 1.0 {
            lo = -lmin * (1.0 - f64::EPSILON);
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if self.psi(y, mid).0 > 1.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let t = 0.5 * (lo + hi);
        for k in 0..p {
            u[k] = self.lam[k] * y[k] / (self.lam[k] + t);
        }
        crate::linalg::dist(&u[..p], y)
    }
    /// Inward normal at a boundary point: `-M^{-1}(q - c)`. A point counts as on the boundary
    /// when `(1 - |q - c|_{M^{-1}}) a_min <= tol` (a lower bound of its distance to the boundary).
    fn project_normal_cone(&self, q: &[f64], v: &[f64], tol: f64, out: &mut [f64]) {
        let p = self.dim();
        let mut n = [0.0; MAX_DIM];
        let mut g = 0.0;
        for i in 0..p {
            n[i] = -(0..p).map(|j| self.m_inv[i * p + j] * (q[j] - self.centre[j])).sum::<f64>();
            g -= n[i] * (q[i] - self.centre[i]);
        }
        let level = g.max(0.0).sqrt();
        if (1.0 - level) * self.lam[0].sqrt() > tol {
            out.iter_mut().for_each(|o| *o = 0.0);
            return;
        }
        let nn = norm(&n[..p]);
        if nn == 0.0 {
            out.iter_mut().for_each(|o| *o = 0.0);
            return;
        }
        let s = (crate::linalg::dot(v, &n[..p]) / (nn * nn)).max(0.0);
        for i in 0..p {
            out[i] = s * n[i];
        }
    }
    /// `2 a_max`, from above with the verified bound of `lambda_max(M)`.
    fn diameter(&self) -> Enclosure {
        let up = 2.0 * self.a_max_upper();
        Enclosure::new((2.0 * self.lam[self.lam.len() - 1].sqrt()).min(up), up)
    }
    /// `max_{|u|=1} c^T u + sqrt(u^T M u)`; `a_max` (from above) when `c = 0`, otherwise
    /// certified by [`crate::sphere_max`].
    fn deviation_from_origin(&self) -> Enclosure {
        *self.deviation.0.get_or_init(|| self.deviation_from_origin_uncached())
    }
    /// `R = lambda_max / sqrt(lambda_min)` from the verified eigenvalue enclosure, rounded upward:
    /// `Exact` for a diagonal `M` (exact eigenvalues), `UpperBound` otherwise; `Numerical` (not a
    /// verified upper bound) when the enclosure could not be proved.
    fn strong_convexity(&self) -> StrongConvexity {
        match self.enclosure {
            Some(e) if e.min_lower > 0.0 => {
                let r = div_up(e.max_upper, sqrt_down(e.min_lower));
                if e.exact {
                    StrongConvexity::Exact(r)
                } else {
                    StrongConvexity::UpperBound(r)
                }
            }
            _ => {
                let value = self.lam[self.lam.len() - 1] / self.lam[0].sqrt();
                StrongConvexity::Numerical { value, error: 1e-8 * value }
            }
        }
    }
    fn describe(&self) -> String {
        format!("ellipsoid(centre={}, semi-axes={})", fmt_vec(&self.centre), fmt_vec(&self.semi_axes()))
    }
}
