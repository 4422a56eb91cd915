//! Python bindings of the moreau workspace: `pip install ./python`, then `import moreau`.
//!
//! [`commands`] mirrors the `moreau` subcommands on the library crates (pure Rust, tested by
//! `cargo test --workspace`); `py` (feature `python`, turned on by maturin) is the extension
//! module `moreau._native` that the Python package `moreau` (python/python/moreau) wraps.
#![allow(non_snake_case)]

pub mod commands;
#[cfg(feature = "python")]
mod py;
