//! The pure-Rust core of the Python module: every function here mirrors one `moreau`
//! subcommand (crates/moreau/src/cli) and calls the same library functions with the same
//! checks, so that a Python call and the command print the same numbers and the same one-line
//! error messages. Nothing here needs Python; `py.rs` only converts arguments and results.
use anyhow::{bail, Context};
use bounds::{assemble, ThetaSettings};
use dynamics::trajectory::Trajectory;
use model::{Input, ModelError, System};
use std::path::{Path, PathBuf};

/// The error and its causes on one line, exactly as `moreau` prints them after `error: `.
pub use moreau::cli::one_line;

/// Where a command's model comes from: a model file (errors carry its path, as in the CLI) or
/// a system built in Python (with which parts of `[initial]` it states).
pub enum Source {
    File(PathBuf),
    Built(Box<System>, Stated),
}

/// Which initial values a model states (`[initial] x0`, `z0`): `diagnose` takes a stated
/// `x0` as known instead of estimating it.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Stated {
    pub x0: bool,
    pub z0: bool,
}

impl Stated {
    /// From model-file text, as `moreau diagnose` reads it.
    pub fn of_text(text: &str) -> Self {
        let Ok(root) = toml::from_str::<toml::Table>(text) else { return Self::default() };
        Self::of_table(&root)
    }
    pub fn of_table(root: &toml::Table) -> Self {
        let init = root.get("initial").and_then(|v| v.as_table());
        let has = |k: &str| init.is_some_and(|t| t.contains_key(k));
        Self { x0: has("x0"), z0: has("z0") }
    }
    /// The initial state `diagnose` gets (the CLI's `stated_initial_state`).
    fn initial_state(self, sys: &System) -> Option<discovery::InitialState> {
        self.x0.then(|| discovery::InitialState {
            x0: sys.x0.iter().copied().collect(),
            z0: self.z0.then(|| sys.z0.iter().copied().collect()),
        })
    }
}

impl Source {
    /// The system, loaded like the CLI loads `FILE` (`model::load` with the path as context).
    pub fn system(&self) -> anyhow::Result<System> {
        match self {
            Source::File(p) => load(p),
            Source::Built(s, _) => Ok((**s).clone()),
        }
    }
    /// How the CLI names the model in messages: the file path in backticks (the system's name
    /// for a system built in Python).
    fn label(&self) -> String {
        match self {
            Source::File(p) => format!("`{}`", p.display()),
            Source::Built(s, _) => format!("`{}`", s.name),
        }
    }
}

/// `model::load` with the CLI's context (the path).
pub fn load(path: &Path) -> anyhow::Result<System> {
    model::load(path).with_context(|| path.display().to_string())
}

/// Samples of an input given as arrays (`Samples(t, w, period)` in Python): checked like a
/// `kind = "csv"` input file (model::Input::from_csv) and named `source` in messages.
pub struct SamplesSpec {
    pub t: Vec<f64>,
    pub w: Vec<Vec<f64>>,
    pub period: Option<f64>,
    pub source: String,
}

fn samples_input(s: SamplesSpec) -> Result<Input, ModelError> {
    let ps = s.source.clone();
    let csv = |reason: String| ModelError::Csv { path: ps.clone(), reason };
    if s.t.len() != s.w.len() {
        return Err(csv(format!("{} time stamps but {} rows of w", s.t.len(), s.w.len())));
    }
    if s.t.len() < 2 {
        return Err(csv(format!("needs at least 2 samples, found {}", s.t.len())));
    }
    let m = s.w[0].len();
    if m == 0 {
        return Err(csv("w has no columns".into()));
    }
    for (i, (&t, w)) in s.t.iter().zip(&s.w).enumerate() {
        let row = i + 2; // as in a CSV file: 1-based, after the header
        if w.len() != m {
            return Err(csv(format!("row {row} has {} values of w, row 2 has {m}", w.len())));
        }
        for (name, x) in
            std::iter::once(("t".to_string(), t)).chain(w.iter().enumerate().map(|(j, &x)| (format!("w{}", j + 1), x)))
        {
            if !x.is_finite() {
                return Err(ModelError::CsvValue { path: ps.clone(), row, column: name, value: format!("{x}") });
            }
            if x.abs() > model::MAX_MAGNITUDE {
                return Err(csv(format!(
                    "row {row}, column `{name}`: value {x:e} has a magnitude above {:e}",
                    model::MAX_MAGNITUDE
                )));
            }
        }
        if i > 0 {
            let prev = s.t[i - 1];
            if t <= prev {
                return Err(ModelError::UnsortedTimes { path: ps.clone(), row, t, prev });
            }
            if t - prev <= 1e-12 * t.abs().max(prev.abs()) {
                return Err(csv(format!(
                    "row {row}: time step {} at t = {t} is below the resolution of double precision",
                    t - prev
                )));
            }
        }
    }
    if let Some(per) = s.period {
        if per.is_nan() || per <= 0.0 || per.is_infinite() {
            return Err(ModelError::OutOfRange { key: "input.period".into(), value: per, reason: "must be positive" });
        }
        let span = s.t[s.t.len() - 1] - s.t[0];
        if per < span * (1.0 - 1e-12) {
            return Err(ModelError::Invalid {
                key: "input.period".into(),
                value: per,
                reason: format!(
                    "shorter than the data in `{}` (samples span {span} from t = {} to t = {}): the rest would be cut silently",
                    s.source,
                    s.t[0],
                    s.t[s.t.len() - 1]
                ),
            });
        }
    }
    Ok(Input::Samples { path: s.source, t: s.t, w: s.w, period: s.period })
}

