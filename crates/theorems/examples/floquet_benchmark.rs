//! The verified Floquet enclosure (issue 30, `bounds::beyond_paper::floquet`) against measured
//! exponents on random p = 1 systems:
//! `cargo run --release -p theorems --example floquet_benchmark -- [systems] [seed]`.
//!
//! Systems from `theorems::strategies::systems` (n = 2..4, p = 1, Theta an interval (with
//! `FLOQUET_BENCHMARK_SETS=all` also a ball or an ellipsoid in R^1), sine
//! inputs with amplitude 10^[0, 1.5], mu in [-2, -0.3]). A system counts when its measured
//! exponent's 95 % interval lies below 0 (a periodic regime attracts). For each: the enclosure
//! (verified or not, its relative width, its time), the measured exponent (3 pairs, 30 periods
//! after 10, separation 1e-6 (`FLOQUET_SEPARATION=...` to change), with `step_check`: dt = 2e-3 (`FLOQUET_DT=...` to change), its half
//! and its quarter, the quarter's values with every interval widened by the larger change):
//! the regression of `ln V` (largest pair) and the dominant multiplier fitted to the same pairs'
//! differences (`dynamics::rate::multipliers`, free of the wobble of `ln V` when the slowest
//! multipliers are a complex pair), an independent estimate from the event-driven integrator's
//! period map by finite differences, and `theta_best`. Prints the summary and, with
//! `FLOQUET_BENCHMARK_ROWS=1`, one row per system (the `theta_best / floquet` table).
#![allow(non_snake_case, clippy::neg_cmp_op_on_partial_ord)]
use bounds::beyond_paper::floquet::{floquet_enclosure, FloquetSettings};
use bounds::{assemble, ThetaSettings};
use dynamics::integrators::event_driven::{event_driven, EventDrivenSettings};
use dynamics::periodic::poincare::{periodic_regime, PoincareSettings};
use dynamics::rate::lyapunov_exponent::{measure_rate, RateSettings};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;
use theorems::strategies::inputs::InputStrategyConfig;
use theorems::strategies::sets::{SetKind, SetStrategyConfig};
use theorems::strategies::systems::{system_params, SystemStrategyConfig};

fn config() -> SystemStrategyConfig {
    SystemStrategyConfig {
        max_n: 4,
        max_p: 1,
        mu: (-2.0, -0.3),
        theta: SetStrategyConfig { kinds: set_kinds(), max_dim: 1, max_cond: 4.0, scale_exp: 0.75 },
        input: InputStrategyConfig { amp_exp: (0.0, 1.5), ..Default::default() },
        ..Default::default()
    }
}

/// Theta: intervals; with `FLOQUET_BENCHMARK_SETS=all` also balls and ellipsoids in R^1 (the
/// p = 1 sets of the theta benchmark).
fn set_kinds() -> Vec<SetKind> {
    match std::env::var("FLOQUET_BENCHMARK_SETS").as_deref() {
        Ok("all") => vec![SetKind::Interval, SetKind::Ball, SetKind::Ellipsoid],
        _ => vec![SetKind::Interval],
    }
}

struct Row {
    n: usize,
    rate: f64,
    ci: (f64, f64),
    sigma: f64,
    /// [`finite_difference_exponent`].
    fd: Option<f64>,
    /// `[min (pair - 4 sigma), max (pair + 4 sigma)]` over the measured pairs.
    pair_range: (f64, f64),
    /// The dominant multiplier's exponent from the same pairs: (exponent, ci_low, ci_high).
    mult: Option<(f64, f64, f64)>,
    enc: [f64; 2],
    verified: bool,
    reason: Option<String>,
    rel_width: f64,
    secs: f64,
    theta_best: Option<f64>,
}

/// An independent estimate of the exponent: the period map of the event-driven reference
/// integrator (exact piecewise-linear flow, events by bisection to 1e-13), its Jacobian by
/// central finite differences (step 1e-6) at the regime (catching-up fixed point refined by 20
/// event-driven periods), `ln rho / T`. No saltation matrix, no Krawczyk, no interval.
fn finite_difference_exponent(sys: &model::System) -> Option<f64> {
    let T = sys.period()?;
    let reg = periodic_regime(
        sys,
        &PoincareSettings { dt: T / 2000.0, tol_residual: 1e-9, max_periods: 400, ..Default::default() },
    )
    .ok()?;
    let (n, p) = (sys.n(), sys.p());
    let period_map = |s: &[f64], periods: usize| -> Option<Vec<f64>> {
        let mut s2 = sys.clone();
        s2.x0 = DVector::from_column_slice(&s[..n]);
        s2.z0 = DVector::from_column_slice(&s[n..]);
        let st = EventDrivenSettings { dt_out: T / 64.0, t_end: periods as f64 * T, ..Default::default() };
        let (tr, _) = event_driven(&s2, &st).ok()?;
        let k = tr.len() - 1;
        Some([tr.x_at(k), tr.z_at(k)].concat())
    };
    let s0 = period_map(&[reg.x0.clone(), reg.z0.clone()].concat(), 20)?;
    let d = n + p;
    let mut J = DMatrix::<f64>::zeros(d, d);
    for j in 0..d {
        let h = 1e-6 * (1.0 + s0[j].abs());
        let (mut a, mut b) = (s0.clone(), s0.clone());
        a[j] += h;
        b[j] -= h;
        let (pa, pb) = (period_map(&a, 1)?, period_map(&b, 1)?);
        for i in 0..d {
            J[(i, j)] = (pa[i] - pb[i]) / (2.0 * h);
        }
    }
    let rho = J.complex_eigenvalues().iter().map(|z| z.norm()).fold(0.0, f64::max);
    Some(rho.ln() / T)
}

