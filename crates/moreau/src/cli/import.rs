//! `moreau import FILE --out model.toml`: a model file from a state-space description saved by
//! MATLAB (`save ss.mat A B C E`, a v5 `.mat` file) or by Python (`json.dump({"A": ..., "B":
//! ..., "C": ..., "E": ...})`, e.g. from a python-control `StateSpace`).
//!
//! The plant of eq. (xy) has no feedthrough: a `D` in the file must be zero. `E` (how the
//! backlash output enters the plant) comes from the file or `--e-from-b K` (column `K` of `B`,
//! the usual case of a backlash in an actuator channel); Theta and the input come from the file
//! (JSON: `"theta": {"shape": "interval", "half_width": 0.1}` with the model file's keys,
//! `"input": {...}` likewise) or from the flags. The result is validated like any model file
//! and written atomically.
use anyhow::{bail, Context};
use geometry::{Ball, Interval, Shape};
use model::error::clip;
use model::{Input, System};
use nalgebra::{DMatrix, DVector};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Debug, clap::Args)]
#[command(after_help = "Examples:
  moreau import ss.mat --out plant.toml --interval 0.1 --sine 1.0 --omega 1.0
  moreau import ss.json --out plant.toml --e-from-b 0 --ball 0.05 --sine 0.5,0.5 --omega 2
In MATLAB: [A,B,C,D] = ssdata(sys); E = B(:,1); save ss.mat A B C D E
In Python: json.dump({k: getattr(ss, k).tolist() for k in 'ABCD'} | {'E': E.tolist()}, f)")]
pub struct Args {
    /// State-space file: `.mat` (MATLAB v5, variables A, B, C and optionally D, E) or `.json`.
    pub file: PathBuf,
    /// Model file to write.
    #[arg(long)]
    pub out: PathBuf,
    /// Use column K (0-based) of B as E (when the file has no E).
    #[arg(long)]
    pub e_from_b: Option<usize>,
    /// Theta = [-H, H] (p = 1).
    #[arg(long, value_name = "H")]
    pub interval: Option<f64>,
    /// Theta = the ball of radius R centred at 0.
    #[arg(long, value_name = "R")]
    pub ball: Option<f64>,
    /// Sine input amplitudes (comma separated, one per input).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    pub sine: Option<Vec<f64>>,
    /// Angular frequency of the sine input.
    #[arg(long, default_value_t = 1.0)]
    pub omega: f64,
    /// Model name (default: the file name).
    #[arg(long)]
    pub name: Option<String>,
}

/// The matrices read from a file, with the optional parts.
#[derive(Debug, Default)]
pub struct StateSpace {
    pub A: Option<DMatrix<f64>>,
    pub B: Option<DMatrix<f64>>,
    pub C: Option<DMatrix<f64>>,
    pub D: Option<DMatrix<f64>>,
    pub E: Option<DMatrix<f64>>,
    /// JSON only: `theta` and `input` tables in the model file's format.
    pub rest: toml::Table,
}

fn matrix_from_json(name: &str, v: &serde_json::Value) -> anyhow::Result<DMatrix<f64>> {
    let rows: Vec<Vec<f64>> = match v {
        // a flat list of numbers is a column (one entry per state)
        serde_json::Value::Array(r) if r.iter().all(|x| x.is_number()) => {
            r.iter().map(|x| vec![x.as_f64().unwrap_or(f64::NAN)]).collect()
        }
        serde_json::Value::Array(r) => r
            .iter()
            .enumerate()
            .map(|(i, row)| match row {
                serde_json::Value::Array(c) => c
                    .iter()
                    .enumerate()
                    .map(|(j, x)| {
                        x.as_f64()
                            .with_context(|| format!("{name}[{i}][{j}] = {} is not a number", clip(&x.to_string())))
                    })
                    .collect::<anyhow::Result<Vec<f64>>>(),
                other => bail!("{name}[{i}] = {} is not a list of numbers", clip(&other.to_string())),
            })
            .collect::<anyhow::Result<_>>()?,
        serde_json::Value::Number(x) => vec![vec![x.as_f64().unwrap_or(f64::NAN)]],
        other => bail!("{name} = {} is not a matrix (a list of rows)", clip(&other.to_string())),
    };
    let r = rows.len();
    let c = rows.first().map(Vec::len).unwrap_or(0);
    if let Some((i, row)) = rows.iter().enumerate().find(|(_, row)| row.len() != c) {
        bail!("{name}: row {i} has {} entries, row 0 has {c}", row.len());
    }
    Ok(DMatrix::from_fn(r, c, |i, j| rows[i][j]))
}

