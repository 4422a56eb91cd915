//! Shared machinery of the properties that run the closed loop: the catching-up scheme of
//! `dynamics` (`z_{k+1} = P_{y_{k+1} + Theta}(z_k)`) and exact linear responses for sine inputs.
//! Tube support functions (eqs. (Xsupp), (Xinfsupp)) come from the production kernels of
//! `bounds::tube`, not from a copy here.
use dynamics::integrators::catching_up::{CatchingUp, CatchingUpSettings};
use model::System;
use nalgebra::{DMatrix, DVector};

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
