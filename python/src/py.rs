//! The extension module `moreau._native`: argument conversion and the GIL. Results travel as
//! JSON text (the CLI's own objects, parsed by `json.loads` on the Python side) and as raw
//! little-endian `float64` buffers (`numpy.frombuffer`); errors as `MoreauError` with the CLI's
//! one-line message. Every command is the CLI's own function (`moreau::commands`); this module
//! only converts. The Python package `moreau` (python/python/moreau) is the public API.
use crate::system::{system_from_table, SamplesSpec};
use moreau::commands::{self, one_line, Source, Stated};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyBytes, PyComplex, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use std::path::PathBuf;

pyo3::create_exception!(
    moreau,
    MoreauError,
    PyValueError,
    "An error of moreau, with the one-line message the `moreau` command prints after `error: `."
);

fn err(e: anyhow::Error) -> PyErr {
    MoreauError::new_err(one_line(&e))
}

fn to_json(v: &serde_json::Value) -> PyResult<String> {
    serde_json::to_string(v).map_err(|e| err(e.into()))
}

/// A validated system `x' = A x + B w + E z, y = C x, z in y + Theta` (model::System).
#[pyclass(frozen, name = "System", module = "moreau._native")]
pub struct PySystem {
    inner: model::System,
    /// Which of `[initial] x0`, `z0` the model states (diagnose takes a stated x0 as known).
    stated: Stated,
}

/// Counts the numbers of a model's tables as they are converted and refuses more than
/// [`moreau::budget::MAX_MODEL_NUMBERS`] before the rest is converted.
struct NumberBudget(u64);

impl NumberBudget {
    fn take(&mut self, key: &str) -> PyResult<()> {
        self.0 += 1;
        if self.0 > moreau::budget::MAX_MODEL_NUMBERS {
            moreau::budget::model_numbers(self.0, &format!("the model's tables, counted up to `{key}`"))
                .map_err(err)?;
        }
        Ok(())
    }
}

/// A Python value of a model-file table as a TOML value (numbers, strings, booleans, lists,
/// dicts). A complex number is refused (its imaginary part would be dropped).
fn toml_value(key: &str, v: &Bound<'_, PyAny>, budget: &mut NumberBudget) -> PyResult<toml::Value> {
    if v.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(v.extract()?));
    }
    if v.is_instance_of::<PyFloat>() {
        budget.take(key)?;
        return Ok(toml::Value::Float(v.extract()?));
    }
    if v.is_instance_of::<PyInt>() {
        budget.take(key)?;
        return Ok(toml::Value::Integer(v.extract()?));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(v.extract()?));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        return Ok(toml::Value::Table(toml_table(key, d, budget)?));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let mut a = Vec::new();
        for x in v.try_iter()? {
            a.push(toml_value(key, &x?, budget)?);
        }
        return Ok(toml::Value::Array(a));
    }
    if v.is_instance_of::<PyComplex>() {
        return Err(PyTypeError::new_err(format!(
            "key `{key}`: a complex number ({}) cannot be used in a model: the entries are real (its imaginary part would be dropped)",
            v.repr()?
        )));
    }
    if let Ok(x) = v.extract::<f64>() {
        budget.take(key)?;
        return Ok(toml::Value::Float(x));
    }
    Err(PyTypeError::new_err(format!("key `{key}`: cannot use a value of type {} in a model", v.get_type().name()?)))
}

fn toml_table(prefix: &str, d: &Bound<'_, PyDict>, budget: &mut NumberBudget) -> PyResult<toml::Table> {
    let mut t = toml::Table::new();
    for (k, v) in d.iter() {
        let k: String = k.extract()?;
        if v.is_none() {
            continue;
        }
        let key = if prefix.is_empty() { k.clone() } else { format!("{prefix}.{k}") };
        t.insert(k, toml_value(&key, &v, budget)?);
    }
    Ok(t)
}

fn rows(m: &nalgebra::DMatrix<f64>) -> Vec<Vec<f64>> {
    (0..m.nrows()).map(|i| m.row(i).iter().copied().collect()).collect()
}

