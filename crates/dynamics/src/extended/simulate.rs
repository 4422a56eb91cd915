//! The fixed-step free-run simulator of an [`ExtendedModel`], and the runs built on it: a
//! recorded trajectory of a model file ([`simulate_trajectory`]) and the regime reached under a
//! periodic input ([`regime_by_simulation`]).
//!
//! One sample interval is `substeps` sub-steps (one of them split in two at a delayed input's
//! breakpoint, see [`super::input`]); each sub-step is, in order:
//! 1. the input over the sub-step by the model's hold (`InputDrive::advance`);
//! 2. the exact linear step `x+ = Phi x + Psi B w0 + Psi1 B dw + Psi E q (+ Psi1 E dq, a
//!    free play's predicted change of q) (+ Psi b)`, then the cogging and friction forces
//!    ([`super::forces`]) (`ExtendedModel::step_plant`);
//! 3. the play: the backlash output coasts (with inertia) and is projected back into
//!    `y + Theta` (`ExtendedModel::step_play`).
use super::input::InputPath;
use super::model::ExtendedModel;
use super::step_maps::StepMaps;
use crate::error::{check_dt, DynamicsError};
use crate::linear::hold::InputHold;
use crate::periodic::steps_per_period;
use crate::record::Trajectory;
use model::System;

/// `$model.$run::<N, M, P>(args)` with the model's state, input and output counts as
/// constants for the shapes the generator's plants take (2 to 4 states, one input, one
/// output), so that the inner products of every sub-step unroll; `<0, 0, 0>` reads the counts
/// at run time (every other shape). Either way the sums run in the same order: the results
/// are the same to the bit (test `specialised_and_general_runs_agree_to_the_bit`).
macro_rules! with_dims {
    ($model:ident . $run:ident ( $($arg:expr),* $(,)? )) => {
        match ($model.n, $model.m, $model.p) {
            (2, 1, 1) => $model.$run::<2, 1, 1>($($arg),*),
            (3, 1, 1) => $model.$run::<3, 1, 1>($($arg),*),
            (4, 1, 1) => $model.$run::<4, 1, 1>($($arg),*),
            _ => $model.$run::<0, 0, 0>($($arg),*),
        }
    };
}
pub(super) use with_dims;

/// Result of a simulation on the sample grid.
#[derive(Debug, Clone)]
pub struct SimOutput {
    /// `y_meas[k]` flat, `k * p + i`.
    pub y: Vec<f64>,
    /// Whether the play is in contact (`q` on the boundary of Theta) at sample `k`.
    pub contact: Vec<bool>,
    /// The backlash output `z[k]` flat, `k * p + i` (equal to `C x` without a play).
    pub z: Vec<f64>,
    /// Whether the state was finite throughout.
    pub finite: bool,
    /// Root mean square of each state over the run (scales for fitting).
    pub x_rms: Vec<f64>,
    /// The state `x[k]` flat, `k * n + i`.
    pub x: Vec<f64>,
}

impl SimOutput {
    pub(super) fn zeros(ns: usize, n: usize, p: usize) -> Self {
        SimOutput {
            y: vec![0.0; ns * p],
            contact: vec![false; ns],
            z: vec![0.0; ns * p],
            finite: true,
            x_rms: vec![0.0; n],
            x: vec![0.0; ns * n],
        }
    }

    /// Records sample `k` (`y_meas = y + offset`) and accumulates the squares of `x`.
    #[inline]
    pub(super) fn record(&mut self, k: usize, st: &RunState, offset: &[f64]) {
        let (n, p) = (st.x.len(), st.y.len());
        for i in 0..p {
            self.y[k * p + i] = st.y[i] + offset[i];
            self.z[k * p + i] = st.z[i];
        }
        for i in 0..n {
            self.x_rms[i] += st.x[i] * st.x[i];
            self.x[k * n + i] = st.x[i];
        }
    }

    /// The state left the finite numbers after sample `k`: every later output is `NaN`.
    pub(super) fn diverged_after(&mut self, k: usize, ns: usize, p: usize) {
        self.finite = false;
        for kk in k + 1..ns {
            for i in 0..p {
                self.y[kk * p + i] = f64::NAN;
            }
        }
    }
}

/// Per-step constants of one step length.
pub(super) struct Piece<'a> {
    maps: &'a StepMaps,
    /// `Psi b` (constant force).
    fb: Vec<f64>,
    decay: f64,
    coast: f64,
}