/// One convergent system's row: the measurement (pairs, multiplier, step-checked), the
/// finite-difference estimate, the enclosure and `theta_best`; `None` when it does not converge.
fn measure_system(sys: &model::System, measure: &RateSettings) -> Option<Row> {
    let m = measure_rate(sys, measure, None).ok()?;
    if !(m.ci_high < 0.0) {
        return None;
    }
    let pair_range = m.pairs.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
        (a.min(p.exponent - 4.0 * p.std_error), b.max(p.exponent + 4.0 * p.std_error))
    });
    let fd = finite_difference_exponent(sys);
    let t = std::time::Instant::now();
    let f = floquet_enclosure(sys, &FloquetSettings::default());
    let secs = t.elapsed().as_secs_f64();
    let theta_best = assemble(sys, &ThetaSettings::bound_only())
        .ok()
        .and_then(|r| (r.theta_best_verified && r.theta_best < 0.0).then_some(r.theta_best));
    Some(Row {
        n: sys.n(),
        rate: m.exponent,
        ci: (m.ci_low, m.ci_high),
        // a half-width of the (widened) interval is two sigmas
        sigma: 0.25 * (m.ci_high - m.ci_low),
        fd,
        pair_range,
        mult: m.multiplier.as_ref().map(|u| (u.exponent, u.ci_low, u.ci_high)),
        enc: f.floquet_exponent,
        verified: f.verified,
        reason: f.reason.clone(),
        rel_width: f.relative_width(),
        secs,
        theta_best,
    })
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let want: usize = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(50);
    let seed: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(3030);
    let start = std::time::Instant::now();
    let (rows, drawn) = draw_rows(want, seed);
    let total = start.elapsed().as_secs_f64();
    if std::env::var("FLOQUET_BENCHMARK_ROWS").is_ok() {
        print_rows(&rows);
    }
    print_summary(&rows, seed, drawn, total);
    let mut reasons: Vec<String> = rows.iter().filter_map(|r| r.reason.clone()).collect();
    reasons.sort();
    reasons.dedup();
    for r in reasons {
        let c = rows.iter().filter(|x| x.reason.as_deref() == Some(r.as_str())).count();
        println!("  not verified ({c}): {r}");
    }
    let ratios: Vec<f64> =
        rows.iter().filter(|r| r.verified).filter_map(|r| r.theta_best.map(|t| t / r.enc[1])).collect::<Vec<_>>();
    if !ratios.is_empty() {
        let mut s = ratios.clone();
        s.sort_by(f64::total_cmp);
        println!(
            "theta_best / floquet_hi: {} systems, median {:.3}, min {:.3}, max {:.3}",
            s.len(),
            s[s.len() / 2],
            s[0],
            s[s.len() - 1]
        );
    }
}

/// Draws until `want` convergent systems (capped at 40 `want` candidates): their rows and the
/// number of systems drawn.
fn draw_rows(want: usize, seed: u64) -> (Vec<Row>, usize) {
    let params = theorems::strategies::draw(&system_params(&config()), seed, 40 * want);
    let measure = RateSettings {
        periods: 30,
        transient_periods: 10,
        pairs: 3,
        step_check: true,
        separation: std::env::var("FLOQUET_SEPARATION").ok().and_then(|v| v.parse().ok()).unwrap_or(1e-6),
        renorm_below: 1e-2,
        dt: std::env::var("FLOQUET_DT").ok().and_then(|v| v.parse().ok()).unwrap_or(2e-3),
        ..Default::default()
    };
    let mut rows: Vec<Row> = Vec::new();
    let mut drawn = 0;
    for chunk in params.chunks(16) {
        if rows.len() >= want {
            break;
        }
        drawn += chunk.len();
        let got: Vec<Row> =
            chunk.par_iter().filter(|c| c.n >= 2).filter_map(|c| measure_system(&c.build(), &measure)).collect();
        rows.extend(got);
    }
    rows.truncate(want);
    (rows, drawn)
}

