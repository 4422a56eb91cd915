//! Moreau's catching-up scheme coupled with the exact linear step:
//!
//! ```text
//! x_{k+1} = e^{hA} x_k + h Psi(hA) E z_k + int_0^h e^{(h-s)A} B w(t_k + s) ds   (w held or linear)
//! y_{k+1} = C x_{k+1},   z_{k+1} = P_{y_{k+1} + Theta}(z_k) = y_{k+1} + P_Theta(z_k - y_{k+1}).
//! ```
//! `z` is held over a step, so the scheme is first order in `h` (measured: `moreau convergence`).
//!
//! Two implementations that agree to rounding (tested):
//! - [`CatchingUp`]: any `n, p`, any [`geometry::Shape`], preallocated buffers, no allocation per
//!   step;
//! - [`FastCatchingUp`]: fixed sizes `N, P` (nalgebra `SMatrix`), the set as a type parameter
//!   ([`FastSet`]: `Interval` -> clamp), and a sine input advanced by an exact rotation
//!   recurrence (re-seeded every [`SINE_RESEED`] steps) instead of one `sin` per step.
//!
//! [`Simulator`] picks the fast path for common sizes and falls back to [`CatchingUp`].
use crate::error::{check_dt, DynamicsError};
use crate::linear::step_map::{InputHold, SystemStepMap};
use geometry::{ConvexSet, Ellipsoid, Interval, Shape};
use model::{Input, System};
use nalgebra::{DMatrix, SMatrix, SVector};

/// Steps between exact re-seeds of the sine recurrence of the fast path.
pub const SINE_RESEED: usize = 512;

/// Settings of the catching-up scheme.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CatchingUpSettings {
    /// Step `h`. Default `1e-3`.
    pub dt: f64,
    /// Representation of `w` over a step. Default [`InputHold::Foh`].
    pub hold: InputHold,
}

impl Default for CatchingUpSettings {
    fn default() -> Self {
        Self { dt: 1e-3, hold: InputHold::Foh }
    }
}

impl CatchingUpSettings {
    pub fn validate(&self) -> Result<(), DynamicsError> {
        check_dt(self.dt)
    }
}

/// Dynamic-size catching-up integrator for any [`System`].
#[derive(Debug, Clone)]
pub struct CatchingUp {
    map: SystemStepMap,
    C: DMatrix<f64>,
    theta: Shape,
    input: Input,
    n: usize,
    p: usize,
    w0: Vec<f64>,
    w1: Vec<f64>,
    xn: Vec<f64>,
    q: Vec<f64>,
    pq: Vec<f64>,
    y: Vec<f64>,
}

impl CatchingUp {
    pub fn new(sys: &System, settings: &CatchingUpSettings) -> Result<Self, DynamicsError> {
        settings.validate()?;
        let map = SystemStepMap::for_system(sys, settings.dt, settings.hold)?;
        let (n, p, m) = (sys.n(), sys.p(), sys.m());
        Ok(Self {
            map,
            C: sys.C.clone(),
            theta: sys.theta.clone(),
            input: sys.input.clone(),
            n,
            p,
            w0: vec![0.0; m],
            w1: vec![0.0; m],
            xn: vec![0.0; n],
            q: vec![0.0; p],
            pq: vec![0.0; p],
            y: vec![0.0; p],
        })
    }
    pub fn h(&self) -> f64 {
        self.map.h
    }

