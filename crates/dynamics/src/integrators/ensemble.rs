//! Ensemble catching-up: many trajectories of ONE system under the SAME input at once.
//!
//! The states are stored as a structure of arrays ([`EnsembleState`]: component `j` of `x` of
//! every trajectory contiguous), and a step advances a SIMD register of trajectories (lanes)
//! with the arithmetic of the single fixed-size path
//! [`FastCatchingUp`](super::catching_up::FastCatchingUp), operation for operation:
//!
//! ```text
//! x_{k+1} = (Phi x_k + G1E z_k) + f_1 + f_2 + ...      (f_t: forcing terms of step k, shared)
//! y_{k+1} = C x_{k+1},   z_{k+1} = y_{k+1} + P_Theta(z_k - y_{k+1}),
//! ```
//! the matrix-vector products summed column by column as nalgebra does, and the forcing terms
//! (`ga s_k`, `gd (s_{k+1} - s_k)` for a sine by the same rotation recurrence re-seeded every
//! [`SINE_RESEED`] steps; `g1B_j w_j(t_k)`, `g2B_j (w_j(t_{k+1}) - w_j(t_k))` for any other
//! input) computed once per step in scalar code and added in the same order. No fused
//! multiply-add is used, so a lane reproduces the single path (tested: bit for bit on the
//! worked example, to rounding everywhere).
//!
//! Projections: an interval is a clamp and a ball a closed form, both vectorised; any other set
//! (ellipsoid, ball intersection, polytope) is projected lane by lane with the same scalar
//! routine as the single path.
//!
//! SIMD through [`pulp`] (runtime dispatch to AVX2 + FMA on x86-64, NEON on aarch64, scalar
//! elsewhere; no `unsafe` here). Work is tiled: the forcing of [`CHUNK_STEPS`] steps is computed
//! once, then each block of lanes whose states fit in L1 runs those steps.
//!
//! Entry points: [`EnsembleCatchingUp`] (fixed `N = n`, `P = p`) and [`Ensemble`] (any system:
//! the SIMD path for `n <= 6, p <= 3` and `(4, 4)`, else one [`Simulator`] per trajectory).
// Index loops on purpose in the kernels: closures (iterator adaptors, `array::from_fn`) are
// compiled outside the SIMD target features, and their vector operations become calls.
#![allow(clippy::needless_range_loop)]
use super::catching_up::{CatchingUpSettings, Simulator, SINE_RESEED};
use crate::error::DynamicsError;
use crate::linear::step_map::{InputHold, SystemStepMap};
use geometry::{ConvexSet, Shape};
use model::{Input, System};
use pulp::{Arch, Simd, WithSimd};

/// Trajectory counts are padded to a multiple of this (the widest SIMD register, 8 x f64).
pub const LANE_PAD: usize = 8;
/// Steps whose forcing is computed at once (multiple of nothing in particular: the sine
/// recurrence runs across chunks exactly as in the single path).
pub const CHUNK_STEPS: usize = 256;
/// Bytes of state per lane block (L1-resident while a chunk of steps runs over it).
const BLOCK_BYTES: usize = 16 * 1024;

/// States of `len` trajectories, structure of arrays: `x[j * stride + i]` is component `j` of
/// trajectory `i` (same for `z`); `stride` is `len` rounded up to [`LANE_PAD`]. The padding
/// lanes are simulated too (from zero) and never reported.
#[derive(Debug, Clone, PartialEq)]
pub struct EnsembleState {
    n: usize,
    p: usize,
    len: usize,
    stride: usize,
    x: Vec<f64>,
    z: Vec<f64>,
}

