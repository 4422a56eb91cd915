//! Assembly of the paper's bound theta and every quantity in it, and the command-line tool
//! `moreau` (module [`cli`]).
#![allow(non_snake_case)]

pub mod cli;
pub mod error;
pub mod figures;
pub mod orbit;
pub mod output;
pub mod report;
pub mod stationary;
pub mod sweep;
pub mod theta;
pub mod tube;

pub use error::DriverError;
pub mod plot;
