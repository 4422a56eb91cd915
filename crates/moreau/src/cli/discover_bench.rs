//! `moreau discover-bench --cases N --seed S`: the concealed-effect benchmark of `discovery`
//! (N cases of each of the 9 classes: none and the 8 effects, or of the `--classes` given),
//! printing the confusion matrix, the false-alarm rate on `none` and the parameter errors. `--profile digital` generates
//! zero-order-held inputs, 1-10 ms sampling, white or AR(1) noise and lightly damped plants;
//! `--profile mixed` every convention at once (continuous, zero- or first-order-held inputs,
//! 0.5-20 ms sampling).
use anyhow::Context;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, clap::Args)]
pub struct Args {
    /// Cases per class.
    #[arg(long, default_value_t = 8)]
    pub cases: usize,
    /// Seed of the generator.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Generator profile: `classic` (continuous inputs, white noise, 60 samples per natural
    /// period), `digital` (zero-order-held inputs, sample periods 1-10 ms, white or
    /// AR(1)-coloured noise, half the plants lightly damped) or `mixed` (as digital, with
    /// continuous, zero- or first-order-held inputs and sample periods 0.5-20 ms).
    #[arg(long, default_value = "classic", value_parser = ["classic", "digital", "mixed"])]
    pub profile: String,
    /// Classes: `classic` (none and the 8 original effects), `friction` (none,
    /// coulomb_friction, stribeck_friction, asymmetric_coulomb, cogging), `all`, or a
    /// comma-separated list of class names.
    #[arg(long, default_value = "classic")]
    pub classes: String,
    /// Estimate the initial state although each case's model states the true one.
    #[arg(long)]
    pub estimate_x0: bool,
    /// Also write every case's result as JSON here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Instead of diagnosing, write each case's nominal model and recording
    /// (`<class>-<i>.toml`, `<class>-<i>.csv`) into this directory, to run `moreau diagnose` on.
    #[arg(long)]
    pub write_cases: Option<PathBuf>,
}

pub fn run(a: &Args) -> anyhow::Result<ExitCode> {
    if a.cases == 0 {
        anyhow::bail!("--cases must be at least 1 (got 0)");
    }
    if let Some(e) = discovery::bench_gen::env_error() {
        anyhow::bail!("{e}");
    }
    // each case simulates and fits several hypotheses (seconds); the results stay in memory
    crate::budget::check(
        "discover-bench: --cases",
        a.cases as f64,
        crate::budget::MAX_BENCH_CASES as f64,
        1e6,
        "per class",
    )?;
    let profile = discovery::bench_gen::Profile::parse(&a.profile)
        .with_context(|| format!("--profile {:?}: expected classic, digital or mixed", a.profile))?;
    let classes = discovery::bench::class_set(&a.classes).with_context(|| {
        format!(
            "--classes {:?}: expected classic, friction, all or a comma-separated list of {}",
            a.classes,
            discovery::bench_gen::all_classes().join(", ")
        )
    })?;
    if let Some(dir) = &a.write_cases {
        let st = crate::output::StagedDir::new(dir)?;
        for i in 0..a.cases {
            for &c in classes.iter() {
                let case = discovery::bench_gen::generate_profile(c, a.seed, i, profile);
                let mut m = case.nominal.clone();
                m.name = format!("{} [{}]", m.name, case.description);
                std::fs::write(st.path(&format!("{c}-{i}.toml")), model::to_toml_string(&m))?;
                std::fs::write(st.path(&format!("{c}-{i}.csv")), case.recording.to_csv_string())?;
                println!("{c}-{i}: truth {:?}; {}", case.truth, case.description);
            }
        }
        st.commit()?;
        return Ok(ExitCode::SUCCESS);
    }
    // an output that cannot be written is refused now, not after the benchmark
    if let Some(p) = &a.json {
        crate::output::check_writable(p)?;
    }
    let settings = discovery::DiagnoseSettings { estimate_x0: a.estimate_x0, ..Default::default() };
    let r = discovery::bench::run_classes(&classes, a.cases, a.seed, profile, &settings, |c| {
        eprintln!(
            "{:>18} #{:<3} -> {:<34} {} ({:.1} s; {})",
            c.class,
            c.index,
            c.selected,
            c.error.as_deref().unwrap_or(""),
            c.seconds,
            c.conditions.short()
        );
    });
    println!("{}", r.to_text());
    if let Some(p) = &a.json {
        crate::output::write_atomic(p, serde_json::to_string_pretty(&r)?.as_bytes())
            .with_context(|| format!("writing {}", p.display()))?;
    }
    Ok(ExitCode::SUCCESS)
}
