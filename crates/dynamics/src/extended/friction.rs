//! Friction on one velocity state `x_j`, a set-valued law: at rest `f in [-S_+, S_-]` (the
//! static, breakaway levels; `S = level` for Coulomb), sliding in direction `d`
//! `f = -d L_d(|v|)` with the sliding curve `L_d(u) = c_d + sum_i (s_i - c) exp(-(u / v_i)^2)
//! + viscous u` (Stribeck). Several friction effects on one state add up into one
//! `Friction` (`coulomb_friction`, `asymmetric_coulomb`, `stribeck_friction`; registered by
//! [`super::forces`]).
//!
//! Resolved implicitly per step (Moreau-Jean time stepping): with `a` the velocity reached
//! without friction and `g = Psi_jj`, the state sticks (`x_j = 0`, `f = -a / g`) when
//! `-g S_- <= a <= g S_+`, otherwise it slides with the `u > 0` solving `u + g L_d(u) = |a|`
//! (closed form for Coulomb levels, safeguarded Newton on the bracket
//! `[(|a| - g S_d), (|a| - g c_d)] / (1 + g viscous)` otherwise), `f = -d L_d(u)`. Static
//! friction is thus the breakaway threshold from rest, the Stribeck curve the force while
//! sliding, and a mass that slows down to zero is caught by the static level.
//!
//! A load-dependent term (`load_friction`) raises every level of the step by
//! `k |d - e|`, the load the transmission carries at the step's start ([`LoadRows`]).

/// Friction on one velocity state (see the module documentation): Coulomb levels per
/// direction, Stribeck excess terms and a viscous increment.
#[derive(Debug, Clone)]
pub(super) struct Friction {
    pub(super) state: usize,
    /// Sliding (Coulomb) level while moving up / down.
    pos: f64,
    neg: f64,
    /// Stribeck terms `(s_i - c, 1 / v_i)`.
    excess: Vec<(f64, f64)>,
    /// `sum_i (s_i - c)`: static levels are `pos + static_extra`, `neg + static_extra`.
    static_extra: f64,
    viscous: f64,
    /// The load-dependent term: its coefficient (summed over the effects) and rows.
    load: Option<(f64, LoadRows)>,
}

/// The rows of the load on velocity state `x_j` that a transmission carries (`load_friction`):
/// `d - e` with `d = B_j w + E_j z` (the actuator's force on `x_j'`) and
/// `e = sum_{i != j} A_ji x_i` (the plant's own forces on it).
#[derive(Debug, Clone)]
pub(super) struct LoadRows {
    /// `A_ji` for `i != j`, 0 at `i = j` (length n).
    pub(super) a: Vec<f64>,
    /// `B_j` (length m).
    pub(super) b: Vec<f64>,
    /// `E_j` (length p).
    pub(super) e: Vec<f64>,
}

impl LoadRows {
    /// `|d - e|` at state `x`, held input `w` and loop output `z`.
    #[inline]
    fn load(&self, x: &[f64], w: &[f64], z: &[f64]) -> f64 {
        let dot = |r: &[f64], v: &[f64]| r.iter().zip(v).map(|(a, b)| a * b).sum::<f64>();
        (dot(&self.b, w) + dot(&self.e, z) - dot(&self.a, x)).abs()
    }
}

impl Friction {
    /// No friction yet on `state`.
    pub(super) fn new(state: usize) -> Self {
        Self { state, pos: 0.0, neg: 0.0, excess: Vec::new(), static_extra: 0.0, viscous: 0.0, load: None }
    }

    /// Adds a load-dependent term `coefficient |d - e|` (rows `rows`) to every level.
    pub(super) fn add_load(&mut self, coefficient: f64, rows: LoadRows) {
        let k = self.load.as_ref().map_or(0.0, |(k, _)| *k);
        self.load = Some((k + coefficient, rows));
    }

    /// The level the load adds over a step starting at `x` with input `w` and output `z`.
    #[inline]
    pub(super) fn load_level(&self, x: &[f64], w: &[f64], z: &[f64]) -> f64 {
        self.load.as_ref().map_or(0.0, |(k, rows)| k * rows.load(x, w, z))
    }

    /// Adds sliding levels `pos` (moving up) and `neg` (moving down).
    pub(super) fn add_coulomb(&mut self, pos: f64, neg: f64) {
        self.pos += pos;
        self.neg += neg;
    }

    /// Adds a Stribeck term: the static level `excess > 0` above the sliding level, decaying
    /// with speed on the scale `stribeck_velocity`.
    pub(super) fn add_stribeck(&mut self, excess: f64, stribeck_velocity: f64) {
        self.excess.push((excess, 1.0 / stribeck_velocity));
        self.static_extra += excess;
    }

    /// Adds a viscous increment `viscous u` to the sliding curve.
    pub(super) fn add_viscous(&mut self, viscous: f64) {
        self.viscous += viscous;
    }

    /// Sliding level at speed `u >= 0` above the Coulomb level `c`, and its derivative.
    #[inline]
    fn curve(&self, u: f64) -> (f64, f64) {
        let (mut l, mut dl) = (self.viscous * u, self.viscous);
        for &(ds, iv) in &self.excess {
            let r = u * iv;
            let e = ds * (-r * r).exp();
            l += e;
            dl -= 2.0 * r * iv * e;
        }
        (l, dl)
    }

    /// The friction force over a step whose friction-free end velocity is `a`, with
    /// `g = Psi_jj` (implicit: the end velocity is `a + g f`), every level raised by `extra`
    /// (the load's, [`Friction::load_level`]), and whether the state sticks.
    #[inline]
    pub(super) fn force(&self, a: f64, g: f64, extra: f64) -> (f64, bool) {
        let (pos, neg) = (self.pos + extra, self.neg + extra);
        let (s_pos, s_neg) = (pos + self.static_extra, neg + self.static_extra);
        if a <= g * s_pos && a >= -g * s_neg {
            // Sticks (the static levels hold the remaining force).
            return (-a / g, true);
        }
        let (d, c) = if a > 0.0 { (1.0, pos) } else { (-1.0, neg) };
        if self.excess.is_empty() && self.viscous == 0.0 {
            return (-c * d, false);
        }
        // Slides: u + g (c + curve(u)) = |a|, u in [lo, hi].
        let t = a.abs();
        let den = 1.0 + g * self.viscous;
        let (mut lo, mut hi) = (((t - g * (c + self.static_extra)) / den).max(0.0), ((t - g * c) / den).max(0.0));
        let phi = |u: f64| {
            let (l, dl) = self.curve(u);
            (u + g * (c + l) - t, 1.0 + g * dl)
        };
        let mut u = hi;
        for _ in 0..60 {
            let (r, dr) = phi(u);
            if r == 0.0 {
                break;
            }
            if r > 0.0 {
                hi = u;
            } else {
                lo = u;
            }
            let mut un = u - r / dr;
            if !(dr > 0.0 && un > lo && un < hi) {
                un = 0.5 * (lo + hi);
            }
            if (un - u).abs() <= 1e-15 * (1.0 + u.abs()) || hi - lo <= 1e-15 * (1.0 + hi) {
                u = un;
                break;
            }
            u = un;
        }
        let (l, _) = self.curve(u);
        (-d * (c + l), false)
    }
}
