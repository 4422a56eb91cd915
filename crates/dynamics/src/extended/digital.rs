//! A digital controller in the loop (`model::controller`): the plant runs between the
//! controller's ticks with the command held (zero-order hold), integrated by the same exact
//! step maps and effects as every other run; at each tick the controller samples the measured
//! output `y = C x + offset`, updates its state and issues a command that drives the plant
//! `delay` ticks later.
//!
//! One sample interval `[t_k, t_{k+1})` of the recording is, as in [`super::simulate`],
//! `substeps` sub-steps (friction, play and forces stepped inside it), the plant input being
//! the held command; the ticks fall on every `ratio`-th sample (`period = ratio dt`, checked
//! when compiling). An `input_delay` effect shifts the held command's breakpoints
//! (`t_tick + delay`, the split sub-step of [`super::input`]); saturation and a play at the
//! input act on the held commands.
use super::model::ExtendedModel;
use super::simulate::SimOutput;
use super::step_maps::row_major;
use crate::error::DynamicsError;
use model::Controller;
use std::collections::VecDeque;

/// The compiled controller of an [`ExtendedModel`].
#[derive(Debug, Clone)]
pub struct DigitalLoop {
    pub(super) controller: Controller,
    /// Controller states.
    pub(super) nc: usize,
    /// Row-major `Ac (nc x nc)`, `Bc (nc x (m + p))`, `Cc (m x nc)`, `Dc (m x (m + p))`.
    pub(super) Ac: Vec<f64>,
    pub(super) Bc: Vec<f64>,
    pub(super) Cc: Vec<f64>,
    pub(super) Dc: Vec<f64>,
    /// Samples per tick (`period / dt`).
    pub(super) ratio: usize,
}

/// Largest relative distance of `period / dt` from an integer.
const RATIO_TOL: f64 = 1e-6;

impl DigitalLoop {
    /// Compiles `c` for samples `dt` apart: `period / dt` must be a positive integer.
    pub(super) fn new(c: &Controller, dt: f64) -> Result<Self, DynamicsError> {
        let r = c.period / dt;
        let ratio = r.round();
        if !(ratio >= 1.0 && (r - ratio).abs() <= RATIO_TOL * ratio) {
            return Err(DynamicsError::ControllerPeriod { period: c.period, dt });
        }
        let law = c.law();
        Ok(Self {
            controller: c.clone(),
            nc: law.Ac.nrows(),
            Ac: row_major(&law.Ac),
            Bc: row_major(&law.Bc),
            Cc: row_major(&law.Cc),
            Dc: row_major(&law.Dc),
            ratio: ratio as usize,
        })
    }

    /// One tick: `u = Cc x_c + Dc e`, `x_c <- Ac x_c + Bc e`.
    fn tick(&self, xc: &mut Vec<f64>, e: &[f64], u: &mut [f64]) {
        let (nc, ne) = (self.nc, e.len());
        for (i, ui) in u.iter_mut().enumerate() {
            *ui = (0..nc).map(|j| self.Cc[i * nc + j] * xc[j]).sum::<f64>()
                + (0..ne).map(|j| self.Dc[i * ne + j] * e[j]).sum::<f64>();
        }
        let next: Vec<f64> = (0..nc)
            .map(|i| {
                (0..nc).map(|j| self.Ac[i * nc + j] * xc[j]).sum::<f64>()
                    + (0..ne).map(|j| self.Bc[i * ne + j] * e[j]).sum::<f64>()
            })
            .collect();
        *xc = next;
    }
}

