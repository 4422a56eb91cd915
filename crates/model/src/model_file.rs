//! The TOML model file. Example (the worked example of NOTES.md):
//!
//! ```toml
//! name = "worked example"
//! [plant]
//! A = [[0.0, 1.0], [-2.0, -0.6]]
//! B = [[0.0], [1.0]]          # or the flat column [0.0, 1.0]
//! C = [[1.0, 0.0]]
//! E = [[0.0], [1.0]]
//! [theta]                     # absent: Theta = {0}
//! shape = "interval"          # interval | ball | ellipsoid | ball_intersection | polytope | box | point
//! half_width = 0.1            # or lo/hi
//! [input]
//! kind = "sine"               # sine | square | multisine | csv | zero
//! amplitudes = [1.0]
//! omega = 1.0
//! [initial]
//! x0 = [0.0, 0.0]
//! z0 = [0.0]
//! [simulation]
//! dt = 1e-3
//! periods = 20
//! ```
//!
//! Shapes: `interval` (`half_width` or `lo`, `hi`); `ball` (`centre` (default 0), `radius`);
//! `ellipsoid` (`centre` (default 0) and `matrix` (SPD shape matrix `M`, the set is
//! `(x-c)^T M^{-1} (x-c) <= 1`) or `semi_axes`); `ball_intersection` (`centres`, `radii`);
//! `polytope` (`normals`, `offsets`: `normals[i] . x <= offsets[i]`); `box` (`lower`,
//! `upper`); `point` (`{0}`). Input `csv`: `file` (relative to the model file) with header
//! `t,w` or `t,w1,...,wm`, optional `period`.
//!
//! Numbers in `[plant]`, `[initial]` and `[[effects]]` may be expressions of named
//! parameters (`[parameters] M = 2.0`, `A = [[0, 1], ["-k/M", "-c/M"]]`): see
//! [`crate::parameters`].
//!
//! `[controller]`: a digital controller closing the loop at its own sample period (the plant's
//! `B` takes its output, the input `w` is its reference): see [`crate::controller`].
//!
//! Optional tables for `moreau diagnose` (ignored by every other command):
//!
//! ```toml
//! [fit]                       # grey-box refit: parameters or entries freed (0-based indices)
//! free = ["plant.A[1][1]", "plant.B[1][0]"]   # or names of [parameters]: ["M", "c"]
//! [fit.bounds]                # optional, per parameter: [lower, upper], the nominal inside
//! "plant.A[1][1]" = [-10.0, 0.0]
//! [fit.result."plant.A[1][1]"]  # written by diagnose into fitted.toml (informational)
//! nominal = -0.6
//! value = -0.45
//! std = 0.003
//! [signals]                   # units for reports: one string for all, or one per column
//! y = "m"
//! w = ["m", "V"]
//! t = "s"                     # unit of time (figures' time axes)
//! reference = "w1"            # output i tracks this input (servo loops): tracking-error metrics
//! ```
pub use crate::fit::{parse_param_name, FitRecord, FitSpec, FreeParam, FreeTarget, PlantMatrix};
use crate::input::{Harmonic, InputHold};
use crate::parameters::{Parameters, Place};
pub use crate::signals::Signals;
use crate::system::{check_step, SimDefaults, System};
use crate::toml_access::*;
use crate::{Effects, Input, ModelError};
use geometry::{Ball, BallIntersection, ConvexSet, Ellipsoid, GeometryError, Interval, Polytope, Shape};
use nalgebra::DVector;
use std::path::Path;
use toml::{Table, Value};

/// Reads and validates a model file.
pub fn load(path: &Path) -> Result<System, ModelError> {
    let text = crate::files::read_regular(path, crate::files::MAX_MODEL_BYTES)?;
    parse_str_with(&text, &path.display().to_string(), path.parent().unwrap_or(Path::new(".")))
}

/// Parses a model file from a string (`csv` inputs are resolved relative to the current
/// directory).
pub fn parse_str(text: &str) -> Result<System, ModelError> {
    parse_str_with(text, "<string>", Path::new("."))
}

fn geo(key: &str) -> impl FnOnce(GeometryError) -> ModelError + '_ {
    move |source| ModelError::Geometry { key: key.into(), source }
}

