//! The support function of `Theta` in the quadrature's inner loop ([`ThetaSupport`]): a fast
//! exact form for intersections of discs, the shapes' closed forms otherwise, each also from
//! above.
use geometry::{ConvexSet, Shape};

/// Support function of `Theta` for the quadrature's inner loop. Intersections of discs
/// (`p = 2`) get a fast exact form: the maximiser of `u^T x` is either `c_i + r_i u/|u|` (if it
/// lies in every disc) or one of the precomputed vertices (pairwise circle intersections lying
/// in every disc). Other shapes use their own closed forms.
#[derive(Debug, Clone)]
pub enum ThetaSupport {
    Shape(Shape),
    /// `pairs[k]` are the two discs whose circles meet at `vertices[k]`.
    Discs {
        centres: Vec<[f64; 2]>,
        radii: Vec<f64>,
        vertices: Vec<[f64; 2]>,
        pairs: Vec<(usize, usize)>,
    },
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
                let mut pairs = Vec::new();
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
                                pairs.push((i, j));
                            }
                        }
                    }
                }
                ThetaSupport::Discs { centres, radii, vertices, pairs }
            }
            other => ThetaSupport::Shape(other.clone()),
        }
    }

    #[inline]
    pub fn support(&self, u: &[f64]) -> f64 {
        match self {
            ThetaSupport::Shape(s) => s.support(u),
            ThetaSupport::Discs { centres, radii, vertices, .. } => {
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

    /// A proven upper bound of `sigma_Theta(u)` for the exact `u`, the rounding of the evaluation
    /// included: [`geometry::Shape::support_upper`]; for the disc fast path the candidate that
    /// [`Self::support`] would pick is certified: a vertex of discs `i, j` by the split
    /// `sigma <= sigma_{B_i}(a n_i) + sigma_{B_j}(u - a n_i)` (valid for every `a`), a point
    /// `c_i + r_i u/|u|` by `sigma <= sigma_{B_i}(u)`; when the split is singular, the smallest
    /// single-disc bound. Each of these is an upper bound whichever candidate is picked.
    pub fn support_upper(&self, u: &[f64]) -> f64 {
        use geometry::shapes::upper::{ball_support_upper, split_support_upper_2d};
        match self {
            ThetaSupport::Shape(s) => s.support_upper(u),
            ThetaSupport::Discs { centres, radii, vertices, pairs } => {
                let single = || {
                    centres.iter().zip(radii).map(|(c, r)| ball_support_upper(c, *r, u)).fold(f64::INFINITY, f64::min)
                };
                let nu = (u[0] * u[0] + u[1] * u[1]).sqrt();
                // (value, Ok(vertex) | Err(disc))
                let mut best: Option<(f64, Result<usize, usize>)> = None;
                for (k, v) in vertices.iter().enumerate() {
                    let val = u[0] * v[0] + u[1] * v[1];
                    if best.is_none_or(|b| val > b.0) {
                        best = Some((val, Ok(k)));
                    }
                }
                if nu > 0.0 {
                    for (i, (c, r)) in centres.iter().zip(radii).enumerate() {
                        let x = [c[0] + r * u[0] / nu, c[1] + r * u[1] / nu];
                        let ok = centres.iter().zip(radii.iter()).all(|(c2, r2)| {
                            ((x[0] - c2[0]).powi(2) + (x[1] - c2[1]).powi(2)).sqrt() <= r2 * (1.0 + 1e-12) + 1e-15
                        });
                        let val = u[0] * x[0] + u[1] * x[1];
                        if ok && best.is_none_or(|b| val > b.0) {
                            best = Some((val, Err(i)));
                        }
                    }
                }
                match best {
                    Some((_, Ok(k))) => {
                        let (i, j) = pairs[k];
                        split_support_upper_2d(&centres[i], radii[i], &centres[j], radii[j], &vertices[k], u)
                            .unwrap_or_else(single)
                    }
                    Some((_, Err(i))) => ball_support_upper(&centres[i], radii[i], u),
                    None => single(),
                }
            }
        }
    }
}
