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
//! multipliers; with a contact in the period one of them is `0`). It depends on the phase
//! durations alone and is enclosed over their verified box in mean-value form
//! ([`MonodromyEnclosure`]). Its spectral radius is enclosed by Gershgorin's theorem on
//! `V^{-1} M V`, `V` the computed eigenvectors of the midpoint: `V^{-1}` is enclosed as
//! `(I + E) W` with `W ~ V^{-1}`, `R = I - W V`, `||E||_inf <= ||R|| / (1 - ||R||)`; a connected
//! union of `k` discs disjoint from the others holds exactly `k` eigenvalues, so `rho(M)` lies
//! between the largest lower modulus of a component and the largest upper modulus of a disc.
//! The same holds for every diagonal similarity of `V^{-1} M V`; scaling the rows off a disc
//! (and off its complex conjugate's) shrinks that disc, and the enclosures are intersected.
use super::flow::{Generators, PhaseKind};
use super::imat::IMat;
use super::period_map::{switch_kind, SwitchKind};
use nalgebra::{Complex, DMatrix};
use rounding::{add_up, div_up, mul_up, Ival};

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

/// The monodromy over a box of phase durations, in mean-value form. `M` depends on the
/// durations alone, so for every `h` in the box `M(h) = M(h^) + sum_j dM/dh_j (xi) (h_j - h^_j)`
/// with `xi` in the box (the mean-value theorem per entry), and `dM/dh_j` is the same product
/// with the flow `E_j` replaced by `G_j E_j` (over the box). `M(h^)` at the midpoints is nearly
/// exact, and the box's widths enter only times `h_j - h^_j`. The same form carries through
/// any fixed linear map (`W M V` in [`spectral_radius`]): the slopes keep the cancellations
/// that an entrywise enclosure of `M` loses.
#[derive(Debug, Clone)]
pub struct MonodromyEnclosure {
    /// `M(h^)` enclosed.
    pub centre: IMat,
    /// `dM/dh_j` enclosed over the box.
    pub slopes: Vec<IMat>,
    /// `h_j - h^_j` over the box.
    pub offsets: Vec<Ival>,
    /// The product of the flows over the box (the direct enclosure).
    pub direct: IMat,
}

impl MonodromyEnclosure {
    /// The enclosure over the box of durations `durations`, whose flows are `flows`.
    pub fn new(g: &Generators, kinds: &[PhaseKind], durations: &[Ival], flows: &[IMat]) -> Self {
        let centre_h: Vec<f64> = durations.iter().map(|h| h.mid()).collect();
        let at_centre: Vec<IMat> = kinds.iter().zip(&centre_h).map(|(k, h)| g.flow(*k, Ival::point(*h))).collect();
        let slopes = (0..kinds.len())
            .map(|j| {
                let mut f = flows.to_vec();
                f[j] = g.generator(kinds[j]).mul(&flows[j]);
                monodromy(&f, kinds, &g.C)
            })
            .collect();
        Self {
            centre: monodromy(&at_centre, kinds, &g.C),
            slopes,
            offsets: durations.iter().zip(&centre_h).map(|(h, c)| h.sub(Ival::point(*c))).collect(),
            direct: monodromy(flows, kinds, &g.C),
        }
    }

    /// A matrix known only entrywise (no slopes).
    pub fn entrywise(M: IMat) -> Self {
        Self { centre: M.clone(), slopes: vec![], offsets: vec![], direct: M }
    }

    /// `L M R` enclosed for complex point matrices `L`, `R`: the mean-value form intersected
    /// with the direct product.
    fn transformed(&self, L: &CM, R: &CM) -> CM {
        let lift = |A: &IMat| -> CM {
            (0..A.rows).map(|i| (0..A.cols).map(|j| CI { re: A.at(i, j), im: Ival::point(0.0) }).collect()).collect()
        };
        let product = |A: &IMat| cmul(&cmul(L, &lift(A)), R);
        let mut T = product(&self.centre);
        for (S, d) in self.slopes.iter().zip(&self.offsets) {
            let P = product(S);
            for (row, prow) in T.iter_mut().zip(&P) {
                for (t, p) in row.iter_mut().zip(prow) {
                    *t = t.add(CI { re: p.re.mul(*d), im: p.im.mul(*d) });
                }
            }
        }
        let direct = product(&self.direct);
        for (row, drow) in T.iter_mut().zip(&direct) {
            for (t, d) in row.iter_mut().zip(drow) {
                *t = t.intersect(d);
            }
        }
        T
    }