    /// Advances `steps` steps from time `t0` (`t_k = t0 + k h`), in place, calling
    /// `obs(k, t_k, x_k, z_k)` after each step `k = 1..=steps`.
    pub fn run(
        &mut self,
        t0: f64,
        x: &mut [f64],
        z: &mut [f64],
        steps: usize,
        mut obs: impl FnMut(usize, f64, &[f64], &[f64]),
    ) {
        let (n, p, h) = (self.n, self.p, self.map.h);
        let m = self.w0.len();
        let phi = self.map.phi.as_slice();
        let g1e = self.map.g1E.as_slice();
        let g1b = self.map.g1B.as_slice();
        let g2b = self.map.g2B.as_slice();
        let c = self.C.as_slice();
        let linear = self.map.hold == InputHold::Foh;
        self.input.eval(t0, &mut self.w0);
        for k in 0..steps {
            let t1 = t0 + (k + 1) as f64 * h;
            if linear {
                self.input.eval(t1, &mut self.w1);
            }
            for i in 0..n {
                let mut s = 0.0;
                for j in 0..n {
                    s += phi[j * n + i] * x[j];
                }
                for j in 0..p {
                    s += g1e[j * n + i] * z[j];
                }
                for j in 0..m {
                    s += g1b[j * n + i] * self.w0[j];
                    if linear {
                        s += g2b[j * n + i] * (self.w1[j] - self.w0[j]);
                    }
                }
                self.xn[i] = s;
            }
            x.copy_from_slice(&self.xn);
            for i in 0..p {
                let mut s = 0.0;
                for j in 0..n {
                    s += c[j * p + i] * x[j];
                }
                self.y[i] = s;
                self.q[i] = z[i] - s;
            }
            self.theta.project(&self.q, &mut self.pq);
            for i in 0..p {
                z[i] = self.y[i] + self.pq[i];
            }
            if linear {
                std::mem::swap(&mut self.w0, &mut self.w1);
            } else {
                self.input.eval(t1, &mut self.w0);
            }
            obs(k + 1, t1, x, z);
        }
    }
}

/// A convex set usable by the fixed-size fast path.
pub trait FastSet<const P: usize>: Clone {
    /// Metric projection `P_Theta(q)`, eq. (P).
    fn project_fast(&self, q: &SVector<f64, P>) -> SVector<f64, P>;
}

impl FastSet<1> for Interval {
    #[inline(always)]
    fn project_fast(&self, q: &SVector<f64, 1>) -> SVector<f64, 1> {
        SVector::<f64, 1>::new(self.clamp(q[0]))
    }
}

impl<const P: usize> FastSet<P> for Ellipsoid {
    #[inline(always)]
    fn project_fast(&self, q: &SVector<f64, P>) -> SVector<f64, P> {
        let mut o = SVector::<f64, P>::zeros();
        self.project(q.as_slice(), o.as_mut_slice());
        o
    }
}

impl<const P: usize> FastSet<P> for Shape {
    #[inline(always)]
    fn project_fast(&self, q: &SVector<f64, P>) -> SVector<f64, P> {
        if let Shape::Interval(iv) = self {
            let mut o = *q;
            o[0] = iv.clamp(q[0]);
            return o;
        }
        let mut o = SVector::<f64, P>::zeros();
        self.project(q.as_slice(), o.as_mut_slice());
        o
    }
}

#[derive(Debug, Clone)]
enum FastForcing<const N: usize> {
    /// `w = 0`.
    Zero,
    /// `w = a sin(omega t + phase)`: forcing `ga s_k + gd (s_{k+1} - s_k)`.
    Sine { omega: f64, phase: f64, ga: SVector<f64, N>, gd: SVector<f64, N> },
    /// Any input, evaluated once per step.
    General {
        input: Input,
        g1b: Vec<SVector<f64, N>>,
        g2b: Vec<SVector<f64, N>>,
        w0: Vec<f64>,
        w1: Vec<f64>,
        linear: bool,
    },
}

/// Fixed-size catching-up integrator (`N = n`, `P = p`); no allocation in the loop.
#[derive(Debug, Clone)]
pub struct FastCatchingUp<const N: usize, const P: usize, S: FastSet<P>> {
    phi: SMatrix<f64, N, N>,
    g1e: SMatrix<f64, N, P>,
    c: SMatrix<f64, P, N>,
    set: S,
    h: f64,
    forcing: FastForcing<N>,
}

fn to_s<const R: usize, const K: usize>(M: &DMatrix<f64>) -> SMatrix<f64, R, K> {
    SMatrix::<f64, R, K>::from_fn(|i, j| M[(i, j)])
}

