//! Runs a few benchmark cases and prints each result (development aid).
//! Usage: `cargo run --release -p discovery --example bench_one CASES SEED [classic|digital]`.
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let cases: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1);
    let seed: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    let profile = args
        .get(3)
        .map(|s| discovery::bench_gen::Profile::parse(s).expect("profile: classic or digital"))
        .unwrap_or(discovery::bench_gen::Profile::Classic);
    let r = discovery::bench::run_with(cases, seed, profile, &Default::default(), |c| {
        println!("{:>18} -> {:<30} ties {:?} nominal fit {:.1} before {:.1} after {:.1} perr {:?} true {:?} est {:?} sd {:?} {:.1}s {} {:?}", c.class, c.selected, c.ties, c.nominal_fit, c.fit_before, c.fit_after, c.param_error, c.true_param, c.est_param, c.est_std, c.seconds, c.description, c.error);
    });
    println!("{}", r.to_text());
}