#[pymethods]
impl PySystem {
    /// From the tables of a model file as a dict (`plant`, `theta`, `input`, `initial`,
    /// `simulation`, `effects`, `name`); `samples = (t, w, period, source, hold)` replaces the input.
    #[staticmethod]
    #[pyo3(signature = (table, samples=None))]
    fn from_table(py: Python<'_>, table: &Bound<'_, PyDict>, samples: Option<SamplesArg>) -> PyResult<Self> {
        let t = toml_table("", table, &mut NumberBudget(0))?;
        let stated = Stated::of_table(&t);
        if let Some((t, w, _, source, _)) = &samples {
            let numbers = t.len() as u64 + w.iter().map(|r| r.len() as u64).sum::<u64>();
            moreau::budget::sample_numbers(numbers, &format!("t and w of {source}")).map_err(err)?;
        }
        let samples = samples.map(|(t, w, period, source, hold)| SamplesSpec { t, w, period, source, hold });
        let inner = py.detach(move || system_from_table(t, samples)).map_err(err)?;
        Ok(Self { inner, stated })
    }
    /// Reads a model file (as `moreau validate FILE`).
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Self> {
        let inner = commands::load(&path).map_err(err)?;
        let stated = std::fs::read_to_string(&path).map(|t| Stated::of_text(&t)).unwrap_or_default();
        Ok(Self { inner, stated })
    }
    /// Parses model-file text (`csv` inputs relative to the working directory).
    #[staticmethod]
    fn from_toml(text: &str) -> PyResult<Self> {
        Ok(Self { inner: model::parse_str(text).map_err(|e| err(e.into()))?, stated: Stated::of_text(text) })
    }
    /// The model file of this system.
    fn to_toml(&self) -> String {
        model::model_file::to_toml_string_stating(&self.inner, self.stated)
    }
    #[getter]
    fn name(&self) -> String {
        self.inner.name.clone()
    }
    #[getter]
    fn n(&self) -> usize {
        self.inner.n()
    }
    #[getter]
    fn m(&self) -> usize {
        self.inner.m()
    }
    #[getter]
    fn p(&self) -> usize {
        self.inner.p()
    }
    #[getter(A)]
    fn a(&self) -> Vec<Vec<f64>> {
        rows(&self.inner.A)
    }
    #[getter(B)]
    fn b(&self) -> Vec<Vec<f64>> {
        rows(&self.inner.B)
    }
    #[getter(C)]
    fn c(&self) -> Vec<Vec<f64>> {
        rows(&self.inner.C)
    }
    #[getter(E)]
    fn e(&self) -> Vec<Vec<f64>> {
        rows(&self.inner.E)
    }
    #[getter]
    fn x0(&self) -> Vec<f64> {
        self.inner.x0.iter().copied().collect()
    }
    #[getter]
    fn z0(&self) -> Vec<f64> {
        self.inner.z0.iter().copied().collect()
    }
    /// Period `T` of the input (`None` if not periodic).
    #[getter]
    fn period(&self) -> Option<f64> {
        self.inner.period()
    }
    /// `mu = max Re eig(F)`, `F = A + E C` (estimate).
    #[getter]
    fn mu(&self) -> f64 {
        self.inner.mu()
    }
    /// Eigenvalues of `F` as (re, im), by decreasing real part.
    fn eig_f(&self) -> Vec<(f64, f64)> {
        self.inner.eig_F().iter().map(|c| (c.re, c.im)).collect()
    }
    #[getter]
    fn theta_kind(&self) -> &'static str {
        self.inner.theta.kind()
    }
    #[getter]
    fn theta_description(&self) -> String {
        use geometry::ConvexSet;
        self.inner.theta.describe()
    }
    /// Upper bound of the strong-convexity constant `R` of Theta (`inf` if not strongly
    /// convex) and whether it is proven.
    fn strong_convexity(&self) -> (f64, bool) {
        use geometry::ConvexSet;
        let s = self.inner.theta.strong_convexity();
        (s.upper(), s.is_verified_upper())
    }
    #[getter]
    fn input_kind(&self) -> &'static str {
        self.inner.input.kind()
    }
    #[getter]
    fn dt(&self) -> f64 {
        self.inner.sim.dt
    }
    #[getter]
    fn periods(&self) -> usize {
        self.inner.sim.periods
    }
    #[getter]
    fn t_end(&self) -> Option<f64> {
        self.inner.sim.t_end
    }
    /// Kinds of the `[[effects]]` (empty for the paper's class).
    #[getter]
    fn effects(&self) -> Vec<&'static str> {
        self.inner.effects.list.iter().map(|e| e.kind()).collect()
    }
    /// The input `w(t)` at the given times, row-major (len(t) x m) float64 bytes.
    fn input_at<'py>(&self, py: Python<'py>, t: Vec<f64>) -> Bound<'py, PyBytes> {
        let mut out = vec![0.0; self.inner.m()];
        let mut v = Vec::with_capacity(t.len() * out.len());
        for &s in &t {
            self.inner.input.eval(s, &mut out);
            v.extend_from_slice(&out);
        }
        bytes(py, &v)
    }
}

