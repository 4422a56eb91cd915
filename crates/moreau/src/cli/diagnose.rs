//! `moreau diagnose --model M.toml --data R.csv --out DIR`: compare a nominal model with a
//! recording, locate the mismatch, name the missing physics, refit and validate
//! (crate `discovery`). Writes `report.md`, `report.json`, `fitted.toml`, `residual.svg`,
//! `fit.svg` (and PNG copies) into DIR, all together or not at all.
use crate::output::StagedDir;
use crate::plot::{self, LinePlot, Series};
use anyhow::Context;
use discovery::{DiagnoseSettings, Recording, Report};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Nominal model file (TOML).
    #[arg(long)]
    pub model: PathBuf,
    /// Recording CSV: header `t,w,y` or `t,w1..wm,y1..yp`, optional `z`.
    #[arg(long)]
    pub data: PathBuf,
    /// Output directory.
    #[arg(long)]
    pub out: PathBuf,
    /// Fraction of the record used for estimation (the rest validates). Default 0.7.
    #[arg(allow_negative_numbers = true, long, default_value_t = 0.7)]
    pub estimation_fraction: f64,
    /// Greatest number of effects added by forward selection.
    #[arg(long, default_value_t = 2)]
    pub max_effects: usize,
    /// Input between samples: `zoh` (each sample held until the next, as a digital
    /// controller's command), `foh` (linear interpolation) or `auto` (the hold under which the
    /// nominal model fits better; the report says which and by how much).
    #[arg(long, default_value = "auto", value_parser = ["auto", "zoh", "foh"])]
    pub input_hold: String,
    /// Estimate the initial state even when the model file states `[initial] x0` (by default
    /// a stated x0, and z0, is used as known).
    #[arg(long)]
    pub estimate_x0: bool,
    /// Headline of the verdict: `auto` (RMSE in the output's units, from the model file's
    /// `[signals] y`, when the validation fit % exceeds 99 %, as for a tightly tracking servo
    /// loop; else fit %), `fit` or `rmse`.
    #[arg(long, default_value = "auto", value_parser = ["auto", "fit", "rmse"])]
    pub metric: String,
    /// Keep the nominal parameters that the model file frees (`[fit] free`) at their values:
    /// no grey-box refit.
    #[arg(long)]
    pub no_refit: bool,
}

/// The initial state the model file states (`[initial] x0`, optional `z0`), if any.
fn stated_initial_state(
    path: &std::path::Path,
    sys: &model::System,
) -> anyhow::Result<Option<discovery::InitialState>> {
    let text = std::fs::read_to_string(path).with_context(|| format!("model {}", path.display()))?;
    let root: toml::Table = match toml::from_str(&text) {
        Ok(t) => t,
        Err(_) => return Ok(None), // model::load accepted it; nothing more to learn here
    };
    let init = root.get("initial").and_then(|v| v.as_table());
    let has = |k: &str| init.is_some_and(|t| t.contains_key(k));
    if !has("x0") {
        return Ok(None);
    }
    Ok(Some(discovery::InitialState {
        x0: sys.x0.iter().copied().collect(),
        z0: has("z0").then(|| sys.z0.iter().copied().collect()),
    }))
}

/// At most `max` evenly spaced points of a series (for figures of long records).
fn thin(t: &[f64], v: &[f64], max: usize) -> (Vec<f64>, Vec<f64>) {
    let step = (t.len() / max.max(1)).max(1);
    (t.iter().step_by(step).copied().collect(), v.iter().step_by(step).copied().collect())
}

/// The two figures of a report: residual timeline with windows shaded, and measured vs
/// nominal vs fitted (output 1).
pub fn figures(r: &Report) -> Vec<(&'static str, LinePlot)> {
    let s = &r.series;
    let p = s.p.max(1);
    let col = |v: &[f64], i: usize| -> Vec<f64> { v.iter().skip(i).step_by(p).copied().collect() };
    let mut out = Vec::new();
    let windows: Vec<(f64, f64)> = r.windows.iter().map(|w| (w.t_start, w.t_end)).collect();
    // Units from the model file's `[signals] y`.
    let unit = r.units.first().filter(|u| !u.is_empty()).map_or(String::new(), |u| format!(" ({u})"));
    let y0 = col(&s.y, 0);
    let en: Vec<f64> = col(&s.y, 0).iter().zip(col(&s.yhat_nominal, 0)).map(|(a, b)| a - b).collect();
    let ef: Vec<f64> = col(&s.y, 0).iter().zip(col(&s.yhat_fitted, 0)).map(|(a, b)| a - b).collect();
    let mk = |label: &str, v: &[f64]| {
        let (x, y) = thin(&s.t, v, 4000);
        Series { label: label.into(), x, y }
    };
    out.push((
        "residual",
        LinePlot {
            title: format!(
                "Residual y - yhat (output 1); shaded: located windows; validation from t = {:.3}",
                r.validation_segment[0]
            ),
            x_label: "t (s)".into(),
            y_label: format!("residual{unit}"),
            series: vec![mk("nominal", &en), mk("fitted", &ef)],
            windows: windows.clone(),
            size: (1200, 500),
        },
    ));
    out.push((
        "fit",
        LinePlot {
            title: format!("Measured vs nominal vs fitted (output 1): {}", r.selected()),
            x_label: "t (s)".into(),
            y_label: format!("y{unit}"),
            series: vec![
                mk("measured", &y0),
                mk("nominal", &col(&s.yhat_nominal, 0)),
                mk("fitted", &col(&s.yhat_fitted, 0)),
            ],
            windows: vec![(r.validation_segment[0], r.validation_segment[1])],
            size: (1200, 500),
        },
    ));
    out
}

