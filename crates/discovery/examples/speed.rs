//! Speed of `discovery::diagnose` (issue 27 item 5): per-case time over the generator's cases,
//! growth with record length, with the number of hypotheses, and with threads. A benchmark,
//! not a test: it prints tables and asserts nothing.
//!
//! Usage (release):
//! `cargo run --release -p discovery --example speed -- [SECTIONS] [--cases N] [--seed S]
//! [--threads 1,2] [--lengths 2000,5000,...] [--verdicts]`
//! with `SECTIONS` a comma-separated list of `cases`, `length`, `hypotheses`, `simulator`,
//! `threads` (default all but `simulator`). `--cases N`: N cases per class and profile (every class of the generator,
//! profiles classic and digital; default 2). `--verdicts`: also print each case's verdict and
//! main estimate with its sigma, one line per case (to compare two builds on the same cases).
//! `--white`: the record-length section with white noise instead of the benchmark's sawtooth.
//! `--classes LIST` (as `bench_one`: `classic`, `friction`, `all` or class names) and
//! `--profiles classic,digital` narrow the cases.
//!
//! Each diagnosis is timed by wall clock and by the process's CPU time (user + system, from
//! `/proc/self/stat`; every thread of the process counted): on a shared machine the CPU time
//! is what survives the load, and the load average (`/proc/loadavg`) is printed beside the
//! tables. Threads: each run goes through a local rayon pool of the stated size.
use discovery::bench_gen::long_record::LongNoise;
use discovery::bench_gen::{self, Profile};
use discovery::{diagnose, DiagnoseSettings, InitialState, Recording, Report};
use dynamics::extended::ExtendedModel;
use std::time::Instant;

/// Wall and CPU seconds of one run.
#[derive(Debug, Clone, Copy)]
struct Timing {
    wall: f64,
    cpu: f64,
}

/// CPU seconds (user + system) of this process so far, every thread counted.
fn cpu_seconds() -> f64 {
    let s = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // Fields after the command name (which is in parentheses and may hold spaces).
    let rest = s.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<&str> = rest.split_whitespace().collect();
    // utime and stime are fields 14 and 15 of the line, 12 and 13 after the name.
    let ticks = |i: usize| f.get(i).and_then(|v| v.parse::<f64>().ok()).unwrap_or(f64::NAN);
    (ticks(11) + ticks(12)) / clock_ticks()
}

/// Clock ticks per second of `/proc` times (`getconf CLK_TCK`; 100 on Linux).
fn clock_ticks() -> f64 {
    std::process::Command::new("getconf")
        .arg("CLK_TCK")
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .and_then(|s| s.trim().parse().ok())
        .unwrap_or(100.0)
}

fn loadavg() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .unwrap_or_default()
        .split_whitespace()
        .take(3)
        .collect::<Vec<_>>()
        .join(" ")
}

/// Runs `f` in a local rayon pool of `threads` threads, timed.
fn timed<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> (T, Timing) {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("rayon pool");
    let (c0, t0) = (cpu_seconds(), Instant::now());
    let out = pool.install(f);
    let wall = t0.elapsed().as_secs_f64();
    drop(pool);
    (out, Timing { wall, cpu: cpu_seconds() - c0 })
}

/// `p`-quantile (nearest rank) of `v`.
fn quantile(v: &[f64], p: f64) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    if s.is_empty() {
        return f64::NAN;
    }
    s[((p * s.len() as f64).ceil() as usize).clamp(1, s.len()) - 1]
}

/// Single hypotheses fitted by a diagnosis (its ranking's entries of at most one effect).
fn singles(r: &Report) -> usize {
    r.ranking.iter().filter(|h| h.parts.len() <= 1).count()
}

/// One line with a report's verdict and the first effect's parameters and sigmas.
fn verdict_line(r: &Report) -> String {
    let eff: Vec<String> = r
        .effects
        .iter()
        .map(|e| {
            let ps: Vec<String> =
                e.params.iter().zip(&e.uncertainty).map(|((n, v), (_, s))| format!("{n}={v:.6e}+-{s:.3e}")).collect();
            format!("{}[{}]", e.label, ps.join(","))
        })
        .collect();
    format!(
        "{} | {} | fit {:.2} | substeps {} hold {}",
        r.selected(),
        eff.join(" "),
        r.fit_after.fit_percent[0].unwrap_or(f64::NAN),
        r.substeps,
        r.hold.chosen
    )
}

/// The settings a generator case is diagnosed with (as `bench::run_case_with`: the model
/// file's initial state, as `discover-bench --write-cases` writes it).
fn case_settings(case: &bench_gen::Case) -> DiagnoseSettings {
    DiagnoseSettings {
        initial_state: Some(InitialState {
            x0: case.nominal.x0.iter().copied().collect(),
            z0: Some(case.nominal.z0.iter().copied().collect()),
        }),
        ..Default::default()
    }
}