impl<'a> Piece<'a> {
    fn new(maps: &'a StepMaps, force: &[f64], inertia_tau: f64) -> Self {
        let n = maps.n;
        let h = maps.h;
        let decay = if inertia_tau > 0.0 && inertia_tau.is_finite() { (-h / inertia_tau).exp() } else { 1.0 };
        let coast = if inertia_tau > 0.0 {
            if inertia_tau.is_finite() {
                inertia_tau * (1.0 - decay)
            } else {
                h
            }
        } else {
            0.0
        };
        let fb = (0..n).map(|i| (0..n).map(|j| maps.Psi[i * n + j] * force[j]).sum()).collect();
        Self { maps, fb, decay, coast }
    }
}

/// The pieces of one run: the regular sub-step and, with an input delay, the split sub-step's
/// two parts (`(substep, at, first, second)`), and each sub-step's pieces as fractions of the
/// sample interval, computed once per run.
pub(super) struct Pieces<'a> {
    main: Piece<'a>,
    split: Option<(usize, f64, Piece<'a>, Piece<'a>)>,
    /// Per sub-step: its pieces `(fa, fb, which)` (`which`: 0 the regular piece, 1 and 2 the
    /// split's parts) and their count.
    table: Vec<SubstepPieces>,
}

/// The pieces `(fa, fb, which)` of one sub-step and their count (see [`Pieces`]).
type SubstepPieces = ([(f64, f64, u8); 2], usize);

impl<'a> Pieces<'a> {
    pub(super) fn new(model: &'a ExtendedModel) -> Self {
        let (force, tau) = (&model.forces.force, model.inertia_tau);
        let main = Piece::new(&model.maps, force, tau);
        let split = model
            .split
            .as_ref()
            .map(|sp| (sp.substep, sp.at, Piece::new(&sp.first, force, tau), Piece::new(&sp.second, force, tau)));
        let sub = model.substeps;
        let table = (0..sub)
            .map(|s| {
                let f0 = s as f64 / sub as f64;
                let f1 = (s + 1) as f64 / sub as f64;
                match &split {
                    Some((ss, at, _, _)) if *ss == s => {
                        let fm = f0 + at / sub as f64;
                        ([(f0, fm, 1), (fm, f1, 2)], 2)
                    }
                    _ => ([(f0, f1, 0), (f1, f1, 0)], 1),
                }
            })
            .collect();
        Self { main, split, table }
    }

    /// Sub-step `s` of `sub` as one or two pieces `(fa, fb, piece)` (fractions of the sample
    /// interval); the count is the second value.
    #[inline]
    pub(super) fn of_substep(&self, s: usize, sub: usize) -> ([(f64, f64, &Piece<'a>); 2], usize) {
        debug_assert_eq!(sub, self.table.len());
        let (parts, np) = &self.table[s];
        let piece = |w: u8| match (&self.split, w) {
            (Some((_, _, a, _)), 1) => a,
            (Some((_, _, _, b)), 2) => b,
            _ => &self.main,
        };
        let [(a0, b0, w0), (a1, b1, w1)] = *parts;
        ([(a0, b0, piece(w0)), (a1, b1, piece(w1))], *np)
    }
}

/// The running state of one simulation.
pub(super) struct RunState {
    pub(super) x: Vec<f64>,
    /// The next state (a linear step's end, then the forces).
    xn: Vec<f64>,
    /// The play's deviation `q = z - y`.
    q: Vec<f64>,
    pub(super) z: Vec<f64>,
    pub(super) y: Vec<f64>,
    /// Coasting velocity of the backlash output (`backlash_inertia`).
    pub(super) v: Vec<f64>,
    /// With a play: `y` at the start of the current step and of the step before,
    /// and the length of the step before (0 before the first), for the output's velocity
    /// ([`ExtendedModel::output_velocity`]).
    pub(super) y_start: Vec<f64>,
    pub(super) y_before: Vec<f64>,
    h_before: f64,
    h_last: f64,
    /// With a play: whether it was projected (in contact) at the last step's end, and the
    /// change of `q` predicted over the current step (free: `z` coasts or stays).
    pub(super) touching: Vec<bool>,
    dq: Vec<f64>,
    scratch: Vec<f64>,
    /// `q` before the projection.
    qp: Vec<f64>,
}

/// The input over each piece of a step: the start value `w0` and the increment `dw` (zero
/// under a zero-order hold).
pub(super) struct InputDrive<'w> {
    w: &'w [f64],
    m: usize,
    ns: usize,
    /// The delay in samples.
    shift: f64,
    /// Zero-order hold: the saturated, played samples (empty under a first-order hold).
    held: Vec<f64>,
    /// First-order hold: input play state, input at the piece's start and end.
    uplay: Vec<f64>,
    ucur: Vec<f64>,
    unext: Vec<f64>,
    w0: Vec<f64>,
    dw: Vec<f64>,
}

impl<'w> InputDrive<'w> {
    pub(super) fn new(input: &InputPath, w: &'w [f64], dt: f64, m: usize, ns: usize) -> Self {
        let shift = input.delay / dt;
        // Zero-order hold: saturation and input play act on the held samples exactly.
        let held = match input.hold {
            InputHold::Zoh => input.held_samples(w, m, ns),
            InputHold::Foh => Vec::new(),
        };
        let mut uplay = input.play_start(w, m);
        let mut ucur = vec![0.0; m];
        input.foh_at(w, m, ns, -shift, &mut uplay, &mut ucur);
        Self { w, m, ns, shift, held, uplay, ucur, unext: vec![0.0; m], w0: vec![0.0; m], dw: vec![0.0; m] }
    }

