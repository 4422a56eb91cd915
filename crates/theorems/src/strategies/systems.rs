//! Random systems `(A, B, C, E)` of eq. (xy) with `F = A + E C` Hurwitz (eq. (F), (stab)) and
//! a controlled spectral abscissa `mu`, a random strongly convex `Theta` and a random periodic
//! input.
//!
//! `F = V J V^{-1}` with `J` block diagonal (real eigenvalues `a` or 2x2 blocks
//! `[[a, b], [-b, a]]`, `a` in the configured `mu` range) and `V = I + 0.4 R`, `R` in
//! `[-1, 1]^{n x n}` (conditioning bounded); `C`, `E`, `B` are random and `A = F - E C`.
use super::inputs::{periodic_input, InputParams, InputStrategyConfig, MAX_M};
use super::sets::{point_params, set_params, PointParams, SetKind, SetParams, SetStrategyConfig, MAX_P};
use geometry::{Ball, ConvexSet, Shape};
use model::{SimDefaults, System};
use nalgebra::{DMatrix, DVector};
use proptest::prelude::*;

/// Largest state dimension the strategies generate.
pub const MAX_N: usize = 4;

/// Settings of [`system_params`].
#[derive(Debug, Clone)]
pub struct SystemStrategyConfig {
    /// Largest `n`. Default `4`.
    pub max_n: usize,
    /// Largest `p` (at most `n`). Default `2`.
    pub max_p: usize,
    /// Real parts of the eigenvalues of `F` lie in this range (so `mu` does). Default `[-2, -0.2]`.
    pub mu: (f64, f64),
    /// Backlash sets. Default: strongly convex shapes, size `10^[-1.5, 0]`, conditioning <= 5.
    pub theta: SetStrategyConfig,
    /// Inputs. Default: [`InputStrategyConfig::default`].
    pub input: InputStrategyConfig,
    /// Time step of the catching-up scheme stored in the model. Default `1e-3`.
    pub dt: f64,
    /// Periods to simulate stored in the model. Default `20`.
    pub periods: usize,
}

impl Default for SystemStrategyConfig {
    fn default() -> Self {
        Self {
            max_n: MAX_N,
            max_p: 2,
            mu: (-2.0, -0.2),
            theta: SetStrategyConfig { max_cond: 5.0, scale_exp: 0.75, ..SetStrategyConfig::strongly_convex() },
            input: InputStrategyConfig::default(),
            dt: 1e-3,
            periods: 20,
        }
    }
}

/// Parameters of a random system; [`SystemParams::build`] makes the [`System`].
#[derive(Debug, Clone)]
pub struct SystemParams {
    pub n: usize,
    pub p: usize,
    pub m: usize,
    /// Real parts of the eigenvalues of `F` (within the configured range).
    pub re: [f64; MAX_N],
    /// Imaginary parts of 2x2 blocks.
    pub im: [f64; MAX_N],
    /// Use 2x2 complex blocks where possible.
    pub complex: bool,
    pub v: [f64; MAX_N * MAX_N],
    pub c: [f64; MAX_N * MAX_N],
    pub e: [f64; MAX_N * MAX_N],
    pub b: [f64; MAX_N * MAX_M],
    pub theta: SetParams,
    pub input: InputParams,
    pub x0: [f64; MAX_N],
    pub q0: PointParams,
    pub dt: f64,
    pub periods: usize,
}

impl SystemParams {
    /// `F = V J V^{-1}`.
    pub fn F(&self) -> DMatrix<f64> {
        let n = self.n;
        let mut j = DMatrix::zeros(n, n);
        let mut k = 0;
        while k < n {
            if self.complex && k + 1 < n {
                let (a, b) = (self.re[k], self.im[k]);
                j[(k, k)] = a;
                j[(k + 1, k + 1)] = a;
                j[(k, k + 1)] = b;
                j[(k + 1, k)] = -b;
                k += 2;
            } else {
                j[(k, k)] = self.re[k];
                k += 1;
            }
        }
        let v = DMatrix::from_fn(n, n, |i, l| if i == l { 1.0 } else { 0.0 } + 0.4 * self.v[i * MAX_N + l]);
        match v.clone().try_inverse() {
            Some(vi) if (v.norm() * vi.norm()) < 1e3 => &v * j * vi,
            _ => j,
        }
    }

