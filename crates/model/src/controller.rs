//! `[controller]`: a digital controller in the loop, at its own sample period, as the machine
//! runs it. With a controller the plant `x' = A x + B u + E z` is driven by the controller's
//! output `u` (held constant between ticks, zero-order hold), the controller samples the
//! measured output `y` at its ticks, and the recording's `w` is the reference:
//!
//! ```toml
//! [controller]
//! period = 1e-3        # s, the controller's sample period (a multiple of the sample spacing)
//! delay = 1            # computation delay in controller periods (a non-negative integer)
//! kind = "cascade"     # cascade | pid | state_space
//! kp = 60.0            # cascade: position gain (1/s)
//! kv = 400.0           #          velocity gain (force per velocity)
//! ki = 0.0             #          velocity integral gain (force per position), optional
//! velocity_filter = 0  #          time constant (s) of a low-pass on the velocity estimate
//! ```
//!
//! The laws, with `T` the period, `k` the tick, `w` the reference and `y` the sampled output:
//! - `cascade` (position P, velocity PI, `m = p = 1`): `v_k = a v_{k-1} + (1 - a)(y_k -
//!   y_{k-1}) / T` (the difference of two samples, low-passed with `a = exp(-T / tau)`,
//!   `tau = velocity_filter`, `a = 0` without filter), `e_k = kp (w_k - y_k) - v_k`,
//!   `u_k = kv e_k + ki I_k`, `I_{k+1} = I_k + T e_k`;
//! - `pid` (`m = p = 1`): `e_k = w_k - y_k`, `d_k = a d_{k-1} + (1 - a)(e_k - e_{k-1}) / T`
//!   (`a = exp(-T / derivative_filter)`), `u_k = kp e_k + ki I_k + kd d_k`, `I_{k+1} = I_k +
//!   T e_k`;
//! - `state_space`: `x_c[k+1] = Ac x_c[k] + Bc e[k]`, `u[k] = Cc x_c[k] + Dc e[k]` with
//!   `e = [w; y]` (the `m` references, then the `p` sampled outputs: `Bc`, `Dc` have `m + p`
//!   columns; an error law `e = w - y` is `Bc = [B1, -B1]`), optional start `x0` (default 0).
//!
//! The first two are compiled to the third ([`Controller::law`]); their memories start at the
//! first samples (`y_{-1} = y_0`, `e_{-1} = e_0`), so the first tick sees no velocity kick.
//! With a computation delay of `d` periods, the output computed at tick `k` drives the plant
//! from tick `k + d` on (0 before the first). Every number may be an expression of
//! `[parameters]` (`kv = "gtau*kv0/M"`).
use crate::toml_access::*;
use crate::ModelError;
use nalgebra::DMatrix;
use toml::{Table, Value};

/// The form of a controller's law.
#[derive(Debug, Clone, PartialEq)]
pub enum ControlLaw {
    /// Position P + velocity PI on a difference-based velocity estimate.
    Cascade { kp: f64, kv: f64, ki: f64, velocity_filter: f64 },
    /// PID on `e = w - y` with a filtered difference-based derivative.
    Pid { kp: f64, ki: f64, kd: f64, derivative_filter: f64 },
    /// `x_c+ = Ac x_c + Bc [w; y]`, `u = Cc x_c + Dc [w; y]`, from `x0`.
    StateSpace { Ac: DMatrix<f64>, Bc: DMatrix<f64>, Cc: DMatrix<f64>, Dc: DMatrix<f64>, x0: Vec<f64> },
}

/// A digital controller (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct Controller {
    /// Sample period `T` (s), positive and finite.
    pub period: f64,
    /// Computation delay in periods.
    pub delay: usize,
    pub law: ControlLaw,
}

/// The discrete state-space form of a law (matrices with `nc` = rows of `Ac`, which may be 0).
#[derive(Debug, Clone, PartialEq)]
pub struct StateSpaceLaw {
    pub Ac: DMatrix<f64>,
    pub Bc: DMatrix<f64>,
    pub Cc: DMatrix<f64>,
    pub Dc: DMatrix<f64>,
    /// Which state starts at which input: `x_c[0][i] = e_0[j]` for `(i, j)` listed, the other
    /// states at `x0`.
    pub memory: Vec<(usize, usize)>,
    pub x0: Vec<f64>,
}