    /// Sets `w0`, `dw` for the piece `[fa, fb]` of sample interval `k`.
    #[inline(always)]
    fn advance(&mut self, input: &InputPath, k: usize, fa: f64, fb: f64) {
        let (m, ns) = (self.m, self.ns);
        match input.hold {
            InputHold::Zoh => {
                let tau = k as f64 + 0.5 * (fa + fb) - self.shift;
                // `tau > 0`: truncation is the floor (and no call into libm).
                let idx = if tau <= 0.0 { 0 } else { (tau as usize).min(ns - 1) };
                // (`dw` stays zero under this hold; a loop, not a `memcpy` call, for the few inputs)
                for (a, b) in self.w0.iter_mut().zip(&self.held[idx * m..(idx + 1) * m]) {
                    *a = *b;
                }
            }
            InputHold::Foh => {
                input.foh_at(self.w, m, ns, k as f64 + fb - self.shift, &mut self.uplay, &mut self.unext);
                for j in 0..m {
                    self.w0[j] = self.ucur[j];
                    self.dw[j] = self.unext[j] - self.ucur[j];
                }
                // `unext` is overwritten whole by the next `foh_at`.
                std::mem::swap(&mut self.ucur, &mut self.unext);
            }
        }
    }
}

impl ExtendedModel {
    /// Free-run simulation from `x0` (with `q0 = 0`, i.e. `z0 = C x0`) driven by the measured
    /// input `w` (flat, `k * m + j`, sample spacing `dt`, the spacing the model was compiled
    /// for). Returns `y_meas` on the sample grid.
    pub fn simulate(&self, w: &[f64], dt: f64, x0: &[f64]) -> SimOutput {
        self.simulate_from(w, dt, x0, None)
    }

    /// As [`ExtendedModel::simulate`] from `(x0, z0)`; `z0 = None` starts at rest in the play
    /// (`z0 = C x0`). `z0 - C x0` is taken as it is (it should lie in the play's set).
    ///
    /// Between samples the input follows the model's [`InputHold`]: linear interpolation of
    /// the samples (first-order hold, the default) or the sample held until the next one
    /// (zero-order hold). Either is integrated exactly by the linear step maps: an input delay
    /// moves the input's breakpoints to `t_k + delay`, and the sub-step that contains one is
    /// split there (two extra step maps, computed once per model). Saturation and a play at
    /// the input act on the held samples exactly (ZOH) or on the sub-step knots (FOH).
    ///
    /// With a `[controller]`, `w` is its reference and the loop is closed by the sampled
    /// controller ([`super::digital`]).
    pub fn simulate_from(&self, w: &[f64], dt: f64, x0: &[f64], z0: Option<&[f64]>) -> SimOutput {
        match &self.digital {
            Some(dl) => with_dims!(self.simulate_loop(dl, w, dt, x0, z0)),
            None => with_dims!(self.free_run(w, dt, x0, z0)),
        }
    }