impl<const N: usize, const P: usize, S: FastSet<P>> FastCatchingUp<N, P, S> {
    /// Builds the integrator; `set` must be the system's `Theta` (or an equivalent fast set).
    pub fn new(sys: &System, set: S, settings: &CatchingUpSettings) -> Result<Self, DynamicsError> {
        settings.validate()?;
        if sys.n() != N {
            return Err(DynamicsError::Dimension { what: "n (fast path)", expected: N, got: sys.n() });
        }
        if sys.p() != P {
            return Err(DynamicsError::Dimension { what: "p (fast path)", expected: P, got: sys.p() });
        }
        let map = SystemStepMap::for_system(sys, settings.dt, settings.hold)?;
        let linear = settings.hold == InputHold::Foh;
        let forcing = match &sys.input {
            Input::Zero { .. } => FastForcing::Zero,
            Input::Sine { amplitudes, omega, phase } if linear => {
                let a = nalgebra::DVector::from_column_slice(amplitudes);
                FastForcing::Sine {
                    omega: *omega,
                    phase: *phase,
                    ga: SVector::<f64, N>::from_column_slice((&map.g1B * &a).as_slice()),
                    gd: SVector::<f64, N>::from_column_slice((&map.g2B * &a).as_slice()),
                }
            }
            other => {
                let m = other.m();
                FastForcing::General {
                    input: other.clone(),
                    g1b: (0..m).map(|j| to_s(&map.g1B.columns(j, 1).into_owned())).collect(),
                    g2b: (0..m).map(|j| to_s(&map.g2B.columns(j, 1).into_owned())).collect(),
                    w0: vec![0.0; m],
                    w1: vec![0.0; m],
                    linear,
                }
            }
        };
        Ok(Self { phi: to_s(&map.phi), g1e: to_s(&map.g1E), c: to_s(&sys.C), set, h: settings.dt, forcing })
    }
    pub fn h(&self) -> f64 {
        self.h
    }

    /// Advances `steps` steps from `t0` in place, calling `obs(k, t_k, x_k, z_k)` after each.
    #[inline]
    pub fn run<O: FnMut(usize, f64, &SVector<f64, N>, &SVector<f64, P>)>(
        &mut self,
        t0: f64,
        x: &mut SVector<f64, N>,
        z: &mut SVector<f64, P>,
        steps: usize,
        mut obs: O,
    ) {
        let h = self.h;
        match &mut self.forcing {
            FastForcing::Zero => {
                let (phi, g1e) = (self.phi, self.g1e);
                for k in 0..steps {
                    let xn = phi * *x + g1e * *z;
                    let y = self.c * xn;
                    *z = y + self.set.project_fast(&(*z - y));
                    *x = xn;
                    obs(k + 1, t0 + (k + 1) as f64 * h, x, z);
                }
            }
            FastForcing::Sine { omega, phase, ga, gd } => {
                let (phi, g1e, ga, gd) = (self.phi, self.g1e, *ga, *gd);
                let (sw, cw) = (*omega * h).sin_cos();
                let mut k = 0;
                while k < steps {
                    let chunk = SINE_RESEED.min(steps - k);
                    let (mut s, mut c) = (*omega * (t0 + k as f64 * h) + *phase).sin_cos();
                    for j in 0..chunk {
                        let s1 = s * cw + c * sw;
                        let c1 = c * cw - s * sw;
                        let xn = phi * *x + g1e * *z + ga * s + gd * (s1 - s);
                        let y = self.c * xn;
                        *z = y + self.set.project_fast(&(*z - y));
                        *x = xn;
                        s = s1;
                        c = c1;
                        let kk = k + j + 1;
                        obs(kk, t0 + kk as f64 * h, x, z);
                    }
                    k += chunk;
                }
            }
            FastForcing::General { input, g1b, g2b, w0, w1, linear } => {
                input.eval(t0, w0);
                for k in 0..steps {
                    let t1 = t0 + (k + 1) as f64 * h;
                    if *linear {
                        input.eval(t1, w1);
                    }
                    let mut xn = self.phi * *x + self.g1e * *z;
                    for j in 0..w0.len() {
                        xn += g1b[j] * w0[j];
                        if *linear {
                            xn += g2b[j] * (w1[j] - w0[j]);
                        }
                    }
                    let y = self.c * xn;
                    *z = y + self.set.project_fast(&(*z - y));
                    *x = xn;
                    if *linear {
                        std::mem::swap(w0, w1);
                    } else {
                        input.eval(t1, w0);
                    }
                    obs(k + 1, t1, x, z);
                }
            }
        }
    }
}