/// Reads a JSON state space (`A`, `B`, `C`, optional `D`, `E`, `theta`, `input`).
pub fn read_json(text: &str) -> anyhow::Result<StateSpace> {
    let v: serde_json::Value = serde_json::from_str(text).context("not valid JSON")?;
    let obj = v.as_object().context("the JSON must be an object with keys A, B, C (and D, E, theta, input)")?;
    let mut ss = StateSpace::default();
    for (k, val) in obj {
        match k.as_str() {
            "A" => ss.A = Some(matrix_from_json("A", val)?),
            "B" => ss.B = Some(matrix_from_json("B", val)?),
            "C" => ss.C = Some(matrix_from_json("C", val)?),
            "D" => ss.D = Some(matrix_from_json("D", val)?),
            "E" => ss.E = Some(matrix_from_json("E", val)?),
            "theta" | "input" => {
                let t: toml::Value =
                    serde_json::from_value(val.clone()).with_context(|| format!("`{k}` is not a table"))?;
                ss.rest.insert(k.clone(), t);
            }
            other => bail!("unknown key `{}` (known: A, B, C, D, E, theta, input)", clip(other)),
        }
    }
    Ok(ss)
}

/// Parses a .mat file with `matfile`, whose parser panics on some damaged files (declared
/// sizes whose product overflows): such a panic is reported as a damaged file, quietly.
fn parse_mat(bytes: &[u8]) -> anyhow::Result<matfile::MatFile> {
    const HOW: &str = "in MATLAB save with `save ss.mat A B C -v7` (v7.3/HDF5 files are not read)";
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let parsed = std::panic::catch_unwind(|| matfile::MatFile::parse(bytes));
    std::panic::set_hook(hook);
    match parsed {
        Ok(Ok(mf)) => Ok(mf),
        Ok(Err(e)) => bail!("not a readable MATLAB v5 .mat file ({e:?}); {HOW}"),
        Err(_) => bail!("not a readable MATLAB v5 .mat file (damaged: its declared sizes do not fit its data); {HOW}"),
    }
}

/// Reads a MATLAB v5 `.mat` file (real double or integer arrays A, B, C, optional D, E).
pub fn read_mat(bytes: &[u8]) -> anyhow::Result<StateSpace> {
    let mf = parse_mat(bytes)?;
    let get = |name: &str| -> anyhow::Result<Option<DMatrix<f64>>> {
        let Some(a) = mf.find_by_name(name) else { return Ok(None) };
        let size = a.size();
        if size.len() != 2 {
            bail!("{name} has {} dimensions, a matrix has 2", size.len());
        }
        let data: Vec<f64> = match a.data() {
            matfile::NumericData::Double { real, imag } => {
                if imag.is_some() {
                    bail!("{name} is complex");
                }
                real.clone()
            }
            matfile::NumericData::Single { real, imag: None } => real.iter().map(|&x| x as f64).collect(),
            matfile::NumericData::Int32 { real, imag: None } => real.iter().map(|&x| x as f64).collect(),
            matfile::NumericData::Int64 { real, imag: None } => real.iter().map(|&x| x as f64).collect(),
            _ => bail!("{name} is not a real numeric array"),
        };
        if size[0].checked_mul(size[1]) != Some(data.len()) {
            bail!("{name} is declared {} x {} but holds {} values: the file is damaged", size[0], size[1], data.len());
        }
        // MATLAB stores column-major
        Ok(Some(DMatrix::from_column_slice(size[0], size[1], &data)))
    };
    Ok(StateSpace { A: get("A")?, B: get("B")?, C: get("C")?, D: get("D")?, E: get("E")?, rest: toml::Table::new() })
}

