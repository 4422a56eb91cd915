//! The record of a run: a sampled trajectory `(t, w, x, y, z, q)` of the closed loop and its
//! CSV form. The bottom of the simulators: every integrator and the extended model write
//! into a [`Trajectory`]; simulating into one is [`crate::trajectory`].

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