/// The `[theta]` table (the origin of `R^p` where there is none): one of the shapes, checked.
fn parse_theta(t: Option<&Table>, p: usize) -> Result<Shape, ModelError> {
    let Some(t) = t else { return Ok(Shape::origin(p)) };
    let pre = "theta";
    let shape = str_at(t, pre, "shape")?;
    let centre = |t: &Table| -> Result<Vec<f64>, ModelError> {
        if t.contains_key("centre") {
            vec_at(t, pre, "centre")
        } else {
            Ok(vec![0.0; p])
        }
    };
    Ok(match shape {
        "interval" => theta_interval(t)?,
        "ball" => {
            check_keys(t, pre, "shape, centre, radius")?;
            let r = nonneg(t, pre, "radius")?;
            Shape::Ball(Ball::new(centre(t)?, r).map_err(geo("theta.radius"))?)
        }
        "point" => {
            check_keys(t, pre, "shape")?;
            Shape::origin(p)
        }
        "ellipsoid" => {
            check_keys(t, pre, "shape, centre, matrix, semi_axes")?;
            if t.contains_key("semi_axes") && t.contains_key("matrix") {
                return Err(ModelError::ExclusiveKeys { a: "theta.semi_axes".into(), b: "theta.matrix".into() });
            }
            theta_ellipsoid(t, centre(t)?)?
        }
        "ball_intersection" => {
            check_keys(t, pre, "shape, centres, radii")?;
            let centres = rows_at(t, pre, "centres")?;
            let radii = vec_at(t, pre, "radii")?;
            check_ball_interior(&centres, &radii)?;
            Shape::BallIntersection(BallIntersection::new(centres, radii).map_err(geo("theta"))?)
        }
        "polytope" => {
            check_keys(t, pre, "shape, normals, offsets")?;
            let normals = rows_at(t, pre, "normals")?;
            let offsets = vec_at(t, pre, "offsets")?;
            Shape::Polytope(Polytope::new(normals, offsets).map_err(geo("theta"))?)
        }
        "box" => {
            check_keys(t, pre, "shape, lower, upper")?;
            Shape::Polytope(
                Polytope::from_box(&vec_at(t, pre, "lower")?, &vec_at(t, pre, "upper")?).map_err(geo("theta"))?,
            )
        }
        other => return Err(ModelError::UnknownShape { value: other.to_string() }),
    })
}

/// `shape = "interval"`: `half_width` (symmetric) or `lo` and `hi`.
fn theta_interval(t: &Table) -> Result<Shape, ModelError> {
    let pre = "theta";
    check_keys(t, pre, "shape, half_width, lo, hi")?;
    Ok(Shape::Interval(match opt_nonneg(t, pre, "half_width")? {
        Some(d) => Interval::symmetric(d).map_err(geo("theta.half_width"))?,
        None => Interval::new(f64_at(t, pre, "lo")?, f64_at(t, pre, "hi")?).map_err(geo("theta.lo/hi"))?,
    }))
}

/// `shape = "ellipsoid"` about centre `c`: positive `semi_axes` along the coordinates, or a
/// `matrix`.
fn theta_ellipsoid(t: &Table, c: Vec<f64>) -> Result<Shape, ModelError> {
    let pre = "theta";
    if !t.contains_key("semi_axes") {
        let m = matrix_at(t, pre, "matrix", false)?;
        return Ok(Shape::Ellipsoid(Ellipsoid::new(c, &m).map_err(geo("theta.matrix"))?));
    }
    let a = vec_at(t, pre, "semi_axes")?;
    if let Some(&bad) = a.iter().find(|&&x| x <= 0.0) {
        return Err(ModelError::OutOfRange {
            key: "theta.semi_axes".into(),
            value: bad,
            reason: "semi-axes must be positive",
        });
    }
    if a.len() != c.len() {
        return Err(ModelError::Dimension {
            key: "theta.semi_axes".into(),
            expected: format!("length {}", c.len()),
            got: format!("length {}", a.len()),
        });
    }
    Ok(Shape::Ellipsoid(Ellipsoid::axis_aligned(c, &a).map_err(geo("theta.semi_axes"))?))
}

/// Inscribed radius, relative to the largest radius, below which an intersection of balls
/// counts as having an empty interior.
pub const MIN_RELATIVE_INTERIOR: f64 = 1e-6;

/// Rejects an intersection of balls whose interior is empty or thinner than
/// [`MIN_RELATIVE_INTERIOR`] times the largest radius (balls touching at a point, disjoint
/// balls): the projection onto such a set never converges to its tolerance. Pairs are
/// checked exactly (the lens of two balls has inscribed radius `(r_i + r_j - |c_i - c_j|)/2`);
/// more balls by cyclic projections onto the balls shrunk by the margin, which find a point
/// at depth at least half the margin whenever the shrunk balls intersect with interior.
fn check_ball_interior(centres: &[Vec<f64>], radii: &[f64]) -> Result<(), ModelError> {
    let k = centres.len().min(radii.len());
    if k < 2 || centres.iter().any(|c| c.len() != centres[0].len()) {
        return Ok(()); // dimension errors are reported by the geometry crate
    }
    let rmax = radii.iter().copied().fold(0.0, f64::max);
    let t = MIN_RELATIVE_INTERIOR * rmax;
    let dist = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>().sqrt();
    for i in 0..k {
        if radii[i] <= t {
            return Err(ModelError::EmptyInterior { reason: format!("ball {i} has radius {}", radii[i]) });
        }
        for j in i + 1..k {
            let d = dist(&centres[i], &centres[j]);
            if radii[i] + radii[j] - d < 2.0 * t {
                return Err(ModelError::EmptyInterior {
                    reason: format!(
                        "balls {i} and {j}: distance of the centres {d} against radii {} + {} = {}",
                        radii[i],
                        radii[j],
                        radii[i] + radii[j]
                    ),
                });
            }
        }
    }
    if k == 2 {
        return Ok(());
    }
    let p = centres[0].len();
    let mut x: Vec<f64> = (0..p).map(|d| centres.iter().map(|c| c[d]).sum::<f64>() / k as f64).collect();
    for _ in 0..20_000 {
        let worst = (0..k).map(|i| dist(&x, &centres[i]) - (radii[i] - t)).fold(f64::NEG_INFINITY, f64::max);
        if worst <= 0.5 * t {
            return Ok(());
        }
        for i in 0..k {
            let d = dist(&x, &centres[i]);
            let r = radii[i] - t;
            if d > r {
                for (xd, cd) in x.iter_mut().zip(&centres[i]) {
                    *xd = cd + (*xd - cd) * (r / d);
                }
            }
        }
    }
    Err(ModelError::EmptyInterior {
        reason: format!(
            "no point lies at depth {t:e} ({MIN_RELATIVE_INTERIOR:e} x the largest radius {rmax}) inside all {k} balls"
        ),
    })
}

