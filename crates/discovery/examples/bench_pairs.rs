//! Runs cases with two concealed effects at once and prints each result (issue 27 item 4;
//! development aid and the source of the BENCHMARKS.md table).
//! Usage: `cargo run --release -p discovery --example bench_pairs CASES SEED [classic|digital|mixed]
//! [PAIRS]`, `PAIRS` `all` (default: every pair of `bench_gen::pairs`) or a comma-separated
//! list of `a+b`.
//!
//! Per case: the selected model, how many of the two concealed effects it names (strict) and
//! how many the best of it and its equivalent readings names, whether the report calls the
//! model incomplete, the final residual's portmanteau statistic, the BIC gains of the selected
//! model and of the true pair (where fitted), the time and the case.
//!
//! `ESTIMATE_X0=1` has the initial state estimated (as for a model file that states none).
//! `BENCH_NEXT=1` also records each machine's next experiment and predicts it with the
//! returned model (a line per case, `bench::next_experiment`).
//!
//! `BENCH_PAIRS_TRUTH` set: each unflagged miss is diagnosed again with only its two true
//! effects offered (`DiagnoseSettings::library`), and the line `truth only` gives what that
//! selects, its BIC gain over the nominal and its residual's portmanteau statistic. Where the
//! true pair gains no more than the reading selected from the whole library and leaves a
//! residual as white, nothing in the recording tells the two apart: the miss is the
//! recording's, not the selection's (the ceiling of "misses flagged", BENCHMARKS).
//! `BENCH_PAIRS_TRUTH=all` does so for every miss, flagged or not. With either, the summary
//! counts the unflagged misses at that ceiling (the true pair fits as well, within the
//! selection's BIC margin), those whose true pair's fit falls short of the selected reading by
//! more (a fit that missed the true parameters, or a reading fitting coloured noise: not the
//! recording's ceiling), and the misses flagged among the rest.
fn main() {
    if let Some(e) = discovery::bench_gen::env_error() {
        eprintln!("error: {e}");
        std::process::exit(2);
    }
    use discovery::bench_gen;
    let args: Vec<String> = std::env::args().collect();
    let cases: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1);
    let seed: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(1);
    let profile = args
        .get(3)
        .map(|s| bench_gen::Profile::parse(s).expect("profile: classic, digital or mixed"))
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
    let (mut n, mut both, mut both_eq, mut missed, mut flagged, mut missed_eq, mut flagged_eq) = (0, 0, 0, 0, 0, 0, 0);
    // unflagged misses by what the true pair, offered alone, gains against the reading selected
    let (mut unshown, mut short) = (0, 0);
    let truth = std::env::var("BENCH_PAIRS_TRUTH").ok();
    let settings = discovery::DiagnoseSettings { estimate_x0: estimate_x0(), ..Default::default() };
    for i in 0..cases {
        for &p in &pairs {
            let Some(r) = discovery::bench::run_pair_case(p, seed, i, profile, &settings) else { continue };
            println!(
                "{:>36} #{i} -> {:<40} named {} (or equivalent {}) incomplete {} Q {:.1}/{:.1} dBIC {:.1} true pair {} {:.1}s {} equivalents {:?} {:?}",
                format!("{}+{}", p[0], p[1]),
                r.selected,
                r.named,
                r.named_or_equivalent,
                r.model_incomplete,
                r.q_final,
                r.q_threshold,
                r.delta_bic_selected,
                r.delta_bic_true_pair.map_or("not fitted".into(), |v| format!("{v:.1}")),
                r.seconds,
                r.description,
                r.equivalents,
                r.error
            );
            if let Some(n) = &r.next {
                println!("{:>36}    {n}", "");
            }
            let again = match truth.as_deref() {
                Some("all") => true,
                Some(_) => !r.model_incomplete,
                None => false,
            };
            if r.named < 2 && again {
                let reading = print_truth_ceiling(p, seed, i, profile, r.delta_bic_selected);
                if !r.model_incomplete {
                    unshown += (reading == Some(TruthReading::AsGood)) as usize;
                    short += (reading == Some(TruthReading::FallsShort)) as usize;
                }
            }
            if std::env::var_os("BENCH_PAIRS_RANKING").is_some() {
                print_ranking(p, seed, i, profile);
            }
            n += 1;
            if r.named == 2 {
                both += 1;
            } else {
                missed += 1;
                flagged += r.model_incomplete as usize;
            }
            if r.named_or_equivalent == 2 {
                both_eq += 1;
            } else {
                missed_eq += 1;
                flagged_eq += r.model_incomplete as usize;
            }
        }
    }
    println!("cases {n}: both named {both}; one or both missed {missed}, of which flagged incomplete {flagged}");
    println!(
        "counting equivalent readings: both named {both_eq}; one or both missed {missed_eq}, of which flagged incomplete {flagged_eq}"
    );
    if truth.is_some() {
        println!(
            "unflagged misses whose true pair, offered alone, fits as well as the reading selected (within the margin, {MARGIN_BIC} in BIC: the recording's ceiling): {unshown}; whose true pair's fit falls short of it by more (a fit that missed the truth, or a reading of coloured noise): {short}; misses flagged among the others: {flagged} of {}",
            missed - unshown - short
        );
    }
}