/// A system from the tables of a model file (`plant`, `theta`, `input`, `initial`,
/// `simulation`, `effects`, `name`), validated by the model-file reader itself: a system built
/// in Python is exactly the model file it describes, with the same checks and messages.
/// `samples` replaces the input by sampled arrays (checked like an input CSV).
pub fn system_from_table(root: toml::Table, samples: Option<SamplesSpec>) -> anyhow::Result<System> {
    let mut root = root;
    if samples.is_some() {
        root.remove("input");
    }
    let text = toml::to_string(&root).context("the model does not serialise to TOML")?;
    let sys = model::parse_str(&text)?;
    let Some(s) = samples else { return Ok(sys) };
    let input = samples_input(s)?;
    let sys = System::builder()
        .name(sys.name)
        .A(sys.A)
        .B(sys.B)
        .C(sys.C)
        .E(sys.E)
        .theta(sys.theta)
        .input(input)
        .x0(sys.x0)
        .z0(sys.z0)
        .sim(sys.sim)
        .effects(sys.effects)
        .build()?;
    model::check_step(sys.sim.dt, sys.period(), sys.sim.t_end, "simulation.dt")?;
    Ok(sys)
}

/// Options of `theta` (the CLI's `--no-measure`, `--no-stationary`, `--no-guidance`).
#[derive(Debug, Clone, Copy)]
pub struct ThetaOptions {
    pub measure: bool,
    pub stationary: bool,
    pub guidance: bool,
}

/// `moreau theta FILE --json`: the JSON object the command prints (`ThetaReport::to_json`,
/// plus `guidance` when nothing is certified and guidance is on, as in the CLI).
pub fn theta_json(src: &Source, o: ThetaOptions) -> anyhow::Result<serde_json::Value> {
    let sys = match src {
        Source::File(p) => {
            moreau::budget::theta_size_of_file("theta", p)?;
            load(p)?
        }
        Source::Built(s, _) => {
            moreau::budget::theta_size("theta", s.n(), s.p())?;
            (**s).clone()
        }
    };
    let mut settings = ThetaSettings::default();
    if !o.measure {
        settings.measure = None;
    }
    if !o.stationary {
        settings.stationary = None;
    }
    let rep = match src {
        Source::File(p) => assemble(&sys, &settings).with_context(|| p.display().to_string())?,
        Source::Built(..) => assemble(&sys, &settings)?,
    };
    let guide = (o.guidance && !rep.convergence_guaranteed && rep.effects.is_empty())
        .then(|| moreau::guidance::guidance(&sys, &rep, &Default::default()));
    let mut obj = rep.to_json();
    if let (Some(g), Some(m)) = (&guide, obj.as_object_mut()) {
        m.insert("guidance".into(), serde_json::to_value(g)?);
    }
    Ok(obj)
}

/// A simulated trajectory as columns: `t` (N), and `w`, `x`, `y`, `z`, `q = z - y`, row-major
/// N x m, N x n, N x p.
pub struct SimOut {
    pub n: usize,
    pub m: usize,
    pub p: usize,
    pub t: Vec<f64>,
    pub w: Vec<f64>,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub z: Vec<f64>,
    pub q: Vec<f64>,
    /// How it was simulated (`catching-up, h = ...`), as in the CLI's summary line.
    pub method: String,
    pub h: f64,
}

