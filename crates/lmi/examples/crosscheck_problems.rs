//! Write the 20 seeded beta-SDP problems of the cross-check (`bench/peers/lmi/`) with the
//! Rust answers and timings to `<out>/problems.json`.
//!
//! `cargo run --release -p lmi --example crosscheck_problems -- --out <dir>`
#![allow(non_snake_case)]

use lmi::fixtures::random_hurwitz_system;
use lmi::{certified_beta, hurwitz_mu, solve_beta_sdp, BetaSdpSettings};
use nalgebra::DMatrix;
use std::time::Instant;

fn rows(M: &DMatrix<f64>) -> Vec<Vec<f64>> {
    (0..M.nrows()).map(|i| M.row(i).iter().copied().collect()).collect()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let out = match args.iter().position(|a| a == "--out").and_then(|i| args.get(i + 1)) {
        Some(d) => std::path::PathBuf::from(d),
        None => {
            eprintln!("usage: crosscheck_problems --out <dir>");
            std::process::exit(2);
        }
    };
    let reps = 20;
    let s = BetaSdpSettings::default();
    let mut problems = Vec::new();
    for seed in 0..20u64 {
        let n = 2 + (seed as usize % 5);
        let p = (1 + (seed as usize % 3)).min(n);
        let (F, E, C) = random_hurwitz_system(1000 + seed, n, p);
        let mu = hurwitz_mu(&F).expect("fixture is Hurwitz");
        let lambda = 0.5 * -mu;
        let sol = solve_beta_sdp(&F, &E, &C, lambda, &s).expect("solvable");
        let cb = certified_beta(&F, &E, &C, lambda, &s).expect("certified");
        let t_solve = median(
            (0..reps)
                .map(|_| {
                    let t = Instant::now();
                    std::hint::black_box(solve_beta_sdp(&F, &E, &C, lambda, &s).unwrap());
                    t.elapsed().as_secs_f64()
                })
                .collect(),
        );
        let t_cert = median(
            (0..reps)
                .map(|_| {
                    let t = Instant::now();
                    std::hint::black_box(certified_beta(&F, &E, &C, lambda, &s).unwrap());
                    t.elapsed().as_secs_f64()
                })
                .collect(),
        );
        problems.push(serde_json::json!({
            "seed": 1000 + seed, "n": n, "p": p,
            "F": rows(&F), "E": rows(&E), "C": rows(&C),
            "mu": mu, "lambda": lambda, "ali_margin": sol.ali_margin, "trace_max": sol.trace_max,
            "beta_rust": sol.beta, "b_hat_verified": cb.certificate.b_hat,
            "lambda_verified": cb.certificate.lambda, "iterations": sol.iterations,
            "rust_solve_s": t_solve, "rust_certified_s": t_cert,
        }));
        println!(
            "seed {:4} n={n} p={p} beta={:.10e} b_hat={:.10e} solve {:.3} ms certified {:.3} ms",
            1000 + seed,
            sol.beta,
            cb.certificate.b_hat,
            t_solve * 1e3,
            t_cert * 1e3
        );
    }
    std::fs::create_dir_all(&out).expect("create --out dir");
    let path = out.join("problems.json");
    std::fs::write(&path, serde_json::to_string_pretty(&problems).expect("json")).expect("write");
    println!("wrote {}", path.display());
}