impl ExtendedModel {
    /// The closed digital loop driven by the reference `w` (flat, `k * m + j`): see the module
    /// documentation. The plant input before the first command arrives (computation delay)
    /// is 0.
    /// The dimensions are `N, M, P` (`super::simulate::with_dims`).
    pub(super) fn simulate_loop<const N: usize, const M: usize, const P: usize>(
        &self,
        dl: &DigitalLoop,
        w: &[f64],
        dt: f64,
        x0: &[f64],
        z0: Option<&[f64]>,
    ) -> SimOutput {
        let (n, m, p) = self.dims::<N, M, P>();
        let ns = w.len() / m;
        let mut out = SimOutput::zeros(ns, n, p);
        let mut st = self.start(x0, z0);
        if ns == 0 {
            return out;
        }
        let sub = self.substeps;
        let pieces = super::simulate::Pieces::new(self);
        let shift = self.input.delay / dt;
        let mut held = vec![0.0; ns * m];
        let mut queue: VecDeque<Vec<f64>> = (0..dl.controller.delay).map(|_| vec![0.0; m]).collect();
        let mut cmd = vec![0.0; m];
        let mut u = vec![0.0; m];
        let mut e = vec![0.0; m + p];
        let mut xc: Vec<f64> = Vec::new();
        let mut uplay: Option<Vec<f64>> = None;
        let dw = vec![0.0; m];
        for k in 0..ns {
            out.record(k, &st, &self.offset);
            if k % dl.ratio == 0 {
                e[..m].copy_from_slice(&w[k * m..(k + 1) * m]);
                for i in 0..p {
                    e[m + i] = st.y[i] + self.offset[i];
                }
                if k == 0 {
                    xc = dl.controller.start_state(&e);
                }
                dl.tick(&mut xc, &e, &mut u);
                queue.push_back(u.clone());
                cmd = queue.pop_front().expect("the queue holds the command just pushed");
            }
            // the plant input from sample k on: saturated, through the input play
            let up = uplay.get_or_insert_with(|| self.input.play_start(&cmd, m));
            for j in 0..m {
                held[k * m + j] = self.input.shaped(cmd[j], &mut up[j]);
            }
            if k + 1 == ns {
                break;
            }
            for s in 0..sub {
                let (parts, np) = pieces.of_substep(s, sub);
                for (pi, &(fa, fb, pc)) in parts[..np].iter().enumerate() {
                    let tau = k as f64 + 0.5 * (fa + fb) - shift;
                    let idx = if tau <= 0.0 { 0 } else { (tau.floor() as usize).min(k) };
                    self.step_plant::<N, M, P>(&mut st, pc, &held[idx * m..(idx + 1) * m], &dw);
                    let hit = self.step_play::<N, M, P>(&mut st, pc);
                    if s + 1 == sub && pi + 1 == np {
                        if let Some(hit) = hit {
                            out.contact[k + 1] = hit;
                        }
                    }
                }
            }
            if !st.x.iter().all(|v| v.is_finite()) || !xc.iter().all(|v| v.is_finite()) {
                out.diverged_after(k, ns, p);
                break;
            }
        }
        out.x_rms.iter_mut().for_each(|v| *v = (*v / ns as f64).sqrt());
        out
    }
}

/// The closed sampled loop's decay rate as a continuous-time spectral abscissa:
/// `mu = ln(rho) / period` with `rho` the spectral radius of the map over one period of the
/// linearised loop (plant `F = A + E C` held over the period, controller state, and the `d`
/// commands in flight of the computation delay), reference 0. `None` without a controller.
/// `mu < 0` iff the sampled loop is asymptotically stable (`-inf` for a deadbeat loop).
pub fn closed_loop_mu(sys: &model::System) -> Option<f64> {
    let c = sys.controller.as_ref()?;
    let (n, m, p) = (sys.n(), sys.m(), sys.p());
    let law = c.law();
    let nc = law.Ac.nrows();
    let d = c.delay;
    let T = c.period;
    let I = crate::linear::expm::exp_integrals(&sys.F(), T);
    let (Phi, Gam) = (I.phi, &I.gamma1 * &sys.B);
    // the law's response to the sampled output y = C x (the reference columns dropped)
    let Dy = law.Dc.columns(m, p) * &sys.C;
    let By = law.Bc.columns(m, p) * &sys.C;
    let N = n + nc + d * m;
    let mut M = nalgebra::DMatrix::<f64>::zeros(N, N);
    // u = Cc xc + Dy x: applied now (d = 0) or queued
    let (ox, oc, oq) = (0, n, n + nc);
    if d == 0 {
        M.view_mut((ox, ox), (n, n)).copy_from(&(&Phi + &Gam * &Dy));
        M.view_mut((ox, oc), (n, nc)).copy_from(&(&Gam * &law.Cc));
    } else {
        M.view_mut((ox, ox), (n, n)).copy_from(&Phi);
        M.view_mut((ox, oq), (n, m)).copy_from(&Gam);
        for i in 0..d - 1 {
            M.view_mut((oq + i * m, oq + (i + 1) * m), (m, m)).fill_with_identity();
        }
        let last = oq + (d - 1) * m;
        M.view_mut((last, ox), (m, n)).copy_from(&Dy);
        M.view_mut((last, oc), (m, nc)).copy_from(&law.Cc);
    }
    M.view_mut((oc, ox), (nc, n)).copy_from(&By);
    M.view_mut((oc, oc), (nc, nc)).copy_from(&law.Ac);
    let rho = M.complex_eigenvalues().iter().map(|z| z.norm()).fold(0.0, f64::max);
    Some(rho.ln() / T)
}
