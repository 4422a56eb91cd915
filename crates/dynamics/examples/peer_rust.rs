//! Rust side of the peer harness (bench/peers/dynamics): catching-up steps/s on the worked
//! example for one trajectory and for an ensemble of `M` trajectories (one core).
//! Usage: `peer_rust STEPS ENSEMBLE ENSEMBLE_STEPS [REPS]`; prints
//! - `rust_single <steps/s>`: the fixed-size single path;
//! - `rust_ensemble <trajectory-steps/s>`: the SIMD ensemble integrator
//!   (`dynamics::integrators::ensemble`), median of `REPS` runs (default 9);
//! - `rust_ensemble_loop <trajectory-steps/s>`: the single path in a loop over the trajectories
//!   (the previous "ensemble"), with the largest difference between the two final ensembles
//!   (they agree to rounding; bit for bit here).
use dynamics::integrators::catching_up::{CatchingUpSettings, FastCatchingUp};
use dynamics::integrators::ensemble::{EnsembleCatchingUp, EnsembleState};
use geometry::Interval;
use nalgebra::SVector;
use std::time::Instant;

fn main() {
    let a: Vec<usize> = std::env::args().skip(1).map(|s| s.parse().expect("integer arguments")).collect();
    let (steps, ens, ens_steps) = (
        a.first().copied().unwrap_or(10_000_000),
        a.get(1).copied().unwrap_or(1000),
        a.get(2).copied().unwrap_or(10_000),
    );
    let reps = a.get(3).copied().unwrap_or(9);
    let sys = model::parse_str(include_str!("../../../examples/worked-example.toml")).unwrap();
    let st = CatchingUpSettings::default();
    let mut f = FastCatchingUp::<2, 1, Interval>::new(&sys, Interval::symmetric(0.1).unwrap(), &st).unwrap();
    let (mut x, mut z) = (SVector::<f64, 2>::zeros(), SVector::<f64, 1>::zeros());
    let t = Instant::now();
    f.run(0.0, &mut x, &mut z, steps, |_, _, _, _| {});
    let dt = t.elapsed().as_secs_f64();
    println!("rust_single {:.6e} final_x1 {:.12}", steps as f64 / dt, x[0]);

    // the peer's initial states: x = (0.01 j / M, 0), z = x_1
    let init = |j: usize, x: &mut [f64], z: &mut [f64]| {
        x[0] = 0.01 * j as f64 / ens as f64;
        z[0] = x[0];
    };
    // one run takes ~10 ms: repeated `reps` times on a shared machine, the median reported
    let mut e = EnsembleCatchingUp::<2, 1>::new(&sys, &st).unwrap();
    let mut rates = Vec::new();
    let mut state = EnsembleState::from_fn(2, 1, ens, init);
    e.run(0.0, &mut state, 1000.min(ens_steps)); // warm-up (caches, frequency)
    for _ in 0..reps.max(1) {
        state = EnsembleState::from_fn(2, 1, ens, init);
        let t = Instant::now();
        e.run(0.0, &mut state, ens_steps);
        rates.push((ens * ens_steps) as f64 / t.elapsed().as_secs_f64());
    }
    rates.sort_by(f64::total_cmp);
    let acc: f64 = state.x_component(0).iter().sum();
    println!(
        "rust_ensemble {:.6e} checksum {:.6} (median of {} runs; best {:.6e}, worst {:.6e})",
        rates[rates.len() / 2],
        acc,
        rates.len(),
        rates[rates.len() - 1],
        rates[0]
    );

    let t = Instant::now();
    let mut acc = 0.0;
    let mut diff: f64 = 0.0;
    for j in 0..ens {
        let mut x = SVector::<f64, 2>::zeros();
        let mut z = SVector::<f64, 1>::zeros();
        init(j, x.as_mut_slice(), z.as_mut_slice());
        f.run(0.0, &mut x, &mut z, ens_steps, |_, _, _, _| {});
        acc += x[0];
        let (xe, ze) = (state.x_of(j), state.z_of(j));
        diff = diff.max((xe[0] - x[0]).abs()).max((xe[1] - x[1]).abs()).max((ze[0] - z[0]).abs());
    }
    let dt = t.elapsed().as_secs_f64();
    println!(
        "rust_ensemble_loop {:.6e} checksum {:.6} max_abs_diff_vs_ensemble {:.3e}",
        (ens * ens_steps) as f64 / dt,
        acc,
        diff
    );
}