    /// `(n, m, p)`: the constants `(N, M, P)` of a specialised run ([`with_dims`]), the
    /// model's own where they are 0.
    #[inline(always)]
    pub(super) fn dims<const N: usize, const M: usize, const P: usize>(&self) -> (usize, usize, usize) {
        if N == 0 {
            (self.n, self.m, self.p)
        } else {
            debug_assert_eq!((N, M, P), (self.n, self.m, self.p));
            (N, M, P)
        }
    }

    /// [`ExtendedModel::simulate_from`] without a controller, with the dimensions `N, M, P`
    /// ([`with_dims`]).
    fn free_run<const N: usize, const M: usize, const P: usize>(
        &self,
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
        self.run_samples::<N, M, P>(w, dt, &mut st, &mut out, |_, _| true);
        out.x_rms.iter_mut().for_each(|v| *v = (*v / ns as f64).sqrt());
        out
    }

    /// The free run from `st` over the samples of `w`: records each sample in `out` and steps
    /// to the next, until the last, a state that leaves the finite numbers (the rest of `out`
    /// `NaN`), or `go_on(k + 1, &st)` returning `false` after the step to sample `k + 1`.
    #[inline(always)]
    pub(super) fn run_samples<const N: usize, const M: usize, const P: usize>(
        &self,
        w: &[f64],
        dt: f64,
        st: &mut RunState,
        out: &mut SimOutput,
        mut go_on: impl FnMut(usize, &RunState) -> bool,
    ) {
        let (_, m, p) = self.dims::<N, M, P>();
        let ns = w.len() / m;
        let pieces = Pieces::new(self);
        let mut drive = InputDrive::new(&self.input, w, dt, m, ns);
        for k in 0..ns {
            out.record(k, st, &self.offset);
            if k + 1 == ns {
                break;
            }
            if let Some(hit) = self.step_sample::<N, M, P>(st, &mut drive, &pieces, k) {
                out.contact[k + 1] = hit;
            }
            if !st.x.iter().all(|v| v.is_finite()) {
                out.diverged_after(k, ns, p);
                break;
            }
            if !go_on(k + 1, st) {
                break;
            }
        }
    }

    /// Sample interval `k` (every sub-step and its pieces): from sample `k` to `k + 1`.
    /// Whether the play is in contact at its end (`None` without a play).
    #[inline(always)]
    pub(super) fn step_sample<const N: usize, const M: usize, const P: usize>(
        &self,
        st: &mut RunState,
        drive: &mut InputDrive,
        pieces: &Pieces,
        k: usize,
    ) -> Option<bool> {
        let sub = self.substeps;
        let mut last = None;
        for s in 0..sub {
            let (parts, np) = pieces.of_substep(s, sub);
            for (pi, &(fa, fb, pc)) in parts[..np].iter().enumerate() {
                drive.advance(&self.input, k, fa, fb);
                self.step_plant::<N, M, P>(st, pc, &drive.w0, &drive.dw);
                let hit = self.step_play::<N, M, P>(st, pc);
                if s + 1 == sub && pi + 1 == np {
                    last = hit;
                }
            }
        }
        last
    }

    /// `y = C x`.
    #[inline(always)]
    fn output<const N: usize, const M: usize, const P: usize>(&self, x: &[f64], y: &mut [f64]) {
        let (n, _, p) = self.dims::<N, M, P>();
        let x = &x[..n];
        for (i, yi) in y[..p].iter_mut().enumerate() {
            *yi = self.C[i * n..][..n].iter().zip(x).map(|(a, b)| a * b).sum();
        }
    }

    /// The state at `t = 0`: `x0`, `y = C x0`, `z = z0` (with a play) or `y`.
    pub(super) fn start(&self, x0: &[f64], z0: Option<&[f64]>) -> RunState {
        let (n, p) = (self.n, self.p);
        let mut st = RunState {
            x: x0.to_vec(),
            xn: vec![0.0; n],
            q: vec![0.0; p],
            z: vec![0.0; p],
            y: vec![0.0; p],
            v: vec![0.0; p],
            scratch: vec![0.0; p],
            qp: vec![0.0; p],
            y_start: vec![0.0; p],
            y_before: vec![0.0; p],
            h_before: 0.0,
            h_last: 0.0,
            touching: vec![true; p],
            dq: vec![0.0; p],
        };
        self.output::<0, 0, 0>(&st.x, &mut st.y);
        st.z.copy_from_slice(&st.y);
        if let (Some(z0), true) = (z0, self.has_play()) {
            st.z.copy_from_slice(z0);
            for i in 0..p {
                st.q[i] = st.z[i] - st.y[i];
            }
        }
        st
    }

