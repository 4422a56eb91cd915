//! Coverage of the truth by the reported sigma, per class, with and without the stepping part
//! of the sigma (issue 27 item 2; development aid).
//! Usage: `cargo run -p discovery --example coverage CLASS SEED CASES`.
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let class: &'static str = Box::leak(args.get(1).cloned().unwrap_or("backlash_inertia".into()).into_boxed_str());
    let seed: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    let cases: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(4);
    let (mut named, mut within, mut within_before) = (0, 0, 0);
    for i in 0..cases {
        let case = discovery::bench_gen::generate(class, seed, i);
        let s = discovery::DiagnoseSettings {
            initial_state: Some(discovery::InitialState {
                x0: case.nominal.x0.iter().copied().collect(),
                z0: Some(case.nominal.z0.iter().copied().collect()),
            }),
            ..Default::default()
        };
        let r = match discovery::diagnose(&case.nominal, &case.recording, &s) {
            Ok(r) => r,
            Err(e) => {
                println!("{class} #{i}: error {e}");
                continue;
            }
        };
        let truth = case.truth.as_ref().map(discovery::bench::main_param).unwrap_or(f64::NAN);
        let Some(e) = r.effects.first().filter(|e| e.kind == class) else {
            println!("{class} #{i}: named {}", r.selected());
            continue;
        };
        named += 1;
        let (est, sd) = (e.params[0].1, e.uncertainty[0].1);
        let (st, jk, sp) = (e.uncertainty_statistical[0].1, e.uncertainty_jackknife[0].1, e.uncertainty_stepping[0].1);
        let before = discovery::fit::jackknife::combine(st, jk);
        within += usize::from((est - truth).abs() <= 2.0 * sd);
        within_before += usize::from((est - truth).abs() <= 2.0 * before);
        println!(
            "{class} #{i} n = {} sub-steps {} truth {truth:.5} est {est:.5} ({:+.2} %) sigma {sd:.5} (stat {st:.5}, jackknife {jk:.5}, stepping {sp:.5}): {:+.2} sigma, {:+.2} without stepping",
            case.nominal.n(),
            r.substeps,
            100.0 * (est / truth - 1.0),
            (est - truth) / sd,
            (est - truth) / before
        );
    }
    println!("{class} seed {seed}: named {named}/{cases}, within 2 sigma {within}/{named} (without the stepping part {within_before}/{named})");
}
