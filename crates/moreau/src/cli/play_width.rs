//! `moreau play-width --data LOG.csv --config CONFIG.json [--json OUT]`: play (backlash) width
//! from a quasi-static two-sided loading log of the Robonine test stand
//! (`discovery::play_width`): loaded and unloaded flank-to-flank position difference per tested
//! servo, with its standard uncertainty from the spread over load cycles and the 1-count
//! encoder resolution.
use anyhow::Context;
use discovery::play_width::{robonine, PlayWidthSettings};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, clap::Args)]
#[command(after_help = "Examples:
  moreau play-width --data log.csv --config stand.toml --json play.json")]
pub struct Args {
    /// Telemetry CSV (columns `target pos (ID)`, `pos (ID)` in encoder counts).
    #[arg(long)]
    pub data: PathBuf,
    /// Upstream analysis config (`analysis_config_*.json`: home position, tested servos,
    /// puller relaxed/stretched targets and tolerances). Unknown keys are refused; the
    /// upstream script's `home_tolerance`, `home_motor_ids`, `require_home_position_match` and
    /// `min_segment_samples` are range-checked but not used (see --min-segment-samples).
    #[arg(long)]
    pub config: PathBuf,
    /// Shortest steady segment (samples).
    #[arg(long, default_value_t = 2)]
    pub min_segment_samples: usize,
    /// Samples dropped at the start of each segment.
    #[arg(long, default_value_t = 0)]
    pub skip_samples: usize,
    /// Also write the full result (segments, per-cycle differences) as JSON here.
    #[arg(long)]
    pub json: Option<PathBuf>,
}

/// Values of the stand configuration that make no sense: non-finite or negative tolerances,
/// non-finite targets, both pullers on the same servo, the servo under test among them.
pub(crate) fn check_config(c: &robonine::StandConfig) -> anyhow::Result<()> {
    let lim = model::MAX_MAGNITUDE;
    anyhow::ensure!(
        c.home_position.is_finite() && c.home_position.abs() <= lim,
        "home_position {} is not a finite position",
        c.home_position
    );
    for (i, p) in c.actuated_motors.iter().enumerate() {
        for (key, v) in [("relaxed_target", p.relaxed_target), ("stretched_target", p.stretched_target)] {
            anyhow::ensure!(v.is_finite() && v.abs() <= lim, "actuated_motors[{i}].{key} {v} is not a finite position");
        }
        for (key, v) in [("relaxed_tolerance", p.relaxed_tolerance), ("stretched_tolerance", p.stretched_tolerance)] {
            anyhow::ensure!(
                v.is_finite() && v >= 0.0 && v <= lim,
                "actuated_motors[{i}].{key} {v} must be a non-negative number"
            );
        }
        anyhow::ensure!(
            !c.report_motor_ids.contains(&p.motor_id),
            "actuated_motors[{i}].motor_id {} is also in report_motor_ids (a puller cannot be the servo under test)",
            p.motor_id
        );
    }
    if let [a, b] = c.actuated_motors.as_slice() {
        anyhow::ensure!(a.motor_id != b.motor_id, "both actuated_motors have motor_id {}", a.motor_id);
    }
    Ok(())
}

pub fn run(a: &Args) -> anyhow::Result<ExitCode> {
    crate::output::register_input(&a.data);
    crate::output::register_input(&a.config);
    let text =
        discovery::recording::read_checked(&a.data, "log", discovery::recording::TimeColumn::Iso8601("timestamp"))?;
    let cfg_text = model::files::read_regular(&a.config, model::files::MAX_MODEL_BYTES)?;
    let cfg = robonine::StandConfig::from_json_str(&cfg_text).with_context(|| a.config.display().to_string())?;
    check_config(&cfg).with_context(|| a.config.display().to_string())?;
    if a.min_segment_samples == 0 {
        anyhow::bail!("--min-segment-samples must be at least 1, got 0");
    }
    let s = PlayWidthSettings {
        min_segment_samples: a.min_segment_samples,
        skip_samples: a.skip_samples,
        resolution: 1.0,
        ..Default::default()
    };
    let res = robonine::analyse(&text, &a.data.display().to_string(), &cfg, &s)?;
    println!(
        "play width from {} (1 count = {:.4} deg; +- is one standard uncertainty)",
        a.data.display(),
        robonine::COUNT_DEG
    );
    println!("{:>6} {:>9} {:>22} {:>16} {:>7}", "servo", "state", "width (counts)", "width (deg)", "cycles");
    for r in &res {
        for (state, e) in [("unloaded", &r.unloaded), ("loaded", &r.loaded)] {
            println!(
                "{:>6} {:>9} {:>13.2} +- {:<5.2} {:>7.3} +- {:<5.3} {:>7}",
                r.motor_id,
                state,
                e.width,
                e.std_uncertainty,
                e.width * robonine::COUNT_DEG,
                e.std_uncertainty * robonine::COUNT_DEG,
                e.cycle_differences.len()
            );
        }
    }
    println!("the unloaded width is the closer reading of the play (2 x the half-width of Theta); the loaded one adds gear and holding-controller deflection under the band force");
    if let Some(p) = &a.json {
        crate::output::write_atomic(p, serde_json::to_string_pretty(&res)?.as_bytes())?;
    }
    Ok(ExitCode::SUCCESS)
}