impl EnsembleState {
    /// `len` trajectories at `x = 0, z = 0`.
    pub fn zeros(n: usize, p: usize, len: usize) -> Self {
        let stride = len.div_ceil(LANE_PAD).max(1) * LANE_PAD;
        Self { n, p, len, stride, x: vec![0.0; n * stride], z: vec![0.0; p * stride] }
    }
    /// `len` trajectories, trajectory `i` from `init(i, x, z)`.
    pub fn from_fn(n: usize, p: usize, len: usize, mut init: impl FnMut(usize, &mut [f64], &mut [f64])) -> Self {
        let mut s = Self::zeros(n, p, len);
        let (mut x, mut z) = (vec![0.0; n], vec![0.0; p]);
        for i in 0..len {
            x.iter_mut().for_each(|v| *v = 0.0);
            z.iter_mut().for_each(|v| *v = 0.0);
            init(i, &mut x, &mut z);
            s.set(i, &x, &z);
        }
        s
    }
    /// All trajectories at the same state.
    pub fn replicate(x: &[f64], z: &[f64], len: usize) -> Self {
        Self::from_fn(x.len(), z.len(), len, |_, xi, zi| {
            xi.copy_from_slice(x);
            zi.copy_from_slice(z);
        })
    }
    pub fn n(&self) -> usize {
        self.n
    }
    pub fn p(&self) -> usize {
        self.p
    }
    /// Number of trajectories.
    pub fn len(&self) -> usize {
        self.len
    }
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
    /// Padded length of each component array.
    pub fn stride(&self) -> usize {
        self.stride
    }
    /// Sets trajectory `i` to `(x, z)`.
    pub fn set(&mut self, i: usize, x: &[f64], z: &[f64]) {
        assert!(i < self.len && x.len() == self.n && z.len() == self.p, "EnsembleState::set: index or size");
        for (j, v) in x.iter().enumerate() {
            self.x[j * self.stride + i] = *v;
        }
        for (j, v) in z.iter().enumerate() {
            self.z[j * self.stride + i] = *v;
        }
    }
    /// Copies trajectory `i` into `(x, z)`.
    pub fn get(&self, i: usize, x: &mut [f64], z: &mut [f64]) {
        assert!(i < self.len && x.len() == self.n && z.len() == self.p, "EnsembleState::get: index or size");
        for (j, v) in x.iter_mut().enumerate() {
            *v = self.x[j * self.stride + i];
        }
        for (j, v) in z.iter_mut().enumerate() {
            *v = self.z[j * self.stride + i];
        }
    }
    /// `x` of trajectory `i`.
    pub fn x_of(&self, i: usize) -> Vec<f64> {
        (0..self.n).map(|j| self.x[j * self.stride + i]).collect()
    }
    /// `z` of trajectory `i`.
    pub fn z_of(&self, i: usize) -> Vec<f64> {
        (0..self.p).map(|j| self.z[j * self.stride + i]).collect()
    }
    /// Component `j` of `x` over the trajectories (length `len`).
    pub fn x_component(&self, j: usize) -> &[f64] {
        &self.x[j * self.stride..j * self.stride + self.len]
    }
    /// Component `j` of `z` over the trajectories (length `len`).
    pub fn z_component(&self, j: usize) -> &[f64] {
        &self.z[j * self.stride..j * self.stride + self.len]
    }
    /// True if every state of every (reported) trajectory is finite.
    pub fn all_finite(&self) -> bool {
        (0..self.n).all(|j| self.x_component(j).iter().all(|v| v.is_finite()))
            && (0..self.p).all(|j| self.z_component(j).iter().all(|v| v.is_finite()))
    }
}

/// The input's contribution to a step, shared by every lane.
#[derive(Debug, Clone)]
enum Forcing {
    Zero,
    /// `ga s_k + gd (s_{k+1} - s_k)`, `s_k = sin(omega t_k + phase)` by recurrence.
    Sine {
        omega: f64,
        phase: f64,
        ga: Vec<f64>,
        gd: Vec<f64>,
    },
    /// Any input evaluated once per step: `sum_j g1B_j w_j(t_k) [+ g2B_j (w_j(t_{k+1}) - w_j(t_k))]`.
    General {
        input: Input,
        g1b: Vec<Vec<f64>>,
        g2b: Vec<Vec<f64>>,
        linear: bool,
    },
}