fn parse_input(t: Option<&Table>, m: usize, dir: &Path) -> Result<Input, ModelError> {
    let Some(t) = t else { return Ok(Input::Zero { m }) };
    let pre = "input";
    let kind = str_at(t, pre, "kind")?;
    let omega_phase = |t: &Table| -> Result<(f64, f64), ModelError> {
        let omega = f64_at(t, pre, "omega")?;
        if omega <= 0.0 {
            return Err(ModelError::OutOfRange {
                key: "input.omega".into(),
                value: omega,
                reason: "angular frequency must be positive",
            });
        }
        Ok((omega, opt_f64(t, pre, "phase")?.unwrap_or(0.0)))
    };
    Ok(match kind {
        "zero" => {
            check_keys(t, pre, "kind")?;
            Input::Zero { m }
        }
        "sine" | "square" => {
            check_keys(t, pre, "kind, amplitudes, omega, phase")?;
            let amplitudes = vec_at(t, pre, "amplitudes")?;
            let (omega, phase) = omega_phase(t)?;
            if kind == "sine" {
                Input::Sine { amplitudes, omega, phase }
            } else {
                Input::Square { amplitudes, omega, phase }
            }
        }
        "multisine" => {
            check_keys(t, pre, "kind, amplitudes, omega, phase, harmonics, weights, phases")?;
            let amplitudes = vec_at(t, pre, "amplitudes")?;
            let (omega, phase) = omega_phase(t)?;
            Input::Multisine { amplitudes, omega, phase, harmonics: parse_harmonics(t)? }
        }
        "csv" => {
            check_keys(t, pre, "kind, file, period, hold")?;
            let file = str_at(t, pre, "file")?;
            let hold = match t.get("hold") {
                None => InputHold::Foh,
                Some(_) => InputHold::parse(str_at(t, pre, "hold")?, "input.hold")?,
            };
            let period = opt_positive(t, pre, "period")?;
            let input = Input::from_csv(&dir.join(file), period, hold)?;
            if let (Some(per), Input::Samples { t, .. }) = (period, &input) {
                crate::input::check_period(per, t, file)?;
            }
            input
        }
        other => return Err(ModelError::UnknownInput { value: other.to_string() }),
    })
}

/// `harmonics`, `weights` (default 1) and `phases` (default 0) of a multisine input.
fn parse_harmonics(t: &Table) -> Result<Vec<Harmonic>, ModelError> {
    let pre = "input";
    let ks = vec_at(t, pre, "harmonics")?;
    let per_harmonic = |name: &str, default: f64| -> Result<Vec<f64>, ModelError> {
        let Some(v) = t.get(name) else { return Ok(vec![default; ks.len()]) };
        let v = crate::toml_access::vector(v, &format!("input.{name}"))?;
        if v.len() != ks.len() {
            return Err(ModelError::Dimension {
                key: format!("input.{name}"),
                expected: format!("one per harmonic ({})", ks.len()),
                got: format!("{}", v.len()),
            });
        }
        Ok(v)
    };
    let (weights, phases) = (per_harmonic("weights", 1.0)?, per_harmonic("phases", 0.0)?);
    let mut out = Vec::with_capacity(ks.len());
    for (j, &k) in ks.iter().enumerate() {
        if k.fract() != 0.0 || !(1.0..=1e6).contains(&k) {
            return Err(ModelError::OutOfRange {
                key: format!("input.harmonics[{j}]"),
                value: k,
                reason: "each harmonic is a whole multiple of omega from 1 to 10^6",
            });
        }
        out.push(Harmonic { k: k as u32, weight: weights[j], phase: phases[j] });
    }
    crate::input::check_harmonics(&out)?;
    Ok(out)
}

/// Longest model `name` in bytes: it goes into plot titles, tables and reports.
pub const MAX_NAME_BYTES: usize = 1000;