fn columns(tr: &Trajectory, sys: &System, method: String, h: f64) -> SimOut {
    let (n, m, p) = (sys.n(), sys.m(), sys.p());
    let mut y = Vec::with_capacity(tr.len() * p);
    let mut q = Vec::with_capacity(tr.len() * p);
    for i in 0..tr.len() {
        let yi = tr.y_at(&sys.C, i);
        q.extend(tr.z_at(i).iter().zip(&yi).map(|(a, b)| a - b));
        y.extend(yi);
    }
    SimOut { n, m, p, t: tr.t.clone(), w: tr.w.clone(), x: tr.x.clone(), y, z: tr.z.clone(), q, method, h }
}

/// Options of `simulate`: the CLI's `--periods`, `--dt`, `--integrator`, `--max-rows`, and
/// `t_end` (the final time; the CLI takes it from `simulation.t_end` of the file).
#[derive(Debug, Clone, Default)]
pub struct SimulateOptions {
    pub periods: Option<usize>,
    pub dt: Option<f64>,
    pub t_end: Option<f64>,
    pub event: bool,
    /// Keep at most this many samples (every k-th step); `None` keeps every step.
    pub max_rows: Option<usize>,
}

/// `moreau simulate FILE`: the same step, final time, budgets and integrators; the samples
/// instead of `trajectory.csv`.
pub fn simulate(src: &Source, a: &SimulateOptions) -> anyhow::Result<SimOut> {
    use dynamics::integrators::event_driven::{event_driven, EventDrivenSettings};
    use dynamics::trajectory::simulate_model;
    let sys = src.system()?;
    let dt = a.dt.unwrap_or(sys.sim.dt);
    if !(dt > 0.0 && dt.is_finite()) {
        bail!("--dt must be positive and finite, got {dt}");
    }
    if let Some(te) = a.t_end {
        if !(te > 0.0 && te.is_finite()) {
            bail!("t_end must be positive and finite, got {te}");
        }
        if a.periods.is_some() {
            bail!("give t_end or periods, not both");
        }
    }
    let t_end_arg = a.t_end.or(sys.sim.t_end);
    if a.dt.is_some() {
        moreau::budget::step(dt, &sys, t_end_arg.filter(|_| sys.period().is_none() || a.t_end.is_some()), "--dt")?;
    }
    let periods = a.periods.unwrap_or(sys.sim.periods);
    if periods == 0 {
        bail!("--periods must be at least 1, got 0");
    }
    if a.max_rows.is_some_and(|r| r < 2) {
        bail!("--max-rows must be at least 2, got {}", a.max_rows.unwrap_or(0));
    }
    let num = moreau::budget::num;
    let (t_end, h) = match (sys.period(), a.t_end) {
        (Some(T), None) => {
            moreau::budget::steps(
                "simulate",
                periods as f64 * (T / dt).ceil(),
                &format!("{} periods of T = {} at dt = {}", num(periods as f64), num(T), num(dt)),
            )?;
            let (n, h) = dynamics::periodic::steps_per_period(T, dt)?;
            (periods as f64 * n as f64 * h, h)
        }
        (Some(T), Some(te)) => {
            let (_, h) = dynamics::periodic::steps_per_period(T, dt)?;
            (te, h)
        }
        (None, te) => {
            if a.periods.is_some() {
                bail!(
                    "--periods needs a periodic input; {} has input `{}` (set simulation.t_end instead)",
                    src.label(),
                    sys.input.kind()
                );
            }
            (te.or(sys.sim.t_end).unwrap_or(100.0), dt)
        }
    };
    moreau::budget::steps("simulate", (t_end / h).round(), &format!("t_end = {} at dt = {}", num(t_end), num(h)))?;
    let steps = (t_end / h).round().max(1.0) as usize;
    let max_rows = a.max_rows.unwrap_or(steps + 1);
    let rows = (steps as f64 + 1.0).min(max_rows as f64);
    moreau::budget::samples(
        "simulate",
        rows * (1 + sys.n() + sys.m() + 3 * sys.p()) as f64,
        "numbers in the returned arrays, max_rows",
    )?;
    let every = steps.div_ceil(max_rows).max(1);
    let effects: Vec<&str> = sys.effects.list.iter().map(|e| e.kind()).collect();
    let (tr, what) = if !a.event {
        let what = if effects.is_empty() {
            format!("catching-up, h = {h:e}")
        } else {
            format!("extended model with {}, h = {h:e}", effects.join(", "))
        };
        (simulate_model(&sys, h, steps, every)?, what)
    } else if !effects.is_empty() {
        bail!(
            "--integrator event simulates the paper's class only; {} has effects ({}): use --integrator catching-up (the extended-model simulator)",
            src.label(),
            effects.join(", ")
        );
    } else {
        let (tr, events) = event_driven(
            &sys,
            &EventDrivenSettings {
                dt_out: h * every as f64,
                t_end: (steps / every) as f64 * every as f64 * h,
                ..Default::default()
            },
        )?;
        (tr, format!("event-driven, {events} events"))
    };
    Ok(columns(&tr, &sys, what, h))
}