impl Forcing {
    fn new(sys: &System, map: &SystemStepMap) -> Self {
        let n = sys.n();
        let linear = map.hold == InputHold::Foh;
        let col = |M: &nalgebra::DMatrix<f64>, j: usize| (0..n).map(|i| M[(i, j)]).collect::<Vec<f64>>();
        match &sys.input {
            Input::Zero { .. } => Forcing::Zero,
            Input::Sine { amplitudes, omega, phase } if linear => {
                let a = nalgebra::DVector::from_column_slice(amplitudes);
                Forcing::Sine {
                    omega: *omega,
                    phase: *phase,
                    ga: (&map.g1B * &a).as_slice().to_vec(),
                    gd: (&map.g2B * &a).as_slice().to_vec(),
                }
            }
            other => {
                let m = other.m();
                Forcing::General {
                    input: other.clone(),
                    g1b: (0..m).map(|j| col(&map.g1B, j)).collect(),
                    g2b: (0..m).map(|j| col(&map.g2B, j)).collect(),
                    linear,
                }
            }
        }
    }
    /// Forcing vectors added per step.
    fn terms(&self) -> usize {
        match self {
            Forcing::Zero => 0,
            Forcing::Sine { .. } => 2,
            Forcing::General { g1b, linear, .. } => g1b.len() * if *linear { 2 } else { 1 },
        }
    }
}

/// The forcing of consecutive steps of one `run` from `t0` (the single path's recurrence).
struct ForcingStream<'a> {
    f: &'a Forcing,
    t0: f64,
    h: f64,
    k: usize,
    s: f64,
    c: f64,
    sw: f64,
    cw: f64,
    w0: Vec<f64>,
    w1: Vec<f64>,
}

impl<'a> ForcingStream<'a> {
    fn new(f: &'a Forcing, t0: f64, h: f64) -> Self {
        let mut st = Self { f, t0, h, k: 0, s: 0.0, c: 0.0, sw: 0.0, cw: 1.0, w0: Vec::new(), w1: Vec::new() };
        match f {
            Forcing::Zero => {}
            Forcing::Sine { omega, .. } => (st.sw, st.cw) = (omega * h).sin_cos(),
            Forcing::General { input, g1b, .. } => {
                st.w0 = vec![0.0; g1b.len()];
                st.w1 = vec![0.0; g1b.len()];
                input.eval(t0, &mut st.w0);
            }
        }
        st
    }
    /// Terms of the next `count` steps into `buf` (`[step][term][i]`).
    fn fill(&mut self, count: usize, buf: &mut Vec<f64>) {
        buf.clear();
        let (t0, h) = (self.t0, self.h);
        for _ in 0..count {
            match self.f {
                Forcing::Zero => {}
                Forcing::Sine { omega, phase, ga, gd } => {
                    if self.k.is_multiple_of(SINE_RESEED) {
                        (self.s, self.c) = (*omega * (t0 + self.k as f64 * h) + *phase).sin_cos();
                    }
                    let (s, c) = (self.s, self.c);
                    let s1 = s * self.cw + c * self.sw;
                    let c1 = c * self.cw - s * self.sw;
                    buf.extend(ga.iter().map(|g| g * s));
                    buf.extend(gd.iter().map(|g| g * (s1 - s)));
                    self.s = s1;
                    self.c = c1;
                }
                Forcing::General { input, g1b, g2b, linear } => {
                    let t1 = t0 + (self.k + 1) as f64 * h;
                    if *linear {
                        input.eval(t1, &mut self.w1);
                    }
                    for j in 0..g1b.len() {
                        let w0 = self.w0[j];
                        buf.extend(g1b[j].iter().map(|g| g * w0));
                        if *linear {
                            let dw = self.w1[j] - w0;
                            buf.extend(g2b[j].iter().map(|g| g * dw));
                        }
                    }
                    if *linear {
                        std::mem::swap(&mut self.w0, &mut self.w1);
                    } else {
                        input.eval(t1, &mut self.w0);
                    }
                }
            }
            self.k += 1;
        }
    }
}

/// Projection of a register of lanes onto `Theta` (`prepare`: the set's constants splatted
/// once per kernel call).
trait LaneProj<const P: usize>: Sync {
    type Prep<S: Simd>: Copy;
    fn prepare<S: Simd>(&self, simd: S) -> Self::Prep<S>;
    /// `live`: lanes holding a trajectory (the others may be left unprojected).
    fn project<S: Simd>(&self, prep: &Self::Prep<S>, simd: S, q: [S::f64s; P], live: usize) -> [S::f64s; P];
}