/// Parses model-file text as [`load`] reads a file named `origin` in directory `dir` (`csv`
/// inputs resolved relative to `dir`): what a file with this text there would give.
pub fn parse_str_with(text: &str, origin: &str, dir: &Path) -> Result<System, ModelError> {
    let mut root: Table = text
        .parse::<Table>()
        .map_err(|e| ModelError::Syntax { path: origin.to_string(), message: toml_message(&e.to_string()) })?;
    check_keys(
        &root,
        "",
        "name, parameters, plant, theta, input, initial, simulation, effects, controller, fit, signals",
    )?;
    let parameters = Parameters::take_from(&mut root)?;
    let name = match root.get("name") {
        Some(Value::String(s)) if s.len() > MAX_NAME_BYTES => {
            return Err(ModelError::TooLong { key: "name".into(), bytes: s.len(), limit: MAX_NAME_BYTES })
        }
        Some(Value::String(s)) => s.clone(),
        Some(other) => {
            return Err(ModelError::WrongType { key: "name".into(), expected: "a string", found: describe(other) })
        }
        None => origin.to_string(),
    };
    let plant = table_at(&root, "", "plant")?;
    check_keys(plant, "plant", "A, B, C, E")?;
    let A = matrix_at(plant, "plant", "A", false)?;
    let B = matrix_at(plant, "plant", "B", true)?;
    let C = matrix_at(plant, "plant", "C", false)?;
    let E = matrix_at(plant, "plant", "E", true)?;
    let n = A.nrows();
    let p = C.nrows();
    let sub = |k: &str| -> Result<Option<&Table>, ModelError> {
        match root.get(k) {
            None => Ok(None),
            Some(Value::Table(t)) => Ok(Some(t)),
            Some(other) => Err(ModelError::WrongType { key: k.into(), expected: "a table", found: describe(other) }),
        }
    };
    let theta = parse_theta(sub("theta")?, p)?;
    let input = parse_input(sub("input")?, B.ncols(), dir)?;
    let (x0, z0) = match sub("initial")? {
        None => (DVector::zeros(n), DVector::zeros(p)),
        Some(t) => {
            check_keys(t, "initial", "x0, z0")?;
            let x0 =
                if t.contains_key("x0") { DVector::from_vec(vec_at(t, "initial", "x0")?) } else { DVector::zeros(n) };
            let z0 = if t.contains_key("z0") {
                DVector::from_vec(vec_at(t, "initial", "z0")?)
            } else if C.ncols() == x0.len() {
                &C * &x0 // q0 = 0
            } else {
                DVector::zeros(p)
            };
            (x0, z0)
        }
    };
    let mut sim = SimDefaults::default();
    if let Some(t) = sub("simulation")? {
        check_keys(t, "simulation", "dt, periods, t_end")?;
        if let Some(dt) = opt_f64(t, "simulation", "dt")? {
            sim.dt = dt;
        }
        if let Some(per) = opt_f64(t, "simulation", "periods")? {
            if per < 1.0 || per.fract() != 0.0 {
                return Err(ModelError::OutOfRange {
                    key: "simulation.periods".into(),
                    value: per,
                    reason: "must be a positive integer",
                });
            }
            sim.periods = per as usize;
        }
        sim.t_end = opt_positive(t, "simulation", "t_end")?;
    }
    let effects = Effects::parse(root.get("effects"), n, p)?;
    let mut sys = System::validated(name, A, B, C, E, theta, input, x0, z0, sim, effects)?;
    check_step(sys.sim.dt, sys.period(), sys.sim.t_end, "simulation.dt")?;
    sys.parameters = parameters;
    if let Some(t) = sub("controller")? {
        sys.controller = Some(crate::controller::Controller::parse(t, sys.m(), sys.p())?);
    }
    sys.fit = parse_fit(sub("fit")?, &sys)?;
    sys.signals = parse_signals(sub("signals")?, sys.m(), sys.p())?;
    Ok(sys)
}

/// One line from a TOML error: the reason (its last line) and where (its first line).
fn toml_message(full: &str) -> String {
    let lines: Vec<&str> = full.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
    let first = lines.first().copied().unwrap_or("");
    let last = lines.last().copied().unwrap_or("");
    let place = first.strip_prefix("TOML parse error at ").unwrap_or(first);
    if lines.len() <= 1 || last == first {
        place.to_string()
    } else {
        format!("{last} ({place})")
    }
}