/// `moreau periodic FILE --json`: the same object.
pub fn periodic_json(src: &Source, dt: Option<f64>, periods: usize, pairs: usize) -> anyhow::Result<serde_json::Value> {
    use bounds::tube::localisation::{check_localisation, LocalisationSettings};
    use dynamics::periodic::linearised::{linearised_periodic, LinearisedSettings};
    use dynamics::periodic::poincare::{periodic_regime, PoincareSettings};
    use dynamics::rate::lyapunov_exponent::{measure_rate, RateSettings};
    let num = moreau::budget::num;
    let sys = src.system()?;
    let dt_given = dt;
    let dt = dt.unwrap_or(sys.sim.dt);
    if !(dt > 0.0 && dt.is_finite()) {
        bail!("--dt must be positive and finite, got {dt}");
    }
    if periods == 0 {
        bail!("--periods must be at least 1, got 0");
    }
    let Some(T) = sys.period() else {
        bail!(
            "{} has a non-periodic input (`{}`): the periodic regime needs a T-periodic w",
            src.label(),
            sys.input.kind()
        );
    };
    if pairs == 0 {
        bail!("--pairs must be at least 1, got 0");
    }
    if dt_given.is_some() {
        moreau::budget::step(dt, &sys, None, "--dt")?;
    }
    moreau::budget::steps(
        "periodic",
        (T / dt).ceil() * (periods as f64 * (2 * pairs + 1) as f64 + 100.0),
        &format!("{} periods, {} pairs, T = {}, dt = {}", periods, pairs, num(T), num(dt)),
    )?;
    if !sys.effects.list.is_empty() {
        let kinds: Vec<&str> = sys.effects.list.iter().map(|e| e.kind()).collect();
        let reg = dynamics::extended::regime_by_simulation(&sys, dt, periods)?;
        let last = reg.residuals.last().copied().unwrap_or(f64::NAN);
        let note = format!(
            "the model has effects outside the paper's class ({}): the regime below is where the extended-model simulator is after {} periods; uniqueness and the convergence rate are not established for it",
            kinds.join(", "),
            reg.periods
        );
        return Ok(serde_json::json!({
            "name": sys.name, "period": reg.period, "h": reg.h, "effects": kinds,
            "simulated_regime": reg, "last_period_residual": last, "note": note,
        }));
    }
    let reg = periodic_regime(&sys, &PoincareSettings { dt, ..Default::default() })?;
    let lin = linearised_periodic(&sys, &LinearisedSettings::default())?;
    let loc = check_localisation(&sys, lin.xi0(), &reg.x0, &reg.z0, &LocalisationSettings::default())?;
    let transient = (periods / 6).clamp(1, 10);
    let rate = measure_rate(
        &sys,
        &RateSettings { dt, periods, transient_periods: transient, pairs, ..Default::default() },
        None,
    )?;
    Ok(serde_json::json!({
        "name": sys.name, "period": reg.period, "h": reg.h,
        "periodic_regime": reg, "xi_T0": lin.xi0(), "localisation": loc,
        "rate": { "exponent": rate.exponent, "ci95": [rate.ci_low, rate.ci_high], "pairs": rate.pairs.iter().map(|p| serde_json::json!({"exponent": p.exponent, "ci95": [p.ci_low, p.ci_high], "renormalisations": p.renormalisations, "collapsed": p.collapsed})).collect::<Vec<_>>() },
        "path_length_per_period": rate.path_length_per_period, "limsup_z_speed": rate.limsup_z_speed,
        "osc_eta_T_lower": lin.osc_lower(), "eta_T_dot_inf_sampled": lin.deta_inf_sampled(),
    }))
}

/// Options of `check` (the CLI's `--cases`, `--seed`, `--only`, `--negative-control`, `--out`).
#[derive(Debug, Clone, Default)]
pub struct CheckOptions {
    pub cases: Option<u64>,
    pub seed: u64,
    pub only: Option<String>,
    pub negative_control: bool,
    /// Directory for counterexample files; `None` writes none.
    pub out: Option<PathBuf>,
}

