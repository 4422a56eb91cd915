//! Seeded test systems `(F, E, C)` shared by tests, benches, examples and the
//! cross-check against CVXPY/SCS (`bench/peers/lmi/`).

use nalgebra::DMatrix;

/// A small deterministic generator (SplitMix64) so that the fixtures do not depend on
/// the version of `rand` and the Python side could regenerate them if needed.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in `[lo, hi)`.
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        let u = (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        lo + (hi - lo) * u
    }
}

/// The worked example of `NOTES.md`: `F = [[0,1],[-1,-0.6]]` (`mu = -0.3`),
/// `E = [0,1]^T`, `C = [1,0]`.
pub fn paper_example() -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) {
    (
        DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -1.0, -0.6]),
        DMatrix::from_row_slice(2, 1, &[0.0, 1.0]),
        DMatrix::from_row_slice(1, 2, &[1.0, 0.0]),
    )
}

/// Seeded random system: `F = M - (mu(M) + m) I` with `M` uniform in `[-1, 1]^{n x n}`
/// and margin `m` uniform in `[0.2, 1]` (so `mu(F) = -m` up to rounding), `E`, `C`
/// uniform in `[-1, 1]`.
pub fn random_hurwitz_system(seed: u64, n: usize, p: usize) -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) {
    let mut rng = SplitMix64(seed ^ 0x5EED_1A11);
    let M = DMatrix::from_fn(n, n, |_, _| rng.uniform(-1.0, 1.0));
    let margin = rng.uniform(0.2, 1.0);
    let E = DMatrix::from_fn(n, p, |_, _| rng.uniform(-1.0, 1.0));
    let C = DMatrix::from_fn(p, n, |_, _| rng.uniform(-1.0, 1.0));
    let mu = M.complex_eigenvalues().iter().map(|z| z.re).fold(f64::NEG_INFINITY, f64::max);
    let F = &M - DMatrix::<f64>::identity(n, n) * (mu + margin);
    (F, E, C)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn random_systems_are_hurwitz_and_seeded() {
        for seed in 0..20 {
            let (F, E, C) = random_hurwitz_system(seed, 1 + (seed as usize % 6), 1 + (seed as usize % 3));
            let mu = crate::spectral_abscissa(&F).unwrap();
            assert!((-1.0 - 1e-9..=-0.2 + 1e-9).contains(&mu), "seed {seed}: mu = {mu}");
            assert_eq!(E.nrows(), F.nrows());
            assert_eq!(C.ncols(), F.nrows());
        }
        assert_eq!(random_hurwitz_system(3, 4, 2), random_hurwitz_system(3, 4, 2));
        assert_ne!(random_hurwitz_system(3, 4, 2).0, random_hurwitz_system(4, 4, 2).0);
    }
}