impl StateSpaceLaw {
    /// The start state for the first input `e0 = [w_0; y_0]`.
    pub fn start(&self, e0: &[f64]) -> Vec<f64> {
        let mut x = self.x0.clone();
        for &(i, j) in &self.memory {
            x[i] = e0[j];
        }
        x
    }
}

const KEYS: &str = "period, delay, kind, kp, kv, ki, kd, velocity_filter, derivative_filter, Ac, Bc, Cc, Dc, x0";

/// The law without its last state (the integrator) when `ki = 0`: that state never reaches the
/// output, and its eigenvalue 1 would make the closed loop look marginally stable.
fn without_unused_integrator(law: StateSpaceLaw, ki: f64) -> StateSpaceLaw {
    if ki != 0.0 {
        return law;
    }
    let k = law.Ac.nrows() - 1;
    StateSpaceLaw {
        Ac: law.Ac.view((0, 0), (k, k)).into_owned(),
        Bc: law.Bc.rows(0, k).into_owned(),
        Cc: law.Cc.columns(0, k).into_owned(),
        Dc: law.Dc,
        memory: law.memory,
        x0: law.x0[..k].to_vec(),
    }
}

fn filter_coeff(period: f64, tau: f64) -> f64 {
    if tau > 0.0 {
        (-period / tau).exp()
    } else {
        0.0
    }
}