/// The recording of `benches/diagnose.rs` at `n` samples ([`bench_gen::long_record`]), with
/// its sawtooth pseudo-noise.
fn long_recording(n: usize) -> (model::System, Recording) {
    long_recording_with(n, false)
}

/// The same with white noise (`white`) or the sawtooth.
fn long_recording_with(n: usize, white: bool) -> (model::System, Recording) {
    let noise = if white { LongNoise::White } else { LongNoise::Sawtooth };
    bench_gen::long_record::long_recording(n, noise)
}

/// One simulator run of the `simulator` section: name, model, effects, input, sample time,
/// sub-steps, hold.
type SimRun<'a> =
    (&'a str, &'a model::System, Vec<model::effects::Effect>, &'a [f64], f64, usize, dynamics::extended::InputHold);

struct Args {
    sections: Vec<String>,
    cases: usize,
    seed: u64,
    threads: Vec<usize>,
    lengths: Vec<usize>,
    verdicts: bool,
    white: bool,
    classes: Vec<&'static str>,
    profiles: Vec<Profile>,
}

fn parse_args() -> Args {
    let mut a = Args {
        sections: vec!["cases".into(), "length".into(), "hypotheses".into(), "threads".into()],
        cases: 2,
        seed: 5101,
        threads: vec![1, 2],
        lengths: vec![2_000, 5_000, 10_000, 20_000, 50_000],
        verdicts: false,
        white: false,
        classes: bench_gen::all_classes(),
        profiles: vec![Profile::Classic, Profile::Digital],
    };
    let list = |s: &str| -> Vec<usize> { s.split(',').filter_map(|v| v.trim().parse().ok()).collect() };
    let mut it = std::env::args().skip(1);
    while let Some(x) = it.next() {
        match x.as_str() {
            "--cases" => a.cases = it.next().and_then(|v| v.parse().ok()).expect("--cases N"),
            "--seed" => a.seed = it.next().and_then(|v| v.parse().ok()).expect("--seed S"),
            "--threads" => a.threads = list(&it.next().expect("--threads 1,2")),
            "--lengths" => a.lengths = list(&it.next().expect("--lengths 2000,5000")),
            "--verdicts" => a.verdicts = true,
            "--white" => a.white = true,
            "--classes" => {
                a.classes = discovery::bench::class_set(&it.next().expect("--classes LIST"))
                    .expect("classes: classic, friction, all or a list of class names")
            }
            "--profiles" => {
                a.profiles = it
                    .next()
                    .expect("--profiles classic,digital")
                    .split(',')
                    .map(|p| Profile::parse(p).expect("profile: classic, digital or mixed"))
                    .collect()
            }
            s if !s.starts_with("--") => a.sections = s.split(',').map(String::from).collect(),
            other => panic!("unknown option {other}"),
        }
    }
    a
}

/// One generator case diagnosed: its key, timing, single hypotheses, samples and report line.
struct CaseRun {
    key: String,
    t: Timing,
    singles: usize,
    samples: usize,
    verdict: String,
}

fn run_cases(a: &Args, threads: usize) -> Vec<CaseRun> {
    let mut out = Vec::new();
    for &profile in &a.profiles {
        for &class in &a.classes {
            for i in 0..a.cases {
                let case = bench_gen::generate_profile(class, a.seed, i, profile);
                let s = case_settings(&case);
                let (r, t) = timed(threads, || diagnose(&case.nominal, &case.recording, &s));
                let key = format!("{}/{class}/{}/{i}", profile.name(), a.seed);
                let (singles, verdict) = match &r {
                    Ok(rep) => (singles(rep), verdict_line(rep)),
                    Err(e) => (0, format!("error: {e}")),
                };
                out.push(CaseRun { key, t, singles, samples: case.recording.len(), verdict });
            }
        }
    }
    out
}

fn print_summary(label: &str, runs: &[CaseRun]) {
    let wall: Vec<f64> = runs.iter().map(|r| r.t.wall).collect();
    let cpu: Vec<f64> = runs.iter().map(|r| r.t.cpu).collect();
    println!(
        "| {label} | {} | {:.2} / {:.2} | {:.2} / {:.2} | {:.2} / {:.2} | {:.1} / {:.1} |",
        runs.len(),
        quantile(&wall, 0.5),
        quantile(&cpu, 0.5),
        quantile(&wall, 0.9),
        quantile(&cpu, 0.9),
        wall.iter().copied().fold(0.0, f64::max),
        cpu.iter().copied().fold(0.0, f64::max),
        wall.iter().sum::<f64>(),
        cpu.iter().sum::<f64>(),
    );
}

fn main() {
    let a = parse_args();
    let max_threads = *a.threads.iter().max().unwrap_or(&2);
    println!(
        "# diagnose speed: {} threads available, load average {}",
        std::thread::available_parallelism().map_or(0, |n| n.get()),
        loadavg()
    );
    if a.sections.iter().any(|s| s == "cases") {
        print_cases(&a, max_threads);
    }
    if a.sections.iter().any(|s| s == "length") {
        print_length(&a, max_threads);
    }
    if a.sections.iter().any(|s| s == "hypotheses") {
        print_hypotheses(&a, max_threads);
    }
    if a.sections.iter().any(|s| s == "simulator") {
        print_simulator(&a);
    }
    if a.sections.iter().any(|s| s == "threads") {
        print_threads(&a);
    }
    println!("\n# load average at the end: {}", loadavg());
}

/// Per-case times over the generator's classes and profiles (and, with the `hypotheses` section, binned by the single hypotheses fitted).
fn print_cases(a: &Args, max_threads: usize) {
    let runs = run_cases(a, max_threads);
    println!(
        "\n## Generator cases (seed {}, {} per class and profile, {max_threads} threads; load after: {})",
        a.seed,
        a.cases,
        loadavg()
    );
    for r in &runs {
        println!(
            "{:<36} wall {:>7.2} s cpu {:>7.2} s singles {:>2} samples {:>6}",
            r.key, r.t.wall, r.t.cpu, r.singles, r.samples
        );
    }
    if a.verdicts {
        for r in &runs {
            println!("verdict {} :: {}", r.key, r.verdict);
        }
    }
    println!("\n| set | cases | median wall / cpu (s) | p90 wall / cpu | max wall / cpu | total wall / cpu |");
    println!("|---|---|---|---|---|---|");
    print_summary("all", &runs);
    for p in ["classic", "digital"] {
        let sub: Vec<CaseRun> = runs
            .iter()
            .filter(|r| r.key.starts_with(p))
            .map(|r| CaseRun {
                key: r.key.clone(),
                t: r.t,
                singles: r.singles,
                samples: r.samples,
                verdict: String::new(),
            })
            .collect();
        print_summary(p, &sub);
    }
    // Number of hypotheses: cases binned by the single hypotheses their diagnosis fitted.
    if a.sections.iter().any(|s| s == "hypotheses") {
        println!("\n## Time per number of single hypotheses (same cases)");
        println!("| singles | cases | median samples | median wall (s) | median cpu (s) | median cpu per single per 1000 samples (ms) |");
        println!("|---|---|---|---|---|---|");
        let mut counts: Vec<usize> = runs.iter().map(|r| r.singles).collect();
        counts.sort();
        counts.dedup();
        for c in counts {
            let sub: Vec<&CaseRun> = runs.iter().filter(|r| r.singles == c).collect();
            let v = |f: &dyn Fn(&CaseRun) -> f64| quantile(&sub.iter().map(|r| f(r)).collect::<Vec<_>>(), 0.5);
            println!(
                "| {c} | {} | {:.0} | {:.2} | {:.2} | {:.2} |",
                sub.len(),
                v(&|r| r.samples as f64),
                v(&|r| r.t.wall),
                v(&|r| r.t.cpu),
                v(&|r| 1e6 * r.t.cpu / (r.singles.max(1) as f64 * r.samples as f64)),
            );
        }
    }
}

/// Time against record length (the recording of `benches/diagnose.rs`).
fn print_length(a: &Args, max_threads: usize) {
    let noise = if a.white { "white noise" } else { "its sawtooth pseudo-noise" };
    println!(
        "\n## Record length (recording of benches/diagnose.rs, {noise}, {max_threads} threads; load {})",
        loadavg()
    );
    println!("| samples | wall (s) | cpu (s) | cpu per 1000 samples (s) | hypotheses fitted | verdict |");
    println!("|---|---|---|---|---|---|");
    for &n in &a.lengths {
        let (sys, rec) = long_recording_with(n, a.white);
        let s = DiagnoseSettings::default();
        let (r, t) = timed(max_threads, || diagnose(&sys, &rec, &s));
        let (sg, v) = match &r {
            Ok(rep) => (rep.ranking.len(), verdict_line(rep)),
            Err(e) => (0, format!("error: {e}")),
        };
        println!("| {n} | {:.2} | {:.2} | {:.3} | {sg} | {v} |", t.wall, t.cpu, 1000.0 * t.cpu / n as f64);
    }
}

/// Hypotheses fitted against `max_effects` on a long record and a generator case.
fn print_hypotheses(a: &Args, max_threads: usize) {
    // Number of hypotheses fitted, controlled: the same recordings with `max_effects` 0
    // (singles only, nothing selected), 1 (the best single cross-validated) and 2 (the
    // default: second effects and, where the residual stays coloured, the pair search).
    println!("\n## Hypotheses fitted against max_effects ({max_threads} threads; load {})", loadavg());
    println!("| recording | max_effects | hypotheses fitted (singles + combinations) | wall (s) | cpu (s) | cpu per hypothesis (s) | verdict |");
    println!("|---|---|---|---|---|---|---|");
    let (sys, rec) = long_recording(10_000);
    let case = bench_gen::generate_profile("backlash", a.seed, 0, Profile::Digital);
    for me in [0, 1, 2] {
        for (name, sys, rec, base) in [
            ("long record, 10,000 samples", &sys, &rec, DiagnoseSettings::default()),
            ("digital backlash case 0", &case.nominal, &case.recording, case_settings(&case)),
        ] {
            let s = DiagnoseSettings { max_effects: me, ..base };
            let (r, t) = timed(max_threads, || diagnose(sys, rec, &s));
            let (nh, v) = match &r {
                Ok(rep) => (rep.ranking.len(), rep.selected()),
                Err(e) => (0, format!("error: {e}")),
            };
            println!("| {name} | {me} | {nh} | {:.2} | {:.2} | {:.3} | {v} |", t.wall, t.cpu, t.cpu / nh.max(1) as f64);
        }
    }
}

/// The simulator alone: CPU per run and per sub-step.
fn print_simulator(a: &Args) {
    // The simulator alone (the inner loop of every fit): the 10,000-sample recording with
    // its Coulomb friction, and the digital backlash case, at their diagnoses' sub-steps.
    println!("\n## Simulator (load {})", loadavg());
    println!("| run | samples x sub-steps | runs | cpu per run (ms) | ns per sub-step |");
    println!("|---|---|---|---|---|");
    let (sys, rec) = long_recording(10_000);
    let truth = bench_gen::generate("coulomb_friction", 3, 0).truth.into_iter().collect::<Vec<_>>();
    let w: Vec<f64> = rec.w.iter().flatten().copied().collect();
    let case = bench_gen::generate_profile("backlash", a.seed, 0, Profile::Digital);
    let wc: Vec<f64> = case.recording.w.iter().flatten().copied().collect();
    let runs: [SimRun; 3] = [
        ("friction, foh", &sys, truth.clone(), &w, rec.dt, 5, dynamics::extended::InputHold::Foh),
        ("friction, zoh", &sys, truth, &w, rec.dt, 5, dynamics::extended::InputHold::Zoh),
        ("digital backlash, zoh", &case.nominal, vec![], &wc, case.recording.dt, 8, dynamics::extended::InputHold::Zoh),
    ];
    for (name, sys, eff, w, dt, sub, hold) in runs {
        let ext = ExtendedModel::new(sys, &eff, dt, sub).unwrap().with_hold(hold);
        let reps = (2_000_000 / w.len()).max(1);
        let (chk, t) =
            timed(1, || (0..reps).map(|_| ext.simulate(w, dt, sys.x0.as_slice()).y[w.len() - 1]).sum::<f64>());
        println!(
            "| {name} | {} x {sub} | {reps} | {:.3} | {:.1} | checksum {chk:?}",
            w.len(),
            1e3 * t.cpu / reps as f64,
            1e9 * t.cpu / (reps * w.len() * sub) as f64
        );
    }
}

/// Wall and CPU time against the rayon thread count.
fn print_threads(a: &Args) {
    println!("\n## Threads (load {})", loadavg());
    println!("| run | threads | wall (s) | cpu (s) | speed-up (wall, against 1 thread) | cpu / wall |");
    println!("|---|---|---|---|---|---|");
    let (sys, rec) = long_recording(*a.lengths.last().unwrap_or(&50_000));
    let case = bench_gen::generate_profile("backlash", a.seed, 0, Profile::Digital);
    let cs = case_settings(&case);
    let mut base: [Option<f64>; 2] = [None, None];
    for &th in &a.threads {
        for (j, name) in ["long record", "digital backlash case 0"].iter().enumerate() {
            let t = if j == 0 {
                timed(th, || diagnose(&sys, &rec, &DiagnoseSettings::default())).1
            } else {
                timed(th, || diagnose(&case.nominal, &case.recording, &cs)).1
            };
            let b = *base[j].get_or_insert(t.wall);
            println!("| {name} | {th} | {:.2} | {:.2} | {:.2} | {:.2} |", t.wall, t.cpu, b / t.wall, t.cpu / t.wall);
        }
    }
}