/// One row per system (`FLOQUET_BENCHMARK_ROWS=1`): the measurements, the enclosure, its time
/// and `theta_best / floquet`.
fn print_rows(rows: &[Row]) {
    println!("| # | n | measured ln V (95 % CI + step) | measured multiplier (95 % CI + step) | event-driven FD | floquet_exponent | rel. width | time | theta_best | theta_best / floquet |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for (i, r) in rows.iter().enumerate() {
        let enc = if r.verified {
            format!("[{:.6}, {:.6}]", r.enc[0], r.enc[1])
        } else {
            format!("not verified: {}", r.reason.as_deref().unwrap_or("?"))
        };
        let tb = r.theta_best.map(|v| format!("{v:.4}")).unwrap_or("-".into());
        let ratio = match (r.verified, r.theta_best) {
            (true, Some(v)) => format!("{:.3}", v / r.enc[1]),
            _ => "-".into(),
        };
        println!(
            "| {i} | {} | {:.5} ({:.5}, {:.5}) | {} | {} | {enc} | {:.1e} | {:.0} ms | {tb} | {ratio} |",
            r.n,
            r.rate,
            r.ci.0,
            r.ci.1,
            r.mult.map(|u| format!("{:.6} ({:.6}, {:.6})", u.0, u.1, u.2)).unwrap_or("-".into()),
            r.fd.map(|v| format!("{v:.6}")).unwrap_or("-".into()),
            r.rel_width,
            1e3 * r.secs
        );
    }
    println!();
}

/// The enclosures against the measurements: verified, narrow, overlapping the measured interval
/// or excluded beyond 4 sigma of it, the same against the dominant multiplier, bracketed by the
/// pairs, and against the event-driven finite differences.
fn print_summary(rows: &[Row], seed: u64, drawn: usize, total: f64) {
    let ver: Vec<&Row> = rows.iter().filter(|r| r.verified).collect();
    let narrow = ver.iter().filter(|r| r.rel_width <= 1e-3).count();
    let overlap = ver.iter().filter(|r| r.enc[0] <= r.ci.1 && r.ci.0 <= r.enc[1]).count();
    // exclusion beyond 4 sigma of the measurement
    let far = ver.iter().filter(|r| r.enc[0] > r.rate + 4.0 * r.sigma || r.enc[1] < r.rate - 4.0 * r.sigma).count();
    // the dominant multiplier: overlap, and exclusion by more than 4 sigma (2 half-widths)
    let with_mult: Vec<(&Row, (f64, f64, f64))> = ver.iter().filter_map(|r| r.mult.map(|u| (*r, u))).collect();
    let overlap_mult = with_mult.iter().filter(|(r, u)| r.enc[0] <= u.2 && u.1 <= r.enc[1]).count();
    let far_mult = with_mult
        .iter()
        .filter(|(r, u)| {
            let half = 0.5 * (u.2 - u.1);
            r.enc[0] > u.0 + 2.0 * half || r.enc[1] < u.0 - 2.0 * half
        })
        .count();
    let mut mult_width: Vec<f64> = with_mult.iter().map(|(_, u)| (u.2 - u.1) / u.0.abs()).collect();
    mult_width.sort_by(f64::total_cmp);
    let mult_width_median = mult_width.get(mult_width.len() / 2).copied().unwrap_or(f64::NAN);
    let bracketed = ver.iter().filter(|r| r.pair_range.0 <= r.enc[1] && r.enc[0] <= r.pair_range.1).count();
    let fd_dev: Vec<f64> =
        ver.iter().filter_map(|r| r.fd.map(|f| (f - 0.5 * (r.enc[0] + r.enc[1])).abs() / f.abs())).collect();
    let fd_max = fd_dev.iter().copied().fold(0.0, f64::max);
    let fd_1e4 = fd_dev.iter().filter(|d| **d <= 1e-4).count();
    let max_secs = rows.iter().map(|r| r.secs).fold(0.0, f64::max);
    let max_width = ver.iter().map(|r| r.rel_width).fold(0.0, f64::max);
    println!(
        "seed {seed}: {} convergent p = 1 systems ({drawn} drawn, {total:.0} s); verified {} ({:.0} %); \
         relative width <= 1e-3: {narrow} (max {max_width:.1e}); measured CI overlaps: {overlap} of {}; \
         excluded beyond 4 sigma: {far}; slowest enclosure {:.0} ms\n\
         the dominant multiplier measured from the pairs: {} measured, its interval overlaps the enclosure on \
         {overlap_mult}, excluded beyond 4 sigma {far_mult}, median relative width {mult_width_median:.1e}\n\
         the measured pairs (each +- 4 sigma) bracket the enclosure on {bracketed} of {}\n\
         event-driven finite differences: {} compared, relative deviation from the enclosure <= 1e-4 on {fd_1e4}, max {fd_max:.1e}",
        rows.len(),
        ver.len(),
        100.0 * ver.len() as f64 / rows.len().max(1) as f64,
        ver.len(),
        1e3 * max_secs,
        with_mult.len(),
        ver.len(),
        fd_dev.len()
    );
}