/// Builds the model from the state space and the flags.
pub fn build(ss: StateSpace, a: &Args) -> anyhow::Result<System> {
    let A = ss.A.context("the file has no A")?;
    let B = ss.B.context("the file has no B")?;
    let C = ss.C.context("the file has no C")?;
    if let Some(D) = &ss.D {
        if let Some(x) = D.iter().find(|x| **x != 0.0) {
            bail!("D has a nonzero entry {x}: the plant of eq. (xy) has no feedthrough (y = C x)");
        }
    }
    let E = match (ss.E, a.e_from_b) {
        (Some(E), None) => E,
        (Some(_), Some(_)) => bail!("the file has E and --e-from-b was given: use one"),
        (None, Some(k)) => {
            if k >= B.ncols() {
                bail!("--e-from-b {k}: B has {} columns", B.ncols());
            }
            B.columns(k, 1).into_owned()
        }
        (None, None) => {
            bail!("the file has no E (how the backlash output enters the plant): add it, or give --e-from-b K")
        }
    };
    let (n, p, m) = (A.nrows(), C.nrows(), B.ncols());
    let theta = match (a.interval, a.ball, ss.rest.get("theta")) {
        (Some(h), None, None) => {
            if p != 1 {
                bail!("--interval needs p = 1 output, C has {p} rows (use --ball)");
            }
            Shape::Interval(Interval::symmetric(h).map_err(|e| anyhow::anyhow!("--interval {h}: {e}"))?)
        }
        (None, Some(r), None) => Shape::Ball(Ball::centred(p, r).map_err(|e| anyhow::anyhow!("--ball {r}: {e}"))?),
        (None, None, Some(_)) => {
            // parsed below through the model file reader
            Shape::Ball(Ball::centred(p, 0.0).map_err(|e| anyhow::anyhow!("{e}"))?)
        }
        (None, None, None) => bail!("no backlash set: give --interval H or --ball R (or `theta` in the JSON)"),
        _ => bail!("give exactly one backlash set (--interval, --ball or `theta` in the JSON)"),
    };
    let input = match (&a.sine, ss.rest.get("input")) {
        (Some(amp), None) => {
            if amp.len() != m {
                bail!("--sine has {} amplitudes, B has {m} columns", amp.len());
            }
            Input::Sine { amplitudes: amp.clone(), omega: a.omega, phase: 0.0 }
        }
        (None, Some(_)) => Input::Zero { m },
        (None, None) => bail!("no input: give --sine A1,...,Am (and --omega), or `input` in the JSON"),
        (Some(_), Some(_)) => bail!("the JSON has `input` and --sine was given: use one"),
    };
    let name = a.name.clone().unwrap_or_else(|| format!("imported from {}", a.file.display()));
    let mut sim = model::SimDefaults::default();
    sim.dt = step_for(&input, ss.rest.get("input"), sim.dt);
    let sys = System::builder()
        .name(name)
        .A(A)
        .B(B)
        .C(C)
        .E(E)
        .theta(theta)
        .input(input)
        .x0(DVector::zeros(n))
        .z0(DVector::zeros(p))
        .sim(sim)
        .build()
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    if ss.rest.is_empty() {
        return Ok(sys);
    }
    // JSON `theta` / `input` tables: merge into the model file and read it back (same keys and
    // checks as any model file).
    let mut t: toml::Table = toml::from_str(&model::to_toml_string(&sys))?;
    for (k, v) in ss.rest {
        t.insert(k, v);
    }
    // `csv` inputs are read relative to the state-space file, as a model file reads them
    let dir = a.file.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    model::model_file::parse_str_with(&toml::to_string(&t)?, &a.file.display().to_string(), dir)
        .map_err(|e| anyhow::anyhow!("{e}"))
}

