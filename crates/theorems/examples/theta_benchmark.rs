//! Certified bounds against measured exponents on random convergent systems (issue 15's
//! benchmark): `cargo run --release -p theorems --example theta_benchmark -- [systems] [seed]`.
//!
//! Systems from `theorems::strategies::systems` (n = 2..4, p = 1..3, intervals, balls and
//! ellipsoids, sine inputs); each is assembled with the measured side (pairs of catching-up
//! trajectories, 30 periods after 10 of transient). A system counts as convergent when the
//! measured exponent's 95 % interval lies below 0. For every bound (the paper's `theta`,
//! `theta_star`, `theta_profile`, `theta_engaged`, `theta_best`) it reports how many systems it certifies
//! (verified `< 0`), the median of bound / measured over the certified ones, and violations
//! (a certified bound below the measured interval's upper end). Prints a Markdown table.
//! `THETA_BENCHMARK_INPUT=square` gives every system a square wave of the same amplitudes,
//! period and phase instead of its sine (issue 29 item 2: the same systems, another input);
//! `THETA_BENCHMARK_INPUT=multisine` the multisine of [`multisine_harmonics`] (harmonics 1, 2
//! and 3 of the sine's frequency, peak scaled to the sine's amplitude); `csv` and `csv-zoh` the
//! sine sampled at 64 points per period, linearly interpolated or zero-order held. Each of these
//! ends with a paired comparison against the same systems under their sine.
//! `THETA_BENCHMARK_MIN_P=2` keeps only the drawn systems with `p >= 2` (issue 29 item 3: balls
//! and ellipsoids in R^2 and R^3); the tables end with a breakdown by `p`.
//! `THETA_BENCHMARK_NEAR=1` (issue 29 item 4) scales each drawn system to its smallest amplitude
//! where `theta_best` is certified (grid `2^k`, then bisection) times a factor drawn uniformly in
//! `[1, 1.5]` (deterministic per seed) and reports the bounds there, and where the profile bound
//! loses: the report's speed profile with the simulated regime's tube width, cell ceilings and
//! floors in place of the certified ones (not bounds).
use bounds::{assemble, ThetaReport, ThetaSettings};
use dynamics::rate::lyapunov_exponent::RateSettings;
use rayon::prelude::*;
use theorems::strategies::inputs::InputStrategyConfig;
use theorems::strategies::sets::{SetKind, SetStrategyConfig};
use theorems::strategies::systems::{system_params, SystemStrategyConfig};

fn config() -> SystemStrategyConfig {
    SystemStrategyConfig {
        max_n: 4,
        max_p: 3,
        mu: (-2.0, -0.3),
        theta: SetStrategyConfig {
            kinds: vec![SetKind::Interval, SetKind::Ball, SetKind::Ellipsoid],
            max_dim: 3,
            max_cond: 4.0,
            scale_exp: 0.75,
        },
        input: InputStrategyConfig { amp_exp: (0.0, 1.5), ..Default::default() },
        ..Default::default()
    }
}

struct Row {
    n: usize,
    p: usize,
    rep: ThetaReport,
    rate: f64,
    hi: f64,
    /// For systems the paper certifies: eq. (theta) with the measured path and limsup |z'|,
    /// minimised by a lambda search of its own (the ceiling; not a bound).
    ceiling: Option<f64>,
    /// For p >= 2 systems the paper certifies: theta_engaged's profile with the *simulated*
    /// smallest |z'| per cell as floors (the exact normal speed; not a bound), minimised over the
    /// certified curve: how far any speed floor can take theta_engaged.
    floor_ceiling: Option<f64>,
    /// With `THETA_BENCHMARK_INPUT` other than `sine`: the same system under its sine,
    /// `theta_best / measured` where the sine's `theta_best` is certified and its measured
    /// interval lies below 0 (the paired comparison).
    sine_ratio: Option<f64>,
}

fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    v.sort_by(f64::total_cmp);
    let k = v.len();
    if k % 2 == 1 {
        v[k / 2]
    } else {
        0.5 * (v[k / 2 - 1] + v[k / 2])
    }
}

/// One drawn system assembled with its measured side: a row if it converges (measured 95 %
/// interval below 0); under the input `kind` (`sine`, `square`, `multisine`, `csv` or
/// `csv-zoh`) of its sine's amplitudes, period and phase.
fn measure_system(
    c: &theorems::strategies::systems::SystemParams,
    settings: &ThetaSettings,
    kind: &str,
) -> Option<Row> {
    let mut sys = c.build();
    if let model::Input::Sine { amplitudes, omega, phase } = &sys.input {
        let (amplitudes, omega, phase) = (amplitudes.clone(), *omega, *phase);
        match kind {
            "square" => sys.input = model::Input::Square { amplitudes, omega, phase },
            "multisine" => {
                sys.input = model::Input::Multisine { amplitudes, omega, phase, harmonics: multisine_harmonics() }
            }
            "csv" | "csv-zoh" => sys.input = sampled_sine(&amplitudes, omega, phase, kind == "csv-zoh"),
            _ => {}
        }
    }
    let rep = assemble(&sys, settings).ok()?;
    let m = rep.measured.clone()?;
    if m.ci_high >= 0.0 {
        return None;
    }
    // the ceiling's own lambda search (each point: the smallest certified beta at that
    // lambda, so the minimum over lambda of eq. (theta) with exact inputs)
    let ceiling = (rep.theta_verified && rep.theta < 0.0 && m.limsup_zdot > 0.0)
        .then(|| {
            let (g1, ginf) = (m.path_length_per_period / (rep.period * rep.R), m.limsup_zdot / rep.R);
            let psi = |l: f64, b: f64| bounds::Psi { alpha: rep.alpha.lower, lambda: l, beta: b }.theta(g1, ginf);
            let own = lmi::optimise_lambda(&sys.F(), &sys.E, &sys.C, psi, &settings.lambda).ok()?;
            own.curve
                .iter()
                .filter_map(|c| c.value.as_ref().ok().map(|v| psi(v.lambda, v.beta)))
                .chain(rep.curve.iter().map(|&(l, b, _)| psi(l, b)))
                .filter(|t| t.is_finite())
                .min_by(f64::total_cmp)
        })
        .flatten();
    let floor_ceiling =
        (sys.p() >= 2 && rep.theta_verified && rep.theta < 0.0).then(|| measured_floor_ceiling(&sys, &rep)).flatten();
    let sine_ratio = (kind != "sine").then(|| sine_ratio(c, settings)).flatten();
    Some(Row { n: sys.n(), p: sys.p(), rate: m.rate, hi: m.ci_high, rep, ceiling, floor_ceiling, sine_ratio })
}

