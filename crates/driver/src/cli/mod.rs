//! The `moreau` command line: one module per subcommand.
use clap::{Parser, Subcommand};
use std::process::ExitCode;

pub mod validate;

/// Convergence to periodic regimes with a strongly convex backlash: simulate, certify, check.
#[derive(Debug, Parser)]
#[command(name = "moreau", version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Parse and validate model files; print n, m, p, Theta and its R, eig(F) and mu.
    Validate(validate::Args),
}

/// Runs the CLI: prints errors on one line (`error: ...`) and returns a non-zero exit code.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Validate(a) => validate::run(&a),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            let chain: Vec<String> = e.chain().map(|c| c.to_string()).collect();
            eprintln!("error: {}", chain.join(": "));
            ExitCode::from(2)
        }
    }
}