/// Interval `[lo, hi]` (`p = 1`): a clamp, as `Interval::clamp`.
struct IntervalProj {
    lo: f64,
    hi: f64,
}

impl<const P: usize> LaneProj<P> for IntervalProj {
    type Prep<S: Simd> = (S::f64s, S::f64s);
    #[inline(always)]
    fn prepare<S: Simd>(&self, simd: S) -> Self::Prep<S> {
        (simd.splat_f64s(self.lo), simd.splat_f64s(self.hi))
    }
    #[inline(always)]
    fn project<S: Simd>(&self, &(lo, hi): &Self::Prep<S>, simd: S, q: [S::f64s; P], _: usize) -> [S::f64s; P] {
        let mut o = q;
        o[0] = simd.min_f64s(simd.max_f64s(q[0], lo), hi);
        o
    }
}

/// Ball: `q` if `|q - c| <= r`, else `c + (r / |q - c|)(q - c)`, as `Ball::project`.
struct BallProj<const P: usize> {
    c: [f64; P],
    r: f64,
}

impl<const P: usize> LaneProj<P> for BallProj<P> {
    type Prep<S: Simd> = ([S::f64s; P], S::f64s);
    #[inline(always)]
    fn prepare<S: Simd>(&self, simd: S) -> Self::Prep<S> {
        let mut c = [simd.splat_f64s(0.0); P];
        for i in 0..P {
            c[i] = simd.splat_f64s(self.c[i]);
        }
        (c, simd.splat_f64s(self.r))
    }
    #[inline(always)]
    fn project<S: Simd>(&self, &(c, r): &Self::Prep<S>, simd: S, q: [S::f64s; P], _: usize) -> [S::f64s; P] {
        let mut d = q;
        for i in 0..P {
            d[i] = simd.sub_f64s(q[i], c[i]);
        }
        let mut ss = simd.mul_f64s(d[0], d[0]);
        for di in d.iter().skip(1) {
            ss = simd.add_f64s(ss, simd.mul_f64s(*di, *di));
        }
        let dist = simd.sqrt_f64s(ss);
        let inside = simd.less_than_or_equal_f64s(dist, r);
        let s = simd.div_f64s(r, dist);
        let mut o = q;
        for i in 0..P {
            o[i] = simd.select_f64s(inside, q[i], simd.add_f64s(c[i], simd.mul_f64s(s, d[i])));
        }
        o
    }
}

/// Any set: lane by lane with the scalar projection of the single path.
struct ShapeProj<'a>(&'a Shape);

impl<const P: usize> LaneProj<P> for ShapeProj<'_> {
    type Prep<S: Simd> = ();
    #[inline(always)]
    fn prepare<S: Simd>(&self, _simd: S) {}
    #[inline(always)]
    fn project<S: Simd>(&self, _: &(), simd: S, q: [S::f64s; P], live: usize) -> [S::f64s; P] {
        let w = S::F64_LANES;
        let mut buf = [[0.0f64; LANE_PAD]; P];
        for i in 0..P {
            simd.partial_store_f64s(&mut buf[i][..w], q[i]);
        }
        project_lanes(self.0, &mut buf, live.min(w));
        let mut o = q;
        for i in 0..P {
            o[i] = simd.partial_load_f64s(&buf[i][..w]);
        }
        o
    }
}

/// Scalar projection of lanes `0..live` of `buf` (`buf[i][lane]`), kept out of line: inlined,
/// the set's code would swell the SIMD kernel past the point where LLVM still inlines the
/// vector intrinsics into it.
#[inline(never)]
fn project_lanes<const P: usize>(shape: &Shape, buf: &mut [[f64; LANE_PAD]; P], live: usize) {
    let (mut qi, mut oi) = ([0.0; P], [0.0; P]);
    for l in 0..live {
        for i in 0..P {
            qi[i] = buf[i][l];
        }
        shape.project(&qi, &mut oi);
        for i in 0..P {
            buf[i][l] = oi[i];
        }
    }
}

#[derive(Debug, Clone)]
enum ProjKind<const P: usize> {
    Interval { lo: f64, hi: f64 },
    Ball { c: [f64; P], r: f64 },
    Lanes,
}

