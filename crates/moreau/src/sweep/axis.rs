//! Parameter axes of a sweep: which model quantity is varied, and over which values.
//!
//! Parameter names:
//! - `plant.A[i][j]`, `plant.B[i][j]`, `plant.C[i][j]`, `plant.E[i][j]`: one matrix entry of
//!   eq. (xy), 0-based row `i` and column `j` (LaTeX headers show them 1-based, `A_{21}`);
//! - `input.amplitude` (every component of a sine or square input), `input.amplitude[k]`
//!   (component `k`), `input.omega` (so `T = 2 pi / omega`), `input.phase`;
//! - `theta.scale`: `Theta -> s Theta` (the gap size and `R` scale with `s`; the initial
//!   `z0 - C x0` is scaled too so that it stays in the set), `theta.R`: the same scaling
//!   chosen so that the strong-convexity constant `R` of eq. (R) takes the value,
//!   `theta.half_width`: `Theta = [-delta, delta]` (interval backlash only);
//! - `parameters.NAME`: a parameter of the model's `[parameters]`, and with it every number
//!   written as an expression of it.
use super::SweepError;
use geometry::{Ball, BallIntersection, ConvexSet, Ellipsoid, Interval, Polytope, Shape};
use model::System;
use nalgebra::DMatrix;

/// A model quantity that an axis varies.
#[derive(Debug, Clone, PartialEq)]
pub enum Parameter {
    /// Entry `(i, j)` of one of the plant matrices `A, B, C, E`.
    MatrixEntry {
        matrix: Matrix,
        i: usize,
        j: usize,
    },
    /// All amplitudes (`None`) or amplitude `k` of a sine / square input.
    InputAmplitude {
        component: Option<usize>,
    },
    InputOmega,
    InputPhase,
    /// `Theta -> s Theta`.
    ThetaScale,
    /// `Theta -> s Theta` with `s = R / R(Theta)`.
    ThetaR,
    /// `Theta = [-delta, delta]`.
    ThetaHalfWidth,
    /// A parameter of `[parameters]` (the name after `parameters.`).
    Named(String),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Matrix {
    A,
    B,
    C,
    E,
}

impl Matrix {
    fn name(self) -> &'static str {
        match self {
            Matrix::A => "A",
            Matrix::B => "B",
            Matrix::C => "C",
            Matrix::E => "E",
        }
    }
    fn of(self, s: &System) -> &DMatrix<f64> {
        match self {
            Matrix::A => &s.A,
            Matrix::B => &s.B,
            Matrix::C => &s.C,
            Matrix::E => &s.E,
        }
    }
    fn of_mut(self, s: &mut System) -> &mut DMatrix<f64> {
        match self {
            Matrix::A => &mut s.A,
            Matrix::B => &mut s.B,
            Matrix::C => &mut s.C,
            Matrix::E => &mut s.E,
        }
    }
}

fn parse_index(s: &str) -> Option<(usize, &str)> {
    let rest = s.strip_prefix('[')?;
    let close = rest.find(']')?;
    let k = rest[..close].trim().parse().ok()?;
    Some((k, &rest[close + 1..]))
}

