//! Runs cases with two concealed effects at once and prints each result (issue 27 item 4;
//! development aid and the source of the BENCHMARKS.md table).
//! Usage: `cargo run --release -p discovery --example bench_pairs CASES SEED [classic|digital]
//! [PAIRS]`, `PAIRS` `all` (default: every pair of `bench_gen::pairs`) or a comma-separated
//! list of `a+b`.
fn main() {
    use discovery::bench_gen;
    let args: Vec<String> = std::env::args().collect();
    let cases: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1);
    let seed: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    let profile = args
        .get(3)
        .map(|s| bench_gen::Profile::parse(s).expect("profile: classic or digital"))
        .unwrap_or(bench_gen::Profile::Classic);
    let all = bench_gen::pairs();
    let pairs: Vec<[&'static str; 2]> = match args.get(4).map(|s| s.as_str()) {
        None | Some("all") => all,
        Some(list) => list
            .split(',')
            .map(|p| {
                *all.iter()
                    .find(|q| format!("{}+{}", q[0], q[1]) == p || format!("{}+{}", q[1], q[0]) == p)
                    .expect("a pair of bench_gen::pairs, as a+b")
            })
            .collect(),
    };
    let (mut n, mut both, mut missed, mut flagged) = (0, 0, 0, 0);
    for i in 0..cases {
        for &p in &pairs {
            let Some(r) = discovery::bench::run_pair_case(p, seed, i, profile, &Default::default()) else { continue };
            println!(
                "{:>36} #{i} -> {:<40} named {} incomplete {} Q {:.1}/{:.1} {:.1}s {} {:?}",
                format!("{}+{}", p[0], p[1]),
                r.selected,
                r.named,
                r.model_incomplete,
                r.q_final,
                r.q_threshold,
                r.seconds,
                r.description,
                r.error
            );
            n += 1;
            if r.named == 2 {
                both += 1;
            } else {
                missed += 1;
                flagged += r.model_incomplete as usize;
            }
        }
    }
    println!("cases {n}: both named {both}; one or both missed {missed}, of which flagged incomplete {flagged}");
}
