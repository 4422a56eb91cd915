//! Every example line in the `--help` of every subcommand parses with the real argument parser
//! (so the examples cannot drift from the flags); a misspelt flag is rejected (control).
use clap::{CommandFactory, Parser};
use moreau::cli::Cli;

#[test]
fn help_examples_parse() {
    let mut cmd = Cli::command();
    let mut checked = 0;
    let names: Vec<String> = cmd.get_subcommands().map(|s| s.get_name().to_string()).collect();
    for name in names {
        let sub = cmd.find_subcommand_mut(&name).unwrap();
        let help = sub.render_long_help().to_string();
        for line in help.lines().map(str::trim).filter(|l| l.starts_with("moreau ")) {
            let words: Vec<&str> = line.split('#').next().unwrap().split_whitespace().collect();
            let parsed = Cli::try_parse_from(&words);
            assert!(parsed.is_ok(), "`{line}` in `moreau {name} --help` does not parse: {:?}", parsed.err());
            checked += 1;
        }
    }
    assert!(checked >= 20, "only {checked} example lines found");
    // control: a wrong flag in an example would be caught
    assert!(Cli::try_parse_from(["moreau", "theta", "x.toml", "--jsn"]).is_err());
}