fn shape_table(s: &Shape) -> Option<Table> {
    let mut t = Table::new();
    t.insert("shape".into(), Value::String(s.kind().into()));
    match s {
        Shape::Ball(b) if b.radius == 0.0 && b.centre.iter().all(|&c| c == 0.0) => return None,
        Shape::Interval(i) => {
            t.insert("lo".into(), Value::Float(i.lo));
            t.insert("hi".into(), Value::Float(i.hi));
        }
        Shape::Ball(b) => {
            t.insert("shape".into(), Value::String("ball".into()));
            t.insert("centre".into(), vec_value(&b.centre));
            t.insert("radius".into(), Value::Float(b.radius));
        }
        Shape::Ellipsoid(e) => {
            let p = e.dim();
            t.insert("centre".into(), vec_value(e.centre()));
            let m = nalgebra::DMatrix::from_row_slice(p, p, e.matrix());
            t.insert("matrix".into(), matrix_value(&m));
        }
        Shape::BallIntersection(b) => {
            t.insert("centres".into(), Value::Array(b.centres().iter().map(|c| vec_value(c)).collect()));
            t.insert("radii".into(), vec_value(b.radii()));
        }
        Shape::Polytope(pl) => {
            t.insert("normals".into(), Value::Array(pl.normals().iter().map(|c| vec_value(c)).collect()));
            t.insert("offsets".into(), vec_value(pl.offsets()));
        }
    }
    Some(t)
}

/// Writes a system as a model file (round-trips through [`parse_str`]; a `csv` input keeps
/// its file path as given).
pub fn to_toml_string(s: &System) -> String {
    to_toml_string_stating(s, StatedInitial { x0: true, z0: true })
}

/// Which initial values a model file states (`[initial] x0`, `z0`): `diagnose` takes a stated
/// `x0` as known instead of estimating it, so a system whose `x0` was never given must not
/// gain one by being written and read back.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StatedInitial {
    pub x0: bool,
    pub z0: bool,
}

impl StatedInitial {
    /// From model-file text (nothing stated when the text is no TOML table).
    pub fn of_text(text: &str) -> Self {
        let Ok(root) = text.parse::<Table>() else { return Self::default() };
        Self::of_table(&root)
    }

    /// From the tables of a model file.
    pub fn of_table(root: &Table) -> Self {
        let init = root.get("initial").and_then(|v| v.as_table());
        let has = |k: &str| init.is_some_and(|t| t.contains_key(k));
        Self { x0: has("x0"), z0: has("z0") }
    }
}

/// [`to_toml_string`] writing `[initial] x0` and `z0` only where `stated` says so (an unstated
/// one reads back as the same default: `x0 = 0`, `z0` from `x0`).
pub fn to_toml_string_stating(s: &System, stated: StatedInitial) -> String {
    let mut root = Table::new();
    root.insert("name".into(), Value::String(s.name.clone()));
    let mut plant = Table::new();
    plant.insert("A".into(), matrix_value(&s.A));
    plant.insert("B".into(), matrix_value(&s.B));
    plant.insert("C".into(), matrix_value(&s.C));
    plant.insert("E".into(), matrix_value(&s.E));
    root.insert("plant".into(), Value::Table(plant));
    if let Some(t) = shape_table(&s.theta) {
        root.insert("theta".into(), Value::Table(t));
    }
    let mut inp = Table::new();
    inp.insert("kind".into(), Value::String(s.input.kind().into()));
    match &s.input {
        Input::Zero { .. } => {}
        Input::Sine { .. } | Input::Square { .. } | Input::Multisine { .. } => {
            let (amplitudes, omega, phase) = s.input.wave().expect("a sine, square wave or multisine");
            inp.insert("amplitudes".into(), vec_value(amplitudes));
            inp.insert("omega".into(), Value::Float(omega));
            inp.insert("phase".into(), Value::Float(phase));
            if let Input::Multisine { harmonics, .. } = &s.input {
                let each = |f: fn(&Harmonic) -> f64| harmonics.iter().map(f).collect::<Vec<f64>>();
                inp.insert(
                    "harmonics".into(),
                    Value::Array(harmonics.iter().map(|h| Value::Integer(h.k.into())).collect()),
                );
                inp.insert("weights".into(), vec_value(&each(|h| h.weight)));
                inp.insert("phases".into(), vec_value(&each(|h| h.phase)));
            }
        }
        Input::Samples { path, period, hold, .. } => {
            inp.insert("file".into(), Value::String(path.clone()));
            if *hold == InputHold::Zoh {
                inp.insert("hold".into(), Value::String(hold.name().into()));
            }
            if let Some(per) = period {
                inp.insert("period".into(), Value::Float(*per));
            }
        }
    }
    root.insert("input".into(), Value::Table(inp));
    let mut init = Table::new();
    if stated.x0 {
        init.insert("x0".into(), vec_value(s.x0.as_slice()));
    }
    if stated.z0 {
        init.insert("z0".into(), vec_value(s.z0.as_slice()));
    }
    if !init.is_empty() {
        root.insert("initial".into(), Value::Table(init));
    }
    let mut sim = Table::new();
    sim.insert("dt".into(), Value::Float(s.sim.dt));
    sim.insert("periods".into(), Value::Integer(s.sim.periods as i64));
    if let Some(te) = s.sim.t_end {
        sim.insert("t_end".into(), Value::Float(te));
    }
    root.insert("simulation".into(), Value::Table(sim));
    if let Some(e) = s.effects.to_value() {
        root.insert("effects".into(), e);
    }
    if let Some(c) = &s.controller {
        root.insert("controller".into(), Value::Table(c.to_table()));
    }
    if let Some(f) = fit_table(&s.fit) {
        root.insert("fit".into(), Value::Table(f));
    }
    if let Some(t) = signals_table(&s.signals) {
        root.insert("signals".into(), Value::Table(t));
    }
    write_expressions(s, &mut root);
    // sections in the order of the file format (the parser's key list and the examples), not
    // alphabetically as a TOML table would serialise them
    let mut out = String::new();
    for k in SECTION_ORDER {
        if let Some(v) = root.remove(*k) {
            let mut one = Table::new();
            one.insert((*k).into(), v);
            if !out.is_empty() && !out.ends_with("\n\n") {
                out.push('\n');
            }
            out.push_str(&toml::to_string(&one).expect("a TOML table always serialises"));
        }
    }
    debug_assert!(root.is_empty(), "every section of a model file is in SECTION_ORDER");
    out
}

