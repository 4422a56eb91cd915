//! Stiff plants (issue 29 item 1): `cargo run --release -p theorems --example stiff_benchmark --
//! [seed] [per_cell]`.
//!
//! For each stiffness ratio `|fast| / |slow|` in {10, 1e2, 1e3, 1e4} and each `n` in 2..=6,
//! `per_cell` systems (default 2) `F = V J V^{-1}`: `n - 1` slow modes (real parts in
//! `[a0, 3 a0]`, `a0` in `[-0.6, -0.3]`, a complex pair when `n >= 3`) and one fast real mode
//! at `ratio * a0 * [1, 1.2]`; `V = I + 0.5 R`, `R` in `[-1, 1]^{n x n}`; `p = 1`, `C = e_1^T +
//! 0.3 R`, `E`, `B` random, `A = F - E C`; `Theta = [-0.1, 0.1]`; a sine input of `omega = 1`
//! and amplitude `10^[0.5, 1.5]`. Everything from a splitmix64 stream of `(seed, ratio, n, k)`.
//! Per system: the verdict of `bounds::assemble` (bound only, timed: the answer's time), or its
//! error; `theta_best`; the measured exponent (`dynamics::rate::lyapunov_exponent::measure_rate`,
//! 2 pairs x 30 periods after 10); bound / measured. Prints Markdown tables. With
//! `STIFF_DUMP=DIR` the systems are also written to `DIR` as model files (`ratio-n-k.toml`), so
//! that another build's `moreau theta` can be run on the same family.
#![allow(non_snake_case)]
use bounds::{assemble, ThetaSettings};
use dynamics::rate::lyapunov_exponent::{measure_rate, RateSettings};
use geometry::{Interval, Shape};
use model::{Input, SimDefaults, System};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

/// splitmix64: a fixed, dependency-free stream.
struct Rng(u64);
impl Rng {
    fn new(seed: u64, ratio: f64, n: usize, k: usize) -> Self {
        let mut r = Rng(seed ^ ratio.to_bits().rotate_left(17) ^ ((n as u64) << 40) ^ ((k as u64) << 48));
        r.next();
        r
    }
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next() >> 11) as f64 / (1u64 << 53) as f64)
    }
}

fn stiff_system(seed: u64, ratio: f64, n: usize, k: usize) -> System {
    let mut g = Rng::new(seed, ratio, n, k);
    let a0 = g.uniform(-0.6, -0.3);
    let mut J = DMatrix::<f64>::zeros(n, n);
    J[(0, 0)] = ratio * a0 * g.uniform(1.0, 1.2);
    let mut i = 1;
    while i < n {
        let a = if i == 1 { a0 } else { a0 * g.uniform(1.0, 3.0) };
        if i + 1 < n && i == 1 {
            let b = g.uniform(0.5, 2.0);
            J[(i, i)] = a;
            J[(i + 1, i + 1)] = a;
            J[(i, i + 1)] = b;
            J[(i + 1, i)] = -b;
            i += 2;
        } else {
            J[(i, i)] = a;
            i += 1;
        }
    }
    let V = DMatrix::from_fn(n, n, |r, c| if r == c { 1.0 } else { 0.0 } + 0.5 * g.uniform(-1.0, 1.0));
    let Vi = V.clone().try_inverse().expect("V = I + 0.5 R is invertible for these draws");
    let F = &V * &J * &Vi;
    let C = DMatrix::from_fn(1, n, |_, c| if c == 0 { 1.0 } else { 0.0 } + 0.3 * g.uniform(-1.0, 1.0));
    let E = DMatrix::from_fn(n, 1, |_, _| g.uniform(-1.0, 1.0));
    let B = DMatrix::from_fn(n, 1, |_, _| g.uniform(-1.0, 1.0));
    let A = &F - &E * &C;
    let amp = 10f64.powf(g.uniform(0.5, 1.5));
    System::builder()
        .name(format!("stiff ratio {ratio:e} n {n} #{k}"))
        .A(A)
        .B(B)
        .C(C)
        .E(E)
        .theta(Shape::Interval(Interval::symmetric(0.1).expect("0.1 > 0")))
        .input(Input::Sine { amplitudes: vec![amp], omega: 1.0, phase: 0.0 })
        .x0(DVector::zeros(n))
        .z0(DVector::zeros(1))
        .sim(SimDefaults { dt: 1e-3, periods: 20, t_end: None })
        .build()
        .expect("a valid stiff system")
}

/// CPU time of this thread in seconds (`/proc/thread-self/schedstat`, Linux; NaN elsewhere):
/// the answer's time without the waiting of a shared machine.
fn thread_cpu() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next().and_then(|x| x.parse::<f64>().ok()))
        .map_or(f64::NAN, |ns| ns * 1e-9)
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