impl Controller {
    /// The kind as the model file names it.
    pub fn kind(&self) -> &'static str {
        match self.law {
            ControlLaw::Cascade { .. } => "cascade",
            ControlLaw::Pid { .. } => "pid",
            ControlLaw::StateSpace { .. } => "state_space",
        }
    }

    /// The law in state-space form (cascade and PID compiled; see the module documentation).
    pub fn law(&self) -> StateSpaceLaw {
        let T = self.period;
        match &self.law {
            ControlLaw::Cascade { kp, kv, ki, velocity_filter } => {
                // x_c = [y_prev, v_prev, I], e = [w, y]
                let a = filter_coeff(T, *velocity_filter);
                let b = (1.0 - a) / T;
                // e_v = kp w - (kp + b) y + b y_prev - a v_prev
                let ev_x = [b, -a, 0.0];
                let ev_e = [*kp, -(kp + b)];
                let Ac = DMatrix::from_row_slice(
                    3,
                    3,
                    &[0.0, 0.0, 0.0, -b, a, 0.0, T * ev_x[0], T * ev_x[1], 1.0 + T * ev_x[2]],
                );
                let Bc = DMatrix::from_row_slice(3, 2, &[0.0, 1.0, 0.0, b, T * ev_e[0], T * ev_e[1]]);
                let Cc = DMatrix::from_row_slice(1, 3, &[kv * ev_x[0], kv * ev_x[1], *ki]);
                let Dc = DMatrix::from_row_slice(1, 2, &[kv * ev_e[0], kv * ev_e[1]]);
                without_unused_integrator(StateSpaceLaw { Ac, Bc, Cc, Dc, memory: vec![(0, 1)], x0: vec![0.0; 3] }, *ki)
            }
            ControlLaw::Pid { kp, ki, kd, derivative_filter } => {
                // x_c = [e_prev, d_prev, I], e = w - y
                let a = filter_coeff(T, *derivative_filter);
                let b = (1.0 - a) / T;
                let Ac = DMatrix::from_row_slice(3, 3, &[0.0, 0.0, 0.0, -b, a, 0.0, 0.0, 0.0, 1.0]);
                let Bc = DMatrix::from_row_slice(3, 2, &[1.0, -1.0, b, -b, T, -T]);
                let Cc = DMatrix::from_row_slice(1, 3, &[-kd * b, kd * a, *ki]);
                let g = kp + kd * b;
                let Dc = DMatrix::from_row_slice(1, 2, &[g, -g]);
                // e_prev starts at e_0 = w_0 - y_0 (set by `Controller::start_state`)
                without_unused_integrator(StateSpaceLaw { Ac, Bc, Cc, Dc, memory: vec![], x0: vec![0.0; 3] }, *ki)
            }
            ControlLaw::StateSpace { Ac, Bc, Cc, Dc, x0 } => StateSpaceLaw {
                Ac: Ac.clone(),
                Bc: Bc.clone(),
                Cc: Cc.clone(),
                Dc: Dc.clone(),
                memory: vec![],
                x0: x0.clone(),
            },
        }
    }

    /// The start state of the compiled law for the first input `e0 = [w_0; y_0]`.
    pub fn start_state(&self, e0: &[f64]) -> Vec<f64> {
        let law = self.law();
        let mut x = law.start(e0);
        if let ControlLaw::Pid { .. } = self.law {
            x[0] = e0[0] - e0[1];
        }
        x
    }

    /// Reads `[controller]` for a plant with `m` inputs and `p` outputs.
    pub(crate) fn parse(t: &Table, m: usize, p: usize) -> Result<Self, ModelError> {
        let pre = "controller";
        check_keys(t, pre, KEYS)?;
        let period = f64_at(t, pre, "period")?;
        let delay = match t.get("delay") {
            None => 0,
            Some(v) => {
                let d = number(v, "controller.delay")?;
                if d < 0.0 || d.fract() != 0.0 || d > 1e6 {
                    return Err(ModelError::Invalid {
                        key: "controller.delay".into(),
                        value: d,
                        reason: "the computation delay must be a non-negative integer number of controller periods (at most 1e6)".into(),
                    });
                }
                d as usize
            }
        };
        let kind = str_at(t, pre, "kind")?;
        let allowed = |keys: &'static str| check_keys(t, pre, keys);
        let opt = |k: &str| -> Result<f64, ModelError> { Ok(opt_f64(t, pre, k)?.unwrap_or(0.0)) };
        let law = match kind {
            "cascade" => {
                allowed("period, delay, kind, kp, kv, ki, velocity_filter")?;
                ControlLaw::Cascade {
                    kp: f64_at(t, pre, "kp")?,
                    kv: f64_at(t, pre, "kv")?,
                    ki: opt("ki")?,
                    velocity_filter: opt("velocity_filter")?,
                }
            }
            "pid" => {
                allowed("period, delay, kind, kp, ki, kd, derivative_filter")?;
                ControlLaw::Pid {
                    kp: f64_at(t, pre, "kp")?,
                    ki: opt("ki")?,
                    kd: opt("kd")?,
                    derivative_filter: opt("derivative_filter")?,
                }
            }
            "state_space" => {
                allowed("period, delay, kind, Ac, Bc, Cc, Dc, x0")?;
                let Dc = matrix_at(t, pre, "Dc", false)?;
                let (Ac, Bc, Cc) = if t.contains_key("Ac") || t.contains_key("Bc") || t.contains_key("Cc") {
                    (matrix_at(t, pre, "Ac", false)?, matrix_at(t, pre, "Bc", false)?, matrix_at(t, pre, "Cc", false)?)
                } else {
                    (DMatrix::zeros(0, 0), DMatrix::zeros(0, Dc.ncols()), DMatrix::zeros(Dc.nrows(), 0))
                };
                let x0 = if t.contains_key("x0") { vec_at(t, pre, "x0")? } else { vec![0.0; Ac.nrows()] };
                ControlLaw::StateSpace { Ac, Bc, Cc, Dc, x0 }
            }
            other => {
                return Err(ModelError::WrongType {
                    key: "controller.kind".into(),
                    expected: "one of cascade, pid, state_space",
                    found: format!("{other:?}"),
                })
            }
        };
        let c = Controller { period, delay, law };
        c.validate(m, p)?;
        Ok(c)
    }

    /// Checks the period, the filters and the dimensions against a plant with `m` inputs and
    /// `p` outputs; the error names the key and the value.
    pub fn validate(&self, m: usize, p: usize) -> Result<(), ModelError> {
        if !(self.period > 0.0 && self.period.is_finite()) {
            return Err(ModelError::Invalid {
                key: "controller.period".into(),
                value: self.period,
                reason: "the sample period must be positive and finite".into(),
            });
        }
        let nonneg = |k: &str, v: f64| -> Result<(), ModelError> {
            if v >= 0.0 && v.is_finite() {
                Ok(())
            } else {
                Err(ModelError::Invalid {
                    key: format!("controller.{k}"),
                    value: v,
                    reason: "a filter time constant must be non-negative and finite (0: no filter)".into(),
                })
            }
        };
        let siso = |kind: &str| -> Result<(), ModelError> {
            if m == 1 && p == 1 {
                Ok(())
            } else {
                Err(ModelError::Dimension {
                    key: "controller.kind".into(),
                    expected: format!("one plant input and one output for kind = {kind:?} (use state_space otherwise)"),
                    got: format!("m = {m}, p = {p}"),
                })
            }
        };
        match &self.law {
            ControlLaw::Cascade { velocity_filter, .. } => {
                siso("cascade")?;
                nonneg("velocity_filter", *velocity_filter)?;
            }
            ControlLaw::Pid { derivative_filter, .. } => {
                siso("pid")?;
                nonneg("derivative_filter", *derivative_filter)?;
            }
            ControlLaw::StateSpace { Ac, Bc, Cc, Dc, x0 } => {
                let nc = Ac.nrows();
                let dim = |key: &str, expected: String, got: &DMatrix<f64>| ModelError::Dimension {
                    key: format!("controller.{key}"),
                    expected,
                    got: format!("{}x{}", got.nrows(), got.ncols()),
                };
                if Ac.ncols() != nc {
                    return Err(dim("Ac", "a square nc x nc matrix".into(), Ac));
                }
                if Dc.nrows() != m || Dc.ncols() != m + p {
                    return Err(dim("Dc", format!("{m}x{} (m x (m + p))", m + p), Dc));
                }
                if Bc.nrows() != nc || Bc.ncols() != m + p {
                    return Err(dim("Bc", format!("{nc}x{} (nc x (m + p): references, then outputs)", m + p), Bc));
                }
                if Cc.nrows() != m || Cc.ncols() != nc {
                    return Err(dim("Cc", format!("{m}x{nc} (m x nc: one row per plant input)"), Cc));
                }
                ModelError::check_length("controller.x0", x0.len(), "nc", nc)?;
            }
        }
        Ok(())
    }

    /// The controller with number `key` (`element`: `(row, col)` of a matrix, `(i, 0)` of
    /// `x0`) set to `x`, validated against `m`, `p`.
    pub fn with_number(
        &self,
        key: &str,
        element: Option<(usize, usize)>,
        x: f64,
        m: usize,
        p: usize,
    ) -> Result<Self, ModelError> {
        let mut c = self.clone();
        let bad = || ModelError::Missing { key: format!("controller.{key}") };
        match (key, &mut c.law) {
            ("period", _) => c.period = x,
            ("delay", _) => {
                if !(x >= 0.0 && x.fract() == 0.0 && x <= 1e6) {
                    return Err(ModelError::Invalid {
                        key: "controller.delay".into(),
                        value: x,
                        reason: "the computation delay must be a non-negative integer number of controller periods (at most 1e6)".into(),
                    });
                }
                c.delay = x as usize;
            }
            ("kp", ControlLaw::Cascade { kp, .. }) | ("kp", ControlLaw::Pid { kp, .. }) => *kp = x,
            ("kv", ControlLaw::Cascade { kv, .. }) => *kv = x,
            ("ki", ControlLaw::Cascade { ki, .. }) | ("ki", ControlLaw::Pid { ki, .. }) => *ki = x,
            ("kd", ControlLaw::Pid { kd, .. }) => *kd = x,
            ("velocity_filter", ControlLaw::Cascade { velocity_filter, .. }) => *velocity_filter = x,
            ("derivative_filter", ControlLaw::Pid { derivative_filter, .. }) => *derivative_filter = x,
            ("x0", ControlLaw::StateSpace { x0, .. }) => {
                *x0.get_mut(element.map_or(0, |e| e.0)).ok_or_else(bad)? = x;
            }
            (k, ControlLaw::StateSpace { Ac, Bc, Cc, Dc, .. }) if matches!(k, "Ac" | "Bc" | "Cc" | "Dc") => {
                let mat = match k {
                    "Ac" => Ac,
                    "Bc" => Bc,
                    "Cc" => Cc,
                    _ => Dc,
                };
                let (i, j) = element.ok_or_else(bad)?;
                *mat.get_mut((i, j)).ok_or_else(bad)? = x;
            }
            _ => return Err(bad()),
        }
        c.validate(m, p)?;
        Ok(c)
    }

    /// `[controller]` for the writer.
    pub(crate) fn to_table(&self) -> Table {
        let mut t = Table::new();
        t.insert("period".into(), Value::Float(self.period));
        t.insert("delay".into(), Value::Integer(self.delay as i64));
        t.insert("kind".into(), Value::String(self.kind().into()));
        let mut f = |k: &str, v: f64| {
            t.insert(k.into(), Value::Float(v));
        };
        match &self.law {
            ControlLaw::Cascade { kp, kv, ki, velocity_filter } => {
                f("kp", *kp);
                f("kv", *kv);
                f("ki", *ki);
                f("velocity_filter", *velocity_filter);
            }
            ControlLaw::Pid { kp, ki, kd, derivative_filter } => {
                f("kp", *kp);
                f("ki", *ki);
                f("kd", *kd);
                f("derivative_filter", *derivative_filter);
            }
            ControlLaw::StateSpace { Ac, Bc, Cc, Dc, x0 } => {
                if Ac.nrows() > 0 {
                    t.insert("Ac".into(), matrix_value(Ac));
                    t.insert("Bc".into(), matrix_value(Bc));
                    t.insert("Cc".into(), matrix_value(Cc));
                    t.insert("x0".into(), vec_value(x0));
                }
                t.insert("Dc".into(), matrix_value(Dc));
            }
        }
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{parse_str, to_toml_string};

    const PLANT: &str = r#"
[parameters]
M = 2.0
kv0 = 400.0
[plant]
A = [[0, 1], [0, "-3/M"]]
B = [0, "1/M"]
C = [[1, 0]]
E = [0, 0]
"#;

    fn with(controller: &str) -> Result<crate::System, ModelError> {
        parse_str(&format!("{PLANT}[controller]\n{controller}"))
    }

    #[test]
    fn a_cascade_with_expressions_round_trips() {
        let sys =
            with("period = 1e-3\ndelay = 1\nkind = \"cascade\"\nkp = 60\nkv = \"kv0*M/2\"\nvelocity_filter = 2e-4\n")
                .unwrap();
        let c = sys.controller.clone().unwrap();
        assert_eq!(c.delay, 1);
        assert_eq!(c.law, ControlLaw::Cascade { kp: 60.0, kv: 400.0, ki: 0.0, velocity_filter: 2e-4 });
        let text = to_toml_string(&sys);
        assert!(text.contains("kv = \"kv0*M/2\""), "{text}");
        let back = parse_str(&text).unwrap();
        assert_eq!(back.controller, sys.controller);
        // the expression moves with its parameter
        let mut moved = back.clone();
        moved.set_parameter("M", 3.0).unwrap();
        assert_eq!(
            moved.controller.unwrap().law,
            ControlLaw::Cascade { kp: 60.0, kv: 600.0, ki: 0.0, velocity_filter: 2e-4 }
        );
        // negative control: without the controller the written file has none
        let mut plain = sys.clone();
        plain.controller = None;
        assert!(!to_toml_string(&plain).contains("[controller]"));
    }

    #[test]
    fn pid_and_state_space_round_trip() {
        for c in [
            "period = 0.002\nkind = \"pid\"\nkp = 5\nki = 1\nkd = 0.1\nderivative_filter = 0.004\n",
            "period = 0.001\ndelay = 2\nkind = \"state_space\"\nAc = [[0.5]]\nBc = [[1, -1]]\nCc = [[\"M\"]]\nDc = [[2, -2]]\nx0 = [0.25]\n",
            "period = 0.001\nkind = \"state_space\"\nDc = [[2, -2]]\n",
        ] {
            let sys = with(c).unwrap_or_else(|e| panic!("{c}: {e}"));
            let back = parse_str(&to_toml_string(&sys)).unwrap();
            assert_eq!(back.controller, sys.controller, "{c}");
        }
    }

    #[test]
    fn the_compiled_cascade_is_the_cascade() {
        let (kp, kv, ki, tau, T) = (60.0, 400.0, 3000.0, 5e-4, 1e-3);
        let c = Controller { period: T, delay: 0, law: ControlLaw::Cascade { kp, kv, ki, velocity_filter: tau } };
        let law = c.law();
        let a = (-T / tau).exp();
        let (mut yp, mut vp, mut i) = (0.1, 0.0, 0.0);
        let mut x = c.start_state(&[0.0, 0.1]);
        for k in 0..50 {
            let (w, y) = ((k as f64 * 0.3).sin(), (k as f64 * 0.2).cos() * 0.1);
            let e = nalgebra::DVector::from_vec(vec![w, y]);
            let xc = nalgebra::DVector::from_vec(x.clone());
            let u_ss = (&law.Cc * &xc + &law.Dc * &e)[0];
            x = (&law.Ac * &xc + &law.Bc * &e).iter().copied().collect();
            let v = a * vp + (1.0 - a) * (y - yp) / T;
            let ev = kp * (w - y) - v;
            let u = kv * ev + ki * i;
            i += T * ev;
            (yp, vp) = (y, v);
            assert!((u - u_ss).abs() <= 1e-9 * u.abs().max(1.0), "tick {k}: {u} against {u_ss}");
        }
    }

    #[test]
    fn bad_controllers_are_one_line_errors_naming_key_and_value() {
        for (c, key, value) in [
            ("period = 0\nkind = \"cascade\"\nkp = 1\nkv = 1\n", "controller.period", "0"),
            ("period = -1e-3\nkind = \"cascade\"\nkp = 1\nkv = 1\n", "controller.period", "-0.001"),
            ("period = nan\nkind = \"cascade\"\nkp = 1\nkv = 1\n", "controller.period", "NaN"),
            ("period = inf\nkind = \"cascade\"\nkp = 1\nkv = 1\n", "controller.period", "inf"),
            ("period = 1e-3\ndelay = 1.5\nkind = \"cascade\"\nkp = 1\nkv = 1\n", "controller.delay", "1.5"),
            ("period = 1e-3\ndelay = -1\nkind = \"cascade\"\nkp = 1\nkv = 1\n", "controller.delay", "-1"),
            ("period = 1e-3\nkind = \"state_space\"\nAc = [[1, 0]]\nBc = [[1, 1]]\nCc = [[1]]\nDc = [[1, 1]]\n", "controller.Ac", "1x2"),
            ("period = 1e-3\nkind = \"state_space\"\nAc = [[1]]\nBc = [[1]]\nCc = [[1]]\nDc = [[1, 1]]\n", "controller.Bc", "1x1"),
            ("period = 1e-3\nkind = \"state_space\"\nAc = [[1]]\nBc = [[1, 1]]\nCc = [[1, 2]]\nDc = [[1, 1]]\n", "controller.Cc", "1x2"),
            ("period = 1e-3\nkind = \"state_space\"\nDc = [[1, 1, 1]]\n", "controller.Dc", "1x3"),
            ("period = 1e-3\nkind = \"state_space\"\nAc = [[1]]\nBc = [[1, 1]]\nCc = [[1]]\nDc = [[1, 1]]\nx0 = [0, 0]\n", "controller.x0", "length 2"),
            ("period = 1e-3\nkind = \"cascade\"\nkp = 1\nkv = 1\nvelocity_filter = -1\n", "controller.velocity_filter", "-1"),
            ("period = 1e-3\nkind = \"cascade\"\nkp = 1\nkv = 1\nkd = 3\n", "controller.kd", ""),
            ("period = 1e-3\nkind = \"lead_lag\"\n", "controller.kind", "lead_lag"),
            ("period = 1e-3\nkind = \"cascade\"\nkv = 1\n", "controller.kp", ""),
        ] {
            let msg = with(c).map(|_| ()).expect_err(c).to_string();
            assert!(!msg.contains('\n'), "{msg}");
            assert!(msg.contains(key) && msg.contains(value), "{c}: {msg}");
        }
        // a parameter moving the delay off the integers is refused, the system unchanged
        let mut sys = with("period = 1e-3\ndelay = \"M - 1\"\nkind = \"cascade\"\nkp = 1\nkv = 1\n").unwrap();
        assert_eq!(sys.controller.as_ref().unwrap().delay, 1);
        // the delay's expression is written back (an integer slot)
        assert!(crate::to_toml_string(&sys).contains("delay = \"M - 1\""), "{}", crate::to_toml_string(&sys));
        let msg = sys.set_parameter("M", 2.5).unwrap_err().to_string();
        assert!(msg.contains("controller.delay") && msg.contains("1.5"), "{msg}");
        assert_eq!(sys.parameters.value("M"), Some(2.0));
        // cascade on a two-output plant
        let two = PLANT.replace("C = [[1, 0]]", "C = [[1, 0], [0, 1]]").replace("E = [0, 0]", "E = [[0, 0], [0, 0]]");
        let msg = parse_str(&format!("{two}[controller]\nperiod = 1e-3\nkind = \"cascade\"\nkp = 1\nkv = 1\n"))
            .map(|_| ())
            .unwrap_err()
            .to_string();
        assert!(msg.contains("controller.kind") && msg.contains("p = 2"), "{msg}");
    }
}