/// The top-level keys of a model file in the order files are written (the order of the
/// examples and of the file-format reference).
const SECTION_ORDER: &[&str] = &[
    "name",
    "parameters",
    "plant",
    "theta",
    "input",
    "initial",
    "simulation",
    "effects",
    "controller",
    "fit",
    "signals",
];

/// `[parameters]` and, in place of a number, the expression that gives it: where the number
/// is still the expression's value (a number changed by other means, e.g. a sweep over the
/// entry, is written as the number).
fn write_expressions(s: &System, root: &mut Table) {
    let Some(t) = s.parameters.to_table() else { return };
    root.insert("parameters".into(), Value::Table(t));
    for b in &s.parameters.bindings {
        let Ok(x) = s.parameters.evaluate(b, &s.parameters.values) else { continue };
        let slot = match &b.place {
            Place::Plant { matrix, row, col } => root
                .get_mut("plant")
                .and_then(|p| p.get_mut(matrix.name()))
                .and_then(|m| m.get_mut(*row))
                .and_then(|r| r.get_mut(*col)),
            Place::Initial { x0, index } => root
                .get_mut("initial")
                .and_then(|t| t.get_mut(if *x0 { "x0" } else { "z0" }))
                .and_then(|v| v.get_mut(*index)),
            Place::Effect { index, key, element } => {
                let v = root.get_mut("effects").and_then(|e| e.get_mut(*index)).and_then(|t| t.get_mut(key.as_str()));
                match element {
                    Some(e) => v.and_then(|a| a.get_mut(*e)),
                    None => v,
                }
            }
            Place::Controller { key, element } => {
                let v = root.get_mut("controller").and_then(|c| c.get_mut(key.as_str()));
                match (element, key.as_str()) {
                    (Some((i, _)), "x0") => v.and_then(|a| a.get_mut(*i)),
                    (Some((i, j)), _) => v.and_then(|a| a.get_mut(*i)).and_then(|r| r.get_mut(*j)),
                    (None, _) => v,
                }
            }
        };
        if let Some(v) = slot {
            // (an integer slot: the controller's delay)
            if v.as_float() == Some(x) || v.as_integer().map(|i| i as f64) == Some(x) {
                *v = Value::String(b.text.clone());
            }
        }
    }
}

const FREE_FORM: &str =
    "a nominal parameter `plant.X[row][col]` with X one of A, B, C, E and 0-based indices, e.g. \"plant.A[1][1]\"";
const FREE_FORM_OR_PARAMETER: &str =
    "a parameter of [parameters] or an entry `plant.X[row][col]` (X one of A, B, C, E, 0-based indices)";

/// `[fit] free` entry `s` (at `key`): a parameter of `[parameters]` or a plant entry that no
/// expression gives (that one moves with its parameters).
fn free_param(s: &str, key: &str, sys: &System) -> Result<FreeParam, ModelError> {
    if sys.parameters.value(s.trim()).is_some() {
        return Ok(FreeParam { name: s.trim().to_string(), target: FreeTarget::Parameter, bounds: None });
    }
    let Some((matrix, row, col)) = parse_param_name(s) else {
        let expected = if sys.parameters.is_empty() { FREE_FORM } else { FREE_FORM_OR_PARAMETER };
        let known = if sys.parameters.is_empty() {
            String::new()
        } else {
            format!(" (parameters: {})", sys.parameters.names.join(", "))
        };
        return Err(ModelError::WrongType { key: key.into(), expected, found: format!("string {s:?}{known}") });
    };
    let m = sys.plant_matrix(matrix);
    if row >= m.nrows() || col >= m.ncols() {
        return Err(ModelError::Dimension {
            key: key.into(),
            expected: format!(
                "row < {} and column < {} (plant.{} is {}x{}; indices are 0-based)",
                m.nrows(),
                m.ncols(),
                matrix.name(),
                m.nrows(),
                m.ncols()
            ),
            got: format!("{s:?}"),
        });
    }
    if let Some(b) = sys.parameters.binding_at(&Place::Plant { matrix, row, col }) {
        return Err(ModelError::Expression {
            key: key.into(),
            text: b.text.clone(),
            reason: format!("{} is written as this expression: free its parameters instead", b.place.key()),
        });
    }
    Ok(FreeParam::entry(matrix, row, col))
}