/// `moreau check --json`: the same object (`seed`, `variant`, `results`) and whether the
/// command would exit with status 1 (a violated claim, or a negative control that held).
pub fn check_json(a: &CheckOptions) -> anyhow::Result<(serde_json::Value, bool)> {
    use theorems::{CampaignSettings, Variant};
    if a.cases == Some(0) {
        bail!("--cases must be at least 1, got 0");
    }
    if let Some(c) = a.cases {
        moreau::budget::cases(c)?;
    }
    let variant = if a.negative_control { Variant::NegativeControl } else { Variant::Claim };
    let settings = CampaignSettings { cases: a.cases, seed: a.seed, only: a.only.clone(), variant };
    let props = theorems::campaign::select(theorems::registry(), a.only.as_deref())?;
    let mut reports = Vec::new();
    for p in &props {
        reports.push(theorems::run_property(p.as_ref(), &settings, &|_| {})?);
    }
    let mut results = Vec::new();
    for r in &reports {
        let file = match (&r.counterexample, &a.out) {
            (Some(c), Some(dir)) => {
                let suffix = if a.negative_control { "-negative-control" } else { "" };
                let path = dir.join(format!("{}{}.{}", r.name, suffix, c.extension));
                moreau::output::write_atomic(&path, c.text.as_bytes())
                    .with_context(|| format!("writing counterexample {}", path.display()))?;
                Some(path)
            }
            _ => None,
        };
        results.push(moreau::cli::check::report_json(r, file.as_ref()));
    }
    let bad = if a.negative_control {
        reports.iter().any(|r| r.violations == 0)
    } else {
        reports.iter().any(|r| r.violations > 0)
    };
    let v = serde_json::json!({
        "seed": a.seed,
        "variant": if a.negative_control { "negative_control" } else { "claim" },
        "results": results,
    });
    Ok((v, bad))
}

/// A recording for `diagnose`: a CSV file (read and checked like `--data`) or CSV text built
/// in Python from a DataFrame or an array (`source` names it in messages).
pub enum RecordingSource {
    File(PathBuf),
    Text { text: String, source: String },
}

/// What `diagnose` returns: `report.json`'s object, the fitted model and the series of the
/// figures (`t`, and row-major N x p `y`, `yhat_nominal`, `yhat_fitted`).
pub struct DiagnoseOut {
    pub report: serde_json::Value,
    pub fitted: Option<System>,
    pub t: Vec<f64>,
    pub p: usize,
    pub y: Vec<f64>,
    pub yhat_nominal: Vec<f64>,
    pub yhat_fitted: Vec<f64>,
}

/// Options of `diagnose` (the CLI's `--estimation-fraction`, `--max-effects`,
/// `--input-hold`, `--estimate-x0`, `--out`).
#[derive(Debug, Clone)]
pub struct DiagnoseOptions {
    pub estimation_fraction: f64,
    pub max_effects: usize,
    pub input_hold: String,
    pub estimate_x0: bool,
    pub out: Option<PathBuf>,
}

impl Default for DiagnoseOptions {
    fn default() -> Self {
        Self { estimation_fraction: 0.7, max_effects: 2, input_hold: "auto".into(), estimate_x0: false, out: None }
    }
}

/// `moreau diagnose --model M --data R --out DIR`: the same reader checks, settings and
/// report; the output directory only when `out` is given.
pub fn diagnose(model_src: &Source, rec: &RecordingSource, o: &DiagnoseOptions) -> anyhow::Result<DiagnoseOut> {
    use discovery::{DiagnoseSettings, HoldChoice, Recording};
    use moreau::csv_check::{check_text, read_checked, TimeColumn};
    let Some(input_hold) = HoldChoice::parse(&o.input_hold) else {
        bail!("invalid value '{}' for '--input-hold <INPUT_HOLD>' [possible values: auto, zoh, foh]", o.input_hold);
    };
    let (sys, stated) = match model_src {
        Source::File(p) => {
            let sys = model::load(p).with_context(|| format!("model {}", p.display()))?;
            let text = std::fs::read_to_string(p).with_context(|| format!("model {}", p.display()))?;
            (sys, Stated::of_text(&text))
        }
        Source::Built(s, stated) => ((**s).clone(), *stated),
    };
    let rec = match rec {
        RecordingSource::File(p) => {
            let text = read_checked(p, "recording", TimeColumn::Numeric("t"))?;
            Recording::parse_str(&text, &p.display().to_string())?
        }
        RecordingSource::Text { text, source } => {
            check_text(text, source, TimeColumn::Numeric("t"))?;
            Recording::parse_str(text, source)?
        }
    };
    let settings = DiagnoseSettings {
        estimation_fraction: o.estimation_fraction,
        max_effects: o.max_effects,
        input_hold,
        initial_state: stated.initial_state(&sys),
        estimate_x0: o.estimate_x0,
        ..Default::default()
    };
    let r = discovery::diagnose(&sys, &rec, &settings)?;
    if let Some(dir) = &o.out {
        moreau::cli::diagnose::write_outputs(&r, dir)?;
    }
    Ok(DiagnoseOut {
        report: serde_json::to_value(&r)?,
        fitted: r.fitted_model.clone(),
        t: r.series.t.clone(),
        p: r.series.p,
        y: r.series.y.clone(),
        yhat_nominal: r.series.yhat_nominal.clone(),
        yhat_fitted: r.series.yhat_fitted.clone(),
    })
}

