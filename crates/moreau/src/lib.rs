//! `moreau`: the command-line tool of the workspace and what only it needs: the command layer
//! shared with the Python package ([`commands`]: validation, budgets ([`budget`]) and typed
//! results, one module per command), the command line that parses, prints and writes
//! ([`cli`]), parameter sweeps with checkpoints and shards ([`sweep`]), figures ([`figures`]),
//! design guidance ([`guidance`]) and atomic output files ([`output`]). The numbers themselves come
//! from the library crates (`bounds`, `dynamics`, `lmi`, `theorems`, `discovery`).
#![allow(non_snake_case)]

pub mod budget;
pub mod cli;
pub mod commands;
pub mod figures;
#[doc(hidden)]
pub mod fuzzing;
pub mod guidance;
pub mod output;
pub mod sweep;