/// Matrices of the step, row-major arrays (`phi[i][j] = Phi_ij`).
#[derive(Debug, Clone)]
struct Consts<const N: usize, const P: usize> {
    phi: [[f64; N]; N],
    g1e: [[f64; P]; N],
    c: [[f64; N]; P],
}

/// One step of one register of lanes: the single path's operations in its order.
#[inline(always)]
#[allow(clippy::type_complexity)]
fn step<S: Simd, const N: usize, const P: usize, PR: LaneProj<P>>(
    simd: S,
    (phi, g1e, c): (&[[S::f64s; N]; N], &[[S::f64s; P]; N], &[[S::f64s; N]; P]),
    f: &[[S::f64s; N]],
    (proj, prep, live): (&PR, &PR::Prep<S>, usize),
    x: [S::f64s; N],
    z: [S::f64s; P],
) -> ([S::f64s; N], [S::f64s; P]) {
    // plain loops, no closures: a closure is compiled outside the SIMD target features and
    // its vector operations would become calls
    let mut xn = x;
    for i in 0..N {
        // nalgebra gemv: y = a_0 x_0, then y = a_j x_j + y
        let mut a = simd.mul_f64s(phi[i][0], x[0]);
        for j in 1..N {
            a = simd.add_f64s(simd.mul_f64s(phi[i][j], x[j]), a);
        }
        let mut e = simd.mul_f64s(g1e[i][0], z[0]);
        for j in 1..P {
            e = simd.add_f64s(simd.mul_f64s(g1e[i][j], z[j]), e);
        }
        let mut s = simd.add_f64s(a, e);
        for ft in f {
            s = simd.add_f64s(s, ft[i]);
        }
        xn[i] = s;
    }
    let mut y = z;
    for i in 0..P {
        let mut a = simd.mul_f64s(c[i][0], xn[0]);
        for j in 1..N {
            a = simd.add_f64s(simd.mul_f64s(c[i][j], xn[j]), a);
        }
        y[i] = a;
    }
    let mut q = z;
    for i in 0..P {
        q[i] = simd.sub_f64s(z[i], y[i]);
    }
    let pq = proj.project(prep, simd, q, live);
    let mut zn = z;
    for i in 0..P {
        zn[i] = simd.add_f64s(y[i], pq[i]);
    }
    (xn, zn)
}

/// `K` of [`Kernel`] when the number of forcing terms is only known at run time.
const DYN_TERMS: usize = usize::MAX;
/// Most forcing terms per step (`2 m` for a linearly interpolated input with `m` channels).
const MAX_TERMS: usize = 8;

/// Observer of a run: `(k, t_k, state)`.
type StepObs<'a> = &'a mut dyn FnMut(usize, f64, &EnsembleState);

/// Observer of [`Kernel`]: `(step within the chunk, state)`.
type ChunkObs<'a> = &'a mut dyn FnMut(usize, &EnsembleState);

/// Runs `steps` steps (forcing `terms`, `nterms * N` per step) over lanes `lanes` of the state,
/// calling `obs` after each step if given; `K = nterms` known at compile time (the common sine
/// case) or [`DYN_TERMS`]. Only the registers holding a trajectory are advanced (the padding
/// lanes past the last such register keep their values).
struct Kernel<'a, const N: usize, const P: usize, const K: usize, PR> {
    k: &'a Consts<N, P>,
    proj: &'a PR,
    terms: &'a [f64],
    nterms: usize,
    steps: usize,
    state: &'a mut EnsembleState,
    lanes: std::ops::Range<usize>,
    obs: Option<ChunkObs<'a>>,
}

