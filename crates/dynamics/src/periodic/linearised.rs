//! The `T`-periodic solution `xi_T` of the linearised system `xi' = F xi + B w` (eqs. (xieta),
//! (F)) and its output `eta_T = C xi_T` (eq. (etaT)), with time derivatives, on a grid over
//! `[0, T]`.
//!
//! Initial condition, eq. (xT) with its typo corrected (`e^{(T-s)F}`, not `e^{(T-t)F}`):
//! `xi_T(0) = (I - e^{TF})^{-1} int_0^T e^{(T-s)F} B w(s) ds`, then (eq. (xiT))
//! `xi_T(t) = e^{tF} xi_T(0) + int_0^t e^{(t-s)F} B w(s) ds`, and `xi_T' = F xi_T + B w`,
//! `eta_T' = C xi_T'`.
//!
//! Sine inputs are solved exactly through the exosystem `(s, c)' = omega (c, -s)`:
//! one matrix exponential of `[[F, B a, 0], [0, 0, omega], [0, -omega, 0]]`. Other periodic inputs
//! (square, sampled) use the exact first-order-hold step map on `substeps` sub-steps per grid
//! interval (exact for piecewise-linear `w` with breakpoints on the sub-grid).
use super::period_of;
use crate::error::DynamicsError;
use crate::linear::expm::expm;
use crate::linear::step_map::{InputHold, SystemStepMap};
use model::{Input, System};
use nalgebra::{Complex, DMatrix, DVector};
use serde::Serialize;

/// Settings of the grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearisedSettings {
    /// Grid intervals over one period (`samples + 1` points including both ends). Default `2000`.
    pub samples: usize,
    /// Sub-steps per grid interval for non-sine inputs. Default `16`.
    pub substeps: usize,
}

impl Default for LinearisedSettings {
    fn default() -> Self {
        Self { samples: 2000, substeps: 16 }
    }
}

/// Samples of `xi_T`, `xi_T'`, `eta_T`, `eta_T'` at `t_k = k T / samples`, `k = 0..=samples`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LinearisedPeriodic {
    pub period: f64,
    pub t: Vec<f64>,
    pub xi: Vec<Vec<f64>>,
    pub dxi: Vec<Vec<f64>>,
    pub eta: Vec<Vec<f64>>,
    pub deta: Vec<Vec<f64>>,
    /// True when the samples are exact up to rounding (sine or zero input).
    pub exact: bool,
}

impl LinearisedPeriodic {
    /// `xi_T(0)`.
    pub fn xi0(&self) -> &[f64] {
        &self.xi[0]
    }
    /// Largest distance between two sampled points of `eta_T`: a valid LOWER bound of
    /// `osc = diam eta_T([0, T])` (Thm 2) when the samples are exact.
    ///
    /// Same value, bit for bit, as the maximum of `geometry::linalg::dist` over all pairs
    /// ([`Self::osc_lower_pairwise`]), faster: `sqrt` and the rounded square sum are monotone,
    /// so the maximum of the distances is the root of the maximum of the square sums (summed in
    /// the same order); for `p = 1` the farthest pair is (max, min), `fl(a - b)` being monotone.
    /// Non-finite samples are ignored as there (`f64::max` drops a NaN).
    pub fn osc_lower(&self) -> f64 {
        let k = self.eta.len();
        let p = self.eta.first().map_or(0, Vec::len);
        if k < 2 || p == 0 {
            return 0.0;
        }
        if p == 1 {
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for e in &self.eta {
                lo = lo.min(e[0]);
                hi = hi.max(e[0]);
            }
            return if lo <= hi { 0.0f64.max(geometry::linalg::dist(&[hi], &[lo])) } else { 0.0 };
        }
        // structure of arrays, then the pairwise maximum of square sums, 4 accumulators
        let cols: Vec<Vec<f64>> = (0..p).map(|c| self.eta.iter().map(|e| e[c]).collect()).collect();
        let mut best = [0.0f64; 4];
        let mut d = vec![0.0f64; k];
        for i in 0..k - 1 {
            let m = k - i - 1;
            let v = cols[0][i];
            for (dj, w) in d[..m].iter_mut().zip(&cols[0][i + 1..]) {
                *dj = (v - w) * (v - w);
            }
            for col in &cols[1..] {
                let v = col[i];
                for (dj, w) in d[..m].iter_mut().zip(&col[i + 1..]) {
                    *dj += (v - w) * (v - w);
                }
            }
            let mut chunks = d[..m].chunks_exact(4);
            for c in &mut chunks {
                for l in 0..4 {
                    if c[l] > best[l] {
                        best[l] = c[l];
                    }
                }
            }
            for &s in chunks.remainder() {
                if s > best[0] {
                    best[0] = s;
                }
            }
        }
        best.iter().fold(0.0f64, |a, &b| a.max(b)).sqrt()
    }
    /// [`Self::osc_lower`] by the definition: the largest `geometry::linalg::dist` over all
    /// pairs of samples (for tests).
    pub fn osc_lower_pairwise(&self) -> f64 {
        let mut best = 0.0f64;
        for i in 0..self.eta.len() {
            for j in i + 1..self.eta.len() {
                best = best.max(geometry::linalg::dist(&self.eta[i], &self.eta[j]));
            }
        }
        best
    }
    /// Sampled maximum of `|eta_T'|`: an estimate (a lower bound) of `||eta_T'||_inf`, NOT an
    /// upper bound.
    pub fn deta_inf_sampled(&self) -> f64 {
        self.deta.iter().map(|d| geometry::linalg::norm(d)).fold(0.0, f64::max)
    }
}