/// The index in `free` of the parameter named `raw` (an entry's name in any spelling).
fn lookup(free: &[FreeParam], key: &str, raw: &str) -> Result<usize, ModelError> {
    let canonical = parse_param_name(raw).map(|(m, i, j)| FreeParam::entry(m, i, j).name);
    let name = canonical.as_deref().unwrap_or(raw.trim());
    free.iter().position(|f| f.name == name).ok_or_else(|| ModelError::WrongType {
        key: key.into(),
        expected: "a parameter listed in fit.free",
        found: format!("{raw:?} (fit.free: {:?})", free.iter().map(|f| f.name.as_str()).collect::<Vec<_>>()),
    })
}

fn parse_fit(t: Option<&Table>, sys: &System) -> Result<FitSpec, ModelError> {
    let Some(t) = t else { return Ok(FitSpec::default()) };
    check_keys(t, "fit", "free, bounds, result")?;
    let mut free: Vec<FreeParam> = Vec::new();
    if let Some(v) = t.get("free") {
        let Value::Array(items) = v else {
            return Err(ModelError::WrongType {
                key: "fit.free".into(),
                expected: "an array of parameter names",
                found: describe(v),
            });
        };
        for (k, it) in items.iter().enumerate() {
            let key = format!("fit.free[{k}]");
            let Value::String(s) = it else {
                return Err(ModelError::WrongType { key, expected: FREE_FORM, found: describe(it) });
            };
            let param = free_param(s, &key, sys)?;
            if let Some(i) = free.iter().position(|f| f.name == param.name) {
                return Err(ModelError::WrongType {
                    key,
                    expected: "each parameter at most once",
                    found: format!("{s:?}, already fit.free[{i}]"),
                });
            }
            free.push(param);
        }
    }
    if let Some(v) = t.get("bounds") {
        let Value::Table(b) = v else {
            return Err(ModelError::WrongType { key: "fit.bounds".into(), expected: "a table", found: describe(v) });
        };
        for (raw, bv) in b {
            let key = format!("fit.bounds.{raw:?}");
            let i = lookup(&free, &key, raw)?;
            let lu = vector(bv, &key)?;
            if lu.len() != 2 {
                return Err(ModelError::Dimension {
                    key,
                    expected: "[lower, upper]".into(),
                    got: format!("length {}", lu.len()),
                });
            }
            let (lo, hi) = (lu[0], lu[1]);
            if lo >= hi {
                return Err(ModelError::Invalid {
                    key,
                    value: lo,
                    reason: format!("the lower bound {lo} must lie below the upper bound {hi}"),
                });
            }
            let v0 = free[i].get(sys);
            if !(lo..=hi).contains(&v0) {
                return Err(ModelError::Invalid {
                    key,
                    value: v0,
                    reason: format!("the nominal value of {} lies outside the bounds [{lo}, {hi}]", free[i].name),
                });
            }
            free[i].bounds = Some((lo, hi));
        }
    }
    let mut result = Vec::new();
    if let Some(v) = t.get("result") {
        let Value::Table(r) = v else {
            return Err(ModelError::WrongType { key: "fit.result".into(), expected: "a table", found: describe(v) });
        };
        for (raw, rv) in r {
            let key = format!("fit.result.{raw:?}");
            let i = lookup(&free, &key, raw)?;
            let Value::Table(rt) = rv else {
                return Err(ModelError::WrongType {
                    key,
                    expected: "a table (nominal, value, std)",
                    found: describe(rv),
                });
            };
            check_keys(rt, &key, "nominal, value, std, correlation")?;
            result.push(FitRecord {
                name: free[i].name.clone(),
                nominal: f64_at(rt, &key, "nominal")?,
                value: f64_at(rt, &key, "value")?,
                std: opt_f64(rt, &key, "std")?.unwrap_or(f64::NAN),
                correlation: parse_correlation(rt.get("correlation"), &key, &free)?,
            });
        }
    }
    Ok(FitSpec { free, result })
}

/// `correlation = { NAME = r, ... }` of one `[fit.result]` entry: each name a freed parameter,
/// each value in `[-1, 1]`.
fn parse_correlation(v: Option<&Value>, key: &str, free: &[FreeParam]) -> Result<Vec<(String, f64)>, ModelError> {
    let Some(v) = v else { return Ok(vec![]) };
    let key = format!("{key}.correlation");
    let Value::Table(t) = v else {
        return Err(ModelError::WrongType { key, expected: "a table of correlations", found: describe(v) });
    };
    let mut out = Vec::with_capacity(t.len());
    for name in t.keys() {
        let i = lookup(free, &key, name)?;
        let r = f64_at(t, &key, name)?;
        if !(-1.0..=1.0).contains(&r) {
            return Err(ModelError::Invalid {
                key: format!("{key}.{name}"),
                value: r,
                reason: "a correlation lies in [-1, 1]".into(),
            });
        }
        out.push((free[i].name.clone(), r));
    }
    Ok(out)
}

