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
//! period and phase instead of its sine (issue 29 item 2: the same systems, another input).
//! `THETA_BENCHMARK_MIN_P=2` keeps only the drawn systems with `p >= 2` (issue 29 item 3: balls
//! and ellipsoids in R^2 and R^3); the tables end with a breakdown by `p`.
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
/// interval below 0); with `square`, under the square wave of its sine's amplitudes, period
/// and phase.
fn measure_system(
    c: &theorems::strategies::systems::SystemParams,
    settings: &ThetaSettings,
    square: bool,
) -> Option<Row> {
    let mut sys = c.build();
    if square {
        if let model::Input::Sine { amplitudes, omega, phase } = &sys.input {
            sys.input = model::Input::Square { amplitudes: amplitudes.clone(), omega: *omega, phase: *phase };
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
    Some(Row { n: sys.n(), p: sys.p(), rate: m.rate, hi: m.ci_high, rep, ceiling, floor_ceiling })
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
    let square = std::env::var("THETA_BENCHMARK_INPUT").is_ok_and(|v| v == "square");
    let min_p: usize = std::env::var("THETA_BENCHMARK_MIN_P").ok().and_then(|v| v.parse().ok()).unwrap_or(1);
    let params = theorems::strategies::draw(&system_params(&config()), seed, 60 * want);
    let measure = RateSettings { periods: 30, transient_periods: 10, pairs: 2, ..Default::default() };
    let settings = ThetaSettings { stationary: None, measure: Some(measure), ..Default::default() };
    let start = std::time::Instant::now();
    // Draw until `want` convergent systems and `want` certified by the paper's theta (capped at
    // 60 `want` candidates). Table A: all convergent systems drawn; table B: those certified by
    // the paper's theta (the bounds' ratios compared on the same systems).
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
            .filter_map(|c| measure_system(c, &settings, square))
            .collect();
        paper_certified += got.iter().filter(|r| r.rep.theta_verified && r.rep.theta < 0.0).count();
        rows.extend(got);
    }
    let secs = start.elapsed().as_secs_f64();

    let table_a: Vec<&Row> = rows.iter().collect();
    let table_b: Vec<&Row> = rows.iter().filter(|r| r.rep.theta_verified && r.rep.theta < 0.0).collect();
    if std::env::var("THETA_BENCHMARK_ROWS").is_ok() {
        print_rows(&table_a);
    }
    let bounds: [(&str, Get); 5] = [
        ("theta (paper)", |r| (r.theta, r.theta_verified)),
        ("theta_star", |r| (r.theta_star, r.theta_star_verified)),
        ("theta_profile", |r| (r.theta_profile, r.theta_profile_verified)),
        ("theta_engaged", |r| (r.theta_engaged, r.theta_engaged_verified)),
        ("theta_best", |r| (r.theta_best, r.theta_best_verified)),
    ];
    let summary = |title: &str, set: &[&Row]| {
        println!("{title}");
        println!();
        println!("| bound | certified (verified < 0) | median bound / measured | min | max | violations |");
        println!("|---|---|---|---|---|---|");
        for (name, get) in bounds {
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
    };
    println!(
        "Seed {seed}: {drawn} systems drawn, {} convergent (measured 95 % interval below 0), {} of them certified by the paper's theta; {secs:.0} s on this machine.",
        rows.len(),
        table_b.len()
    );
    println!();
    summary(&format!("A. All {} convergent systems:", table_a.len()), &table_a);
    summary(&format!("B. The {} convergent systems certified by the paper's theta:", table_b.len()), &table_b);
    // Ceiling of eq. (theta) itself (NOT a bound): the chord with the measured path length per
    // period and the measured limsup |z'| in place of their certified bounds, minimised over
    // lambda (table B: a lambda search of its own with this objective, plus the report's curve;
    // table A: the report's curve only). Any theta built on eq. (theta) with tighter path or
    // speed bounds stays above it, so its median ratio caps theta_star's.
    let ceiling = |r: &Row| -> Option<f64> {
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
    };
    for (title, set) in [("A", &table_a), ("B", &table_b)] {
        let c: Vec<(f64, f64)> = set.iter().filter_map(|r| ceiling(r).map(|t| (t, r.rate))).collect();
        let neg: Vec<f64> = c.iter().filter(|(t, _)| *t < 0.0).map(|(t, m)| t / m).collect();
        println!(
            "Table {title}: ceiling of eq. (theta) with the measured path and limsup |z'| (not a bound): < 0 on {} of {}, median ceiling / measured {:.3}.",
            neg.len(),
            set.len(),
            median(neg.clone())
        );
    }
    // where theta_star loses against the ceiling: certified path / measured path (<= 1) and
    // certified limsup |z'| / measured (>= 1), medians over table B
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
    // by output dimension (issue 29 item 3): theta_engaged and theta_best per p
    for (title, set) in [("A", &table_a), ("B", &table_b)] {
        print_by_p(title, set, &bounds[2..]);
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
        .filter(|r| bounds.iter().any(|(_, g)| g(&r.rep).1 && g(&r.rep).0 < 0.0 && g(&r.rep).0 < r.hi))
        .count();
    println!("Violations over all {} convergent systems and all bounds: {all_viol}.", rows.len());
}

fn kind(r: &Row) -> &'static str {
    match (r.p, r.rep.R.is_finite()) {
        (1, _) => "interval",
        (_, true) => "ball/ellipsoid",
        _ => "other",
    }
}