    /// The plant over one piece: the exact linear step with `q` and the forces held, then the
    /// cogging and friction forces; `x` advances and `y = C x`.
    ///
    /// The sums run in the order of the formula (`Phi x`, then `Psi B w0 + Psi1 B dw` per
    /// input, then `Psi E q`, then `Psi b`); the slices are cut to their lengths once so that
    /// the inner loops carry no bounds checks (the hot loop of every fit).
    #[inline(always)]
    pub(super) fn step_plant<const N: usize, const M: usize, const P: usize>(
        &self,
        st: &mut RunState,
        pc: &Piece,
        w0: &[f64],
        dw: &[f64],
    ) {
        let (n, m, p) = self.dims::<N, M, P>();
        let mp = pc.maps;
        let free = self.has_play() && self.predict_free_play::<N, M, P>(st, pc);
        let (x, xn, q, z, dq) = (&st.x[..n], &mut st.xn[..n], &st.q[..p], &st.z[..p], &st.dq[..p]);
        let (w0, dw) = (&w0[..m], &dw[..m]);
        for (i, xn_i) in xn.iter_mut().enumerate() {
            let (phi, pb, p1, pe) =
                (&mp.Phi[i * n..][..n], &mp.PsiB[i * m..][..m], &mp.Psi1B[i * m..][..m], &mp.PsiE[i * p..][..p]);
            let mut acc = 0.0;
            for (a, b) in phi.iter().zip(x) {
                acc += a * b;
            }
            for ((a, b), (c, d)) in pb.iter().zip(w0).zip(p1.iter().zip(dw)) {
                acc += a * b + c * d;
            }
            for (a, b) in pe.iter().zip(q) {
                acc += a * b;
            }
            if free {
                for (a, b) in mp.Psi1E[i * p..][..p].iter().zip(dq) {
                    acc += a * b;
                }
            }
            if self.forces.has_force {
                acc += pc.fb[i];
            }
            *xn_i = acc;
        }
        self.forces.apply(x, xn, &mp.Psi, w0, z);
        std::mem::swap(&mut st.x, &mut st.xn);
        if self.has_play() {
            std::mem::swap(&mut st.y_before, &mut st.y_start);
            st.y_start.copy_from_slice(&st.y);
            st.h_before = st.h_last;
            st.h_last = mp.h;
        }
        self.output::<N, M, P>(&st.x, &mut st.y);
    }

    /// With a play: the change of `q = z - y` over the coming step `pc` where the play is not
    /// in contact (`z` coasts by `v coast`, 0 for a massless output; `y` moves by its velocity
    /// times `h`), so that the plant sees `q` change linearly over the step (`Psi1 E dq`)
    /// instead of held (second order in the step where the play is free); 0 in contact and on
    /// the first step. Whether any output is free.
    #[inline(always)]
    fn predict_free_play<const N: usize, const M: usize, const P: usize>(&self, st: &mut RunState, pc: &Piece) -> bool {
        let (_, _, p) = self.dims::<N, M, P>();
        let mut any = false;
        for i in 0..p {
            st.dq[i] = if st.touching[i] || st.h_last == 0.0 {
                0.0
            } else {
                any = true;
                st.v[i] * pc.coast - Self::output_velocity(st, i) * pc.maps.h
            };
        }
        any
    }

    /// The output's velocity at the end of the step just taken, by the second-order backward
    /// difference over the last two steps (first order after the first step): the velocity a
    /// massive backlash output takes on in an inelastic contact, and the rate at which `q`
    /// changes where the play is free.
    #[inline(always)]
    fn output_velocity(st: &RunState, i: usize) -> f64 {
        let d2 = (st.y[i] - st.y_start[i]) / st.h_last;
        if st.h_before > 0.0 {
            let d1 = (st.y_start[i] - st.y_before[i]) / st.h_before;
            d2 + st.h_last / (st.h_before + st.h_last) * (d2 - d1)
        } else {
            d2
        }
    }

