//! The monodromy of the variational equation along the verified regime and an enclosure of its
//! spectral radius.
//!
//! Within a phase the variation `(dx, dz)` follows the `(n+1) x (n+1)` leading block of the
//! phase generator (resting `[[A, E], [0, 0]]`, engaged `[[F, 0], [C F, 0]]`), so its flow is the
//! leading block of `e^{h_j G_j}` (the generator is block upper triangular). At a switch with
//! event function `g` the variation jumps by the saltation matrix
//! `S = I + (f+ - f-) grad g^T / (grad g . f- + dg/dt)`:
//! - contact (`g = z - C x - b`, `f+ - f- = (0, y')`, `grad g . f- = -y'`, `y' != 0` proven):
//!   `S = [[I, 0], [C, 0]]` (the play locks `dz = C dx`);
//! - release (`g = y'`, `f+ = f-` at the switch since `y' = 0`, `y'' != 0` proven): `S = I`.
//!
//! The monodromy is `M = E_k S_k E_{k-1} ... S_1 E_0` (its eigenvalues are the Floquet
//! multipliers; with a contact in the period one of them is `0`). Its spectral radius is
//! enclosed by Gershgorin's theorem on `V^{-1} M V`, `V` the computed eigenvectors of the
//! midpoint: `V^{-1}` is enclosed as `(I + E) W` with `W ~ V^{-1}`, `R = I - W V`, `||E||_inf <=
//! ||R|| / (1 - ||R||)`; a connected union of `k` discs disjoint from the others holds exactly
//! `k` eigenvalues, so `rho(M)` lies between the largest lower modulus of a component and the
//! largest upper modulus of a disc.
use super::flow::PhaseKind;
use super::imat::IMat;
use super::period_map::{switch_kind, SwitchKind};
use nalgebra::{Complex, DMatrix};
use rounding::{add_up, Ival};

/// `M = E_k S_k ... S_1 E_0` from the phase flows (`(n+4)`-square) over the verified box.
pub fn monodromy(flows: &[IMat], kinds: &[PhaseKind], C: &[f64]) -> IMat {
    let n = C.len();
    let mut M = flows[0].block(0, 0, n + 1, n + 1);
    for j in 1..flows.len() {
        if switch_kind(kinds[j - 1], kinds[j]) == Some(SwitchKind::Contact) {
            // dz <- C dx
            let row = (0..n + 1)
                .map(|c| (0..n).fold(Ival::point(0.0), |s, i| s.add(M.at(i, c).scale(C[i]))))
                .collect::<Vec<_>>();
            for (c, v) in row.into_iter().enumerate() {
                M.set(n, c, v);
            }
        }
        M = flows[j].block(0, 0, n + 1, n + 1).mul(&M);
    }
    M
}

#[derive(Debug, Clone, Copy)]
struct CI {
    re: Ival,
    im: Ival,
}

impl CI {
    fn p(z: Complex<f64>) -> Self {
        Self { re: Ival::point(z.re), im: Ival::point(z.im) }
    }
    fn add(self, o: CI) -> CI {
        CI { re: self.re.add(o.re), im: self.im.add(o.im) }
    }
    fn mul(self, o: CI) -> CI {
        CI { re: self.re.mul(o.re).sub(self.im.mul(o.im)), im: self.re.mul(o.im).add(self.im.mul(o.re)) }
    }
    /// Upper bound of `|z|` over the rectangle.
    fn abs_up(self) -> f64 {
        self.re.sqr().add(self.im.sqr()).sqrt().hi
    }
}

type CM = Vec<Vec<CI>>;

fn cmul(a: &CM, b: &CM) -> CM {
    let (r, m, c) = (a.len(), b.len(), b[0].len());
    (0..r)
        .map(|i| {
            (0..c).map(|j| (0..m).fold(CI::p(Complex::new(0.0, 0.0)), |s, l| s.add(a[i][l].mul(b[l][j])))).collect()
        })
        .collect()
}

/// Why the spectral enclosure failed.
#[derive(Debug, Clone, PartialEq)]
pub enum SpectrumFailure {
    EigenvectorsIllConditioned,
    NonFinite,
}

