//! Repeats the beta SDP of eq. (bet) on one seeded system, for profiling (`valgrind
//! --tool=callgrind` counts instructions, which do not depend on the machine's load).
//! Usage: `sdp_profile SEED N P REPEATS`.
#![allow(non_snake_case)]
use lmi::fixtures::random_hurwitz_system;
use lmi::{hurwitz_mu, solve_beta_sdp, BetaSdpSettings};

fn main() {
    let a: Vec<u64> = std::env::args().skip(1).map(|s| s.parse().expect("integer arguments")).collect();
    let (seed, n, p, reps) = (
        a.first().copied().unwrap_or(1007),
        a.get(1).copied().unwrap_or(4) as usize,
        a.get(2).copied().unwrap_or(2) as usize,
        a.get(3).copied().unwrap_or(50),
    );
    let (F, E, C) = random_hurwitz_system(seed, n, p);
    let lambda = 0.5 * -hurwitz_mu(&F).expect("Hurwitz");
    let s = BetaSdpSettings::default();
    let t = std::time::Instant::now();
    let mut beta = 0.0;
    let mut iters = 0;
    for _ in 0..reps {
        let sol = solve_beta_sdp(&F, &E, &C, lambda, &s).expect("solvable");
        beta = sol.beta;
        iters = sol.iterations;
    }
    println!("beta {beta:.12e} iterations {iters} mean {:.3} ms", t.elapsed().as_secs_f64() * 1e3 / reps as f64);
}