/// Writes every output of a report into `out` atomically.
pub fn write_outputs(r: &Report, out: &std::path::Path) -> anyhow::Result<()> {
    let figs = figures(r);
    let st = StagedDir::new(out)?;
    let mut captions = Vec::new();
    for (name, fig) in &figs {
        let svg = plot::to_svg_string(fig).with_context(|| format!("figure {name}"))?;
        std::fs::write(st.path(&format!("{name}.svg")), svg)?;
        plot::write_png(fig, &st.path(&format!("{name}.png"))).with_context(|| format!("figure {name}"))?;
        captions.push((format!("{name}.svg"), fig.title.clone()));
    }
    let caps: Vec<(&str, &str)> = captions.iter().map(|(a, b)| (a.as_str(), b.as_str())).collect();
    std::fs::write(st.path("report.md"), r.to_markdown(&caps))?;
    std::fs::write(st.path("report.json"), serde_json::to_string_pretty(r)?)?;
    if let Some(m) = &r.fitted_model {
        let text = model::to_toml_string(m);
        if let (model::Input::Samples { path, .. }, Some(csv)) = (&m.input, m.input.samples_csv()) {
            std::fs::write(st.path(path), csv)?;
        }
        std::fs::write(st.path("fitted.toml"), text)?;
        model::load(&st.path("fitted.toml")).context("the fitted model does not read back (internal error)")?;
    }
    st.commit()
}

pub fn run(a: &Args) -> anyhow::Result<ExitCode> {
    let sys = model::load(&a.model).with_context(|| format!("model {}", a.model.display()))?;
    let text = crate::csv_check::read_checked(&a.data, "recording", crate::csv_check::TimeColumn::Numeric("t"))?;
    let rec = Recording::parse_str(&text, &a.data.display().to_string())?;
    let settings = DiagnoseSettings {
        estimation_fraction: a.estimation_fraction,
        max_effects: a.max_effects,
        input_hold: discovery::HoldChoice::parse(&a.input_hold).unwrap_or_default(),
        initial_state: stated_initial_state(&a.model, &sys)?,
        estimate_x0: a.estimate_x0,
        metric: discovery::diagnose::Metric::parse(&a.metric).unwrap_or_default(),
        refit_nominal: !a.no_refit,
        ..Default::default()
    };
    let start = std::time::Instant::now();
    let r = discovery::diagnose(&sys, &rec, &settings)?;
    let secs = start.elapsed().as_secs_f64();
    write_outputs(&r, &a.out)?;
    println!("{}", r.verdict);
    println!(
        "input hold {}{}; {} sub-step(s) per sample (remaining discretisation error {:.2e} output standard deviations; noise level {}); initial state {}",
        r.hold.chosen,
        match (r.hold.requested, r.hold.delta_bic) {
            (discovery::HoldChoice::Auto, Some(d)) => format!(" (auto: better by {d:.1} in BIC{})", if r.hold.decisive { "" } else { ", not decisive" }),
            _ => " (as requested)".to_string(),
        },
        r.substeps,
        r.discretisation.error_rms,
        r.noise_level.iter().map(|v| format!("{v:.2e}")).collect::<Vec<_>>().join(", "),
        r.initial_state.source
    );
    let pct = |v: &[Option<f64>]| {
        v.iter().map(|x| x.map_or("undefined".to_string(), |x| format!("{x:.1}"))).collect::<Vec<_>>().join(", ")
    };
    if r.headline_metric == "rmse" {
        println!("{}", r.headline);
    } else {
        let rmse = |v: &[f64]| v.iter().map(|x| format!("{x:.3e}")).collect::<Vec<_>>().join(", ");
        println!(
            "validation fit % (nominal -> fitted): {} -> {}; RMSE {} -> {}",
            pct(&r.fit_before.fit_percent),
            pct(&r.fit_after.fit_percent),
            rmse(&r.fit_before.rmse),
            rmse(&r.fit_after.rmse)
        );
    }
    for v in &r.nominal_refit {
        println!(
            "  {}: {} -> {} +- {} (refitted plant parameter)",
            v.name,
            sig4(v.nominal),
            sig4(v.value),
            sig4(v.std)
        );
    }
    if !r.fit_before.constant_outputs.is_empty() {
        println!("fit % undefined: the validation output is constant; judge by the RMSE");
    }
    for e in &r.effects {
        // "width = 0.553 +- 0.012" per parameter, the uncertainty where the fit gives one
        let params: Vec<String> = e
            .params
            .iter()
            .map(|(name, v)| match e.uncertainty.iter().find(|(n, _)| n == name) {
                Some((_, s)) => format!("{name} = {} +- {}", sig4(*v), sig4(*s)),
                None => format!("{name} = {}", sig4(*v)),
            })
            .collect();
        println!("  {}: {}", e.label, params.join(", "));
    }
    println!("{} hypotheses ranked in {secs:.2} s; report in {}", r.ranking.len(), a.out.display());
    Ok(ExitCode::SUCCESS)
}

/// 4 significant digits, as the sweep tables write numbers.
fn sig4(v: f64) -> String {
    crate::sweep::table::sig(v, 4, false)
}
