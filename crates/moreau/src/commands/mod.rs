//! The command layer: one function per `moreau` subcommand that validates its arguments,
//! checks its work budget ([`crate::budget`], once per command, here), computes and returns a
//! typed result. The CLI ([`crate::cli`]) parses arguments, calls these functions, prints and
//! writes; the Python package (crate `moreau-python`) converts arguments and results. Both
//! front ends therefore refuse the same inputs with the same one-line messages ([`one_line`])
//! and get the same numbers.
//!
//! | command | function | result |
//! |---|---|---|
//! | `theta` | [`theta::theta`] | [`theta::ThetaRun`] (report, guidance; JSON) |
//! | `simulate` | [`simulate::simulate`] | [`simulate::Simulation`] (trajectory, method, step) |
//! | `periodic` | [`periodic::periodic`] | [`periodic::PeriodicRun`] (regime, rate; JSON) |
//! | `check` | [`check::plan`] then [`check::CheckPlan::run`] | [`check::CheckRun`] (reports, files; JSON) |
//! | `convergence` | [`convergence::plan`] then [`convergence::ConvergencePlan::run`] | `dynamics::convergence::ConvergenceStudy` |
//! | `diagnose` | [`diagnose::diagnose`] (+ [`diagnose::write_outputs`]) | [`diagnose::DiagnoseRun`] |
//! | `sweep` | [`sweep::sweep`] | [`sweep::SweepRun`] (summary, files) |
use anyhow::Context;
use model::System;
use std::path::{Path, PathBuf};

pub mod check;
pub mod convergence;
pub mod diagnose;
pub mod periodic;
pub mod simulate;
pub mod sweep;
pub mod theta;

/// Where a command's model comes from: a model file (errors carry its path) or a system built
/// in memory (by the Python package, with which parts of `[initial]` it states).
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
    /// From model-file text (nothing stated when the text is no TOML table).
    pub fn of_text(text: &str) -> Self {
        let Ok(root) = toml::from_str::<toml::Table>(text) else { return Self::default() };
        Self::of_table(&root)
    }

    /// From the tables of a model file.
    pub fn of_table(root: &toml::Table) -> Self {
        let init = root.get("initial").and_then(|v| v.as_table());
        let has = |k: &str| init.is_some_and(|t| t.contains_key(k));
        Self { x0: has("x0"), z0: has("z0") }
    }

    /// The initial state `diagnose` gets: the model's `x0` (and `z0`) where stated.
    pub fn initial_state(self, sys: &System) -> Option<discovery::InitialState> {
        self.x0.then(|| discovery::InitialState {
            x0: sys.x0.iter().copied().collect(),
            z0: self.z0.then(|| sys.z0.iter().copied().collect()),
        })
    }
}

impl Source {
    /// The system: a file read by [`load`], a built one cloned.
    pub fn system(&self) -> anyhow::Result<System> {
        match self {
            Source::File(p) => load(p),
            Source::Built(s, _) => {
                crate::budget::plant_entries(s)?;
                Ok((**s).clone())
            }
        }
    }

    /// How messages name the model: the file path in backticks (the system's name for a
    /// built system).
    pub fn label(&self) -> String {
        match self {
            Source::File(p) => format!("`{}`", p.display()),
            Source::Built(s, _) => format!("`{}`", s.name),
        }
    }
}

/// `model::load` with the path as context (as every command reads `FILE`).
pub fn load(path: &Path) -> anyhow::Result<System> {
    crate::output::register_input(path);
    let sys = model::load(path).with_context(|| path.display().to_string())?;
    crate::budget::plant_entries(&sys).with_context(|| path.display().to_string())?;
    Ok(sys)
}

/// The error and its causes on one line; a cause whose text an outer message already carries
/// (thiserror variants that format their `source`) is not repeated.
/// A context that the next cause repeats (`f.toml` then `f.toml: TOML syntax error ...` or
/// `cannot read f.toml: ...`) is replaced by that cause, so the path is printed once; line breaks inside a
/// message are folded.
pub fn one_line(e: &anyhow::Error) -> String {
    let mut parts: Vec<String> = Vec::new();
    for cause in e.chain() {
        let text = cause.to_string().lines().map(str::trim).filter(|l| !l.is_empty()).collect::<Vec<_>>().join(" ");
        if parts.iter().any(|p| p.contains(&text)) {
            continue;
        }
        match parts.last_mut() {
            Some(last) if text.contains(last.as_str()) => *last = text,
            _ => parts.push(text),
        }
    }
    clip_message(&parts.join(": "))
}

/// Longest one-line error printed whole (bytes).
pub const MAX_ERROR_BYTES: usize = 4000;

/// An error line of bounded size: each word longer than [`model::error::MAX_ECHO`] (a 10 MB
/// key, header name or cell that a message quotes) is clipped to its start and its length,
/// and the whole line to [`MAX_ERROR_BYTES`].
fn clip_message(line: &str) -> String {
    use model::error::{clip, clip_to, MAX_ECHO};
    if line.len() <= MAX_ECHO {
        return line.to_string();
    }
    let words: Vec<std::borrow::Cow<str>> = line.split(' ').map(clip).collect();
    clip_to(&words.join(" "), MAX_ERROR_BYTES).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn error_lines_are_bounded_whatever_they_quote() {
        let key = "k".repeat(10 << 20);
        let e = anyhow::anyhow!("recording r.csv: header [\"t\", \"w\", \"{key}\"] lacks column `y`");
        let line = one_line(&e);
        assert!(line.len() < 400, "{} bytes", line.len());
        assert!(line.ends_with("lacks column `y`") && line.contains("bytes in all"), "{line}");
        let many = (0..100_000).map(|k| format!("\"y{k}\"")).collect::<Vec<_>>().join(", ");
        let line = one_line(&anyhow::anyhow!("header [{many}]"));
        assert!(line.len() <= MAX_ERROR_BYTES + 100, "{} bytes", line.len());
        // negative control: an ordinary message is kept as it is
        let e = anyhow::anyhow!("key `plant.A`: expected 2 rows, got 3").context("m.toml");
        assert_eq!(one_line(&e), "m.toml: key `plant.A`: expected 2 rows, got 3");
    }
}