fn cols(M: &DMatrix<f64>) -> Vec<Vec<f64>> {
    (0..M.ncols()).map(|j| M.column(j).iter().copied().collect()).collect()
}

/// `xi_T`, `eta_T` and derivatives of `sys` on a grid (the system's `Theta` is ignored).
pub fn linearised_periodic(sys: &System, settings: &LinearisedSettings) -> Result<LinearisedPeriodic, DynamicsError> {
    let T = period_of(sys)?;
    if settings.samples == 0 || settings.substeps == 0 {
        return Err(DynamicsError::BadSetting { name: "samples/substeps", value: 0.0, reason: "must be at least 1" });
    }
    let n = sys.n();
    let F = sys.F();
    let K = settings.samples;
    let dt = T / K as f64;
    let eTF = expm(&(&F * T));
    let I_minus = DMatrix::<f64>::identity(n, n) - &eTF;
    let sv = I_minus.clone().singular_values();
    let smin = sv.iter().copied().fold(f64::INFINITY, f64::min);
    if !(smin > 1e-12 * (1.0 + sv.max())) {
        return Err(DynamicsError::ResonantPeriod { sigma_min: smin });
    }
    let lu = I_minus.lu();
    let mut X = DMatrix::<f64>::zeros(n, K + 1);
    let exact;
    match &sys.input {
        Input::Sine { amplitudes, omega, phase } => {
            exact = true;
            let a = DVector::from_column_slice(amplitudes);
            let Ba = &sys.B * &a;
            let mut G = DMatrix::<f64>::zeros(n + 2, n + 2);
            G.view_mut((0, 0), (n, n)).copy_from(&F);
            G.view_mut((0, n), (n, 1)).copy_from(&Ba);
            G[(n, n + 1)] = *omega;
            G[(n + 1, n)] = -*omega;
            let eTG = expm(&(&G * T));
            let v0 = DVector::from_vec(vec![phase.sin(), phase.cos()]);
            let forced = eTG.view((0, n), (n, 2)) * &v0;
            let xi0 = lu.solve(&forced).ok_or(DynamicsError::ResonantPeriod { sigma_min: smin })?;
            let mut state = DVector::<f64>::zeros(n + 2);
            state.rows_mut(0, n).copy_from(&xi0);
            state.rows_mut(n, 2).copy_from(&v0);
            // exact propagation from t = 0 at every grid point (no accumulation of rounding)
            for k in 0..=K {
                let Xk = if k == 0 { state.clone() } else { expm(&(&G * (k as f64 * dt))) * &state };
                X.column_mut(k).copy_from(&Xk.rows(0, n));
            }
        }
        Input::Zero { .. } => {
            exact = true;
        }
        other => {
            exact = false;
            let sub = settings.substeps;
            let hs = dt / sub as f64;
            let map = SystemStepMap::new(&F, &sys.B, &sys.E, hs, InputHold::Foh)?;
            let m = other.m();
            let mut w0 = vec![0.0; m];
            let mut w1 = vec![0.0; m];
            let mut x = DVector::<f64>::zeros(n);
            let mut particular = vec![x.clone()];
            for k in 0..K {
                for j in 0..sub {
                    let t0 = k as f64 * dt + j as f64 * hs;
                    other.eval(t0, &mut w0);
                    other.eval(t0 + hs, &mut w1);
                    let (a, b) = (DVector::from_column_slice(&w0), DVector::from_column_slice(&w1));
                    x = &map.phi * &x + &map.g1B * &a + &map.g2B * (b - &a);
                }
                particular.push(x.clone());
            }
            let xi0 = lu.solve(&particular[K]).ok_or(DynamicsError::ResonantPeriod { sigma_min: smin })?;
            let ed = expm(&(&F * dt));
            let mut hom = xi0.clone();
            for k in 0..=K {
                if k > 0 {
                    hom = &ed * &hom;
                }
                X.column_mut(k).copy_from(&(&hom + &particular[k]));
            }
        }
    }
    let mut W = DMatrix::<f64>::zeros(sys.m(), K + 1);
    let mut wbuf = vec![0.0; sys.m()];
    let t: Vec<f64> = (0..=K).map(|k| k as f64 * dt).collect();
    for (k, &tk) in t.iter().enumerate() {
        sys.input.eval(tk, &mut wbuf);
        W.column_mut(k).copy_from_slice(&wbuf);
    }
    let dX = &F * &X + &sys.B * &W;
    let Y = &sys.C * &X;
    let dY = &sys.C * &dX;
    Ok(LinearisedPeriodic { period: T, t, xi: cols(&X), dxi: cols(&dX), eta: cols(&Y), deta: cols(&dY), exact })
}