/// `theta_best / measured` of the drawn system under its own sine, where certified and convergent.
fn sine_ratio(c: &theorems::strategies::systems::SystemParams, settings: &ThetaSettings) -> Option<f64> {
    let rep = assemble(&c.build(), settings).ok()?;
    let m = rep.measured.as_ref()?;
    (m.ci_high < 0.0 && rep.theta_best_verified && rep.theta_best < 0.0).then(|| rep.theta_best / m.rate)
}

/// theta_engaged's bound with the simulated smallest `|z'|` per cell (400 cells, catching-up
/// steps of `T / 20000`, two periods after `e^{mu t} < 1e-6`) as the floors and the certified
/// ceilings and path bounds otherwise, at the best point of the certified curve (not a bound).
fn measured_floor_ceiling(sys: &model::System, rep: &ThetaReport) -> Option<f64> {
    use dynamics::integrators::catching_up::{CatchingUpSettings, Simulator};
    const CELLS: usize = 400;
    let orbit = bounds::orbit::EtaOrbit::new(sys, &bounds::orbit::OrbitSettings::default()).ok()?;
    let (edot, nodes) = orbit.eta_dot_cells(CELLS)?;
    let period = rep.period;
    let steps = 20_000usize;
    let h = period / steps as f64;
    let mut sim = Simulator::new(sys, &CatchingUpSettings { dt: h, ..Default::default() }).ok()?;
    let (mut x, mut z) = (vec![0.0; sys.n()], vec![0.0; sys.p()]);
    let transient = ((14.0 / -rep.mu) / period).ceil().max(5.0) as usize;
    sim.run(0.0, &mut x, &mut z, transient * steps, |_, _, _, _| {});
    let mut speed = vec![f64::INFINITY; CELLS];
    let mut prev = z.clone();
    sim.run(transient as f64 * period, &mut x, &mut z, 2 * steps, |k, _, _, zk| {
        let c = ((k - 1) % steps) / (steps / CELLS);
        let v = prev.iter().zip(zk).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt() / h;
        speed[c] = speed[c].min(v);
        prev.copy_from_slice(zk);
    });
    let prof = bounds::beyond_paper::SpeedProfile::new(period, nodes, &edot, rep.d_ftheta, rep.d, rep.R)
        .with_speed_floors(&speed);
    let alpha = rep.alpha.lower;
    let at = |l: f64, b: f64| bounds::Psi { alpha, lambda: l, beta: b };
    let (l0, b0, _) = *rep.curve.iter().min_by(|a, b| a.2.total_cmp(&b.2))?;
    let parts = prof.best_partition(&at(l0, b0), 4);
    rep.curve.iter().map(|&(l, b, _)| prof.bound(&at(l, b), &parts)).filter(|t| t.is_finite()).min_by(f64::total_cmp)
}

/// Every row of table A (`THETA_BENCHMARK_ROWS`).
fn print_rows(rows: &[&Row]) {
    println!("| # | n | p | Theta | measured | theta | theta* | theta_profile | theta_engaged | best |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for (i, r) in rows.iter().enumerate() {
        let f = |v: f64, ok: bool| if ok && v < 0.0 { format!("{v:.4}") } else { format!("({v:.3})") };
        println!(
            "| {i} | {} | {} | {} | {:.4} | {} | {} | {} | {} | {} |",
            r.n,
            r.p,
            kind(r),
            r.rate,
            f(r.rep.theta, r.rep.theta_verified),
            f(r.rep.theta_star, r.rep.theta_star_verified),
            f(r.rep.theta_profile, r.rep.theta_profile_verified),
            f(r.rep.theta_engaged, r.rep.theta_engaged_verified),
            r.rep.theta_best_method
        );
    }
    println!();
}

/// A bound of the report: its value and whether it is verified.
type Get = fn(&ThetaReport) -> (f64, bool);

/// Every bound of the report with its verified flag, in the order of the tables.
const BOUNDS: [(&str, Get); 5] = [
    ("theta (paper)", |r| (r.theta, r.theta_verified)),
    ("theta_star", |r| (r.theta_star, r.theta_star_verified)),
    ("theta_profile", |r| (r.theta_profile, r.theta_profile_verified)),
    ("theta_engaged", |r| (r.theta_engaged, r.theta_engaged_verified)),
    ("theta_best", |r| (r.theta_best, r.theta_best_verified)),
];