/// Sampled input as it crosses from Python: `(t, w rows, period, source name)`.
type SamplesArg = (Vec<f64>, Vec<Vec<f64>>, Option<f64>, String, String);

fn bytes<'py>(py: Python<'py>, v: &[f64]) -> Bound<'py, PyBytes> {
    let b: Vec<u8> = v.iter().flat_map(|x| x.to_le_bytes()).collect();
    PyBytes::new(py, &b)
}

/// A `System` or a path (str or os.PathLike) to a model file.
fn source(obj: &Bound<'_, PyAny>) -> PyResult<Source> {
    if let Ok(s) = obj.cast::<PySystem>() {
        let s = s.get();
        return Ok(Source::Built(Box::new(s.inner.clone()), s.stated));
    }
    match obj.extract::<PathBuf>() {
        Ok(p) => Ok(Source::File(p)),
        Err(_) => Err(PyTypeError::new_err(format!(
            "expected a moreau.System or the path of a model file, got {}",
            obj.get_type().name()?
        ))),
    }
}

/// `moreau theta FILE --json` (guidance as without `--no-guidance` when `guidance`).
#[pyfunction]
#[pyo3(signature = (model, *, measure=true, stationary=true, guidance=true, step_check=false))]
fn theta(
    py: Python<'_>,
    model: &Bound<'_, PyAny>,
    measure: bool,
    stationary: bool,
    guidance: bool,
    step_check: bool,
) -> PyResult<String> {
    use commands::theta::{theta, ThetaOptions};
    let src = source(model)?;
    let o = ThetaOptions { measure, stationary, guidance, step_check };
    let v = py.detach(move || theta(&src, &o).and_then(|r| r.to_json())).map_err(err)?;
    to_json(&v)
}

/// A simulated trajectory as columns: `t` (N), and `w`, `x`, `y`, `z`, `q = z - y`, row-major
/// N x m, N x n, N x p.
struct SimOut {
    n: usize,
    m: usize,
    p: usize,
    t: Vec<f64>,
    w: Vec<f64>,
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    q: Vec<f64>,
    method: String,
    h: f64,
}

fn columns(s: &commands::simulate::Simulation) -> SimOut {
    let (sys, tr) = (&s.sys, &s.trajectory);
    let (n, m, p) = (sys.n(), sys.m(), sys.p());
    let mut y = Vec::with_capacity(tr.len() * p);
    let mut q = Vec::with_capacity(tr.len() * p);
    for i in 0..tr.len() {
        let yi = tr.y_at(&sys.C, i);
        q.extend(tr.z_at(i).iter().zip(&yi).map(|(a, b)| a - b));
        y.extend(yi);
    }
    let (t, w, x, z) = (tr.t.clone(), tr.w.clone(), tr.x.clone(), tr.z.clone());
    SimOut { n, m, p, t, w, x, y, z, q, method: s.method.clone(), h: s.h }
}

/// `moreau simulate FILE`: (n, m, p, method, h, {t, w, x, y, z, q} as float64 bytes).
#[pyfunction]
#[pyo3(signature = (model, *, periods=None, dt=None, t_end=None, integrator="catching-up", max_rows=None))]
#[allow(clippy::type_complexity)]
fn simulate<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    periods: Option<usize>,
    dt: Option<f64>,
    t_end: Option<f64>,
    integrator: &str,
    max_rows: Option<usize>,
) -> PyResult<(usize, usize, usize, String, f64, Bound<'py, PyDict>)> {
    use commands::simulate::{simulate, Integrator, SimulateOptions};
    let integrator = match integrator {
        "catching-up" => Integrator::CatchingUp,
        "event" => Integrator::Event,
        other => {
            return Err(MoreauError::new_err(format!(
                "invalid value '{other}' for '--integrator <INTEGRATOR>' [possible values: catching-up, event]"
            )))
        }
    };
    let src = source(model)?;
    let o = SimulateOptions { periods, dt, t_end, integrator, max_rows };
    let r = py.detach(move || simulate(&src, &o).map(|s| columns(&s))).map_err(err)?;
    let d = PyDict::new(py);
    for (k, v) in [("t", &r.t), ("w", &r.w), ("x", &r.x), ("y", &r.y), ("z", &r.z), ("q", &r.q)] {
        d.set_item(k, bytes(py, v))?;
    }
    Ok((r.n, r.m, r.p, r.method, r.h, d))
}