impl<const N: usize, const P: usize, const K: usize, PR: LaneProj<P>> WithSimd for Kernel<'_, N, P, K, PR> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let Kernel { k, proj, terms, nterms, steps, state, lanes, mut obs } = self;
        let w = S::F64_LANES;
        let live = state.len.saturating_sub(lanes.start).min(lanes.len());
        let nv = live.div_ceil(w);
        let last_live = live - nv.saturating_sub(1) * w;
        let lanes = lanes.start..lanes.start + nv * w;
        let zero = simd.splat_f64s(0.0);
        let (mut phi, mut g1e, mut c) = ([[zero; N]; N], [[zero; P]; N], [[zero; N]; P]);
        for i in 0..N {
            for j in 0..N {
                phi[i][j] = simd.splat_f64s(k.phi[i][j]);
            }
            for j in 0..P {
                g1e[i][j] = simd.splat_f64s(k.g1e[i][j]);
                c[j][i] = simd.splat_f64s(k.c[j][i]);
            }
        }
        let nt = if K == DYN_TERMS { nterms } else { K };
        debug_assert_eq!(nt, nterms);
        let per = nt * N;
        let prep = proj.prepare(simd);
        let mut fbuf = [[zero; N]; MAX_TERMS];
        assert!(nt <= MAX_TERMS, "ensemble: too many forcing terms per step ({nt} > {MAX_TERMS})");
        let stride = state.stride;
        for s in 0..steps {
            let ts = &terms[s * per..(s + 1) * per];
            for t in 0..nt {
                for i in 0..N {
                    fbuf[t][i] = simd.splat_f64s(ts[t * N + i]);
                }
            }
            let f = &fbuf[..nt];
            {
                let mut xit = state.x.chunks_exact_mut(stride);
                let xs: [&mut [S::f64s]; N] =
                    std::array::from_fn(|_| S::as_mut_simd_f64s(&mut xit.next().expect("n")[lanes.clone()]).0);
                let mut zit = state.z.chunks_exact_mut(stride);
                let zs: [&mut [S::f64s]; P] =
                    std::array::from_fn(|_| S::as_mut_simd_f64s(&mut zit.next().expect("p")[lanes.clone()]).0);
                for v in 0..nv {
                    let (mut xv, mut zv) = ([zero; N], [zero; P]);
                    for j in 0..N {
                        xv[j] = xs[j][v];
                    }
                    for j in 0..P {
                        zv[j] = zs[j][v];
                    }
                    let nlive = if v + 1 == nv { last_live } else { w };
                    let (xn, zn) = step(simd, (&phi, &g1e, &c), f, (proj, &prep, nlive), xv, zv);
                    for j in 0..N {
                        xs[j][v] = xn[j];
                    }
                    for j in 0..P {
                        zs[j][v] = zn[j];
                    }
                }
            }
            if let Some(o) = obs.as_deref_mut() {
                o(s, state);
            }
        }
    }
}

/// Fixed-size ensemble integrator (`N = n`, `P = p`): same results as
/// [`FastCatchingUp<N, P, Shape>`](super::catching_up::FastCatchingUp) for every trajectory.
#[derive(Debug, Clone)]
pub struct EnsembleCatchingUp<const N: usize, const P: usize> {
    k: Consts<N, P>,
    proj: ProjKind<P>,
    theta: Shape,
    forcing: Forcing,
    h: f64,
    arch: Arch,
    buf: Vec<f64>,
}

impl<const N: usize, const P: usize> EnsembleCatchingUp<N, P> {
    pub fn new(sys: &System, settings: &CatchingUpSettings) -> Result<Self, DynamicsError> {
        settings.validate()?;
        if sys.n() != N {
            return Err(DynamicsError::Dimension { what: "n (ensemble)", expected: N, got: sys.n() });
        }
        if sys.p() != P {
            return Err(DynamicsError::Dimension { what: "p (ensemble)", expected: P, got: sys.p() });
        }
        let map = SystemStepMap::for_system(sys, settings.dt, settings.hold)?;
        let k = Consts {
            phi: std::array::from_fn(|i| std::array::from_fn(|j| map.phi[(i, j)])),
            g1e: std::array::from_fn(|i| std::array::from_fn(|j| map.g1E[(i, j)])),
            c: std::array::from_fn(|i| std::array::from_fn(|j| sys.C[(i, j)])),
        };
        let proj = match &sys.theta {
            Shape::Interval(iv) => ProjKind::Interval { lo: iv.lo, hi: iv.hi },
            Shape::Ball(b) if b.centre.len() == P => {
                ProjKind::Ball { c: std::array::from_fn(|i| b.centre[i]), r: b.radius }
            }
            _ => ProjKind::Lanes,
        };
        let forcing = Forcing::new(sys, &map);
        if forcing.terms() > MAX_TERMS {
            return Err(DynamicsError::BadSetting {
                name: "m (ensemble)",
                value: sys.m() as f64,
                reason: "the SIMD ensemble adds at most 8 forcing vectors per step (m <= 4)",
            });
        }
        Ok(Self { k, proj, theta: sys.theta.clone(), forcing, h: settings.dt, arch: Arch::new(), buf: Vec::new() })
    }
    pub fn h(&self) -> f64 {
        self.h
    }

