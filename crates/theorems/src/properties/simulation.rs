//! Shared machinery of the properties that run the closed loop: the catching-up scheme of
//! `dynamics` (`z_{k+1} = P_{y_{k+1} + Theta}(z_k)`), the support function of `Xi(t)` and
//! `Xi_inf` (eqs. (Xsupp), (Xinfsupp)) by trapezoid quadrature of `sigma_Theta(E^T e^{sF^T} u)`,
//! and certified maxima over the unit sphere (`geometry::sphere_max`).
use dynamics::integrators::catching_up::{CatchingUp, CatchingUpSettings};
use geometry::ConvexSet;
use model::System;
use nalgebra::{DMatrix, DVector};

/// Quadrature nodes `(e^{s_k F} E)^T`, `s_k = k ds`, up to `t_max` (or until `|e^{sF}| < 1e-14`),
/// with `int_0^{s} |e^{rF}| dr` alongside (for Lipschitz constants).
pub struct XiNodes {
    pub ds: f64,
    pub nodes: Vec<DMatrix<f64>>,
    /// Trapezoid value of `int_0^inf ||e^{sF}||_2 ds` over the nodes.
    pub int_norm: f64,
}

impl XiNodes {
    pub fn new(sys: &System, ds: f64, t_max: f64) -> Self {
        let F = sys.F();
        let step = (&F * ds).exp();
        let n = sys.n();
        let mut P = DMatrix::<f64>::identity(n, n);
        let mut nodes = Vec::new();
        let mut int_norm = 0.0;
        let mut s = 0.0;
        while s <= t_max + 0.5 * ds {
            nodes.push((&P * &sys.E).transpose());
            let nm = P.norm();
            int_norm += nm * ds;
            if nm < 1e-14 {
                break;
            }
            P = &step * &P;
            s += ds;
        }
        Self { ds, nodes, int_norm }
    }
    /// `sigma_{Xi(t)}(u) = int_0^t sigma_Theta(E^T e^{sF^T} u) ds` (eq. (Xsupp)) by the
    /// trapezoid rule on the nodes with `s <= t` (`t = inf`: all nodes, eq. (Xinfsupp)).
    pub fn support(&self, theta: &geometry::Shape, u: &[f64], t: f64) -> f64 {
        let u = DVector::from_column_slice(u);
        let k = if t.is_finite() {
            ((t / self.ds).floor().max(0.0) as usize).saturating_add(1).min(self.nodes.len())
        } else {
            self.nodes.len()
        };
        let mut s = 0.0;
        for (i, M) in self.nodes[..k].iter().enumerate() {
            let f = theta.support((M * &u).as_slice());
            s += if i == 0 || i + 1 == k { 0.5 * f } else { f };
        }
        s * self.ds
    }
}

/// Runs the catching-up scheme from `(x, z)` at time `t0` for `steps` steps of `dt`, calling
/// `obs(t, x, z)` after every step.
pub fn simulate(
    sys: &System,
    dt: f64,
    t0: f64,
    x: &mut [f64],
    z: &mut [f64],
    steps: usize,
    mut obs: impl FnMut(f64, &[f64], &[f64]),
) -> bool {
    let Ok(mut cu) = CatchingUp::new(sys, &CatchingUpSettings { dt, ..Default::default() }) else { return false };
    cu.run(t0, x, z, steps, |_, t, x, z| obs(t, x, z));
    true
}

/// Operator 2-norm.
pub fn op_norm(M: &DMatrix<f64>) -> f64 {
    if M.is_empty() {
        0.0
    } else {
        M.clone().singular_values().max()
    }
}

/// Exact solution of `x' = M x + B w(t)`, `x(0) = x0`, at `t_k = k h`, `k = 0..=steps`, for a
/// sine (or zero) input: one augmented exponential of `[[M, B a, 0], [0, 0, omega], [0, -omega, 0]]`
/// on the state `[x; sin(omega t + phase); cos(omega t + phase)]`. `M = A` gives `x_*` (eq. (xz0)),
/// `M = F` gives `xi` (eq. (xi)). `None` for other inputs.
pub fn linear_response_exact(sys: &System, M: &DMatrix<f64>, h: f64, steps: usize) -> Option<Vec<DVector<f64>>> {
    let n = sys.n();
    let (a, omega, phase) = match &sys.input {
        model::Input::Sine { amplitudes, omega, phase } => (DVector::from_column_slice(amplitudes), *omega, *phase),
        model::Input::Zero { m } => (DVector::zeros(*m), 0.0, 0.0),
        _ => return None,
    };
    let mut G = DMatrix::<f64>::zeros(n + 2, n + 2);
    G.view_mut((0, 0), (n, n)).copy_from(M);
    G.view_mut((0, n), (n, 1)).copy_from(&(&sys.B * a));
    G[(n, n + 1)] = omega;
    G[(n + 1, n)] = -omega;
    let step = (G * h).exp();
    let mut s = DVector::<f64>::zeros(n + 2);
    s.rows_mut(0, n).copy_from(&sys.x0);
    s[n] = phase.sin();
    s[n + 1] = phase.cos();
    let mut out = Vec::with_capacity(steps + 1);
    for k in 0..=steps {
        if k > 0 {
            s = &step * &s;
        }
        out.push(s.rows(0, n).into_owned());
    }
    Some(out)
}

/// The nodes of [`XiNodes`] right-multiplied by a fixed `K` (`n x r`, `r <= 4`): the support
/// function `v -> sigma_{Xi_inf}(K v)` without a matrix-vector product per node and call.
pub struct MappedNodes {
    pub ds: f64,
    /// `(e^{s_i F} E)^T K`, `p x r` each.
    pub mats: Vec<DMatrix<f64>>,
}

impl XiNodes {
    pub fn mapped(&self, K: &DMatrix<f64>) -> MappedNodes {
        MappedNodes { ds: self.ds, mats: self.nodes.iter().map(|M| M * K).collect() }
    }
}

impl MappedNodes {
    /// `sigma_{Xi_inf}(K v)` by the trapezoid rule over all nodes (as [`XiNodes::support`] with `t = inf`).
    pub fn support(&self, theta: &geometry::Shape, v: &[f64]) -> f64 {
        let k = self.mats.len();
        let mut buf = [0.0f64; 4];
        let mut s = 0.0;
        for (i, M) in self.mats.iter().enumerate() {
            let (p, r) = M.shape();
            for a in 0..p {
                buf[a] = (0..r).map(|b| M[(a, b)] * v[b]).sum();
            }
            let f = theta.support(&buf[..p]);
            s += if i == 0 || i + 1 == k { 0.5 * f } else { f };
        }
        s * self.ds
    }
}