macro_rules! simulator_enum {
    ($( $var:ident => ($N:literal, $P:literal) ),* $(,)?) => {
        /// A catching-up integrator for a given system: the fixed-size fast path when `(n, p)`
        /// is one of `(2,1) (3,1) (4,1) (4,2) (6,2) (6,3)`, else the dynamic one. Same results.
        #[derive(Debug, Clone)]
        pub enum Simulator {
            $( $var(FastCatchingUp<$N, $P, Shape>), )*
            Dynamic(CatchingUp),
        }

        impl Simulator {
            /// Builds the fastest available integrator for `sys`.
            pub fn new(sys: &System, settings: &CatchingUpSettings) -> Result<Self, DynamicsError> {
                match (sys.n(), sys.p()) {
                    $( ($N, $P) => Ok(Simulator::$var(FastCatchingUp::new(sys, sys.theta.clone(), settings)?)), )*
                    _ => Ok(Simulator::Dynamic(CatchingUp::new(sys, settings)?)),
                }
            }
            /// Only the dynamic-size implementation (for tests and comparisons).
            pub fn new_dynamic(sys: &System, settings: &CatchingUpSettings) -> Result<Self, DynamicsError> {
                Ok(Simulator::Dynamic(CatchingUp::new(sys, settings)?))
            }
            pub fn is_fast(&self) -> bool {
                !matches!(self, Simulator::Dynamic(_))
            }
            pub fn h(&self) -> f64 {
                match self {
                    $( Simulator::$var(s) => s.h(), )*
                    Simulator::Dynamic(s) => s.h(),
                }
            }
            /// Advances `steps` steps from time `t0` in place (`x` of length n, `z` of length p),
            /// calling `obs(k, t_k, x_k, z_k)` after each step `k = 1..=steps`.
            pub fn run(&mut self, t0: f64, x: &mut [f64], z: &mut [f64], steps: usize, mut obs: impl FnMut(usize, f64, &[f64], &[f64])) {
                match self {
                    $( Simulator::$var(s) => {
                        let mut xs = SVector::<f64, $N>::from_column_slice(x);
                        let mut zs = SVector::<f64, $P>::from_column_slice(z);
                        s.run(t0, &mut xs, &mut zs, steps, |k, t, a, b| obs(k, t, a.as_slice(), b.as_slice()));
                        x.copy_from_slice(xs.as_slice());
                        z.copy_from_slice(zs.as_slice());
                    } )*
                    Simulator::Dynamic(s) => s.run(t0, x, z, steps, obs),
                }
            }
        }
    };
}