    /// The entrywise enclosure of `M` (mean-value form intersected with the direct product).
    pub fn matrix(&self) -> IMat {
        let n = self.centre.rows;
        let I: CM = (0..n)
            .map(|i| (0..n).map(|j| CI::p(Complex::new(if i == j { 1.0 } else { 0.0 }, 0.0))).collect())
            .collect();
        let T = self.transformed(&I, &I);
        let mut M = self.direct.clone();
        for (i, row) in T.iter().enumerate() {
            for (j, t) in row.iter().enumerate() {
                M.set(i, j, t.re);
            }
        }
        M
    }
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
    /// The intersection where both parts overlap (else `self`: both enclose the same value).
    fn intersect(self, o: &CI) -> CI {
        match (self.re.intersect(&o.re), self.im.intersect(&o.im)) {
            (Some(re), Some(im)) => CI { re, im },
            _ => self,
        }
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
pub fn spectral_radius(E: &MonodromyEnclosure) -> Result<(Ival, f64), SpectrumFailure> {
    let M = E.matrix();
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
    let D = E.transformed(&Wi, &Vi);
    // S = (I + E) D, |(E D)_ij| <= ep max_l |D_lj|
    let colmax: Vec<f64> = (0..n).map(|j| (0..n).map(|l| D[l][j].abs_up()).fold(0.0, f64::max)).collect();
    let discs = Discs { D: &D, extra: colmax.iter().map(|c| Ival::point(ep).mul(Ival::point(*c)).hi).collect() };
    // every diagonal scaling of S gives an enclosure; their intersection is one too. Scaled
    // down: the discs off one disc, or off one disc and its complex conjugate's
    let (centre, _) = discs.discs(&vec![1.0; n]);
    let partner = |i: usize| {
        (0..n)
            .filter(|&j| j != i)
            .min_by(|&a, &b| (centre[a] - centre[i].conj()).norm().total_cmp(&(centre[b] - centre[i].conj()).norm()))
    };
    let mut enclosure = discs.radius_enclosure(&vec![1.0; n]).ok_or(SpectrumFailure::NonFinite)?;
    for i in 0..n {
        for kept in [vec![i], [i].into_iter().chain(partner(i)).collect()] {
            for k in 1..=SCALING_STEPS {
                let delta = (2.0f64).powi(-3 * k);
                let s: Vec<f64> = (0..n).map(|j| if kept.contains(&j) { 1.0 } else { delta }).collect();
                if let Some(r) = discs.radius_enclosure(&s) {
                    enclosure = enclosure.intersect(&r).unwrap_or(enclosure);
                }
            }
        }
    }
    Ok((enclosure, estimate))
}

/// Diagonal scalings tried per disc: `s_j = 2^(-3k)` off the disc, `k = 1..=SCALING_STEPS`
/// (powers of two: the scaled entries are exact).
const SCALING_STEPS: i32 = 8;

/// Gershgorin discs of `S = (I + E) D`: the transformed monodromy `D` and, per column `j`, the
/// bound `extra[j] >= |(E D)_ij|`.
struct Discs<'a> {
    D: &'a CM,
    extra: Vec<f64>,
}

impl Discs<'_> {
    /// Enclosure of the spectral radius from the discs of `diag(s)^-1 S diag(s)` (same
    /// eigenvalues; row `i`'s off-diagonal entries scaled by `s_j / s_i`): a connected union of
    /// `k` discs disjoint from the others holds exactly `k` eigenvalues, so the radius lies
    /// between the largest lower modulus of a component and the largest upper modulus of a
    /// disc. `None` when a radius is not finite.
    fn radius_enclosure(&self, s: &[f64]) -> Option<Ival> {
        let (centre, radius) = self.discs(s);
        if !radius.iter().all(|r| r.is_finite()) {
            return None;
        }
        let comp = components(&centre, &radius);
        let modulus = |i: usize| CI::p(centre[i]);
        let (mut lo, mut hi) = (0.0f64, 0.0f64);
        for root in 0..centre.len() {
            let members: Vec<usize> = (0..centre.len()).filter(|&i| comp[i] == root).collect();
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
        Some(Ival::new(lo.max(0.0), hi))
    }

    /// Centres (the midpoints of the diagonal) and radii of the scaled discs.
    fn discs(&self, s: &[f64]) -> (Vec<Complex<f64>>, Vec<f64>) {
        let n = self.D.len();
        let mut centre = vec![Complex::new(0.0, 0.0); n];
        let mut radius = vec![0.0f64; n];
        for i in 0..n {
            let mut r = 0.0f64;
            for j in 0..n {
                let d = self.D[i][j];
                if i == j {
                    centre[i] = Complex::new(d.re.mid(), d.im.mid());
                    let half = CI { re: d.re.sub(Ival::point(centre[i].re)), im: d.im.sub(Ival::point(centre[i].im)) };
                    r = add_up(r, add_up(half.abs_up(), self.extra[j]));
                } else {
                    let ratio = div_up(s[j], s[i]);
                    r = add_up(r, mul_up(add_up(d.abs_up(), self.extra[j]), ratio));
                }
            }
            radius[i] = r;
        }
        (centre, radius)
    }
}

/// The root of each disc's connected component (discs overlap unless provably apart).
fn components(centre: &[Complex<f64>], radius: &[f64]) -> Vec<usize> {
    let n = centre.len();
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
    (0..n).map(|i| find(&comp, i)).collect()
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
        let (r, est) = spectral_radius(&MonodromyEnclosure::entrywise(IMat::from_f64(&M).inflate(1e-12))).unwrap();
        let exact = 0.5f64 * 2f64.sqrt();
        assert!(r.contains(exact), "{r:?}");
        assert!(r.width() < 1e-10, "{r:?}");
        assert!((est - exact).abs() < 1e-14);
        let M2 = DMatrix::from_row_slice(2, 2, &[0.6, 0.0, 0.3, 0.1]);
        let (r2, _) = spectral_radius(&MonodromyEnclosure::entrywise(IMat::from_f64(&M2))).unwrap();
        assert!(r2.contains(0.6) && !r2.contains(exact));
        // a Jordan block has no basis of eigenvectors: refused, not a wrong answer
        let J = DMatrix::from_row_slice(2, 2, &[0.5, 1.0, 0.0, 0.5]);
        assert!(spectral_radius(&MonodromyEnclosure::entrywise(IMat::from_f64(&J)))
            .map(|(r, _)| r.contains(0.5))
            .unwrap_or(true));
    }
}