    /// The play over one piece: `z` coasts (with inertia), `q` is projected into `Theta` and
    /// `z = y + q`. Returns whether the play is in contact (`None` without a play: `z = y`).
    #[inline(always)]
    pub(super) fn step_play<const N: usize, const M: usize, const P: usize>(
        &self,
        st: &mut RunState,
        pc: &Piece,
    ) -> Option<bool> {
        let (_, _, p) = self.dims::<N, M, P>();
        if !self.has_play() {
            st.z[..p].copy_from_slice(&st.y[..p]);
            return None;
        }
        // z_pred: massless output stays; with inertia it coasts.
        // `qp`: the deviation before projection: the contact is decided on `q` itself
        // (comparing `y + q` with `z_pred` would see rounding of `y + (z - y)` as
        // a contact and slow the coasting decay spuriously).
        for i in 0..p {
            st.scratch[i] = st.z[i] + st.v[i] * pc.coast;
            st.q[i] = st.scratch[i] - st.y[i];
            st.qp[i] = st.q[i];
        }
        let hit = self.play.project_q(&mut st.q, &mut st.scratch);
        for i in 0..p {
            let znew = st.y[i] + st.q[i];
            st.touching[i] = st.q[i] != st.qp[i];
            if self.inertia_tau > 0.0 {
                st.v[i] = if st.q[i] == st.qp[i] {
                    st.v[i] * pc.decay
                } else if p == 1 {
                    // In contact at the step's end: dragged along with `y` (one dimension: `q`
                    // rests on the boundary).
                    Self::output_velocity(st, i)
                } else {
                    (znew - st.z[i]) / pc.maps.h
                };
            }
            st.z[i] = znew;
        }
        Some(hit)
    }
}

/// Simulates `sys` with its own `[[effects]]` from `(sys.x0, sys.z0)` for `steps` steps of `h`
/// (the input sampled at `k h` and interpolated linearly in between, as the catching-up
/// scheme does), recording every `record_every`-th sample and the last. The trajectory's `y`
/// includes the sensor offset. Without effects this is the catching-up scheme of eq. (zdot)
/// (a test checks the two agree).
pub fn simulate_trajectory(
    sys: &System,
    h: f64,
    steps: usize,
    record_every: usize,
) -> Result<Trajectory, DynamicsError> {
    check_dt(h)?;
    let (n, m, p) = (sys.n(), sys.m(), sys.p());
    let ns = steps + 1;
    let mut w = vec![0.0; ns * m];
    for k in 0..ns {
        sys.input.eval(k as f64 * h, &mut w[k * m..(k + 1) * m]);
    }
    let ext = ExtendedModel::new(sys, &[], h, 1)?;
    let out = ext.simulate_from(&w, h, sys.x0.as_slice(), Some(sys.z0.as_slice()));
    if !out.finite {
        let k = (0..ns).find(|&k| !out.x[k * n..(k + 1) * n].iter().all(|v| v.is_finite())).unwrap_or(steps);
        return Err(DynamicsError::NonFinite { t: k as f64 * h });
    }
    let every = record_every.max(1);
    let mut tr = Trajectory::new(n, m, p);
    tr.y_offset = ext.sensor_offset().to_vec();
    for k in (0..ns).filter(|&k| k % every == 0 || k == steps) {
        tr.push(k as f64 * h, &w[k * m..(k + 1) * m], &out.x[k * n..(k + 1) * n], &out.z[k * p..(k + 1) * p]);
    }
    Ok(tr)
}

/// The regime reached by simulating a model with `[[effects]]` under a `T`-periodic input (the
/// paper's uniqueness argument does not cover effects, so no fixed point is claimed: the
/// residuals say whether successive periods still differ).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[non_exhaustive]
pub struct SimulatedRegime {
    pub period: f64,
    pub h: f64,
    pub steps_per_period: usize,
    pub periods: usize,
    /// State at the start of the last simulated period.
    pub x0: Vec<f64>,
    pub z0: Vec<f64>,
    /// `max |(x, z)(kT) - (x, z)((k-1)T)|_inf` for `k = 1..=periods`.
    pub residuals: Vec<f64>,
    /// Path length of `z` over the last period.
    pub path_length_last_period: f64,
    /// `max |z'|` over the last period (difference quotients).
    pub max_z_speed_last_period: f64,
}

/// Simulates `periods` periods of `sys` (with its effects) at a step close to `dt` dividing
/// the period; see [`SimulatedRegime`].
pub fn regime_by_simulation(sys: &System, dt: f64, periods: usize) -> Result<SimulatedRegime, DynamicsError> {
    let T = sys.period().ok_or(DynamicsError::NotPeriodic { kind: sys.input.kind() })?;
    if periods == 0 {
        return Err(DynamicsError::ZeroPeriods { periods });
    }
    let (spp, h) = steps_per_period(T, dt)?;
    let tr = simulate_trajectory(sys, h, spp * periods, 1)?;
    let state = |k: usize| -> Vec<f64> { tr.x_at(k).iter().chain(tr.z_at(k)).copied().collect() };
    let residuals = (1..=periods)
        .map(|k| {
            let (a, b) = (state(k * spp), state((k - 1) * spp));
            a.iter().zip(&b).map(|(u, v)| (u - v).abs()).fold(0.0, f64::max)
        })
        .collect();
    let start = (periods - 1) * spp;
    let (mut path, mut speed) = (0.0f64, 0.0f64);
    for k in start..start + spp {
        let dz = geometry::linalg::dist(tr.z_at(k + 1), tr.z_at(k));
        path += dz;
        speed = speed.max(dz / h);
    }
    Ok(SimulatedRegime {
        period: T,
        h,
        steps_per_period: spp,
        periods,
        x0: tr.x_at(start).to_vec(),
        z0: tr.z_at(start).to_vec(),
        residuals,
        path_length_last_period: path,
        max_z_speed_last_period: speed,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A two-state plant with a play and every effect that has its own code in a sub-step:
    /// friction, cogging, a coasting play, a delayed (split) input through a saturation and a
    /// play; `controller` closes a digital loop around it.
    fn model(controller: bool, hold: InputHold) -> ExtendedModel {
        let loop_ = if controller {
            "[controller]\nperiod = 0.02\ndelay = 1\nkind = \"cascade\"\nkp = 4\nkv = 3\nki = 1\nvelocity_filter = 0.01\n"
        } else {
            ""
        };
        let text = format!(
            r#"
[plant]
A = [[0.0, 1.0], [-2.0, -0.6]]
B = [[0.0], [1.0]]
C = [[1.0, 0.0]]
E = [[0.0], [1.0]]
[theta]
shape = "interval"
half_width = 0.1
{loop_}
[[effects]]
kind = "coulomb_friction"
state = 1
level = 0.05
[[effects]]
kind = "cogging"
state = 1
position_state = 0
amplitude = 0.04
period = 0.3
phase = 0.2
[[effects]]
kind = "backlash_inertia"
mass = 0.05
damping = 1.0
[[effects]]
kind = "input_delay"
delay = 0.013
[[effects]]
kind = "input_saturation"
limit = 0.9
[[effects]]
kind = "backlash"
width = 0.05
location = "input"
"#
        );
        let sys = model::parse_str(&text).unwrap();
        ExtendedModel::new(&sys, &[], 0.01, 3).unwrap().with_hold(hold)
    }

    fn bits(o: &SimOutput) -> Vec<u64> {
        o.y.iter().chain(&o.z).chain(&o.x).map(|v| v.to_bits()).collect()
    }

    #[test]
    fn specialised_and_general_runs_agree_to_the_bit() {
        let w: Vec<f64> = (0..3000).map(|k| 1.2 * (0.011 * k as f64).sin() + 0.3 * (0.05 * k as f64).cos()).collect();
        let x0 = [0.05, -0.1];
        for (controller, hold) in [(false, InputHold::Foh), (false, InputHold::Zoh), (true, InputHold::Zoh)] {
            let ext = model(controller, hold);
            assert!(ext.split.is_some(), "the delay splits a sub-step");
            let fast = ext.simulate_from(&w, 0.01, &x0, None);
            let general = match &ext.digital {
                Some(dl) => ext.simulate_loop::<0, 0, 0>(dl, &w, 0.01, &x0, None),
                None => ext.free_run::<0, 0, 0>(&w, 0.01, &x0, None),
            };
            assert!(fast.finite && fast.contact.iter().any(|c| *c) && fast.contact.iter().any(|c| !*c));
            assert_eq!(bits(&fast), bits(&general), "controller {controller}, {hold:?}");
            assert_eq!(fast.contact, general.contact);
            // Negative control: the comparison sees a one-ulp change of the initial state.
            let nudged = ext.simulate_from(&w, 0.01, &[f64::from_bits(x0[0].to_bits() + 1), x0[1]], None);
            assert_ne!(bits(&fast), bits(&nudged));
        }
    }
}