/// Table `title` by output dimension p: for each bound, how many are certified, the median
/// bound / measured, the smallest ratio and the violations.
fn print_by_p(title: &str, set: &[&Row], bounds: &[(&str, Get)]) {
    println!();
    println!("Table {title} by p:");
    println!();
    println!("| p | systems | bound | certified | median bound / measured | min | violations |");
    println!("|---|---|---|---|---|---|---|");
    for p in 1..=3 {
        let sub: Vec<&&Row> = set.iter().filter(|r| r.p == p).collect();
        for (name, get) in bounds {
            let cert: Vec<&&&Row> = sub.iter().filter(|r| get(&r.rep).1 && get(&r.rep).0 < 0.0).collect();
            let ratios: Vec<f64> = cert.iter().map(|r| get(&r.rep).0 / r.rate).collect();
            let violations = cert.iter().filter(|r| get(&r.rep).0 < r.hi).count();
            let lo = ratios.iter().copied().fold(f64::INFINITY, f64::min);
            println!(
                "| {p} | {} | {name} | {} | {:.3} | {lo:.3} | {violations} |",
                sub.len(),
                cert.len(),
                median(ratios.clone())
            );
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let want: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(50);
    let seed: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(2026);
    let input_kind = std::env::var("THETA_BENCHMARK_INPUT").unwrap_or_else(|_| "sine".into());
    if !["sine", "square", "multisine", "csv", "csv-zoh"].contains(&input_kind.as_str()) {
        eprintln!("THETA_BENCHMARK_INPUT={input_kind}: expected sine, square, multisine, csv or csv-zoh");
        std::process::exit(2);
    }
    let min_p: usize = std::env::var("THETA_BENCHMARK_MIN_P").ok().and_then(|v| v.parse().ok()).unwrap_or(1);
    if std::env::var("THETA_BENCHMARK_NEAR").is_ok_and(|v| v == "1") {
        return near_main(want, seed, min_p);
    }
    let start = std::time::Instant::now();
    let (rows, drawn) = draw_rows(want, seed, min_p, &input_kind);
    let secs = start.elapsed().as_secs_f64();
    let table_a: Vec<&Row> = rows.iter().collect();
    let table_b: Vec<&Row> = rows.iter().filter(|r| r.rep.theta_verified && r.rep.theta < 0.0).collect();
    if std::env::var("THETA_BENCHMARK_ROWS").is_ok() {
        print_rows(&table_a);
    }
    println!(
        "Seed {seed}: {drawn} systems drawn, {} convergent (measured 95 % interval below 0), {} of them certified by the paper's theta; {secs:.0} s on this machine.",
        rows.len(),
        table_b.len()
    );
    println!();
    print_summary(&format!("A. All {} convergent systems:", table_a.len()), &table_a);
    print_summary(&format!("B. The {} convergent systems certified by the paper's theta:", table_b.len()), &table_b);
    print_ceilings(&table_a, &table_b);
    print_where_star_loses(&table_b);
    // by output dimension (issue 29 item 3): theta_engaged and theta_best per p
    for (title, set) in [("A", &table_a), ("B", &table_b)] {
        print_by_p(title, set, &BOUNDS[2..]);
    }
    let fc: Vec<f64> =
        table_b.iter().filter_map(|r| r.floor_ceiling.filter(|c| *c < 0.0).map(|c| c / r.rate)).collect();
    let fc_n = table_b.iter().filter(|r| r.p >= 2).count();
    println!(
        "Table B, p >= 2: theta_engaged with the simulated smallest |z'| per cell as floors (not a bound): < 0 on {} of {fc_n}, median / measured {:.3}.",
        fc.len(),
        median(fc.clone())
    );
    println!();
    let all_viol = rows
        .iter()
        .filter(|r| BOUNDS.iter().any(|(_, g)| g(&r.rep).1 && g(&r.rep).0 < 0.0 && g(&r.rep).0 < r.hi))
        .count();
    println!("Violations over all {} convergent systems and all bounds: {all_viol}.", rows.len());
    paired_with_sine(&rows, &input_kind);
}

/// Draws until `want` convergent systems and `want` certified by the paper's theta (capped at
/// 60 `want` candidates; `p >= min_p`): the rows and the number of systems drawn. Table A: all
/// convergent systems drawn; table B: those certified by the paper's theta (the bounds' ratios
/// compared on the same systems).
fn draw_rows(want: usize, seed: u64, min_p: usize, input_kind: &str) -> (Vec<Row>, usize) {
    let params = theorems::strategies::draw(&system_params(&config()), seed, 60 * want);
    let measure = RateSettings { periods: 30, transient_periods: 10, pairs: 2, ..Default::default() };
    let settings = ThetaSettings { stationary: None, measure: Some(measure), ..Default::default() };
    let mut rows: Vec<Row> = Vec::new();
    let mut paper_certified = 0;
    let mut drawn = 0;
    for chunk in params.chunks(32) {
        if rows.len() >= want && paper_certified >= want {
            break;
        }
        drawn += chunk.len();
        let got: Vec<Row> = chunk
            .par_iter()
            .filter(|c| c.n >= 2 && c.p >= min_p)
            .filter_map(|c| measure_system(c, &settings, input_kind))
            .collect();
        paper_certified += got.iter().filter(|r| r.rep.theta_verified && r.rep.theta < 0.0).count();
        rows.extend(got);
    }
    (rows, drawn)
}

/// Table `title`: for each bound, how many systems of `set` it certifies, the median, smallest
/// and largest bound / measured, and the violations.
fn print_summary(title: &str, set: &[&Row]) {
    println!("{title}");
    println!();
    println!("| bound | certified (verified < 0) | median bound / measured | min | max | violations |");
    println!("|---|---|---|---|---|---|");
    for (name, get) in BOUNDS {
        let cert: Vec<&&Row> = set.iter().filter(|r| get(&r.rep).1 && get(&r.rep).0 < 0.0).collect();
        let ratios: Vec<f64> = cert.iter().map(|r| get(&r.rep).0 / r.rate).collect();
        let violations = cert.iter().filter(|r| get(&r.rep).0 < r.hi).count();
        let (lo, hi) = ratios.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, &x| (a.0.min(x), a.1.max(x)));
        println!(
            "| {name} | {} of {} | {:.3} | {:.3} | {:.3} | {violations} |",
            cert.len(),
            set.len(),
            median(ratios.clone()),
            lo,
            hi
        );
    }
    println!();
}

/// Ceiling of eq. (theta) itself (NOT a bound): the chord with the measured path length per
/// period and the measured limsup |z'| in place of their certified bounds, minimised over
/// lambda (table B: a lambda search of its own with this objective, plus the report's curve;
/// table A: the report's curve only). Any theta built on eq. (theta) with tighter path or
/// speed bounds stays above it, so its median ratio caps theta_star's.
fn ceiling(r: &Row) -> Option<f64> {
    if r.ceiling.is_some() {
        return r.ceiling;
    }
    let m = r.rep.measured.as_ref()?;
    let (g1, ginf) = (m.path_length_per_period / (r.rep.period * r.rep.R), m.limsup_zdot / r.rep.R);
    r.rep
        .curve
        .iter()
        .map(|&(lambda, beta, _)| bounds::Psi { alpha: r.rep.alpha.lower, lambda, beta }.theta(g1, ginf))
        .filter(|t| t.is_finite())
        .min_by(f64::total_cmp)
}

/// The [`ceiling`] against the measured exponent, on tables A and B.
fn print_ceilings(table_a: &[&Row], table_b: &[&Row]) {
    for (title, set) in [("A", table_a), ("B", table_b)] {
        let c: Vec<(f64, f64)> = set.iter().filter_map(|r| ceiling(r).map(|t| (t, r.rate))).collect();
        let neg: Vec<f64> = c.iter().filter(|(t, _)| *t < 0.0).map(|(t, m)| t / m).collect();
        println!(
            "Table {title}: ceiling of eq. (theta) with the measured path and limsup |z'| (not a bound): < 0 on {} of {}, median ceiling / measured {:.3}.",
            neg.len(),
            set.len(),
            median(neg.clone())
        );
    }
}

/// Where theta_star loses against the [`ceiling`]: certified path / measured path (<= 1) and
/// certified limsup |z'| / measured (>= 1), medians over table B.
fn print_where_star_loses(table_b: &[&Row]) {
    let path_ratio: Vec<f64> = table_b
        .iter()
        .filter_map(|r| {
            r.rep.measured.as_ref().map(|m| r.rep.gamma_1_star * r.rep.period * r.rep.R / m.path_length_per_period)
        })
        .collect();
    let speed_ratio = |f: fn(&bounds::ThetaReport) -> f64| -> f64 {
        median(table_b.iter().filter_map(|r| r.rep.measured.as_ref().map(|m| f(&r.rep) / m.limsup_zdot)).collect())
    };
    let star_vs_ceiling: Vec<f64> =
        table_b.iter().filter_map(|r| ceiling(r).filter(|c| *c < 0.0).map(|c| r.rep.theta_star / c)).collect();
    println!(
        "Table B: certified path / measured path median {:.3}; certified limsup |z'| / measured median {:.3} ((zinf): {:.3}); theta_star / ceiling median {:.3}.",
        median(path_ratio),
        speed_ratio(|r| r.zdot_star_bound),
        speed_ratio(|r| r.zdot_bound),
        median(star_vs_ceiling)
    );
}

/// The paired comparison with the sine (`THETA_BENCHMARK_INPUT` other than `sine`): over the
/// systems whose `theta_best` is certified under both inputs, the median and quartiles of
/// (`theta_best / measured` under the input) / (the same under the sine).
fn paired_with_sine(rows: &[Row], input_kind: &str) {
    if input_kind == "sine" {
        return;
    }
    let q: Vec<f64> = rows
        .iter()
        .filter(|r| r.rep.theta_best_verified && r.rep.theta_best < 0.0)
        .filter_map(|r| r.sine_ratio.map(|s| (r.rep.theta_best / r.rate) / s))
        .collect();
    let mut sorted = q.clone();
    sorted.sort_by(f64::total_cmp);
    let at = |f: f64| sorted.get(((sorted.len() as f64 - 1.0) * f).round() as usize).copied().unwrap_or(f64::NAN);
    let sine_only = rows
        .iter()
        .filter(|r| r.sine_ratio.is_some() && !(r.rep.theta_best_verified && r.rep.theta_best < 0.0))
        .count();
    println!(
        "Paired with the sine of equal amplitude and period (same systems): {} certified under both (and {sine_only} under the sine only); (theta_best / measured under {input_kind}) / (under the sine): median {:.3}, quartiles {:.3} - {:.3}, within 20 % of 1 on {} of {}.",
        q.len(),
        median(q.clone()),
        at(0.25),
        at(0.75),
        q.iter().filter(|x| (**x - 1.0).abs() <= 0.2).count(),
        q.len()
    );
}

fn kind(r: &Row) -> &'static str {
    match (r.p, r.rep.R.is_finite()) {
        (1, _) => "interval",
        (_, true) => "ball/ellipsoid",
        _ => "other",
    }
}