impl Parameter {
    /// Parses a parameter name (see the module documentation).
    pub fn parse(name: &str) -> Result<Self, SweepError> {
        let unknown = || SweepError::UnknownParameter { name: name.to_string() };
        let t = name.trim();
        if let Some(rest) = t.strip_prefix("plant.") {
            let mut chars = rest.chars();
            let matrix = match chars.next() {
                Some('A') => Matrix::A,
                Some('B') => Matrix::B,
                Some('C') => Matrix::C,
                Some('E') => Matrix::E,
                _ => return Err(unknown()),
            };
            let (i, r) = parse_index(chars.as_str()).ok_or_else(unknown)?;
            let (j, r) = parse_index(r).ok_or_else(unknown)?;
            if !r.is_empty() {
                return Err(unknown());
            }
            return Ok(Parameter::MatrixEntry { matrix, i, j });
        }
        if let Some(rest) = t.strip_prefix("parameters.") {
            return if model::Parameters::is_name(rest) {
                Ok(Parameter::Named(rest.to_string()))
            } else {
                Err(unknown())
            };
        }
        match t {
            "input.amplitude" | "input.amplitudes" => return Ok(Parameter::InputAmplitude { component: None }),
            "input.omega" => return Ok(Parameter::InputOmega),
            "input.phase" => return Ok(Parameter::InputPhase),
            "theta.scale" => return Ok(Parameter::ThetaScale),
            "theta.R" => return Ok(Parameter::ThetaR),
            "theta.half_width" => return Ok(Parameter::ThetaHalfWidth),
            _ => {}
        }
        for pre in ["input.amplitude", "input.amplitudes"] {
            if let Some(rest) = t.strip_prefix(pre) {
                if let Some((k, "")) = parse_index(rest) {
                    return Ok(Parameter::InputAmplitude { component: Some(k) });
                }
            }
        }
        Err(unknown())
    }

    /// Canonical name (as accepted by [`Parameter::parse`]).
    pub fn name(&self) -> String {
        match self {
            Parameter::MatrixEntry { matrix, i, j } => format!("plant.{}[{i}][{j}]", matrix.name()),
            Parameter::InputAmplitude { component: None } => "input.amplitude".into(),
            Parameter::InputAmplitude { component: Some(k) } => format!("input.amplitude[{k}]"),
            Parameter::InputOmega => "input.omega".into(),
            Parameter::InputPhase => "input.phase".into(),
            Parameter::ThetaScale => "theta.scale".into(),
            Parameter::ThetaR => "theta.R".into(),
            Parameter::ThetaHalfWidth => "theta.half_width".into(),
            Parameter::Named(n) => format!("parameters.{n}"),
        }
    }

    /// Column header for LaTeX tables (math mode, 1-based matrix indices).
    pub fn latex(&self) -> String {
        match self {
            Parameter::MatrixEntry { matrix, i, j } => format!("${}_{{{}{}}}$", matrix.name(), i + 1, j + 1),
            Parameter::InputAmplitude { component: None } => "$a$".into(),
            Parameter::InputAmplitude { component: Some(k) } => format!("$a_{{{}}}$", k + 1),
            Parameter::InputOmega => "$\\omega$".into(),
            Parameter::InputPhase => "$\\varphi$".into(),
            Parameter::ThetaScale => "$s_\\Theta$".into(),
            Parameter::ThetaR => "$R$".into(),
            Parameter::ThetaHalfWidth => "$\\delta$".into(),
            Parameter::Named(n) if n.chars().count() == 1 => format!("${n}$"),
            Parameter::Named(n) => format!("$\\mathrm{{{}}}$", n.replace('_', "\\_")),
        }
    }

    /// Checks that the parameter exists in `base` (matrix sizes, input kind, shape) without
    /// applying a value.
    pub fn check_applicable(&self, base: &System) -> Result<(), SweepError> {
        let name = self.name();
        let na = |reason| Err(SweepError::NotApplicable { name: name.clone(), reason });
        match self {
            Parameter::MatrixEntry { matrix, i, j } => {
                let m = matrix.of(base);
                if *i >= m.nrows() || *j >= m.ncols() {
                    return Err(SweepError::IndexOutOfRange { name, i: *i, j: *j, rows: m.nrows(), cols: m.ncols() });
                }
            }
            Parameter::InputAmplitude { .. } | Parameter::InputOmega | Parameter::InputPhase => match base.input.wave()
            {
                Some((amplitudes, _, _)) => {
                    if let Parameter::InputAmplitude { component: Some(k) } = self {
                        if *k >= amplitudes.len() {
                            return Err(SweepError::IndexOutOfRange {
                                name,
                                i: *k,
                                j: 0,
                                rows: amplitudes.len(),
                                cols: 1,
                            });
                        }
                    }
                }
                None => return na("the base model's input is not a sine, square wave or multisine"),
            },
            Parameter::ThetaScale => {}
            Parameter::ThetaR => {
                let r = base.theta.strong_convexity().upper();
                if !(r.is_finite() && r > 0.0) {
                    return na("R of the base Theta is not finite and positive (polytope or point)");
                }
            }
            Parameter::ThetaHalfWidth => {
                if !matches!(base.theta, Shape::Interval(_)) {
                    return na("theta.half_width needs an interval Theta");
                }
            }
            Parameter::Named(n) => {
                if base.parameters.value(n).is_none() {
                    return Err(SweepError::UnknownModelParameter { name, known: base.parameters.names.join(", ") });
                }
            }
        }
        Ok(())
    }

