//! `moreau discover-bench --cases N --seed S`: the concealed-effect benchmark of `discovery`
//! (N cases of each of the 9 classes: none and the 8 effects), printing the confusion matrix,
//! the false-alarm rate on `none` and the parameter errors.
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
    if let Some(dir) = &a.write_cases {
        let st = crate::output::StagedDir::new(dir)?;
        for i in 0..a.cases {
            for &c in discovery::bench_gen::CLASSES.iter() {
                let case = discovery::bench_gen::generate(c, a.seed, i);
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
    let r = discovery::bench::run(a.cases, a.seed, &Default::default(), |c| {
        eprintln!(
            "{:>18} #{:<3} -> {:<34} {} ({:.1} s)",
            c.class,
            c.index,
            c.selected,
            c.error.as_deref().unwrap_or(""),
            c.seconds
        );
    });
    println!("{}", r.to_text());
    if let Some(p) = &a.json {
        crate::output::write_atomic(p, serde_json::to_string_pretty(&r)?.as_bytes())
            .with_context(|| format!("writing {}", p.display()))?;
    }
    Ok(ExitCode::SUCCESS)
}