/// The waveform of `THETA_BENCHMARK_INPUT=multisine`: `sin a + 0.5 sin(2 a + 0.7) + 0.25
/// sin(3 a + 1.9)`, its weights divided by its peak (on a grid of 2^16 points of a period), so
/// the input's largest `|w_i|` is the sine's amplitude `a_i`; with
/// `THETA_BENCHMARK_MULTISINE=fundamental` not divided (the fundamental is the sine).
fn multisine_harmonics() -> Vec<model::input::Harmonic> {
    let mut h: Vec<model::input::Harmonic> = [(1, 1.0, 0.0), (2, 0.5, 0.7), (3, 0.25, 1.9)]
        .into_iter()
        .map(|(k, weight, phase)| model::input::Harmonic { k, weight, phase })
        .collect();
    let grid = 1 << 16;
    let peak = (0..grid)
        .map(|i| model::input::multisine_wave(&h, std::f64::consts::TAU * i as f64 / grid as f64).abs())
        .fold(0.0, f64::max);
    if !std::env::var("THETA_BENCHMARK_MULTISINE").is_ok_and(|v| v == "fundamental") {
        h.iter_mut().for_each(|x| x.weight /= peak);
    }
    h
}

/// `THETA_BENCHMARK_INPUT=csv` / `csv-zoh`: the sine sampled at 64 points per period as a
/// periodic sampled input, linearly interpolated or zero-order held.
fn sampled_sine(a: &[f64], omega: f64, phase: f64, zoh: bool) -> model::Input {
    const N: usize = 64;
    let period = std::f64::consts::TAU / omega;
    let t: Vec<f64> = (0..N).map(|k| k as f64 * period / N as f64).collect();
    let w = t.iter().map(|tk| a.iter().map(|ai| ai * (omega * tk + phase).sin()).collect()).collect();
    let hold = if zoh { model::input::InputHold::Zoh } else { model::input::InputHold::Foh };
    model::Input::Samples { path: "<sampled sine>".into(), t, w, period: Some(period), hold }
}