    /// Applies `value` to `sys` (unvalidated; [`apply_all`] re-validates the result).
    fn apply(&self, sys: &mut System, value: f64) -> Result<(), SweepError> {
        let name = self.name();
        match self {
            Parameter::MatrixEntry { matrix, i, j } => {
                self.check_applicable(sys)?;
                matrix.of_mut(sys)[(*i, *j)] = value;
            }
            Parameter::InputAmplitude { component } => {
                self.check_applicable(sys)?;
                if let Some((amplitudes, _, _)) = sys.input.wave_mut() {
                    match component {
                        None => amplitudes.iter_mut().for_each(|a| *a = value),
                        Some(k) => amplitudes[*k] = value,
                    }
                }
            }
            Parameter::InputOmega | Parameter::InputPhase => {
                self.check_applicable(sys)?;
                if *self == Parameter::InputOmega && (value.is_nan() || value <= 0.0) {
                    return Err(SweepError::NotApplicable { name, reason: "omega must be positive" });
                }
                if let Some((_, omega, phase)) = sys.input.wave_mut() {
                    if *self == Parameter::InputOmega {
                        *omega = value;
                    } else {
                        *phase = value;
                    }
                }
            }
            Parameter::ThetaScale => scale_theta(sys, value, &name)?,
            Parameter::ThetaR => {
                self.check_applicable(sys)?;
                let r = sys.theta.strong_convexity().upper();
                scale_theta(sys, value / r, &name)?;
            }
            Parameter::ThetaHalfWidth => {
                self.check_applicable(sys)?;
                let iv = Interval::symmetric(value).map_err(|_| SweepError::NotApplicable {
                    name: name.clone(),
                    reason: "the half-width must be non-negative",
                })?;
                let q0 = sys.z0[0] - (sys.C.row(0) * &sys.x0)[0];
                sys.theta = Shape::Interval(iv);
                // keep z0 inside y0 + Theta: clamp q0 into the new interval
                sys.z0[0] = (sys.C.row(0) * &sys.x0)[0] + iv.clamp(q0);
            }
            Parameter::Named(n) => {
                self.check_applicable(sys)?;
                sys.set_parameter(n, value).map_err(|source| SweepError::InvalidPoint { name, value, source })?;
            }
        }
        Ok(())
    }
}

