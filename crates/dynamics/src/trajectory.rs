//! A recorded trajectory `(t, w, x, y, z, q)` of the closed loop and its CSV form.
use crate::error::DynamicsError;
use crate::integrators::catching_up::{CatchingUpSettings, Simulator};
use model::System;

/// Samples of a trajectory, stored row by row (`x` has `n` entries per sample, etc.).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Trajectory {
    pub n: usize,
    pub m: usize,
    pub p: usize,
    pub t: Vec<f64>,
    pub w: Vec<f64>,
    pub x: Vec<f64>,
    pub z: Vec<f64>,
    /// Sensor offset added to `C x` in [`Trajectory::y_at`] (empty: none; models with a
    /// `sensor_offset` effect).
    pub y_offset: Vec<f64>,
}

impl Trajectory {
    pub fn new(n: usize, m: usize, p: usize) -> Self {
        Self { n, m, p, ..Default::default() }
    }
    pub fn len(&self) -> usize {
        self.t.len()
    }
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }
    pub fn push(&mut self, t: f64, w: &[f64], x: &[f64], z: &[f64]) {
        self.t.push(t);
        self.w.extend_from_slice(w);
        self.x.extend_from_slice(x);
        self.z.extend_from_slice(z);
    }
    pub fn x_at(&self, i: usize) -> &[f64] {
        &self.x[i * self.n..(i + 1) * self.n]
    }
    pub fn z_at(&self, i: usize) -> &[f64] {
        &self.z[i * self.p..(i + 1) * self.p]
    }
    pub fn w_at(&self, i: usize) -> &[f64] {
        &self.w[i * self.m..(i + 1) * self.m]
    }
    /// `y = C x` (plus the sensor offset, if any) at sample `i`.
    pub fn y_at(&self, C: &nalgebra::DMatrix<f64>, i: usize) -> Vec<f64> {
        let mut y = (C * nalgebra::DVector::from_column_slice(self.x_at(i))).as_slice().to_vec();
        for (a, o) in y.iter_mut().zip(&self.y_offset) {
            *a += o;
        }
        y
    }
    /// CSV with header `t,w1..,x1..,y1..,z1..,q1..` (`q = z - y`), full precision.
    pub fn to_csv(&self, C: &nalgebra::DMatrix<f64>) -> String {
        let mut s = String::from("t");
        for (name, k) in [("w", self.m), ("x", self.n), ("y", self.p), ("z", self.p), ("q", self.p)] {
            for i in 1..=k {
                s.push_str(&format!(",{name}{i}"));
            }
        }
        s.push('\n');
        for i in 0..self.len() {
            let y = self.y_at(C, i);
            let z = self.z_at(i);
            let q: Vec<f64> = z.iter().zip(&y).map(|(a, b)| a - b).collect();
            s.push_str(&format!("{:e}", self.t[i]));
            for v in self.w_at(i).iter().chain(self.x_at(i)).chain(&y).chain(z).chain(&q) {
                s.push_str(&format!(",{v:e}"));
            }
            s.push('\n');
        }
        s
    }
}

/// Simulates `sys` for `steps` steps of `h` from `(sys.x0, sys.z0)`, recording every
/// `record_every`-th state (and the first and last): the catching-up scheme for a model of the
/// paper's class, the extended model ([`crate::extended::simulate_trajectory`]) when the model
/// has `[[effects]]`. The one entry point of every command that simulates a model file.
pub fn simulate_model(sys: &System, h: f64, steps: usize, record_every: usize) -> Result<Trajectory, DynamicsError> {
    if sys.effects.list.is_empty() {
        simulate_catching_up(sys, &CatchingUpSettings { dt: h, ..Default::default() }, steps, record_every)
    } else {
        crate::extended::simulate_trajectory(sys, h, steps, record_every)
    }
}

/// Simulates `steps` catching-up steps from `(sys.x0, sys.z0)` at `t = 0`, recording every
/// `record_every`-th state (and the first). Ignores `[[effects]]`: use [`simulate_model`] for
/// model files.
pub fn simulate_catching_up(
    sys: &System,
    settings: &CatchingUpSettings,
    steps: usize,
    record_every: usize,
) -> Result<Trajectory, DynamicsError> {
    let mut sim = Simulator::new(sys, settings)?;
    let every = record_every.max(1);
    let mut tr = Trajectory::new(sys.n(), sys.m(), sys.p());
    let (mut x, mut z) = (sys.x0.as_slice().to_vec(), sys.z0.as_slice().to_vec());
    let mut w = vec![0.0; sys.m()];
    sys.input.eval(0.0, &mut w);
    tr.push(0.0, &w, &x, &z);
    let mut bad = None;
    sim.run(0.0, &mut x, &mut z, steps, |k, t, x, z| {
        if k % every == 0 || k == steps {
            sys.input.eval(t, &mut w);
            if bad.is_none() && !(x.iter().chain(z).all(|v| v.is_finite())) {
                bad = Some(t);
            }
            tr.push(t, &w, x, z);
        }
    });
    if let Some(t) = bad {
        return Err(DynamicsError::NonFinite { t });
    }
    Ok(tr)
}
