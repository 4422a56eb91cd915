//! Rust side of the peer harness (bench/peers/dynamics): catching-up steps/s on the worked
//! example for one trajectory and for an ensemble of `M` trajectories (sequential, one core).
//! Usage: `peer_rust STEPS ENSEMBLE ENSEMBLE_STEPS`; prints `rust_single <steps/s>` and
//! `rust_ensemble <trajectory-steps/s>`.
use dynamics::integrators::catching_up::{CatchingUpSettings, FastCatchingUp};
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
    let sys = model::parse_str(include_str!("../../../examples/worked-example.toml")).unwrap();
    let mut f =
        FastCatchingUp::<2, 1, Interval>::new(&sys, Interval::symmetric(0.1).unwrap(), &CatchingUpSettings::default())
            .unwrap();
    let (mut x, mut z) = (SVector::<f64, 2>::zeros(), SVector::<f64, 1>::zeros());
    let t = Instant::now();
    f.run(0.0, &mut x, &mut z, steps, |_, _, _, _| {});
    let dt = t.elapsed().as_secs_f64();
    println!("rust_single {:.6e} final_x1 {:.12}", steps as f64 / dt, x[0]);
    let t = Instant::now();
    let mut acc = 0.0;
    for j in 0..ens {
        let mut x = SVector::<f64, 2>::new(0.01 * j as f64 / ens as f64, 0.0);
        let mut z = SVector::<f64, 1>::new(x[0]);
        f.run(0.0, &mut x, &mut z, ens_steps, |_, _, _, _| {});
        acc += x[0];
    }
    let dt = t.elapsed().as_secs_f64();
    println!("rust_ensemble {:.6e} checksum {:.6}", (ens * ens_steps) as f64 / dt, acc);
}
