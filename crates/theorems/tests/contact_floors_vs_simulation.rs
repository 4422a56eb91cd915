//! The engaged-cell speed floors of balls and ellipsoids in R^2 and R^3
//! (`bounds::beyond_paper::contact_floors`, proofs-notes/theta-engaged-balls.md) against
//! simulated periodic regimes, cell by cell.
//!
//! Random p = 2 and p = 3 systems (balls and ellipsoids, sine inputs), each simulated by the
//! catching-up scheme from rest for enough periods that `e^{mu t}` is below `1e-6`, then over two
//! more periods: on every cell with a floor, the smallest speed `|z_{k+1} - z_k| / h` of its steps
//! must be at least the floor (relative tolerance `1e-2` for the scheme's first-order error plus
//! `1e-6` of the transient). Negative controls, each must be caught on some cell: the floors
//! raised by 10 %, and every cell with `|eta_T'| > D` declared engaged at once with the floor
//! `|eta_T'| - D` (the p = 1 floor, which ignores that the contact point trails the direction of
//! motion and has to travel round the boundary after each turn).
//!
//! The floors are those of the assembly (`contact_floors::for_system` rebuilds its tube kernel;
//! the test checks the same `D` and the same engaged cells as `assemble`), with the engaged
//! ceilings: every engaged cell's largest simulated step speed must lie below its ceiling.
//!
//! `CONTACT_FLOOR_CASES=N` (default 10) systems with at least one engaged cell.
#![allow(non_snake_case)]
use bounds::beyond_paper::contact_floors::{for_system, substeps};
use bounds::orbit::{EtaOrbit, OrbitSettings};
use bounds::{assemble, ThetaSettings};
use dynamics::integrators::catching_up::{CatchingUpSettings, Simulator};
use theorems::strategies::inputs::InputStrategyConfig;
use theorems::strategies::sets::{SetKind, SetStrategyConfig};
use theorems::strategies::systems::{system_params, SystemStrategyConfig};