/// `moreau periodic FILE --json`.
#[pyfunction]
#[pyo3(signature = (model, *, dt=None, periods=60, pairs=3))]
fn periodic(
    py: Python<'_>,
    model: &Bound<'_, PyAny>,
    dt: Option<f64>,
    periods: usize,
    pairs: usize,
) -> PyResult<String> {
    use commands::periodic::{periodic, PeriodicOptions};
    let src = source(model)?;
    let o = PeriodicOptions { dt, periods, pairs };
    let v = py.detach(move || periodic(&src, &o).map(|r| r.to_json())).map_err(err)?;
    to_json(&v)
}

/// `moreau check --json`: (JSON, whether the command would exit with status 1).
#[pyfunction]
#[pyo3(signature = (*, only=None, cases=None, seed=0, negative_control=false, out=None))]
fn check(
    py: Python<'_>,
    only: Option<String>,
    cases: Option<u64>,
    seed: u64,
    negative_control: bool,
    out: Option<PathBuf>,
) -> PyResult<(String, bool)> {
    let o = commands::check::CheckOptions { cases, seed, only, negative_control, out };
    let run = |o| -> anyhow::Result<_> {
        let r = commands::check::plan(&o)?.run(&())?;
        Ok((r.to_json(), r.failed()))
    };
    let (v, bad) = py.detach(move || run(o)).map_err(err)?;
    Ok((to_json(&v)?, bad))
}

/// `moreau diagnose`: (report JSON, fitted System or None, p, {t, y, yhat_nominal, yhat_fitted}).
/// The recording is a path (`data`) or CSV text (`text`, named `source` in messages).
#[pyfunction]
#[pyo3(signature = (model, *, data=None, text=None, source_name="<recording>".to_string(), estimation_fraction=0.7, max_effects=2, input_hold="auto".to_string(), estimate_x0=false, metric="auto".to_string(), no_refit=false, screen_samples=None, out=None))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn diagnose<'py>(
    py: Python<'py>,
    model: &Bound<'py, PyAny>,
    data: Option<PathBuf>,
    text: Option<String>,
    source_name: String,
    estimation_fraction: f64,
    max_effects: usize,
    input_hold: String,
    estimate_x0: bool,
    metric: String,
    no_refit: bool,
    screen_samples: Option<usize>,
    out: Option<PathBuf>,
) -> PyResult<(String, Option<PySystem>, usize, Bound<'py, PyDict>)> {
    use commands::diagnose::{diagnose, write_outputs, RecordingSource};
    let src = source(model)?;
    let rec = match (data, text) {
        (Some(p), None) => RecordingSource::File(p),
        (None, Some(text)) => RecordingSource::Text { text, source: source_name },
        _ => return Err(PyTypeError::new_err("give exactly one of data= (a path) and text= (CSV text)")),
    };
    let o = diagnose_options(
        estimation_fraction,
        max_effects,
        &input_hold,
        estimate_x0,
        &metric,
        no_refit,
        screen_samples,
    )?;
    let run = move || -> anyhow::Result<discovery::Report> {
        let staged = out.as_deref().map(moreau::output::StagedDir::replacing).transpose()?;
        let r = diagnose(&src, &rec, &o)?.report;
        if let Some(st) = staged {
            write_outputs(&r, st)?;
        }
        Ok(r)
    };
    let r = py.detach(run).map_err(err)?;
    let report = serde_json::to_value(&r).map_err(|e| err(e.into()))?;
    let s = &r.series;
    let d = PyDict::new(py);
    for (k, v) in [("t", &s.t), ("y", &s.y), ("yhat_nominal", &s.yhat_nominal), ("yhat_fitted", &s.yhat_fitted)] {
        d.set_item(k, bytes(py, v))?;
    }
    // the fitted model file states the initial state it was fitted with
    let fitted = r.fitted_model.clone().map(|inner| PySystem { inner, stated: Stated { x0: true, z0: true } });
    Ok((to_json(&report)?, fitted, s.p, d))
}