/// `moreau sweep SPEC --out DIR --quiet`: runs the CLI's command itself (same budgets, resume
/// and locks) and returns the JSON table it wrote (`sweep.json`, or the shard's) and the files.
pub fn sweep(args: moreau::cli::sweep::Args) -> anyhow::Result<(serde_json::Value, Vec<PathBuf>, bool)> {
    let shard = args.shard.as_deref().map(moreau::sweep::Shard::parse).transpose()?;
    let stem = moreau::sweep::run::stem(shard);
    let out = args.out.clone();
    let code = moreau::cli::sweep::run(&args)?;
    let json_path = out.join(format!("{stem}.json"));
    let text = std::fs::read_to_string(&json_path).with_context(|| format!("cannot read {}", json_path.display()))?;
    let v: serde_json::Value = serde_json::from_str(&text).with_context(|| json_path.display().to_string())?;
    let files =
        ["csv", "json", "md", "tex"].iter().map(|e| out.join(format!("{stem}.{e}"))).filter(|p| p.exists()).collect();
    Ok((v, files, code == std::process::ExitCode::SUCCESS))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn worked_example() -> toml::Table {
        r#"
name = "worked example (NOTES.md), a = 1"
[plant]
A = [[0.0, 1.0], [-2.0, -0.6]]
B = [[0.0], [1.0]]
C = [[1.0, 0.0]]
E = [[0.0], [1.0]]
[theta]
shape = "interval"
half_width = 0.1
[input]
kind = "sine"
amplitudes = [1.0]
omega = 1.0
"#
        .parse()
        .unwrap()
    }

    #[test]
    fn a_table_builds_the_same_system_as_the_model_file() {
        let a = system_from_table(worked_example(), None).unwrap();
        let b =
            model::load(Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/worked-example.toml"))).unwrap();
        assert_eq!(model::to_toml_string(&a), model::to_toml_string(&b));
    }

    #[test]
    fn bad_tables_fail_with_the_model_file_messages() {
        let mut t = worked_example();
        t["theta"]["half_width"] = toml::Value::Float(-0.1);
        let e = one_line(&system_from_table(t, None).unwrap_err());
        assert_eq!(e, "key `theta.half_width`: must be non-negative (value -0.1)");
        let mut t = worked_example();
        t["plant"]["B"] = toml::Value::Array(vec![toml::Value::Array(vec![toml::Value::Float(1.0)])]);
        let e = one_line(&system_from_table(t, None).unwrap_err());
        assert!(e.contains("plant.B") && e.contains("2 rows"), "{e}");
    }

    #[test]
    fn samples_are_checked_like_an_input_csv() {
        let spec = |t: Vec<f64>, period| SamplesSpec { t, w: vec![vec![0.0]; 3], period, source: "<samples>".into() };
        let e = one_line(&system_from_table(worked_example(), Some(spec(vec![0.0, 1.0, 1.0], None))).unwrap_err());
        assert!(e.contains("time stamps must increase strictly: row 4 has t = 1 after t = 1"), "{e}");
        let e = one_line(&system_from_table(worked_example(), Some(spec(vec![0.0, 1.0, 2.0], Some(1.5)))).unwrap_err());
        assert!(e.starts_with("key `input.period`: shorter than the data"), "{e}");
        let s = system_from_table(worked_example(), Some(spec(vec![0.0, 1.0, 2.0], Some(2.0)))).unwrap();
        assert_eq!(s.period(), Some(2.0));
    }
}