    fn check(state: &EnsembleState) {
        assert!(state.n == N && state.p == P, "ensemble state of size ({}, {}) for ({N}, {P})", state.n, state.p);
    }

    fn run_proj<PR: LaneProj<P>>(
        &mut self,
        proj: &PR,
        t0: f64,
        state: &mut EnsembleState,
        steps: usize,
        mut obs: Option<StepObs>,
    ) {
        let nterms = self.forcing.terms();
        let mut stream = ForcingStream::new(&self.forcing, t0, self.h);
        // observed runs advance all lanes together (one block), step by step
        let block = if obs.is_some() {
            state.stride
        } else {
            (BLOCK_BYTES / ((N + P) * 8)).max(LANE_PAD) / LANE_PAD * LANE_PAD
        };
        let (arch, h, observed) = (self.arch, self.h, obs.is_some());
        let mut k = 0;
        while k < steps {
            let cnt = CHUNK_STEPS.min(steps - k);
            stream.fill(cnt, &mut self.buf);
            let terms = &self.buf[..];
            let mut a = 0;
            while a < state.stride {
                let b = (a + block).min(state.stride);
                let mut hook = |s: usize, st: &EnsembleState| {
                    if let Some(o) = obs.as_deref_mut() {
                        let kk = k + s + 1;
                        o(kk, t0 + kk as f64 * h, st)
                    }
                };
                let o: Option<ChunkObs> = if observed { Some(&mut hook) } else { None };
                macro_rules! go {
                    ($K:expr) => {
                        arch.dispatch(Kernel::<N, P, { $K }, PR> {
                            k: &self.k,
                            proj,
                            terms,
                            nterms,
                            steps: cnt,
                            state: &mut *state,
                            lanes: a..b,
                            obs: o,
                        })
                    };
                }
                match nterms {
                    2 => go!(2),
                    _ => go!(DYN_TERMS),
                }
                a = b;
            }
            k += cnt;
        }
    }

    fn run_any(&mut self, t0: f64, state: &mut EnsembleState, steps: usize, obs: Option<StepObs>) {
        Self::check(state);
        match self.proj.clone() {
            ProjKind::Interval { lo, hi } => self.run_proj(&IntervalProj { lo, hi }, t0, state, steps, obs),
            ProjKind::Ball { c, r } => self.run_proj(&BallProj { c, r }, t0, state, steps, obs),
            ProjKind::Lanes => {
                let theta = self.theta.clone();
                self.run_proj(&ShapeProj(&theta), t0, state, steps, obs)
            }
        }
    }

    /// Advances every trajectory `steps` steps from time `t0` (`t_k = t0 + k h`), in place.
    pub fn run(&mut self, t0: f64, state: &mut EnsembleState, steps: usize) {
        self.run_any(t0, state, steps, None)
    }

    /// As [`Self::run`], calling `obs(k, t_k, state)` after every step `k = 1..=steps` (all
    /// trajectories advance one step at a time: slower for large ensembles).
    pub fn run_observed(
        &mut self,
        t0: f64,
        state: &mut EnsembleState,
        steps: usize,
        mut obs: impl FnMut(usize, f64, &EnsembleState),
    ) {
        self.run_any(t0, state, steps, Some(&mut obs))
    }
}

/// Fallback for sizes without a SIMD kernel: one [`Simulator`] per trajectory.
#[derive(Debug, Clone)]
pub struct PerTrajectory {
    sim: Simulator,
    n: usize,
    p: usize,
}

