//! `eta_T` in closed form for a periodic piecewise-affine input: a square wave (constant
//! pieces) or a periodic CSV input (the linear interpolation of its samples, or each sample
//! held until the next under `hold = "zoh"`; the last sample held until the period wraps).
//!
//! On a piece `[t_j, t_j + L_j)` with `w = u_j + s r_j` the linearised system
//! `xi' = F xi + B w` (eq. (xieta)) has the affine particular solution `alpha_j + s beta_j`,
//! `beta_j = -F^{-1} B r_j`, `alpha_j = F^{-1} (beta_j - B u_j)`, so
//! `xi(t_j + s) = alpha_j + s beta_j + e^{sF} d_j`, `d_j = xi(t_j) - alpha_j`, and
//! `eta_T'(t_j + s) = C beta_j + C F e^{sF} d_j`: no quadrature, one matrix exponential per
//! sample. The periodic `xi_T(t_0)` solves `(I - Phi) xi = c`, `Phi = e^{TF}` composed over the
//! pieces.
//!
//! Inside a piece `|eta_T''| = |C F^2 e^{sF} d_j| <= ||C F^2|| S |d_j|` with
//! `S >= sup_{[0, L_max]} ||e^{sF}||` (the largest Frobenius norm on the sample grid times
//! `e^{h ||F||_F}` for the grid step `h`): the Lipschitz constant of `eta_T'` between samples.
//! Where `w` jumps, `eta_T'` jumps by `C B (w+ - w-)`: both one-sided values are kept
//! ([`Jump`]) and every cell bound takes them in, so the Lipschitz argument never crosses a
//! jump. The samples carry a relative rounding margin `1e-12 + 16 n (cond F + cond(I - Phi) +
//! pieces) eps` plus the exponentials' own error bounds, as the sine's closed form does
//! (verified up to that margin).
use super::eta_orbit::EtaOrbit;
use dynamics::linear::expm::{expm_enclosure, frobenius_up};
use model::input::InputHold;
use model::{Input, System};
use nalgebra::{DMatrix, DVector};
use std::f64::consts::{PI, TAU};

/// One affine piece of the input over one period.
#[derive(Debug, Clone)]
pub(super) struct Piece {
    pub t0: f64,
    pub len: f64,
    /// `w(t0 + s) = u + s r`.
    pub u: DVector<f64>,
    pub r: DVector<f64>,
}

/// Where `eta_T'` jumps: inside sample interval `interval` (`(t_k, t_{k+1}]`), its values just
/// before and just after.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Jump {
    pub interval: usize,
    pub before: Vec<f64>,
    pub after: Vec<f64>,
}

/// The pieces of a square wave or a periodic CSV input over one period starting at `start`
/// (`None` for other inputs, or a CSV input without a period).
pub(super) fn pieces(input: &Input) -> Option<(f64, Vec<Piece>)> {
    let dv = |v: &[f64]| DVector::from_column_slice(v);
    match input {
        Input::Square { amplitudes, omega, phase } => {
            let T = TAU / omega;
            let th0 = phase.rem_euclid(TAU);
            let mut cuts = vec![0.0, ((PI - th0).rem_euclid(TAU)) / omega, ((TAU - th0).rem_euclid(TAU)) / omega, T];
            cuts.sort_by(f64::total_cmp);
            cuts.dedup_by(|a, b| (*a - *b).abs() <= 1e-15 * T);
            let m = amplitudes.len();
            let mut out = Vec::new();
            for w in cuts.windows(2) {
                if w[1] - w[0] <= 0.0 {
                    continue;
                }
                let mut val = vec![0.0; m];
                input.eval(0.5 * (w[0] + w[1]), &mut val);
                out.push(Piece { t0: w[0], len: w[1] - w[0], u: dv(&val), r: DVector::zeros(m) });
            }
            Some((0.0, out))
        }
        Input::Samples { t, w, period: Some(P), hold, .. } => {
            let start = t[0];
            let end = start + P;
            let m = w[0].len();
            let mut out = Vec::new();
            for k in 0..t.len() {
                let (a, b) = (t[k], if k + 1 < t.len() { t[k + 1].min(end) } else { end });
                if b <= a {
                    continue;
                }
                let r = if *hold == InputHold::Foh && k + 1 < t.len() && t[k + 1] <= end {
                    (dv(&w[k + 1]) - dv(&w[k])) / (t[k + 1] - t[k])
                } else {
                    DVector::zeros(m)
                };
                out.push(Piece { t0: a, len: b - a, u: dv(&w[k]), r });
            }
            Some((start, out))
        }
        _ => None,
    }
}