fn parse_signals(t: Option<&Table>, m: usize, p: usize) -> Result<Signals, ModelError> {
    let Some(t) = t else { return Ok(Signals::default()) };
    check_keys(t, "signals", "y, w, t, reference")?;
    let units = |k: &str, n: usize, what: &str| -> Result<Vec<String>, ModelError> {
        let key = format!("signals.{k}");
        match t.get(k) {
            None => Ok(vec![]),
            Some(Value::String(s)) => Ok(vec![s.clone(); n]),
            Some(Value::Array(a)) => {
                let v: Vec<String> = a
                    .iter()
                    .enumerate()
                    .map(|(i, x)| match x {
                        Value::String(s) => Ok(s.clone()),
                        other => Err(ModelError::WrongType {
                            key: format!("{key}[{i}]"),
                            expected: "a unit (string)",
                            found: describe(other),
                        }),
                    })
                    .collect::<Result<_, _>>()?;
                if v.len() != n {
                    return Err(ModelError::Dimension {
                        key,
                        expected: format!("one unit per {what} ({n})"),
                        got: format!("length {}", v.len()),
                    });
                }
                Ok(v)
            }
            Some(other) => Err(ModelError::WrongType {
                key,
                expected: "a unit (string) or an array of units",
                found: describe(other),
            }),
        }
    };
    let time = match t.get("t") {
        None => String::new(),
        Some(Value::String(s)) => s.clone(),
        Some(other) => {
            return Err(ModelError::WrongType {
                key: "signals.t".into(),
                expected: "a unit (string)",
                found: describe(other),
            })
        }
    };
    // reference: "w" / "wJ" (1-based, as the recording's columns), one for all outputs or one per output
    let reference = match units("reference", p, "output")? {
        names if names.is_empty() => vec![],
        names => names
            .iter()
            .enumerate()
            .map(|(i, name)| {
                let j = match name.trim().strip_prefix('w') {
                    Some("") if m == 1 => Some(0),
                    Some(d) => d.parse::<usize>().ok().filter(|&j| (1..=m).contains(&j)).map(|j| j - 1),
                    None => None,
                };
                j.ok_or_else(|| ModelError::WrongType {
                    key: if p > 1 { format!("signals.reference[{i}]") } else { "signals.reference".into() },
                    expected: "an input of the model named as the recording's column (`w` or `wJ`, J = 1..m)",
                    found: format!("\"{name}\" (the model has {m} input{})", if m == 1 { "" } else { "s" }),
                })
            })
            .collect::<Result<Vec<usize>, _>>()?,
    };
    Ok(Signals { y: units("y", p, "output")?, w: units("w", m, "input")?, t: time, reference })
}

fn fit_table(f: &FitSpec) -> Option<Table> {
    if f.is_empty() {
        return None;
    }
    let mut t = Table::new();
    t.insert("free".into(), Value::Array(f.free.iter().map(|p| Value::String(p.name.clone())).collect()));
    let mut b = Table::new();
    for p in &f.free {
        if let Some((lo, hi)) = p.bounds {
            b.insert(p.name.clone(), vec_value(&[lo, hi]));
        }
    }
    if !b.is_empty() {
        t.insert("bounds".into(), Value::Table(b));
    }
    let mut r = Table::new();
    for rec in &f.result {
        let mut e = Table::new();
        e.insert("nominal".into(), Value::Float(rec.nominal));
        e.insert("value".into(), Value::Float(rec.value));
        if rec.std.is_finite() {
            e.insert("std".into(), Value::Float(rec.std));
        }
        let corr: Table =
            rec.correlation.iter().filter(|(_, r)| r.is_finite()).map(|(n, r)| (n.clone(), Value::Float(*r))).collect();
        if !corr.is_empty() {
            e.insert("correlation".into(), Value::Table(corr));
        }
        r.insert(rec.name.clone(), Value::Table(e));
    }
    if !r.is_empty() {
        t.insert("result".into(), Value::Table(r));
    }
    Some(t)
}

fn signals_table(s: &Signals) -> Option<Table> {
    if s.is_empty() {
        return None;
    }
    let mut t = Table::new();
    let arr = |v: &[String]| Value::Array(v.iter().map(|u| Value::String(u.clone())).collect());
    if !s.y.is_empty() {
        t.insert("y".into(), arr(&s.y));
    }
    if !s.w.is_empty() {
        t.insert("w".into(), arr(&s.w));
    }
    if !s.t.is_empty() {
        t.insert("t".into(), Value::String(s.t.clone()));
    }
    if !s.reference.is_empty() {
        t.insert(
            "reference".into(),
            Value::Array(s.reference.iter().map(|j| Value::String(format!("w{}", j + 1))).collect()),
        );
    }
    Some(t)
}