/// An enclosure `[lo, hi]` of the spectral radius of every matrix in `M`, with the midpoint's.
pub fn spectral_radius(M: &IMat) -> Result<(Ival, f64), SpectrumFailure> {
    let n = M.rows;
    if !M.is_valid() {
        return Err(SpectrumFailure::NonFinite);
    }
    let Mc = M.mid();
    let lam = Mc.clone().complex_eigenvalues();
    let estimate = lam.iter().map(|z| z.norm()).fold(0.0, f64::max);
    let Mcc: DMatrix<Complex<f64>> = Mc.map(|v| Complex::new(v, 0.0));
    let mut V = DMatrix::<Complex<f64>>::zeros(n, n);
    for (i, l) in lam.iter().enumerate() {
        let Ai = &Mcc - DMatrix::<Complex<f64>>::identity(n, n) * *l;
        let svd = Ai.svd(false, true);
        let vt = svd.v_t.ok_or(SpectrumFailure::EigenvectorsIllConditioned)?;
        let imin = (0..n).min_by(|&a, &b| svd.singular_values[a].total_cmp(&svd.singular_values[b])).unwrap_or(0);
        for r in 0..n {
            V[(r, i)] = vt[(imin, r)].conj();
        }
    }
    let W = V.clone().try_inverse().ok_or(SpectrumFailure::EigenvectorsIllConditioned)?;
    let to_cm =
        |A: &DMatrix<Complex<f64>>| -> CM { (0..n).map(|i| (0..n).map(|j| CI::p(A[(i, j)])).collect()).collect() };
    let (Vi, Wi) = (to_cm(&V), to_cm(&W));
    let Mi: CM = (0..n).map(|i| (0..n).map(|j| CI { re: M.at(i, j), im: Ival::point(0.0) }).collect()).collect();
    // R = I - W V, e = ||R||_inf
    let WV = cmul(&Wi, &Vi);
    let mut e = 0.0f64;
    for i in 0..n {
        let mut row = 0.0f64;
        for j in 0..n {
            let one = if i == j { 1.0 } else { 0.0 };
            let r = CI { re: Ival::point(one).sub(WV[i][j].re), im: WV[i][j].im.neg() };
            row = add_up(row, r.abs_up());
        }
        e = e.max(row);
    }
    if !(e < 0.5) {
        return Err(SpectrumFailure::EigenvectorsIllConditioned);
    }
    let ep = Ival::point(e).div(Ival::point(1.0).sub(Ival::point(e))).hi;
    let D = cmul(&cmul(&Wi, &Mi), &Vi);
    // S = (I + E) D, |(E D)_ij| <= ep max_l |D_lj|
    let colmax: Vec<f64> = (0..n).map(|j| (0..n).map(|l| D[l][j].abs_up()).fold(0.0, f64::max)).collect();
    let mut centre = vec![Complex::new(0.0, 0.0); n];
    let mut radius = vec![0.0f64; n];
    for i in 0..n {
        let mut r = 0.0f64;
        for j in 0..n {
            let extra = Ival::point(ep).mul(Ival::point(colmax[j])).hi;
            if i == j {
                let d = D[i][i];
                centre[i] = Complex::new(d.re.mid(), d.im.mid());
                let half = CI { re: d.re.sub(Ival::point(centre[i].re)), im: d.im.sub(Ival::point(centre[i].im)) };
                r = add_up(r, add_up(half.abs_up(), extra));
            } else {
                r = add_up(r, add_up(D[i][j].abs_up(), extra));
            }
        }
        radius[i] = r;
    }
    if !radius.iter().all(|r| r.is_finite()) {
        return Err(SpectrumFailure::NonFinite);
    }
    // connected components of overlapping discs (overlap unless provably apart)
    let mut comp: Vec<usize> = (0..n).collect();
    let find = |comp: &Vec<usize>, mut i: usize| {
        while comp[i] != i {
            i = comp[i];
        }
        i
    };
    for i in 0..n {
        for j in i + 1..n {
            let d = (centre[i] - centre[j]).norm() * (1.0 - 1e-12);
            if !(d > add_up(radius[i], radius[j])) {
                let (a, b) = (find(&comp, i), find(&comp, j));
                comp[a] = b;
            }
        }
    }
    let modulus = |i: usize| CI::p(centre[i]);
    let (mut lo, mut hi) = (0.0f64, 0.0f64);
    for root in 0..n {
        let members: Vec<usize> = (0..n).filter(|&i| find(&comp, i) == root).collect();
        if members.is_empty() {
            continue;
        }
        let lo_c = members
            .iter()
            .map(|&i| {
                let m = modulus(i);
                let lower = m.re.sqr().add(m.im.sqr()).sqrt().lo;
                -add_up(-lower, radius[i])
            })
            .fold(f64::INFINITY, f64::min);
        let hi_c = members.iter().map(|&i| add_up(modulus(i).abs_up(), radius[i])).fold(0.0, f64::max);
        lo = lo.max(lo_c);
        hi = hi.max(hi_c);
    }
    Ok((Ival::new(lo.max(0.0), hi), estimate))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rotation-scaling block plus a real eigenvalue: `rho = 0.5 |1 + i| = 0.7071..`; the
    /// enclosure of a slightly widened matrix contains it and is tight; negative control: the
    /// enclosure of a different matrix (`rho = 0.6`) excludes it.
    #[test]
    fn spectral_radius_of_a_known_matrix() {
        let M = DMatrix::from_row_slice(3, 3, &[0.5, 0.5, 0.0, -0.5, 0.5, 0.0, 0.1, 0.0, 0.2]);
        let (r, est) = spectral_radius(&IMat::from_f64(&M).inflate(1e-12)).unwrap();
        let exact = 0.5f64 * 2f64.sqrt();
        assert!(r.contains(exact), "{r:?}");
        assert!(r.width() < 1e-10, "{r:?}");
        assert!((est - exact).abs() < 1e-14);
        let M2 = DMatrix::from_row_slice(2, 2, &[0.6, 0.0, 0.3, 0.1]);
        let (r2, _) = spectral_radius(&IMat::from_f64(&M2)).unwrap();
        assert!(r2.contains(0.6) && !r2.contains(exact));
        // a Jordan block has no basis of eigenvectors: refused, not a wrong answer
        let J = DMatrix::from_row_slice(2, 2, &[0.5, 1.0, 0.0, 0.5]);
        assert!(spectral_radius(&IMat::from_f64(&J)).map(|(r, _)| r.contains(0.5)).unwrap_or(true));
    }
}
