//! Runs the campaign without the CLI: `cargo run --release -p theorems --example campaign -- [cases] [seed] [negative]`.
use theorems::{CampaignSettings, Variant};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let cases = args.get(1).and_then(|s| s.parse().ok());
    let seed = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(0);
    let variant =
        if args.get(3).map(|s| s == "negative").unwrap_or(false) { Variant::NegativeControl } else { Variant::Claim };
    let st = CampaignSettings { cases, seed, only: std::env::var("ONLY").ok(), variant };
    let reps = theorems::run(&st, &|_, _| {}).expect("valid settings");
    println!(
        "{:<14} {:<10} {:>9} {:>8} {:>12} {:>10} {:>8}",
        "result", "label", "cases", "skipped", "min slack", "violations", "time"
    );
    for r in reps {
        println!(
            "{:<14} {:<10} {:>9} {:>8} {:>+12.3e} {:>10} {:>7.2}s",
            r.name, r.label, r.cases, r.skipped, r.min_slack, r.violations, r.seconds
        );
        if let Some(c) = r.counterexample {
            println!("    counterexample: {}", c.summary);
        }
    }
}