/// The options of `diagnose` from the keywords of [`diagnose`] and [`diagnose_recordings`]
/// (the CLI's messages for a bad `input_hold` or `metric`).
fn diagnose_options(
    estimation_fraction: f64,
    max_effects: usize,
    input_hold: &str,
    estimate_x0: bool,
    metric: &str,
    no_refit: bool,
    screen_samples: Option<usize>,
) -> PyResult<commands::diagnose::DiagnoseOptions> {
    let default = commands::diagnose::DiagnoseOptions::default();
    let Some(input_hold) = discovery::HoldChoice::parse(input_hold) else {
        return Err(MoreauError::new_err(format!(
            "invalid value '{input_hold}' for '--input-hold <INPUT_HOLD>' [possible values: auto, zoh, foh]"
        )));
    };
    let Some(metric) = discovery::diagnose::Metric::parse(metric) else {
        return Err(MoreauError::new_err(format!(
            "invalid value '{metric}' for '--metric <METRIC>' [possible values: auto, fit, rmse]"
        )));
    };
    Ok(commands::diagnose::DiagnoseOptions {
        estimation_fraction,
        max_effects,
        input_hold,
        estimate_x0,
        metric,
        refit_nominal: !no_refit,
        screen_samples: screen_samples.unwrap_or(default.screen_samples),
    })
}

/// `moreau diagnose --data A --data B [--validate-on C]` (several recordings of one machine,
/// paths): (joint report JSON, fitted System or None).
#[pyfunction]
#[pyo3(signature = (model, *, data, validate_on=Vec::new(), estimation_fraction=0.7, max_effects=2, input_hold="auto".to_string(), estimate_x0=false, metric="auto".to_string(), no_refit=false, screen_samples=None, out=None))]
#[allow(clippy::too_many_arguments)]
fn diagnose_recordings(
    py: Python<'_>,
    model: &Bound<'_, PyAny>,
    data: Vec<PathBuf>,
    validate_on: Vec<PathBuf>,
    estimation_fraction: f64,
    max_effects: usize,
    input_hold: String,
    estimate_x0: bool,
    metric: String,
    no_refit: bool,
    screen_samples: Option<usize>,
    out: Option<PathBuf>,
) -> PyResult<(String, Option<PySystem>)> {
    use commands::diagnose::{diagnose_recordings, write_joint_outputs, RecordingSource};
    let src = source(model)?;
    let o = diagnose_options(
        estimation_fraction,
        max_effects,
        &input_hold,
        estimate_x0,
        &metric,
        no_refit,
        screen_samples,
    )?;
    let files = |v: Vec<PathBuf>| v.into_iter().map(RecordingSource::File).collect::<Vec<_>>();
    let (fit, val) = (files(data), files(validate_on));
    let run = move || -> anyhow::Result<discovery::diagnose::JointReport> {
        let staged = out.as_deref().map(moreau::output::StagedDir::replacing).transpose()?;
        let r = diagnose_recordings(&src, &fit, &val, &o)?.report;
        if let Some(st) = staged {
            write_joint_outputs(&r, st)?;
        }
        Ok(r)
    };
    let r = py.detach(run).map_err(err)?;
    let report = serde_json::to_value(&r).map_err(|e| err(e.into()))?;
    let fitted = r.fitted_model.clone().map(|inner| PySystem { inner, stated: Stated { x0: true, z0: true } });
    Ok((to_json(&report)?, fitted))
}

/// `moreau sweep SPEC --out DIR --quiet`: (JSON table, files written, exit status 0).
#[pyfunction]
#[pyo3(signature = (spec, out, *, shard=None, threads=None, digits=None, overwrite=false, fresh=false, retry_failed=false))]
#[allow(clippy::too_many_arguments)]
fn sweep(
    py: Python<'_>,
    spec: PathBuf,
    out: PathBuf,
    shard: Option<String>,
    threads: Option<usize>,
    digits: Option<usize>,
    overwrite: bool,
    fresh: bool,
    retry_failed: bool,
) -> PyResult<(String, Vec<PathBuf>, bool)> {
    let o = commands::sweep::SweepOptions {
        spec,
        out,
        shard,
        threads,
        digits,
        overwrite,
        fresh,
        retry_failed,
        progress: false,
    };
    let (v, files, ok) = py.detach(move || sweep_table(&o)).map_err(err)?;
    Ok((to_json(&v)?, files, ok))
}