/// Steps per input period the imported model's `simulation.dt` gives at least (the default
/// step is kept where it is finer): a fast input (`--omega 1e4`) with the default `1e-3`
/// would give a model that `validate` refuses (fewer than `MIN_STEPS_PER_PERIOD` steps).
const IMPORT_STEPS_PER_PERIOD: f64 = 100.0;

/// The step for the imported model: `default`, or the input period over
/// [`IMPORT_STEPS_PER_PERIOD`] where that is finer. The period comes from the flags' input
/// or the JSON `input` table (`omega`, or a `csv` input's `period`).
fn step_for(input: &Input, table: Option<&toml::Value>, default: f64) -> f64 {
    let num =
        |k: &str| table.and_then(|t| t.get(k)).and_then(|v| v.as_float().or_else(|| v.as_integer().map(|i| i as f64)));
    let period = input.period().or_else(|| {
        num("omega")
            .filter(|w| w.is_finite() && *w != 0.0)
            .map(|w| std::f64::consts::TAU / w.abs())
            .or_else(|| num("period"))
    });
    match period {
        Some(T) if T.is_finite() && T > 0.0 => default.min(T / IMPORT_STEPS_PER_PERIOD),
        _ => default,
    }
}

/// A `csv` input as the written model must name it: a model file reads relative paths from
/// its own directory, so the samples file is named by its file name when it sits beside the
/// output, else by its absolute path.
fn relocate_samples(sys: &mut System, out: &Path) {
    let Input::Samples { path, .. } = &mut sys.input else { return };
    let Ok(csv) = std::fs::canonicalize(&*path) else { return };
    let out_dir = out.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let beside = std::fs::canonicalize(out_dir).is_ok_and(|d| csv.parent() == Some(d.as_path()));
    *path = match (beside, csv.file_name()) {
        (true, Some(name)) => name.to_string_lossy().into_owned(),
        _ => csv.display().to_string(),
    };
}

fn read(path: &Path) -> anyhow::Result<StateSpace> {
    // regular files only, 64 MiB at most (a FIFO or a device would block)
    let len = model::files::check_regular(path)?;
    if len > 64 << 20 {
        bail!("{}: {len} bytes, more than the 64 MiB a state-space file may have", path.display());
    }
    let bytes = std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("mat") => read_mat(&bytes),
        Some("json") => read_json(std::str::from_utf8(&bytes).context("not UTF-8 text")?),
        other => bail!("{}: unknown extension {:?} (expected .mat or .json)", path.display(), other.unwrap_or("")),
    }
}

pub fn run(a: &Args) -> anyhow::Result<ExitCode> {
    crate::output::register_input(&a.file);
    crate::output::check_writable(&a.out)?;
    let ss = read(&a.file).with_context(|| a.file.display().to_string())?;
    let mut sys = build(ss, a).with_context(|| a.file.display().to_string())?;
    relocate_samples(&mut sys, &a.out);
    let text = model::to_toml_string(&sys);
    // the file must be one that `moreau validate` accepts where it is written
    if text.len() as u64 > model::files::MAX_MODEL_BYTES {
        bail!(
            "{}: the model it gives is {} bytes, more than the {} a model file may have",
            a.file.display(),
            text.len(),
            model::files::MAX_MODEL_BYTES
        );
    }
    let out_dir = a.out.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    model::model_file::parse_str_with(&text, &a.out.display().to_string(), out_dir).with_context(|| {
        format!("{}: the model it gives would not validate as {}", a.file.display(), a.out.display())
    })?;
    crate::output::write_atomic(&a.out, text.as_bytes())?;
    println!(
        "wrote {}: n = {}, m = {}, p = {}, Theta = {}",
        a.out.display(),
        sys.n(),
        sys.m(),
        sys.p(),
        geometry::ConvexSet::describe(&sys.theta)
    );
    Ok(ExitCode::SUCCESS)
}