// ---------------------------------------------------------------------------------------------
// Near the threshold (issue 29 item 4): `THETA_BENCHMARK_NEAR=1`.
// ---------------------------------------------------------------------------------------------

/// The system with every input amplitude multiplied by `s` (sine, square and multisine inputs).
fn scaled(sys: &model::System, s: f64) -> model::System {
    let mut out = sys.clone();
    if let Some((amplitudes, _, _)) = out.input.wave_mut() {
        amplitudes.iter_mut().for_each(|a| *a *= s);
    }
    out
}

/// `theta_best` verified `< 0` for `sys` at scale `s` (bound only).
fn certified_at(sys: &model::System, s: f64) -> bool {
    assemble(&scaled(sys, s), &ThetaSettings::bound_only()).is_ok_and(|r| r.theta_best_verified && r.theta_best < 0.0)
}

/// Grid of the threshold search: `2^k` times the drawn amplitudes, `k = NEAR_K.0..=NEAR_K.1`.
const NEAR_K: (i32, i32) = (-4, 5);
/// Bisection steps (in `ln s`) after the grid: relative precision `2^(-NEAR_BISECT)` of `ln 2`.
const NEAR_BISECT: usize = 10;

/// Where the threshold search ended for one system.
enum Threshold {
    /// The smallest certified scale found (certified there; not certified at `s / (1 + 7e-4)`).
    At(f64),
    /// Certified already at the bottom of the grid (the threshold lies below the search).
    BelowGrid,
    /// Not certified at any grid point.
    Never,
}