/// The phasor of the `T`-periodic solution for a sine input `w = a sin(omega t + phase)`:
/// `g = (i omega I - F)^{-1} B a`, so `xi_T(t) = Im(g e^{i(omega t + phase)})`, with the
/// condition number of `i omega I - F` (for rounding margins). `None` when `i omega` is an
/// eigenvalue of `F` to working precision.
#[derive(Debug, Clone, PartialEq)]
pub struct SinePhasor {
    pub g: DVector<Complex<f64>>,
    /// `sigma_max / sigma_min` of `i omega I - F`.
    pub cond: f64,
}

/// See [`SinePhasor`]: the one place where `(i omega I - F)^{-1} B a` is solved (used by
/// [`sine_frequency_response`] and by the closed-form orbit of `bounds`).
pub fn sine_phasor(F: &DMatrix<f64>, B: &DMatrix<f64>, a: &[f64], omega: f64) -> Option<SinePhasor> {
    let n = F.nrows();
    let M: DMatrix<Complex<f64>> =
        DMatrix::from_fn(n, n, |i, j| Complex::new(-F[(i, j)], if i == j { omega } else { 0.0 }));
    let Ba = B * DVector::from_column_slice(a);
    let rhs: DVector<Complex<f64>> = Ba.map(|x| Complex::new(x, 0.0));
    let sv = M.clone().singular_values();
    let cond = sv.max() / sv.min().max(1e-300);
    let g = M.lu().solve(&rhs)?;
    Some(SinePhasor { g, cond })
}