/// Runs the sweep and reads back the JSON table it wrote (`sweep.json`, or the shard's) and
/// the files of the table.
fn sweep_table(o: &commands::sweep::SweepOptions) -> anyhow::Result<(serde_json::Value, Vec<PathBuf>, bool)> {
    use anyhow::Context;
    let run = commands::sweep::sweep(o)?;
    let stem = moreau::sweep::run::stem(run.shard);
    let json_path = o.out.join(format!("{stem}.json"));
    let text = std::fs::read_to_string(&json_path).with_context(|| format!("cannot read {}", json_path.display()))?;
    let v: serde_json::Value = serde_json::from_str(&text).with_context(|| json_path.display().to_string())?;
    let files =
        ["csv", "json", "md", "tex"].iter().map(|e| o.out.join(format!("{stem}.{e}"))).filter(|p| p.exists()).collect();
    Ok((v, files, run.summary.failed == 0))
}

/// The CLI's global `--allow-large`: lifts the soft work limits of every later call.
#[pyfunction]
fn set_allow_large(on: bool) {
    moreau::budget::set_allow_large(on);
}

#[pyfunction]
fn allow_large() -> bool {
    moreau::budget::allow_large()
}

/// The model-size budget of the CLI (`moreau::budget::model_numbers`) for an array of
/// `numbers` entries (`detail`: which), checked by the Python package before it converts the
/// array.
#[pyfunction]
fn check_model_numbers(numbers: u64, detail: &str) -> PyResult<()> {
    moreau::budget::model_numbers(numbers, detail).map_err(err)
}

/// The budget of input samples given as arrays (`moreau::budget::sample_numbers`).
#[pyfunction]
fn check_sample_numbers(numbers: u64, detail: &str) -> PyResult<()> {
    moreau::budget::sample_numbers(numbers, detail).map_err(err)
}

/// `moreau figure KIND INPUT --out DIR ...`: the files written. `kind`, `formats` and `size`
/// are the CLI's words (`psi`, `svg`, `column`).
#[pyfunction]
#[pyo3(signature = (kind, input, out, *, formats=vec!["svg".to_string(), "png".to_string(), "pgf".to_string()], size=None, width=None, height=None, dpi=None, title=true, columns=vec![], x=None, t_end=None, dt=None))]
#[allow(clippy::too_many_arguments)]
fn figure(
    py: Python<'_>,
    kind: String,
    input: PathBuf,
    out: PathBuf,
    formats: Vec<String>,
    size: Option<String>,
    width: Option<u32>,
    height: Option<u32>,
    dpi: Option<f64>,
    title: bool,
    columns: Vec<String>,
    x: Option<String>,
    t_end: Option<f64>,
    dt: Option<f64>,
) -> PyResult<Vec<PathBuf>> {
    use clap::ValueEnum;
    use moreau::cli::figure::{write, Args, Kind};
    fn word<T: ValueEnum>(what: &str, s: &str) -> PyResult<T> {
        T::from_str(s, true).map_err(|_| {
            let known: Vec<String> = T::value_variants()
                .iter()
                .filter_map(|v| v.to_possible_value())
                .map(|p| p.get_name().to_string())
                .collect();
            MoreauError::new_err(format!("invalid {what} {s:?} (possible values: {})", known.join(", ")))
        })
    }
    let a = Args {
        kind: word::<Kind>("figure kind", &kind)?,
        input,
        out,
        columns,
        x,
        t_end,
        format: formats.iter().map(|f| word("format", f)).collect::<PyResult<_>>()?,
        dpi,
        size: size.map(|s| word("size", &s)).transpose()?,
        width,
        height,
        no_title: !title,
        dt,
    };
    py.detach(move || write(&a)).map_err(err)
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("MoreauError", m.py().get_type::<MoreauError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<PySystem>()?;
    m.add_function(wrap_pyfunction!(theta, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(periodic, m)?)?;
    m.add_function(wrap_pyfunction!(check, m)?)?;
    m.add_function(wrap_pyfunction!(diagnose, m)?)?;
    m.add_function(wrap_pyfunction!(diagnose_recordings, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(figure, m)?)?;
    m.add_function(wrap_pyfunction!(set_allow_large, m)?)?;
    m.add_function(wrap_pyfunction!(allow_large, m)?)?;
    m.add_function(wrap_pyfunction!(check_model_numbers, m)?)?;
    m.add_function(wrap_pyfunction!(check_sample_numbers, m)?)?;
    m.add("MAX_MODEL_NUMBERS", moreau::budget::MAX_MODEL_NUMBERS)?;
    m.add("MAX_SAMPLE_NUMBERS", moreau::budget::MAX_SAMPLE_NUMBERS)?;
    Ok(())
}
