//! The `moreau` command line: one module per subcommand. Each parses its arguments, calls
//! the command's function in [`crate::commands`] where it has one (validation, budgets and
//! computation live there, shared with the Python package), and prints or writes the result.
use anyhow::{bail, Context};
use clap::{Parser, Subcommand};
use std::path::Path;
use std::process::ExitCode;

pub mod check;
pub mod convergence;
pub mod diagnose;
pub mod discover_bench;
pub mod figure;
pub mod import;
pub mod merge;
pub mod periodic;
pub mod play_width;
pub mod simulate;
pub mod sweep;
pub mod theta;
pub mod validate;

/// Convergence to periodic regimes with a strongly convex backlash: simulate, certify, check.
#[derive(Debug, Parser)]
#[command(name = "moreau", version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
    /// Lift the soft work limits (integration steps, stored samples, check cases, sweep
    /// points, theta's n and p) deliberately; see `moreau::budget`.
    #[arg(long, global = true)]
    pub allow_large: bool,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// The paper's bound theta (eq. (theta)) with every quantity labelled by its equation,
    /// verified flags, and the measured rate, path length and limsup |z'| next to it.
    Theta(theta::Args),
    /// Parse and validate model files; print n, m, p, Theta and its R, eig(F) and mu.
    Validate(validate::Args),
    /// A model file from a state space saved by MATLAB (.mat v5) or Python (.json).
    Import(import::Args),
    /// Property campaign: every inequality of the paper on random cases (table of cases,
    /// minimum normalised slack, violations); exit 1 on a violation, counterexample files.
    Check(check::Args),
    /// Simulate the closed loop; write trajectory.csv (t, w, x, y, z, q) and a plot (SVG, PNG).
    Simulate(simulate::Args),
    /// Periodic regime (Poincare fixed point, residual, (loc) check), measured convergence
    /// exponent with its 95% interval, path length of z per period.
    Periodic(periodic::Args),
    /// Error of the catching-up scheme against the event-driven reference for a ladder of steps.
    Convergence(convergence::Args),
    /// Compare a model with a recording: locate the mismatch, name the missing physics, refit,
    /// validate; writes report.md, report.json, fitted.toml and figures.
    Diagnose(diagnose::Args),
    /// Concealed-effect benchmark of `diagnose`: confusion matrix and parameter errors.
    DiscoverBench(discover_bench::Args),
    /// Parameter sweep (TOML spec): theta, its parts and the measured rate per point, as CSV,
    /// JSON, Markdown and LaTeX; parallel, resumable, `--shard K/N` for job arrays.
    Sweep(sweep::Args),
    /// Join the shards of one sweep (`moreau sweep --shard K/N`) into one table.
    Merge(merge::Args),
    /// Figures for papers (SVG and PNG): psi (Fig. psi1), tube (Fig. loop), trajectory, sweep.
    Figure(figure::Args),
    /// Play (backlash) width from a quasi-static two-sided loading log (Robonine stand):
    /// loaded and unloaded flank-to-flank difference with its uncertainty over cycles.
    PlayWidth(play_width::Args),
}

/// Runs the CLI: prints errors on one line (`error: ...`) and returns a non-zero exit code.
pub fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        // --help, --version, and a bare `moreau` (the command list)
        Err(e) if !e.use_stderr() || e.kind() == clap::error::ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
            e.exit()
        }
        Err(e) => {
            // clap's message, usage and tips on one line, exit code 2 like every bad input
            let text = e.to_string();
            let first = text.lines().next().unwrap_or("").trim();
            let first = first.strip_prefix("error: ").unwrap_or(first);
            match text.lines().find_map(|l| l.trim().strip_prefix("Usage: ")) {
                Some(usage) => eprintln!("error: {first} (usage: {usage})"),
                None => eprintln!("error: {first} (see --help)"),
            }
            return ExitCode::from(2);
        }
    };
    crate::budget::set_allow_large(cli.allow_large);
    crate::output::install_interrupt_cleanup();
    crate::output::exit_quietly_on_broken_pipe();
    let result = match cli.command {
        Command::Theta(a) => theta::run(&a),
        Command::Validate(a) => validate::run(&a),
        Command::Import(a) => import::run(&a),
        Command::Check(a) => check::run(&a),
        Command::Simulate(a) => simulate::run(&a),
        Command::Periodic(a) => periodic::run(&a),
        Command::Convergence(a) => convergence::run(&a),
        Command::Diagnose(a) => diagnose::run(&a),
        Command::DiscoverBench(a) => discover_bench::run(&a),
        Command::Sweep(a) => sweep::run(&a),
        Command::Merge(a) => merge::run(&a),
        Command::Figure(a) => figure::run(&a),
        Command::PlayWidth(a) => play_width::run(&a),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {}", one_line(&e));
            ExitCode::from(2)
        }
    }
}

pub use crate::commands::one_line;

/// Refuses, before a long run, an output file that [`crate::output::write_atomic`] would
/// refuse only after it: an input of the command ([`crate::output::refuse_input`], as `theta`
/// does for `--out`), a directory, a block device or socket, or a file whose directory cannot
/// be created or written (probed with an unnamed temporary file, gone when closed, where the
/// writer will create its own). Character devices and FIFOs are written through and pass.
pub fn check_output_early(path: &Path) -> anyhow::Result<()> {
    crate::output::refuse_input(path)?;
    let file = match std::fs::metadata(path) {
        Ok(m) if m.is_dir() => {
            bail!("output {} is a directory: refusing to replace it (give a file path)", path.display())
        }
        Ok(m) if m.is_file() => std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf()),
        Ok(m) => {
            use std::os::unix::fs::FileTypeExt;
            if m.file_type().is_char_device() || m.file_type().is_fifo() {
                return Ok(());
            }
            bail!("output {} is not a regular file: refusing to replace it (give a file path)", path.display())
        }
        Err(_) => path.to_path_buf(),
    };
    // the nearest existing directory: the writer creates the missing ones below it
    let mut dir = file.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    while std::fs::symlink_metadata(dir).is_err() {
        match dir.parent().filter(|d| !d.as_os_str().is_empty()) {
            Some(up) => dir = up,
            None => break,
        }
    }
    if !dir.is_dir() {
        bail!("output {}: {} is not a directory", path.display(), dir.display());
    }
    tempfile::tempfile_in(dir)
        .with_context(|| format!("output {}: cannot write into {}", path.display(), dir.display()))?;
    Ok(())
}
