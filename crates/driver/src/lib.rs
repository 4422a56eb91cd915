//! Assembly of the paper's bound theta and every quantity in it, and the command-line tool
//! `moreau` (module [`cli`]).
#![allow(non_snake_case)]

pub mod cli;
pub mod output;
pub mod plot;