    /// The backlash set in `R^p` (intervals only for `p = 1`; balls replace them otherwise).
    pub fn theta_set(&self) -> Shape {
        let mut tp = self.theta.clone();
        tp.p = self.p;
        if tp.kind == SetKind::Interval && self.p > 1 {
            tp.kind = SetKind::Ball;
        }
        if tp.kind != SetKind::Interval && self.p == 1 && tp.kind != SetKind::Ball {
            tp.kind = SetKind::Interval;
        }
        tp.build()
    }

    /// Builds the validated system. `x0` in `[-1, 1]^n`, `z0 = C x0 + q0` with `q0 in Theta`.
    pub fn build(&self) -> System {
        let (n, p, m) = (self.n, self.p, self.m);
        let F = self.F();
        let C = DMatrix::from_fn(p, n, |i, j| self.c[i * MAX_N + j] + if i == j { 1.0 } else { 0.0 });
        let E = DMatrix::from_fn(n, p, |i, j| self.e[i * MAX_N + j]);
        let A = &F - &E * &C;
        let B = DMatrix::from_fn(n, m, |i, j| self.b[i * MAX_M + j] + if i == j { 1.0 } else { 0.0 });
        let theta = self.theta_set();
        let x0 = DVector::from_iterator(n, self.x0[..n].iter().copied());
        let (q0, _) = PointParams { interior: true, ..self.q0.clone() }.build(&theta);
        let z0 = &C * &x0 + DVector::from_vec(q0);
        let input = self.input.build(m);
        let sim = SimDefaults { dt: self.dt, periods: self.periods, t_end: None };
        let theta = match theta {
            Shape::Ball(b) if b.radius == 0.0 => Shape::Ball(Ball::centred(p, 0.0).expect("p >= 1")),
            t => t,
        };
        debug_assert_eq!(theta.dim(), p);
        System::builder()
            .name("random system (theorems strategy)")
            .A(A)
            .B(B)
            .C(C)
            .E(E)
            .theta(theta)
            .input(input)
            .x0(x0)
            .z0(z0)
            .sim(sim)
            .build()
            .expect("the strategy builds valid systems")
    }
}

/// Strategy for [`SystemParams`].
pub fn system_params(cfg: &SystemStrategyConfig) -> BoxedStrategy<SystemParams> {
    let max_n = cfg.max_n.clamp(1, MAX_N);
    let max_p = cfg.max_p.clamp(1, MAX_P);
    let (lo, hi) = (cfg.mu.0.min(cfg.mu.1), cfg.mu.0.max(cfg.mu.1));
    let (dt, periods) = (cfg.dt, cfg.periods);
    let dims = (1..=max_n).prop_flat_map(move |n| (Just(n), 1..=max_p.min(n), 1..=MAX_M));
    (
        dims,
        proptest::array::uniform4(lo..=hi),
        proptest::array::uniform4(0.0..=2.0f64),
        any::<bool>(),
        proptest::array::uniform16(-1.0..=1.0f64),
        proptest::array::uniform16(-1.0..=1.0f64),
        proptest::array::uniform16(-1.0..=1.0f64),
        proptest::array::uniform8(-1.0..=1.0f64),
        (set_params(&cfg.theta), periodic_input(&cfg.input), proptest::array::uniform4(-1.0..=1.0f64), point_params()),
    )
        .prop_map(move |((n, p, m), re, im, complex, v, c, e, b, (theta, input, x0, q0))| SystemParams {
            n,
            p,
            m,
            re,
            im,
            complex,
            v,
            c,
            e,
            b,
            theta,
            input,
            x0,
            q0,
            dt,
            periods,
        })
        .boxed()
}
