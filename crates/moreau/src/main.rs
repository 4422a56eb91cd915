//! `moreau`: the command-line tool of the workspace. See `moreau --help`.
use std::process::ExitCode;

fn main() -> ExitCode {
    moreau::cli::main()
}