impl PerTrajectory {
    fn run(&mut self, t0: f64, state: &mut EnsembleState, steps: usize) {
        let (mut x, mut z) = (vec![0.0; self.n], vec![0.0; self.p]);
        for i in 0..state.len() {
            state.get(i, &mut x, &mut z);
            self.sim.run(t0, &mut x, &mut z, steps, |_, _, _, _| {});
            state.set(i, &x, &z);
        }
    }
    /// One step at a time for every trajectory (`t_k = t0 + k h` at each restart: equal to a
    /// single run to rounding).
    fn run_observed(
        &mut self,
        t0: f64,
        state: &mut EnsembleState,
        steps: usize,
        obs: &mut dyn FnMut(usize, f64, &EnsembleState),
    ) {
        let h = self.sim.h();
        let (mut x, mut z) = (vec![0.0; self.n], vec![0.0; self.p]);
        for k in 0..steps {
            let tk = t0 + k as f64 * h;
            for i in 0..state.len() {
                state.get(i, &mut x, &mut z);
                self.sim.run(tk, &mut x, &mut z, 1, |_, _, _, _| {});
                state.set(i, &x, &z);
            }
            obs(k + 1, t0 + (k + 1) as f64 * h, state);
        }
    }
}

macro_rules! ensemble_enum {
    ($( $var:ident => ($N:literal, $P:literal) ),* $(,)?) => {
        /// An ensemble integrator for any system: the SIMD path [`EnsembleCatchingUp`] when
        /// `n <= 6, p <= min(n, 3)` or `(n, p) = (4, 4)` (and `m <= 4`), else one [`Simulator`]
        /// per trajectory. Same results as the single path.
        #[derive(Debug, Clone)]
        pub enum Ensemble {
            $( $var(Box<EnsembleCatchingUp<$N, $P>>), )*
            PerTrajectory(Box<PerTrajectory>),
        }

        impl Ensemble {
            pub fn new(sys: &System, settings: &CatchingUpSettings) -> Result<Self, DynamicsError> {
                match (sys.n(), sys.p()) {
                    $( ($N, $P) if sys.m() <= MAX_TERMS / 2 => Ok(Ensemble::$var(Box::new(EnsembleCatchingUp::new(sys, settings)?))), )*
                    _ => Ok(Ensemble::PerTrajectory(Box::new(PerTrajectory {
                        sim: Simulator::new(sys, settings)?,
                        n: sys.n(),
                        p: sys.p(),
                    }))),
                }
            }
            /// True when the SIMD kernel runs (false: one single path per trajectory).
            pub fn is_simd(&self) -> bool {
                !matches!(self, Ensemble::PerTrajectory(_))
            }
            pub fn h(&self) -> f64 {
                match self {
                    $( Ensemble::$var(e) => e.h(), )*
                    Ensemble::PerTrajectory(s) => s.sim.h(),
                }
            }
            /// Advances every trajectory `steps` steps from time `t0` (`t_k = t0 + k h`).
            pub fn run(&mut self, t0: f64, state: &mut EnsembleState, steps: usize) {
                match self {
                    $( Ensemble::$var(e) => e.run(t0, state, steps), )*
                    Ensemble::PerTrajectory(s) => s.run(t0, state, steps),
                }
            }
            /// As [`Self::run`], calling `obs(k, t_k, state)` after every step `k = 1..=steps`.
            pub fn run_observed(
                &mut self,
                t0: f64,
                state: &mut EnsembleState,
                steps: usize,
                mut obs: impl FnMut(usize, f64, &EnsembleState),
            ) {
                match self {
                    $( Ensemble::$var(e) => e.run_observed(t0, state, steps, obs), )*
                    Ensemble::PerTrajectory(s) => s.run_observed(t0, state, steps, &mut obs),
                }
            }
        }
    };
}

ensemble_enum!(
    E11 => (1, 1), E21 => (2, 1), E22 => (2, 2), E31 => (3, 1), E32 => (3, 2), E33 => (3, 3),
    E41 => (4, 1), E42 => (4, 2), E43 => (4, 3), E44 => (4, 4), E51 => (5, 1), E52 => (5, 2),
    E61 => (6, 1), E62 => (6, 2), E63 => (6, 3),
);