simulator_enum!(F21 => (2, 1), F31 => (3, 1), F41 => (4, 1), F42 => (4, 2), F62 => (6, 2), F63 => (6, 3));

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn worked() -> System {
        model::parse_str(include_str!("../../../../examples/worked-example.toml")).unwrap()
    }

    fn run_both(sys: &System, hold: InputHold, steps: usize) -> (Vec<f64>, Vec<f64>) {
        let st = CatchingUpSettings { dt: 1e-3, hold };
        let mut fast = Simulator::new(sys, &st).unwrap();
        let mut dynm = Simulator::new_dynamic(sys, &st).unwrap();
        assert!(fast.is_fast() && !dynm.is_fast());
        let (mut x1, mut z1) = (sys.x0.as_slice().to_vec(), sys.z0.as_slice().to_vec());
        let (mut x2, mut z2) = (x1.clone(), z1.clone());
        fast.run(0.0, &mut x1, &mut z1, steps, |_, _, _, _| {});
        dynm.run(0.0, &mut x2, &mut z2, steps, |_, _, _, _| {});
        x1.extend(z1);
        x2.extend(z2);
        (x1, x2)
    }

    #[test]
    fn fast_and_dynamic_paths_agree() {
        let sys = worked();
        for hold in [InputHold::Foh, InputHold::Zoh] {
            let (a, b) = run_both(&sys, hold, 20_000);
            for (u, v) in a.iter().zip(&b) {
                assert!((u - v).abs() < 1e-10, "{hold:?}: {a:?} vs {b:?}");
            }
        }
        let ell = model::parse_str(include_str!("../../../../examples/ellipse-p2.toml")).unwrap();
        let (a, b) = run_both(&ell, InputHold::Foh, 20_000);
        for (u, v) in a.iter().zip(&b) {
            assert!((u - v).abs() < 1e-10, "{a:?} vs {b:?}");
        }
    }

    #[test]
    fn constraint_z_minus_y_in_theta_holds_at_every_step() {
        let sys = model::parse_str(include_str!("../../../../examples/ellipse-p2.toml")).unwrap();
        let mut sim = Simulator::new(&sys, &CatchingUpSettings::default()).unwrap();
        let (mut x, mut z) = (sys.x0.as_slice().to_vec(), sys.z0.as_slice().to_vec());
        let C = sys.C.clone();
        let mut worst: f64 = 0.0;
        let mut moved = 0.0;
        let mut zprev = z.clone();
        sim.run(0.0, &mut x, &mut z, 30_000, |_, _, x, z| {
            let q = nalgebra::DVector::from_column_slice(z) - &C * nalgebra::DVector::from_column_slice(x);
            let pq = geometry::convex_set::project_vec(&sys.theta, q.as_slice());
            worst = worst.max(geometry::linalg::dist(q.as_slice(), &pq));
            moved += geometry::linalg::dist(z, &zprev);
            zprev.copy_from_slice(z);
        });
        assert!(worst < 1e-12, "q left Theta by {worst}");
        assert!(moved > 0.1, "the backlash must actually move (path {moved})");
    }

    /// Theta = {0}: the scheme reduces to the exact linear system x' = F x + B w up to O(h).
    #[test]
    fn point_backlash_reduces_to_the_linearised_system() {
        let mut sys = worked();
        sys.theta = Shape::origin(1);
        sys.z0 = &sys.C * &sys.x0;
        sys.x0 = nalgebra::DVector::from_vec(vec![0.5, 0.0]);
        sys.z0 = &sys.C * &sys.x0;
        let h = 1e-4;
        let mut sim = Simulator::new(&sys, &CatchingUpSettings { dt: h, hold: InputHold::Foh }).unwrap();
        let (mut x, mut z) = (sys.x0.as_slice().to_vec(), sys.z0.as_slice().to_vec());
        let steps = 50_000;
        sim.run(0.0, &mut x, &mut z, steps, |_, _, _, _| {});
        // reference: x' = F x + B sin t with the exact step map on a fine grid
        let F = sys.F();
        let sm = crate::linear::step_map::SystemStepMap::new(&F, &sys.B, &sys.E, 1e-3, InputHold::Foh).unwrap();
        let mut xr = sys.x0.clone();
        for k in 0..5000 {
            let (t0, t1) = (k as f64 * 1e-3, (k + 1) as f64 * 1e-3);
            xr = &sm.phi * &xr + &sm.g1B * t0.sin() + &sm.g2B * (t1.sin() - t0.sin());
        }
        assert_relative_eq!(x[0], xr[0], epsilon = 1e-3);
        assert_relative_eq!(x[1], xr[1], epsilon = 1e-3);
        assert!((x[0] - xr[0]).abs() > 1e-9, "z lags by one step: not exact");
    }
}
