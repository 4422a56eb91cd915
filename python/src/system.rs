//! Systems built in Python: the tables of a model file (a dict) and optionally sampled input
//! arrays, validated by the model-file reader itself, so a system built in Python is exactly
//! the model file it describes, with the same checks and messages. The commands themselves
//! are `moreau::commands` (the CLI's own functions); `py.rs` converts arguments and results.
use anyhow::Context;
use model::{Input, ModelError, System};

/// Samples of an input given as arrays (`Samples(t, w, period)` in Python): checked like a
/// `kind = "csv"` input file (model::Input::from_csv) and named `source` in messages.
pub struct SamplesSpec {
    pub t: Vec<f64>,
    pub w: Vec<Vec<f64>>,
    pub period: Option<f64>,
    pub source: String,
    /// `"foh"` or `"zoh"` (the `hold` of a `csv` input).
    pub hold: String,
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
        model::input::check_period(per, &s.t, &s.source)?;
    }
    let hold = model::input::InputHold::parse(&s.hold, "input.hold")?;
    Ok(Input::Samples { path: s.source, t: s.t, w: s.w, period: s.period, hold })
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

#[cfg(test)]
mod tests {
    use super::*;
    use moreau::commands::one_line;
    use std::path::Path;

    /// The worked example's model file as a table (what Python passes as a dict).
    fn worked_example() -> toml::Table {
        include_str!("../../examples/worked-example.toml").parse().unwrap()
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
        let spec = |t: Vec<f64>, period| SamplesSpec {
            t,
            w: vec![vec![0.0]; 3],
            period,
            source: "<samples>".into(),
            hold: "foh".into(),
        };
        let e = one_line(&system_from_table(worked_example(), Some(spec(vec![0.0, 1.0, 1.0], None))).unwrap_err());
        assert!(e.contains("time stamps must increase strictly: row 4 has t = 1 after t = 1"), "{e}");
        let e = one_line(&system_from_table(worked_example(), Some(spec(vec![0.0, 1.0, 2.0], Some(1.5)))).unwrap_err());
        assert!(e.starts_with("key `input.period`: shorter than the data"), "{e}");
        let s = system_from_table(worked_example(), Some(spec(vec![0.0, 1.0, 2.0], Some(2.0)))).unwrap();
        assert_eq!(s.period(), Some(2.0));
    }
}