/// The orbit of `sys` under a piecewise-affine input with `K` sample intervals over the period
/// `T` (`None` when the input is not piecewise affine).
pub(super) fn orbit(sys: &System, T: f64, K: usize) -> Option<EtaOrbit> {
    let (start, pieces) = pieces(&sys.input)?;
    let n = sys.n();
    let F = sys.F();
    let sv = F.clone().svd(false, false).singular_values;
    let cond_F = sv.max() / sv.min().max(1e-300);
    let Finv = F.clone().try_inverse();
    let Some(Finv) = Finv else { return Some(unverified(sys, T, K, "F is singular")) };
    let Some(closed) = Closed::solve(sys, F, &Finv, pieces) else {
        return Some(unverified(sys, T, K, "I - e^{TF} is singular"));
    };
    let h = T / K as f64;
    let (t, eta, deta, exp_err) = closed.samples(start, T, K);
    let jumps = closed.jumps(T, K);
    let deta_lipschitz = closed.deta_lipschitz(h);
    let exp_err = closed.exp_err.max(exp_err);
    let margin =
        1e-12 + 16.0 * n as f64 * (cond_F + closed.cond_P + closed.pieces.len() as f64) * f64::EPSILON + 4.0 * exp_err;
    let finite = eta.iter().chain(&deta).all(|v| v.iter().all(|x| x.is_finite())) && deta_lipschitz.is_finite();
    let mut o = EtaOrbit::from_samples(T, t, eta, deta, deta_lipschitz, jumps);
    // a point orbit (osc 0) is refused by certify_samples itself
    let verified = finite && margin < 1e-3;
    o.certify_samples(margin, verified);
    o.method = "closed form per piece (piecewise-affine input: square wave or periodic CSV samples)";
    Some(o)
}

/// The periodic solution in closed form: per piece the particular solution
/// `alpha_j + s beta_j` and the state `xi(t_j)` at its start.
struct Closed<'s> {
    C: &'s DMatrix<f64>,
    F: DMatrix<f64>,
    CF: DMatrix<f64>,
    pieces: Vec<Piece>,
    alpha: Vec<DVector<f64>>,
    beta: Vec<DVector<f64>>,
    starts: Vec<DVector<f64>>,
    /// The step maps' largest relative error bound.
    exp_err: f64,
    /// Condition number of `I - Phi`.
    cond_P: f64,
}

impl<'s> Closed<'s> {
    /// Solves for the periodic start `(I - Phi) xi = c` over the pieces; `None` where `I - Phi`
    /// is singular.
    fn solve(sys: &'s System, F: DMatrix<f64>, Finv: &DMatrix<f64>, pieces: Vec<Piece>) -> Option<Self> {
        let n = sys.n();
        let B = &sys.B;
        // particular solutions and the composed step map
        let mut alpha = Vec::with_capacity(pieces.len());
        let mut beta = Vec::with_capacity(pieces.len());
        let mut exp_err = 0.0f64;
        let mut Phi = DMatrix::<f64>::identity(n, n);
        let mut c = DVector::<f64>::zeros(n);
        let mut steps = Vec::with_capacity(pieces.len());
        for p in &pieces {
            let b = -(Finv * (B * &p.r));
            let a = Finv * (&b - B * &p.u);
            let (E, e) = expm_enclosure(&(&F * p.len));
            exp_err = exp_err.max(e / frobenius_up(&E).max(1e-300));
            // xi_{j+1} = E xi_j + (a + L b - E a)
            c = &E * &c + (&a + &b * p.len - &E * &a);
            Phi = &E * &Phi;
            alpha.push(a);
            beta.push(b);
            steps.push(E);
        }
        let ImP = DMatrix::<f64>::identity(n, n) - &Phi;
        let svp = ImP.clone().svd(false, false).singular_values;
        let cond_P = svp.max() / svp.min().max(1e-300);
        let xi0 = ImP.lu().solve(&c)?;
        // the state at each piece start
        let mut starts = Vec::with_capacity(pieces.len());
        let mut xi = xi0;
        for (j, p) in pieces.iter().enumerate() {
            starts.push(xi.clone());
            xi = &alpha[j] + &beta[j] * p.len + &steps[j] * (&xi - &alpha[j]);
        }
        let C = &sys.C;
        let CF = C * &F;
        Some(Closed { C, F, CF, pieces, alpha, beta, starts, exp_err, cond_P })
    }