struct Row {
    ratio: f64,
    n: usize,
    k: usize,
    verdict: String,
    theta_best: f64,
    measured: f64,
    secs: f64,
    cpu: f64,
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let seed: u64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(2029);
    let per_cell: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(2);
    let settings = ThetaSettings { stationary: None, measure: None, ..Default::default() };
    let rate = RateSettings { periods: 30, transient_periods: 10, pairs: 2, ..Default::default() };
    let mut cases = Vec::new();
    for ratio in [10.0, 1e2, 1e3, 1e4] {
        for n in 2..=6 {
            for k in 0..per_cell {
                cases.push((ratio, n, k));
            }
        }
    }
    if let Ok(dir) = std::env::var("STIFF_DUMP") {
        std::fs::create_dir_all(&dir).expect("STIFF_DUMP: a writable folder");
        for &(ratio, n, k) in &cases {
            let path = std::path::Path::new(&dir).join(format!("{ratio:e}-{n}-{k}.toml"));
            std::fs::write(&path, model::to_toml_string(&stiff_system(seed, ratio, n, k))).expect("write a model file");
        }
    }
    let start = std::time::Instant::now();
    // the answers one at a time (their times are the point), the measurements in parallel
    let mut rows: Vec<Row> = cases
        .iter()
        .map(|&(ratio, n, k)| {
            let sys = stiff_system(seed, ratio, n, k);
            let (t0, c0) = (std::time::Instant::now(), thread_cpu());
            let rep = assemble(&sys, &settings);
            let (secs, cpu) = (t0.elapsed().as_secs_f64(), thread_cpu() - c0);
            let (verdict, theta_best) = match &rep {
                Ok(r) if r.theta_best_verified && r.theta_best < 0.0 => ("certified".to_string(), r.theta_best),
                Ok(r) if r.theta_best_verified => ("not certified (verified bound >= 0)".to_string(), r.theta_best),
                Ok(r) => ("not certified (unverified)".to_string(), r.theta_best),
                Err(e) => (format!("error: {e}"), f64::NAN),
            };
            Row { ratio, n, k, verdict, theta_best, measured: f64::NAN, secs, cpu }
        })
        .collect();
    let measured: Vec<f64> = cases
        .par_iter()
        .map(|&(ratio, n, k)| {
            measure_rate(&stiff_system(seed, ratio, n, k), &rate, None).map(|m| m.exponent).unwrap_or(f64::NAN)
        })
        .collect();
    for (r, m) in rows.iter_mut().zip(measured) {
        r.measured = m;
    }
    let total = start.elapsed().as_secs_f64();
    println!("Seed {seed}, {} systems, {total:.0} s in all on this machine.", rows.len());
    println!();
    println!("| ratio | n | # | verdict | theta_best | measured | bound / measured | time (s) | CPU (s) |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for r in &rows {
        let ratio_bm = if r.verdict == "certified" { format!("{:.3}", r.theta_best / r.measured) } else { "-".into() };
        println!(
            "| {:e} | {} | {} | {} | {:.4e} | {:.4} | {} | {:.3} | {:.3} |",
            r.ratio, r.n, r.k, r.verdict, r.theta_best, r.measured, ratio_bm, r.secs, r.cpu
        );
    }
    println!();
    println!(
        "| ratio | systems | errors | certified | median bound / measured (certified) | median time (s) | max time (s) | max CPU (s) |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for ratio in [10.0, 1e2, 1e3, 1e4] {
        let set: Vec<&Row> = rows.iter().filter(|r| r.ratio == ratio).collect();
        let errors = set.iter().filter(|r| r.verdict.starts_with("error")).count();
        let cert: Vec<&&Row> = set.iter().filter(|r| r.verdict == "certified").collect();
        let bm = median(cert.iter().map(|r| r.theta_best / r.measured).collect());
        let times: Vec<f64> = set.iter().map(|r| r.secs).collect();
        let tmax = times.iter().copied().fold(0.0, f64::max);
        let cmax = set.iter().map(|r| r.cpu).fold(0.0, f64::max);
        println!(
            "| {ratio:e} | {} | {errors} | {} | {bm:.3} | {:.3} | {tmax:.3} | {cmax:.3} |",
            set.len(),
            cert.len(),
            median(times.clone())
        );
    }
    let violations = rows.iter().filter(|r| r.verdict == "certified" && r.theta_best < r.measured).count();
    println!();
    println!("Certified bounds below the measured exponent (violations): {violations}.");
}
