//! Runs a few benchmark cases and prints each result (development aid).
//! Usage: `cargo run --release -p discovery --example bench_one CASES SEED [classic|digital|mixed]
//! [CLASSES]`, `CLASSES` one of `classic` (default: the original 9 classes), `friction`
//! (none, coulomb_friction and the friction library), `all`, or a comma-separated list.
//! `SCREEN=N` in the environment sets `screen_samples` (0: never screen); `ESTIMATE_X0=1`
//! has the initial state estimated (as for a model file that states none); `BENCH_LENGTH=F`
//! makes the recordings F times longer; `BENCH_NEXT=1` also records each machine's next
//! experiment and predicts it with the returned model (a line per case). A miss is followed
//! by a line comparing the selected model's BIC gain with the best ranked single of the true
//! class.
fn main() {
    if let Some(e) = discovery::bench_gen::env_error() {
        eprintln!("error: {e}");
        std::process::exit(2);
    }
    let args: Vec<String> = std::env::args().collect();
    let cases: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1);
    let seed: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    let profile = args
        .get(3)
        .map(|s| discovery::bench_gen::Profile::parse(s).expect("profile: classic, digital or mixed"))
        .unwrap_or(discovery::bench_gen::Profile::Classic);
    let classes = discovery::bench::class_set(args.get(4).map_or("classic", |s| s.as_str()))
        .expect("classes: classic, friction, all or a comma-separated list of class names");
    let mut s = discovery::DiagnoseSettings::default();
    if let Some(n) = std::env::var("SCREEN").ok().and_then(|v| v.parse().ok()) {
        s.screen_samples = n;
    }
    s.estimate_x0 = std::env::var("ESTIMATE_X0").is_ok_and(|v| v == "1");
    let r = discovery::bench::run_classes(&classes, cases, seed, profile, &s, |c| {
        println!("{:>18} -> {:<30} incomplete {} ties {:?} nominal fit {:.1} before {:.1} after {:.1} perr {:?} {:?} true {:?} est {:?} sd {:?} sdstat {:?} {:.1}s {} {:?}", c.class, c.selected, c.model_incomplete, c.ties, c.nominal_fit, c.fit_before, c.fit_after, c.param_error, c.param_errors, c.true_param, c.est_param, c.est_std, c.est_std_statistical, c.seconds, c.description, c.error);
        if let Some(n) = &c.next {
            println!("{:>18}    {n}", "");
        }
        if !c.correct {
            println!(
                "{:>18}    miss: selected dBIC {:.1}, best single of the truth {}",
                "",
                c.delta_bic_selected,
                c.delta_bic_truth.map_or("not ranked".into(), |t| format!(
                    "{t:.1} ({})",
                    if t > c.delta_bic_selected { "better: a selection gap" } else { "not better: the recording's" }
                ))
            );
        }
    });
    println!("{}", r.to_text());
}
