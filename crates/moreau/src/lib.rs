//! `moreau`: the command-line tool of the workspace and what only it needs: the commands
//! ([`cli`]), parameter sweeps with checkpoints and shards ([`sweep`]), figures
//! ([`figures`], [`plot`]) and atomic output files ([`output`]). The numbers themselves come
//! from the library crates (`bounds`, `dynamics`, `lmi`, `theorems`, `discovery`).
#![allow(non_snake_case)]

pub mod budget;
pub mod cli;
pub mod csv_check;
pub mod figures;
pub mod guidance;
pub mod output;
pub mod plot;
pub mod sweep;
