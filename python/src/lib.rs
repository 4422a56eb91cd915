//! Python bindings of the moreau workspace: `pip install ./python`, then `import moreau`.
//!
//! The commands are the CLI's own functions (`moreau::commands`: the same validation, budgets
//! and results); [`system`] builds a system from Python's tables (pure Rust, tested by
//! `cargo test --workspace`); `py` (feature `python`, turned on by maturin) is the extension
//! module `moreau._native` that the Python package `moreau` (python/python/moreau) wraps: it
//! converts arguments and results.
#![allow(non_snake_case)]

#[cfg(feature = "python")]
mod py;
pub mod system;