/// `Theta -> s Theta` for every parametric shape; `z0 - C x0` is scaled by `s` as well.
fn scale_theta(sys: &mut System, s: f64, name: &str) -> Result<(), SweepError> {
    let bad = |reason| SweepError::NotApplicable { name: name.to_string(), reason };
    if !(s >= 0.0 && s.is_finite()) {
        return Err(bad("the scale factor must be finite and non-negative"));
    }
    let sc = |v: &[f64]| v.iter().map(|x| x * s).collect::<Vec<f64>>();
    let geo = |_| bad("the scaled set is invalid");
    sys.theta = match &sys.theta {
        Shape::Interval(iv) => Shape::Interval(Interval::new(iv.lo * s, iv.hi * s).map_err(geo)?),
        Shape::Ball(b) => Shape::Ball(Ball::new(sc(&b.centre), b.radius * s).map_err(geo)?),
        Shape::Ellipsoid(e) => {
            if s == 0.0 {
                return Err(bad("an ellipsoid cannot be scaled to a point (use a positive scale)"));
            }
            let p = e.centre().len();
            let m = DMatrix::from_row_slice(p, p, e.matrix()) * (s * s);
            Shape::Ellipsoid(Ellipsoid::new(sc(e.centre()), &m).map_err(geo)?)
        }
        Shape::BallIntersection(b) => Shape::BallIntersection(
            BallIntersection::new(b.centres().iter().map(|c| sc(c)).collect(), sc(b.radii())).map_err(geo)?,
        ),
        Shape::Polytope(p) => Shape::Polytope(Polytope::new(p.normals().to_vec(), sc(p.offsets())).map_err(geo)?),
    };
    let y0 = &sys.C * &sys.x0;
    sys.z0 = &y0 + (&sys.z0 - &y0) * s;
    Ok(())
}

/// Applies `(parameter, value)` pairs in order (theta axes last, so that they see the final
/// `C` and `x0`) and re-validates the model through [`System::new`].
pub fn apply_all(base: &System, settings: &[(&Parameter, f64)]) -> Result<System, SweepError> {
    let mut s = base.clone();
    let is_theta = |p: &Parameter| matches!(p, Parameter::ThetaScale | Parameter::ThetaR | Parameter::ThetaHalfWidth);
    for pass_theta in [false, true] {
        for (p, v) in settings.iter().filter(|(p, _)| is_theta(p) == pass_theta) {
            if !v.is_finite() {
                return Err(SweepError::NotFinite { name: p.name(), value: *v });
            }
            p.apply(&mut s, *v)?;
        }
    }
    let (name, value) = settings.last().map(|(p, v)| (p.name(), *v)).unwrap_or_default();
    System::builder()
        .name(s.name)
        .A(s.A)
        .B(s.B)
        .C(s.C)
        .E(s.E)
        .theta(s.theta)
        .input(s.input)
        .x0(s.x0)
        .z0(s.z0)
        .sim(s.sim)
        .effects(s.effects)
        .build()
        .map(|built| System { parameters: s.parameters, ..built })
        .map_err(|source| SweepError::InvalidPoint { name, value, source })
}

/// Values of one axis: an explicit list or a range.
#[derive(Debug, Clone, PartialEq)]
pub enum Values {
    List(Vec<f64>),
    /// `count` points from `from` to `to` inclusive, linearly or logarithmically spaced.
    Count {
        from: f64,
        to: f64,
        count: usize,
        log: bool,
    },
    /// `from, from + step, ...` up to `to` (inclusive within `1e-9 step`).
    Step {
        from: f64,
        to: f64,
        step: f64,
    },
}

impl Values {
    /// Number of values [`Values::expand`] would produce, computed without building them
    /// (an upper estimate for a malformed range, which `expand` then rejects).
    pub fn len_before_expanding(&self) -> u128 {
        match self {
            Values::List(v) => v.len() as u128,
            Values::Count { count, .. } => *count as u128,
            Values::Step { from, to, step } => {
                let n = (to - from) / step;
                // malformed (step 0, non-finite, pointing away): `expand` names the problem
                if n.is_finite() && n >= 0.0 {
                    (n + 1e-9).floor().min(u64::MAX as f64) as u128 + 1
                } else {
                    1
                }
            }
        }
    }