/// `ESTIMATE_X0=1`: the initial state estimated, as for a model file that states none.
fn estimate_x0() -> bool {
    std::env::var("ESTIMATE_X0").is_ok_and(|v| v == "1")
}

/// The selection's BIC margin (`select::Margins::default`): a reading that beats another by
/// less is not preferred to it.
const MARGIN_BIC: f64 = 10.0;

/// The true pair offered alone against the reading selected from the whole library.
#[derive(PartialEq)]
enum TruthReading {
    /// Gains more (beyond the printed precision): the selection missed a better reading.
    Better,
    /// Gains as much, within the margin: the recording tells the two apart by nothing the
    /// selection may use.
    AsGood,
    /// Gains less by more than the margin: a fit of the true pair that missed its true
    /// parameters, or a reading that fits coloured noise; not counted as the recording's
    /// ceiling (at its true parameters the true pair leaves only the noise).
    FallsShort,
}

/// `BENCH_PAIRS_TRUTH` set: the case with only its true effects offered; how its BIC gain
/// compares with that of the reading selected from the whole library (`gain`).
fn print_truth_ceiling(
    p: [&'static str; 2],
    seed: u64,
    i: usize,
    profile: discovery::bench_gen::Profile,
    gain: f64,
) -> Option<TruthReading> {
    let s = discovery::DiagnoseSettings {
        library: Some(vec![p[0].to_string(), p[1].to_string()]),
        estimate_x0: estimate_x0(),
        ..Default::default()
    };
    let t = discovery::bench::run_pair_case(p, seed, i, profile, &s)?;
    println!(
        "{:>36}    truth only -> {:<40} named {} dBIC {:.1} (selected from the library {:.1}: truth {}) Q {:.1}/{:.1} incomplete {}",
        "",
        t.selected,
        t.named,
        t.delta_bic_selected,
        gain,
        if t.delta_bic_selected > gain { format!("better by {:.1}", t.delta_bic_selected - gain) } else { format!("worse by {:.1}", gain - t.delta_bic_selected) },
        t.q_final,
        t.q_threshold,
        t.model_incomplete
    );
    // 0.05: the printed precision (an equivalent reading, direction-dependent friction for
    // Coulomb friction and a constant force, gains the same)
    Some(if t.delta_bic_selected > gain + 0.05 {
        TruthReading::Better
    } else if t.delta_bic_selected >= gain - MARGIN_BIC {
        TruthReading::AsGood
    } else {
        TruthReading::FallsShort
    })
}

/// Development aid (`BENCH_PAIRS_RANKING` set): the case diagnosed again, its ranking printed.
fn print_ranking(p: [&'static str; 2], seed: u64, i: usize, profile: discovery::bench_gen::Profile) {
    let case = discovery::bench_gen::generate_pair(p, seed, i, profile).expect("a pair that can co-occur");
    let s = discovery::DiagnoseSettings { estimate_x0: estimate_x0(), ..Default::default() };
    let Ok(rep) = discovery::diagnose(&case.nominal, &case.recording, &discovery::bench::with_case_start(&case, &s))
    else {
        return;
    };
    for r in &rep.ranking {
        println!("    {:<50} dBIC {:>9.1} {:?} {}", r.label, r.delta_bic, r.status, r.evidence);
    }
    println!("    verdict: {}", rep.verdict);
    println!("    hold {:?}, {} sub-steps", rep.hold, rep.substeps);
    println!(
        "    ladder {:?} final {:?}",
        rep.discretisation.ladder,
        rep.discretisation_final.as_ref().map(|d| d.ladder.clone())
    );
    for n in &rep.notes {
        println!("    note: {n}");
    }
}