    /// `(eta_T, eta_T', relative error of e^{sF})` at `s` into piece `j`.
    fn eval(&self, j: usize, s: f64) -> (Vec<f64>, Vec<f64>, f64) {
        let (E, e) = expm_enclosure(&(&self.F * s));
        let d = &self.starts[j] - &self.alpha[j];
        let x = &self.alpha[j] + &self.beta[j] * s + &E * &d;
        let eta = self.C * &x;
        let deta = self.C * &self.beta[j] + &self.CF * (&E * &d);
        (eta.iter().copied().collect(), deta.iter().copied().collect(), e / frobenius_up(&E).max(1e-300))
    }

    /// Samples at `t_k = k T / K`, mapped into the window `[start, start + T)`: the times,
    /// `eta_T`, `eta_T'` and the largest relative error of the exponentials.
    #[allow(clippy::type_complexity)]
    fn samples(&self, start: f64, T: f64, K: usize) -> (Vec<f64>, Vec<Vec<f64>>, Vec<Vec<f64>>, f64) {
        let pieces = &self.pieces;
        let h = T / K as f64;
        let piece_of = |tau: f64| -> usize { pieces.partition_point(|p| p.t0 <= tau).saturating_sub(1) };
        let at = |tau_in: f64| -> (usize, f64) {
            let tau = start + (tau_in - start).rem_euclid(T);
            let j = piece_of(tau);
            (j, (tau - pieces[j].t0).clamp(0.0, pieces[j].len))
        };
        let (mut t, mut eta, mut deta) =
            (Vec::with_capacity(K + 1), Vec::with_capacity(K + 1), Vec::with_capacity(K + 1));
        let mut exp_err = 0.0f64;
        for k in 0..=K {
            let tk = k as f64 * h;
            let (j, s) = at(tk);
            let (e, d, er) = self.eval(j, s);
            exp_err = exp_err.max(er);
            t.push(tk);
            eta.push(e);
            deta.push(d);
        }
        (t, eta, deta, exp_err)
    }

    /// `eta_T'` jumps where `w` jumps (a square wave's edges, a CSV input's wrap): each edge at
    /// `t_e = t0 mod T` lies in the sample interval `(t_k, t_{k+1}]`, `k = ceil(t_e / h) - 1`.
    fn jumps(&self, T: f64, K: usize) -> Vec<Jump> {
        let pieces = &self.pieces;
        let h = T / K as f64;
        let mut jumps = Vec::new();
        for (j, p) in pieces.iter().enumerate() {
            let prev = &pieces[(j + pieces.len() - 1) % pieces.len()];
            if &prev.u + &prev.r * prev.len == p.u {
                continue;
            }
            let te = p.t0.rem_euclid(T);
            let k = if te <= 0.0 { K - 1 } else { ((te / h).ceil() as usize).saturating_sub(1).min(K - 1) };
            let (_, before, _) = self.eval((j + pieces.len() - 1) % pieces.len(), prev.len);
            let (_, after, _) = self.eval(j, 0.0);
            jumps.push(Jump { interval: k, before, after });
        }
        jumps
    }

    /// The Lipschitz constant of `eta_T'` inside a piece: `||C F^2|| S max_j |d_j|` with
    /// `S >= sup ||e^{sF}||` over the longest piece (grid norms at steps of at most `h` times
    /// `e^{h ||F||}`).
    fn deta_lipschitz(&self, h: f64) -> f64 {
        let F = &self.F;
        let CF2 = &self.CF * F;
        let lmax = self.pieces.iter().map(|p| p.len).fold(0.0, f64::max);
        let grid = (lmax / h).ceil().max(1.0) as usize;
        let hs = lmax / grid as f64;
        let mut S = 1.0f64;
        for i in 0..=grid {
            let (E, e) = expm_enclosure(&(F * (i as f64 * hs)));
            S = S.max(frobenius_up(&E) + e);
        }
        S *= (hs * frobenius_up(F)).exp() * (1.0 + 1e-12);
        let dmax = self.starts.iter().zip(&self.alpha).map(|(x, a)| (x - a).norm()).fold(0.0, f64::max);
        frobenius_up(&CF2) * S * dmax * (1.0 + 1e-12)
    }
}

fn unverified(sys: &System, T: f64, K: usize, why: &'static str) -> EtaOrbit {
    let mut o = EtaOrbit::from_samples(
        T,
        (0..=K).map(|k| k as f64 * T / K as f64).collect(),
        vec![vec![f64::NAN; sys.p()]; K + 1],
        vec![vec![f64::NAN; sys.p()]; K + 1],
        f64::INFINITY,
        vec![],
    );
    o.certify_samples(f64::INFINITY, false);
    o.method = why;
    o
}