fn wanted() -> usize {
    std::env::var("CONTACT_FLOOR_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(10).max(1)
}

const CELLS: usize = 400;
/// Catching-up steps per orbit sample interval (2000 per period).
const SUB: usize = 10;

/// Smallest and largest step speed `|z_{k+1} - z_k| / h` per cell over two periods of the regime.
fn simulated_cell_speeds(sys: &model::System, T: f64, mu: f64) -> (Vec<f64>, Vec<f64>) {
    let K = OrbitSettings::default().samples;
    let h = T / (K * SUB) as f64;
    let mut sim = Simulator::new(sys, &CatchingUpSettings { dt: h, ..Default::default() }).expect("simulator");
    let (n, p) = (sys.n(), sys.p());
    let (mut x, mut z) = (vec![0.0; n], vec![0.0; p]);
    let transient = ((14.0 / -mu) / T).ceil().max(5.0) as usize;
    let per_period = K * SUB;
    sim.run(0.0, &mut x, &mut z, transient * per_period, |_, _, _, _| {});
    let mut speed = vec![f64::INFINITY; CELLS];
    let mut top = vec![0.0f64; CELLS];
    let mut prev = z.clone();
    let per_cell = per_period / CELLS;
    sim.run(transient as f64 * T, &mut x, &mut z, 2 * per_period, |k, _, _, zk| {
        let step = ((k - 1) % per_period) / per_cell;
        let v = prev.iter().zip(zk).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt() / h;
        speed[step] = speed[step].min(v);
        top[step] = top[step].max(v);
        prev.copy_from_slice(zk);
    });
    (speed, top)
}

#[test]
fn contact_floors_hold_cell_by_cell_in_simulated_regimes_with_controls() {
    let config = SystemStrategyConfig {
        max_n: 4,
        max_p: 3,
        mu: (-2.0, -0.3),
        theta: SetStrategyConfig {
            kinds: vec![SetKind::Ball, SetKind::Ellipsoid],
            max_dim: 3,
            max_cond: 4.0,
            scale_exp: 0.75,
        },
        input: InputStrategyConfig { amp_exp: (0.5, 1.5), ..Default::default() },
        ..Default::default()
    };
    let params = theorems::strategies::draw(&system_params(&config), 29, 40 * wanted());
    let (mut checked, mut engaged_cells, mut raised_caught, mut naive_caught) = (0, 0, 0, 0);
    let mut by_p = [0usize; 4];
    let mut tightest = f64::INFINITY;
    for (i, c) in params.iter().enumerate() {
        if checked >= wanted() {
            break;
        }
        if c.p < 2 {
            continue;
        }
        let sys = c.build();
        let Ok(r) = assemble(&sys, &ThetaSettings::bound_only()) else { continue };
        if !(r.d_verified && r.orbit_verified && r.R.is_finite()) {
            continue;
        }
        let orbit = EtaOrbit::new(&sys, &OrbitSettings::default()).expect("orbit");
        // the floors as the assembly computes them (same D, same engaged cells)
        let Ok(Some((floors, d))) = for_system(&sys, CELLS, &ThetaSettings::bound_only()) else { continue };
        assert_eq!(d.to_bits(), r.d_ftheta.to_bits(), "case {i}: D differs from the assembly's");
        let engaged_here = floors.floor.iter().filter(|&&f| f > 0.0).count();
        if r.profile_cells == CELLS && r.engaged_cells > 0 {
            assert_eq!(engaged_here, r.engaged_cells, "case {i}: engaged cells differ from the assembly's");
        }
        let (speed, top) = simulated_cell_speeds(&sys, r.period, r.mu);
        checked += 1;
        by_p[sys.p()] += 1;
        let engaged = floors.floor.iter().filter(|&&f| f > 0.0).count();
        engaged_cells += engaged;
        // the naive control: |eta_T'| - D on every cell where it is positive, engaged at once
        let subs = substeps(&orbit, r.d_ftheta, &|_| r.d_ftheta).expect("substeps");
        let per = subs.len() / CELLS;
        let naive: Vec<f64> = (0..CELLS)
            .map(|c| subs[c * per..(c + 1) * per].iter().map(|s| s.map_or(0.0, |s| s.s)).fold(f64::INFINITY, f64::min))
            .collect();
        let tol = |f: f64| f * (1.0 - 1e-2) - 1e-6 * r.eta_dot_inf;
        let mut min_ratio = f64::INFINITY;
        for cell in 0..CELLS {
            let f = floors.floor[cell];
            if f > 0.0 {
                min_ratio = min_ratio.min(speed[cell] / f);
                assert!(
                    speed[cell] >= tol(f),
                    "case {i} (p = {}, {}): cell {cell}: simulated speed {} below the floor {f}",
                    sys.p(),
                    sys.theta.kind(),
                    speed[cell]
                );
                let u = floors.ceiling[cell];
                assert!(
                    top[cell] <= u * (1.0 + 1e-2) + 1e-6 * r.eta_dot_inf,
                    "case {i}: cell {cell}: simulated speed {} above the engaged ceiling {u}",
                    top[cell]
                );
                if speed[cell] < tol(1.1 * f) {
                    raised_caught += 1;
                }
            }
            if naive[cell] > 0.0 && speed[cell] < tol(naive[cell]) {
                naive_caught += 1;
            }
        }
        tightest = tightest.min(min_ratio);
        eprintln!(
            "case {i}: p = {}, {}, {engaged} of {CELLS} cells engaged, smallest simulated speed / floor {min_ratio:.4}",
            sys.p(),
            sys.theta.kind()
        );
    }
    eprintln!(
        "{checked} systems ({} with p = 2, {} with p = 3), {engaged_cells} engaged cells, tightest {tightest:.4}; caught: raised {raised_caught} cells, naive {naive_caught} cells",
        by_p[2], by_p[3]
    );
    assert!(checked >= wanted().min(4), "too few systems with engaged cells: {checked}");
    assert!(by_p[2] > 0 && by_p[3] > 0, "both p = 2 and p = 3 must be exercised: {by_p:?}");
    assert!(raised_caught > 0, "negative control: floors raised by 10 % were never refuted");
    assert!(naive_caught > 0, "negative control: cells wrongly declared engaged were never refuted");
}