/// The smallest scale `s` of the drawn amplitudes at which `theta_best` is certified: the first
/// certified point of the grid `2^k` (from below), then bisection in `ln s` against the grid
/// point below it. Certification need not be monotone in `s`; this finds the first crossing on
/// the grid's resolution.
fn threshold(sys: &model::System) -> Threshold {
    let mut below = None;
    for k in NEAR_K.0..=NEAR_K.1 {
        let s = 2f64.powi(k);
        if certified_at(sys, s) {
            below = Some((s / 2.0, s));
            break;
        }
    }
    let Some((mut lo, mut hi)) = below else { return Threshold::Never };
    if hi == 2f64.powi(NEAR_K.0) {
        return Threshold::BelowGrid;
    }
    for _ in 0..NEAR_BISECT {
        let mid = (lo * hi).sqrt();
        if certified_at(sys, mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Threshold::At(hi)
}

/// A uniform number in `[0, 1)` from `(seed, index)` (SplitMix64): the scale factor of system
/// `index` is `1 + 0.5 u`, deterministic per seed.
fn unit(seed: u64, index: u64) -> f64 {
    let mut z = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ index.wrapping_add(0x6A09_E667_F3BC_C909);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}

/// The simulated periodic regime on the cells of a profile (catching-up, `h = T / (50 cells)`,
/// after the transient): per cell the smallest and largest `|z'|`, the width of the tube it
/// actually uses (`diam { z - eta_T }` over the cell boundaries), and the speeds of every step.
struct Regime {
    speed_min: Vec<f64>,
    speed_max: Vec<f64>,
    width: f64,
    speeds: Vec<f64>,
}

fn simulate_regime(sys: &model::System, rep: &ThetaReport, eta: &[Vec<f64>]) -> Option<Regime> {
    use dynamics::integrators::catching_up::{CatchingUpSettings, Simulator};
    let cells = eta.len() - 1;
    let sub = 50usize;
    let steps = cells * sub;
    let period = rep.period;
    let h = period / steps as f64;
    let mut sim = Simulator::new(sys, &CatchingUpSettings { dt: h, ..Default::default() }).ok()?;
    let (mut x, mut z) = (vec![0.0; sys.n()], vec![0.0; sys.p()]);
    // settle: 14 e-folds of the slower of mu and the measured exponent, at least 5, at most 300
    let slow = rep.measured.as_ref().map_or(rep.mu, |m| m.rate.max(rep.mu)).min(-1e-3);
    let transient = ((14.0 / -slow) / period).ceil().clamp(5.0, 300.0) as usize;
    sim.run(0.0, &mut x, &mut z, transient * steps, |_, _, _, _| {});
    let (mut speed_min, mut speed_max) = (vec![f64::INFINITY; cells], vec![0.0f64; cells]);
    let mut speeds = Vec::with_capacity(steps);
    let mut q = vec![z.iter().zip(&eta[0]).map(|(a, b)| a - b).collect::<Vec<f64>>()];
    let mut prev = z.clone();
    sim.run(transient as f64 * period, &mut x, &mut z, steps, |k, _, _, zk| {
        let c = (k - 1) / sub;
        let v = prev.iter().zip(zk).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt() / h;
        speed_min[c] = speed_min[c].min(v);
        speed_max[c] = speed_max[c].max(v);
        speeds.push(v);
        prev.copy_from_slice(zk);
        if k % sub == 0 {
            q.push(zk.iter().zip(&eta[k / sub]).map(|(a, b)| a - b).collect());
        }
    });
    let mut width = 0.0f64;
    for i in 0..q.len() {
        for j in 0..i {
            width = width.max(geometry::linalg::dist(&q[i], &q[j]));
        }
    }
    Some(Regime { speed_min, speed_max, width, speeds })
}

/// Where the profile bound loses (not bounds): the report's profile with one input at a time
/// replaced by the simulated regime's, and all of them, and the mean of `psi(|z'| / R)` over the
/// regime itself; each minimised over the report's certified `(lambda, b_hat)` points.
#[derive(Clone, Copy)]
struct Decomposition {
    /// The evidence's own bound (the report's theta_engaged or theta_profile).
    base: f64,
    /// `d` -> the width the regime uses.
    width: f64,
    /// Cell ceilings -> the regime's largest `|z'|` per cell.
    ceilings: f64,
    /// Cell floors -> the regime's smallest `|z'|` per cell.
    floors: f64,
    /// Floors -> the regime's only on the cells the report proves engaged / only on the others.
    floors_engaged: f64,
    floors_other: f64,
    /// All three.
    all: f64,
    /// Mean of `psi(u(t))` over the regime: no chord, no profile (the psi ceiling), over the
    /// report's points and over a lambda search of its own with this objective.
    psi_mean: f64,
    psi_mean_own: f64,
    /// `mu`: every psi-based bound is above `-lambda > mu`.
    mu: f64,
    /// `d` and `D` of the report, the regime's width, the largest ceiling and the regime's
    /// largest `|z'|` (for the table).
    d: f64,
    d_ftheta: f64,
    regime_width: f64,
    engaged_cells: usize,
    moving_cells: usize,
}

fn decompose(sys: &model::System, rep: &ThetaReport) -> Option<Decomposition> {
    let ev = rep.profile_evidence.as_ref()?;
    let prof = &ev.profile;
    let reg = simulate_regime(sys, rep, &prof.eta)?;
    let r_up = prof.R;
    let with = |d: Option<f64>, ceil: bool, floor: Option<bool>| {
        let mut p = prof.clone();
        if let Some(d) = d {
            p.d = d;
        }
        if ceil {
            p.g = reg.speed_max.iter().map(|v| v / r_up).collect();
        }
        // Some(true): every cell; Some(false): only the cells without a certified floor
        if let Some(all) = floor {
            for (c, f) in p.floor.iter_mut().enumerate() {
                if all || *f <= 0.0 {
                    *f = reg.speed_min[c] / r_up;
                }
            }
        }
        for (f, g) in p.floor.iter_mut().zip(&p.g) {
            *f = f.min(*g);
        }
        ev.bound_of(&p)
    };
    let mean_psi = |lambda: f64, beta: f64| {
        let psi = bounds::Psi { alpha: ev.alpha, lambda, beta };
        reg.speeds.iter().map(|v| psi.eval(v / r_up)).sum::<f64>() / reg.speeds.len() as f64
    };
    let psi_mean = ev.points.iter().map(|&(l, b)| mean_psi(l, b)).fold(f64::INFINITY, f64::min);
    let own = lmi::optimise_lambda(&sys.F(), &sys.E, &sys.C, mean_psi, &ThetaSettings::default().lambda).ok();
    let psi_mean_own = own
        .iter()
        .flat_map(|o| o.curve.iter().filter_map(|c| c.value.as_ref().ok().map(|v| mean_psi(v.lambda, v.beta))))
        .fold(psi_mean, f64::min);
    // floors only where the report has none: the engaged cells' variant is all minus this
    let mut engaged_only = prof.clone();
    for (c, f) in engaged_only.floor.iter_mut().enumerate() {
        if *f > 0.0 {
            *f = (reg.speed_min[c] / r_up).min(engaged_only.g[c]);
        }
    }
    Some(Decomposition {
        base: ev.bound_of(prof),
        width: with(Some(reg.width), false, None),
        ceilings: with(None, true, None),
        floors: with(None, false, Some(true)),
        floors_engaged: ev.bound_of(&engaged_only),
        floors_other: with(None, false, Some(false)),
        all: with(Some(reg.width), true, Some(true)),
        psi_mean,
        psi_mean_own,
        mu: rep.mu,
        d: rep.d,
        d_ftheta: rep.d_ftheta,
        regime_width: reg.width,
        engaged_cells: prof.engaged_cells(),
        moving_cells: reg.speed_min.iter().filter(|&&v| v > 1e-9).count(),
    })
}

/// One near-threshold system: its threshold scale, the drawn factor, the report at the scaled
/// amplitude with the measured side, and the decomposition.
struct NearRow {
    row: Row,
    s0: f64,
    factor: f64,
    dec: Option<Decomposition>,
}

/// Why a drawn system is not in the near-threshold family.
enum NearSkip {
    NotSine,
    Never,
    BelowGrid,
    NotConvergent,
}

fn near_system(c: &theorems::strategies::systems::SystemParams, index: u64, seed: u64) -> Result<NearRow, NearSkip> {
    let sys0 = c.build();
    if !matches!(sys0.input, model::Input::Sine { .. }) {
        return Err(NearSkip::NotSine);
    }
    let s0 = match threshold(&sys0) {
        Threshold::At(s) => s,
        Threshold::BelowGrid => return Err(NearSkip::BelowGrid),
        Threshold::Never => return Err(NearSkip::Never),
    };
    let factor = 1.0 + 0.5 * unit(seed, index);
    let sys = scaled(&sys0, s0 * factor);
    let measure = RateSettings { periods: 30, transient_periods: 10, pairs: 2, ..Default::default() };
    let settings = ThetaSettings { stationary: None, measure: Some(measure), ..Default::default() };
    let rep = assemble(&sys, &settings).map_err(|_| NearSkip::NotConvergent)?;
    let m = rep.measured.clone().ok_or(NearSkip::NotConvergent)?;
    if m.ci_high >= 0.0 {
        return Err(NearSkip::NotConvergent);
    }
    let dec = decompose(&sys, &rep);
    let row = Row {
        n: sys.n(),
        p: sys.p(),
        rate: m.rate,
        hi: m.ci_high,
        rep,
        ceiling: None,
        floor_ceiling: None,
        sine_ratio: None,
    };
    Ok(NearRow { row, s0, factor, dec })
}

/// `THETA_BENCHMARK_NEAR=1`: each drawn system (n >= 2, p >= `min_p`) scaled to its smallest
/// certified amplitude times a factor drawn uniformly in `[1, 1.5]`; the bounds against the
/// measured exponent there, and where the profile bound loses.
fn near_main(want: usize, seed: u64, min_p: usize) {
    let params = theorems::strategies::draw(&system_params(&config()), seed, 40 * want);
    let start = std::time::Instant::now();
    let (mut rows, mut drawn) = (Vec::<NearRow>::new(), 0usize);
    let (mut never, mut below, mut divergent) = (0usize, 0usize, 0usize);
    let indexed: Vec<(u64, &theorems::strategies::systems::SystemParams)> =
        params.iter().enumerate().map(|(i, c)| (i as u64, c)).filter(|(_, c)| c.n >= 2 && c.p >= min_p).collect();
    for chunk in indexed.chunks(16) {
        if rows.len() >= want {
            break;
        }
        drawn += chunk.len();
        let got: Vec<Result<NearRow, NearSkip>> = chunk.par_iter().map(|(i, c)| near_system(c, *i, seed)).collect();
        for g in got {
            match g {
                Ok(r) => rows.push(r),
                Err(NearSkip::Never) => never += 1,
                Err(NearSkip::BelowGrid) => below += 1,
                Err(NearSkip::NotConvergent) => divergent += 1,
                Err(NearSkip::NotSine) => {}
            }
        }
    }
    let secs = start.elapsed().as_secs_f64();
    println!(
        "Near-threshold family, seed {seed}: {drawn} systems drawn (n >= 2, p >= {min_p}); {never} never certified on the grid 2^[{}, {}] x the drawn amplitudes, {below} certified already at its bottom, {divergent} not convergent at the drawn scale; {} in the family; {secs:.0} s on this machine.",
        NEAR_K.0,
        NEAR_K.1,
        rows.len()
    );
    println!();
    if std::env::var("THETA_BENCHMARK_ROWS").is_ok() {
        print_near_rows(&rows);
    }
    let bounds = BOUNDS;
    println!("| bound | certified (verified < 0) | median bound / measured | min | max | violations |");
    println!("|---|---|---|---|---|---|");
    for (name, get) in bounds {
        let cert: Vec<&NearRow> = rows.iter().filter(|r| get(&r.row.rep).1 && get(&r.row.rep).0 < 0.0).collect();
        let ratios: Vec<f64> = cert.iter().map(|r| get(&r.row.rep).0 / r.row.rate).collect();
        let violations = cert.iter().filter(|r| get(&r.row.rep).0 < r.row.hi).count();
        let (lo, hi) = ratios.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, &x| (a.0.min(x), a.1.max(x)));
        println!(
            "| {name} | {} of {} | {:.3} | {lo:.3} | {hi:.3} | {violations} |",
            cert.len(),
            rows.len(),
            median(ratios)
        );
    }
    println!();
    // theta_best / measured over the whole family (0 where not certified at the drawn scale:
    // certification need not be monotone in the amplitude)
    let all: Vec<f64> = rows
        .iter()
        .map(|r| {
            let rep = &r.row.rep;
            if rep.theta_best_verified && rep.theta_best < 0.0 {
                rep.theta_best / r.row.rate
            } else {
                0.0
            }
        })
        .collect();
    println!("theta_best / measured over all {} (0 where not certified): median {:.3}.", all.len(), median(all));
    let methods = ["theta", "theta_star", "theta_profile", "theta_engaged"];
    let counts: Vec<String> = methods
        .iter()
        .map(|m| format!("{m} {}", rows.iter().filter(|r| r.row.rep.theta_best_method == *m).count()))
        .collect();
    println!("theta_best attained by: {}.", counts.join(", "));
    println!();
    print_near_losses(&rows);
    let viol = rows
        .iter()
        .filter(|r| bounds.iter().any(|(_, g)| g(&r.row.rep).1 && g(&r.row.rep).0 < 0.0 && g(&r.row.rep).0 < r.row.hi))
        .count();
    println!("Violations over all {} systems and all bounds: {viol}.", rows.len());
}

/// One row per system of the near-threshold family (`THETA_BENCHMARK_ROWS`).
fn print_near_rows(rows: &[NearRow]) {
    println!("| # | n | p | s0 | factor | measured | theta_best (method) | ratio | base | d->width | g->max | l->min | all | mean psi (own) | mu | d | width | D | engaged / moving cells |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for (i, r) in rows.iter().enumerate() {
        let rep = &r.row.rep;
        let best = if rep.theta_best_verified && rep.theta_best < 0.0 {
            format!("{:.4} ({})", rep.theta_best, rep.theta_best_method)
        } else {
            format!("({:.3})", rep.theta_best)
        };
        let dec = r.dec.map_or("| - | - | - | - | - | - | - | - | - | - | - |".to_string(), |d| {
            format!(
                "| {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {:.3} | {:.4} | {:.4} | {:.4} | {} / {} |",
                d.base,
                d.width,
                d.ceilings,
                d.floors,
                d.all,
                d.psi_mean_own,
                d.mu,
                d.d,
                d.regime_width,
                d.d_ftheta,
                d.engaged_cells,
                d.moving_cells
            )
        });
        println!(
            "| {i} | {} | {} | {:.4} | {:.3} | {:.4} | {best} | {:.3} {dec}",
            r.row.n,
            r.row.p,
            r.s0,
            r.factor,
            r.row.rate,
            rep.theta_best / r.row.rate
        );
    }
    println!();
}

/// Where the profile bound loses on the near-threshold family: medians of what-if values
/// (simulated inputs in place of certified ones) over the measured exponent.
fn print_near_losses(rows: &[NearRow]) {
    // the decomposition: medians of (what-if) / measured over the systems with a profile
    let decs: Vec<(Decomposition, f64)> = rows.iter().filter_map(|r| r.dec.map(|d| (d, r.row.rate))).collect();
    let med = |f: fn(&Decomposition) -> f64| median(decs.iter().map(|(d, m)| f(d) / m).collect());
    println!("Where the profile bound loses ({} systems; not bounds: simulated inputs in place of certified ones, medians of value / measured):", decs.len());
    println!();
    println!("| profile bound with | median / measured |");
    println!("|---|---|");
    println!("| the certified inputs (the report's theta_engaged or theta_profile) | {:.3} |", med(|d| d.base));
    println!("| tube width d -> the width the regime uses | {:.3} |", med(|d| d.width));
    println!("| cell ceilings -> the regime's largest \\|z'\\| per cell | {:.3} |", med(|d| d.ceilings));
    println!("| cell floors -> the regime's smallest \\|z'\\| per cell | {:.3} |", med(|d| d.floors));
    println!(
        "| cell floors -> the regime's, only on the cells the report proves engaged | {:.3} |",
        med(|d| d.floors_engaged)
    );
    println!("| cell floors -> the regime's, only on the other cells | {:.3} |", med(|d| d.floors_other));
    println!("| all three | {:.3} |", med(|d| d.all));
    println!(
        "| mean of psi(\\|z'\\|/R) over the regime (no chord), the report's points | {:.3} |",
        med(|d| d.psi_mean)
    );
    println!("| the same, with a lambda search of its own | {:.3} |", med(|d| d.psi_mean_own));
    println!("| mu (every psi-based bound is above -lambda > mu) | {:.3} |", med(|d| d.mu));
    println!();
    let mr = |f: fn(&Decomposition) -> f64| median(decs.iter().map(|(d, _)| f(d)).collect());
    println!(
        "Medians: d {:.4}, regime width {:.4} (width / d {:.3}), D {:.4}; engaged cells {:.0}, moving cells {:.0}.",
        mr(|d| d.d),
        mr(|d| d.regime_width),
        mr(|d| d.regime_width / d.d),
        mr(|d| d.d_ftheta),
        mr(|d| d.engaged_cells as f64),
        mr(|d| d.moving_cells as f64)
    );
}