    /// The values, or an error for an empty or malformed range.
    pub fn expand(&self, name: &str) -> Result<Vec<f64>, SweepError> {
        let nf = |value: f64| SweepError::NotFinite { name: name.to_string(), value };
        let v = match self {
            Values::List(v) => {
                if v.is_empty() {
                    return Err(SweepError::EmptyValues { name: name.to_string() });
                }
                v.clone()
            }
            Values::Count { from, to, count, log } => {
                for x in [*from, *to] {
                    if !x.is_finite() {
                        return Err(nf(x));
                    }
                }
                if *count == 0 {
                    return Err(SweepError::EmptyRange {
                        name: name.into(),
                        from: *from,
                        to: *to,
                        detail: "count = 0".into(),
                    });
                }
                if *log && !(*from > 0.0 && *to > 0.0) {
                    return Err(SweepError::BadRange {
                        name: name.into(),
                        reason: "a log range needs from > 0 and to > 0",
                    });
                }
                if *count == 1 {
                    if from != to {
                        return Err(SweepError::BadRange { name: name.into(), reason: "count = 1 needs from = to" });
                    }
                    vec![*from]
                } else {
                    (0..*count)
                        .map(|k| {
                            let f = k as f64 / (*count - 1) as f64;
                            if k == *count - 1 {
                                *to
                            } else if *log {
                                (from.ln() + f * (to.ln() - from.ln())).exp()
                            } else {
                                from + f * (to - from)
                            }
                        })
                        .collect()
                }
            }
            Values::Step { from, to, step } => {
                for x in [*from, *to, *step] {
                    if !x.is_finite() {
                        return Err(nf(x));
                    }
                }
                if *step == 0.0 {
                    return Err(SweepError::BadRange { name: name.into(), reason: "step = 0" });
                }
                let n = (to - from) / step;
                if n < -1e-9 {
                    return Err(SweepError::EmptyRange {
                        name: name.into(),
                        from: *from,
                        to: *to,
                        detail: format!("step {step} points away from `to`"),
                    });
                }
                let n = (n + 1e-9).floor() as usize;
                if n > 10_000_000 {
                    return Err(SweepError::TooManyPoints { points: n as u128, limit: 10_000_000 });
                }
                (0..=n).map(|k| from + k as f64 * step).collect()
            }
        };
        if let Some(&x) = v.iter().find(|x| !x.is_finite()) {
            return Err(nf(x));
        }
        Ok(v)
    }
}

/// One axis: a parameter and its (expanded) values.
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    pub parameter: Parameter,
    pub values: Vec<f64>,
    /// LaTeX column header (default [`Parameter::latex`]).
    pub label: String,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for n in [
            "plant.A[1][0]",
            "plant.E[0][0]",
            "input.amplitude",
            "input.amplitude[1]",
            "input.omega",
            "input.phase",
            "theta.scale",
            "theta.R",
            "theta.half_width",
        ] {
            assert_eq!(Parameter::parse(n).unwrap().name(), n);
        }
        for bad in ["plant.F[0][0]", "plant.A[1]", "plant.A[x][0]", "input.gain", "theta", "plant.A[0][0]x", ""] {
            assert!(matches!(Parameter::parse(bad), Err(SweepError::UnknownParameter { .. })), "{bad}");
        }
    }

    #[test]
    fn ranges() {
        assert_eq!(
            Values::Count { from: 1.0, to: 3.0, count: 3, log: false }.expand("a").unwrap(),
            vec![1.0, 2.0, 3.0]
        );
        let l = Values::Count { from: 0.1, to: 10.0, count: 3, log: true }.expand("a").unwrap();
        assert!((l[1] - 1.0).abs() < 1e-12 && l[2] == 10.0);
        assert_eq!(Values::Step { from: 0.0, to: 1.0, step: 0.25 }.expand("a").unwrap().len(), 5);
        assert_eq!(Values::Step { from: 1.0, to: 0.0, step: -0.5 }.expand("a").unwrap(), vec![1.0, 0.5, 0.0]);
        assert!(matches!(
            Values::Step { from: 1.0, to: 0.0, step: 0.5 }.expand("a"),
            Err(SweepError::EmptyRange { .. })
        ));
        assert!(matches!(
            Values::Count { from: 1.0, to: 2.0, count: 0, log: false }.expand("a"),
            Err(SweepError::EmptyRange { .. })
        ));
        assert!(matches!(Values::List(vec![]).expand("a"), Err(SweepError::EmptyValues { .. })));
    }
}
