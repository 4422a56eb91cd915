//! `moreau validate FILE...`
use anyhow::Context;
use geometry::ConvexSet;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, clap::Args)]
#[command(after_help = "Examples:
  moreau validate examples/*.toml")]
pub struct Args {
    /// Model files (TOML).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
}

/// One summary of a valid model.
pub fn summary(s: &model::System) -> String {
    let eig: Vec<String> = s
        .eig_F()
        .iter()
        .map(|c| if c.im == 0.0 { format!("{:.6}", c.re) } else { format!("{:.6}{:+.6}i", c.re, c.im) })
        .collect();
    let mu = s.mu();
    let per = s.period().map(|t| format!("{t:.6}")).unwrap_or_else(|| "none".into());
    let effects = if s.effects.list.is_empty() {
        "none (the paper's class)".to_string()
    } else {
        // one per line, in the model file's words (`kind` and keys)
        let list: String = s.effects.list.iter().map(|e| format!("\n    {}", e.describe())).collect();
        format!("{} (outside the paper's class: theta is not a certificate){list}", s.effects.list.len())
    };
    // a digital controller closes the loop: its sampled loop's decay rate
    let controller = match &s.controller {
        None => String::new(),
        Some(c) => {
            let mu_c = dynamics::extended::closed_loop_mu(s).unwrap_or(f64::NAN);
            format!(
                "  controller: {}, period {}, computation delay {} period(s); closed sampled loop mu = ln(rho)/period = {mu_c:.6}{}\n",
                c.kind(),
                c.period,
                c.delay,
                if mu_c < 0.0 { " (stable)" } else { " (NOT stable)" }
            )
        }
    };
    format!(
        "name:    {}\n  n = {}, m = {}, p = {}\n  Theta:   {}\n  R:       {}\n  eig(F):  {}\n  mu:      {:.6}{}\n  input:   {} (period {per})\n  effects: {effects}\n{controller}",
        s.name,
        s.n(),
        s.m(),
        s.p(),
        s.theta.describe(),
        s.theta.strong_convexity(),
        eig.join(", "),
        mu,
        if mu < 0.0 { " (F Hurwitz)" } else { " (F NOT Hurwitz: the paper's theory does not apply)" },
        s.input.kind(),
    )
}

pub fn run(a: &Args) -> anyhow::Result<ExitCode> {
    let mut failed = 0;
    for f in &a.files {
        match model::load(f).with_context(|| f.display().to_string()) {
            Ok(s) => println!("{}\n  {}", f.display(), summary(&s)),
            Err(e) => {
                eprintln!("error: {}", super::one_line(&e));
                failed += 1;
            }
        }
    }
    Ok(if failed == 0 { ExitCode::SUCCESS } else { ExitCode::from(2) })
}