/// Closed form for a sine input, for checks: `xi_T(t) = Im[(i omega I - F)^{-1} B a e^{i(omega t + phase)}]`.
pub fn sine_frequency_response(
    F: &DMatrix<f64>,
    B: &DMatrix<f64>,
    a: &[f64],
    omega: f64,
    phase: f64,
    t: f64,
) -> Option<DVector<f64>> {
    let ph = sine_phasor(F, B, a, omega)?;
    let e = Complex::new(0.0, omega * t + phase).exp();
    Some(ph.g.map(|c| (c * e).im))
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// The fast diameter equals the pairwise definition bit for bit (p = 1, 2, 3, ragged
    /// sample counts, a NaN sample ignored by both).
    #[test]
    fn osc_lower_equals_the_pairwise_maximum_bit_for_bit() {
        for p in 1..=3 {
            for k in [1, 2, 3, 7, 64, 201] {
                let u = |i: usize, c: usize| (((i * 7919 + c * 104729) as f64) * 0.6180339887).fract() * 2.0 - 1.0;
                let mut eta: Vec<Vec<f64>> =
                    (0..k).map(|i| (0..p).map(|c| u(i, c) * 10f64.powi(c as i32)).collect()).collect();
                let mut L = LinearisedPeriodic {
                    period: 1.0,
                    t: vec![0.0; k],
                    xi: eta.clone(),
                    dxi: eta.clone(),
                    eta: eta.clone(),
                    deta: eta.clone(),
                    exact: true,
                };
                assert_eq!(L.osc_lower().to_bits(), L.osc_lower_pairwise().to_bits(), "p {p}, k {k}");
                if k > 3 {
                    eta[2][0] = f64::NAN;
                    L.eta = eta;
                    assert_eq!(L.osc_lower().to_bits(), L.osc_lower_pairwise().to_bits(), "NaN, p {p}, k {k}");
                }
            }
        }
    }

    fn worked() -> System {
        model::parse_str(include_str!("../../../../examples/worked-example.toml")).unwrap()
    }

    #[test]
    fn sine_solution_matches_the_frequency_response_and_is_periodic() {
        let sys = worked();
        let L = linearised_periodic(&sys, &LinearisedSettings { samples: 200, substeps: 16 }).unwrap();
        let F = sys.F();
        for k in [0, 37, 100, 200] {
            let xf = sine_frequency_response(&F, &sys.B, &[1.0], 1.0, 0.0, L.t[k]).unwrap();
            assert_relative_eq!(L.xi[k][0], xf[0], epsilon = 1e-12);
            assert_relative_eq!(L.xi[k][1], xf[1], epsilon = 1e-12);
            // derivative of the closed form by central differences
            let e = 1e-6;
            let d = (sine_frequency_response(&F, &sys.B, &[1.0], 1.0, 0.0, L.t[k] + e).unwrap()
                - sine_frequency_response(&F, &sys.B, &[1.0], 1.0, 0.0, L.t[k] - e).unwrap())
                / (2.0 * e);
            assert_relative_eq!(L.dxi[k][0], d[0], epsilon = 1e-8);
            assert_relative_eq!(L.deta[k][0], d[0], epsilon = 1e-8);
        }
        assert_relative_eq!(L.xi[0][0], L.xi[200][0], epsilon = 1e-12);
        // |G(i)| for x'' + 0.6 x' + x = sin t: amplitude 1/0.6, so osc = 2/0.6
        assert_relative_eq!(L.osc_lower(), 2.0 / 0.6, max_relative = 1e-3);
        assert!(L.osc_lower() <= 2.0 / 0.6 + 1e-12, "sampled diameter is a lower bound");
        assert_eq!(L.osc_lower().to_bits(), L.osc_lower_pairwise().to_bits());
    }

    #[test]
    fn typo_in_xT_matters_the_uncorrected_formula_is_not_periodic() {
        // (xT) as printed integrates e^{(T-t)F} B w(s) with t = 0 fixed: e^{TF} int B w(s) ds,
        // which for a zero-mean sine is ~0, so xi(0) would be 0: not the periodic state.
        let sys = worked();
        let L = linearised_periodic(&sys, &LinearisedSettings::default()).unwrap();
        assert!(geometry::linalg::norm(L.xi0()) > 0.5);
    }

    #[test]
    fn square_wave_uses_sub_steps_and_is_periodic() {
        let mut sys = worked();
        sys.input = Input::Square { amplitudes: vec![1.0], omega: 1.0, phase: 0.0 };
        let L = linearised_periodic(&sys, &LinearisedSettings { samples: 400, substeps: 16 }).unwrap();
        assert!(!L.exact);
        // simulate the linearised system for 40 periods from 0 with the same map: converges to xi_T
        let F = sys.F();
        let T = L.period;
        let hs = T / (400.0 * 16.0);
        let map = SystemStepMap::new(&F, &sys.B, &sys.E, hs, InputHold::Foh).unwrap();
        let mut x = DVector::<f64>::zeros(2);
        for k in 0..(400 * 16 * 40) {
            let t0 = k as f64 * hs;
            let (a, b) = (sys.input.at(t0)[0], sys.input.at(t0 + hs)[0]);
            x = &map.phi * &x + &map.g1B * a + &map.g2B * (b - a);
        }
        assert_relative_eq!(x[0], L.xi[0][0], epsilon = 1e-6);
        assert_relative_eq!(x[1], L.xi[0][1], epsilon = 1e-6);
    }
}
