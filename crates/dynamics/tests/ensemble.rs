//! The SIMD ensemble integrator reproduces the single path trajectory by trajectory: every
//! lane against `FastCatchingUp<N, P, Shape>` (the arithmetic it mirrors) and against
//! `Simulator` (what the rest of the workspace runs), on the worked example and on systems with
//! every kind of set, input and hold, with ensemble sizes that are not multiples of the lane
//! count, split runs and per-step observation.
#![allow(clippy::needless_range_loop)]
use dynamics::integrators::catching_up::{CatchingUpSettings, FastCatchingUp};
use dynamics::integrators::ensemble::{Ensemble, EnsembleCatchingUp, EnsembleState};
use dynamics::{InputHold, Simulator};
use geometry::{Ball, ConvexSet, Shape};
use model::{Input, System};
use nalgebra::{DMatrix, DVector, SVector};

fn example(name: &str) -> System {
    let text = std::fs::read_to_string(format!("{}/../../examples/{name}.toml", env!("CARGO_MANIFEST_DIR"))).unwrap();
    model::parse_str(&text).unwrap()
}

/// Deterministic spread of initial states around the system's own: `x = x0 + a u_i`,
/// `z = C x + P_Theta(q0 + a v_i)`.
fn initial(sys: &System, len: usize, a: f64) -> EnsembleState {
    let (n, p) = (sys.n(), sys.p());
    let q0 = &sys.z0 - &sys.C * &sys.x0;
    EnsembleState::from_fn(n, p, len, |i, x, z| {
        let u = |k: usize| ((i * 7919 + k * 104729) as f64 * 0.6180339887).fract() * 2.0 - 1.0;
        for j in 0..n {
            x[j] = sys.x0[j] + a * u(j);
        }
        let q: Vec<f64> = (0..p).map(|j| q0[j] + a * u(n + j)).collect();
        let mut pq = vec![0.0; p];
        sys.theta.project(&q, &mut pq);
        let y = &sys.C * DVector::from_column_slice(x);
        for j in 0..p {
            z[j] = y[j] + pq[j];
        }
    })
}

/// Largest `|a - b| / (1 + |b|)` between the ensemble and per-trajectory reference states.
fn max_rel_diff(e: &EnsembleState, refs: &[(Vec<f64>, Vec<f64>)]) -> f64 {
    let mut worst: f64 = 0.0;
    for (i, (x, z)) in refs.iter().enumerate() {
        for (a, b) in e.x_of(i).iter().zip(x).chain(e.z_of(i).iter().zip(z)) {
            worst = worst.max((a - b).abs() / (1.0 + b.abs()));
            assert!(a.is_finite() && b.is_finite(), "non-finite state in trajectory {i}");
        }
    }
    worst
}

/// Runs the ensemble and, lane by lane, `FastCatchingUp<N, P, Shape>` and `Simulator` with the
/// same calls (`t0`, steps); returns the largest relative differences (vs fast, vs simulator).
fn compare<const N: usize, const P: usize>(
    sys: &System,
    st: &CatchingUpSettings,
    len: usize,
    calls: &[usize],
) -> (f64, f64) {
    let mut ens = EnsembleCatchingUp::<N, P>::new(sys, st).unwrap();
    let mut dynamic = Ensemble::new(sys, st).unwrap();
    assert!(dynamic.is_simd());
    let mut state = initial(sys, len, 0.3);
    let mut state2 = state.clone();
    let start = state.clone();
    let mut t = 0.0;
    for &c in calls {
        ens.run(t, &mut state, c);
        dynamic.run(t, &mut state2, c);
        t += c as f64 * st.dt;
    }
    assert_eq!(state, state2, "EnsembleCatchingUp and Ensemble differ");
    let mut fast = FastCatchingUp::<N, P, Shape>::new(sys, sys.theta.clone(), st).unwrap();
    let mut sim = Simulator::new(sys, st).unwrap();
    let (mut rf, mut rs) = (Vec::new(), Vec::new());
    for i in 0..len {
        let (x0, z0) = (start.x_of(i), start.z_of(i));
        let mut x = SVector::<f64, N>::from_column_slice(&x0);
        let mut z = SVector::<f64, P>::from_column_slice(&z0);
        let (mut xs, mut zs) = (x0.clone(), z0.clone());
        let mut t = 0.0;
        for &c in calls {
            fast.run(t, &mut x, &mut z, c, |_, _, _, _| {});
            sim.run(t, &mut xs, &mut zs, c, |_, _, _, _| {});
            t += c as f64 * st.dt;
        }
        rf.push((x.as_slice().to_vec(), z.as_slice().to_vec()));
        rs.push((xs, zs));
    }
    (max_rel_diff(&state, &rf), max_rel_diff(&state, &rs))
}

const TOL: f64 = 1e-12;

fn settings(dt: f64, hold: InputHold) -> CatchingUpSettings {
    CatchingUpSettings { dt, hold }
}

#[test]
fn worked_example_is_reproduced_bit_for_bit_with_ragged_sizes() {
    let sys = example("worked-example");
    let st = CatchingUpSettings::default();
    // 1001 trajectories (not a multiple of 4 or 8), 20,000 steps (more than a chunk, several
    // sine re-seeds), one call; 13 trajectories over split calls (re-seeds restart per call)
    for (len, calls) in [(1001, vec![20_000]), (13, vec![700, 1, 4_000, 333]), (1, vec![5_000]), (3, vec![0, 10])] {
        let (df, ds) = compare::<2, 1>(&sys, &st, len, &calls);
        // no fused multiply-add and the same order of operations: identical, not just close
        assert_eq!(df, 0.0, "len {len}: ensemble vs FastCatchingUp differ by {df:e}");
        assert!(ds <= TOL, "len {len}: ensemble vs Simulator {ds:e}");
    }
}

#[test]
fn every_input_kind_and_hold_agrees_with_the_single_path() {
    let base = example("worked-example");
    let mut cases: Vec<(&str, System, InputHold)> = Vec::new();
    cases.push(("sine, held", base.clone(), InputHold::Zoh));
    let mut sq = base.clone();
    sq.input = Input::Square { amplitudes: vec![0.7], omega: 2.3, phase: 0.4 };
    cases.push(("square, linear", sq.clone(), InputHold::Foh));
    cases.push(("square, held", sq, InputHold::Zoh));
    let mut zero = base.clone();
    zero.input = Input::Zero { m: 1 };
    cases.push(("zero", zero, InputHold::Foh));
    // two input channels (4 forcing terms per step, the run-time-count kernel)
    let mut two = base.clone();
    two.B = DMatrix::from_row_slice(2, 2, &[0.0, 0.3, 1.0, -0.2]);
    two.input = Input::Square { amplitudes: vec![1.0, 0.5], omega: 1.3, phase: 0.0 };
    cases.push(("two channels, linear", two, InputHold::Foh));
    for (what, sys, hold) in cases {
        let (df, ds) = compare::<2, 1>(&sys, &settings(2e-3, hold), 37, &[3_000, 1_111]);
        assert!(df <= TOL && ds <= TOL, "{what}: vs fast {df:e}, vs simulator {ds:e}");
    }
}

#[test]
fn balls_ellipsoids_and_other_sets_agree_with_the_single_path() {
    let st = CatchingUpSettings::default();
    // p = 2 ellipsoid (projected lane by lane) and the same plant with a ball (vectorised)
    let ell = example("ellipse-p2");
    let (df, ds) = compare::<4, 2>(&ell, &st, 29, &[10_000]);
    assert!(df <= TOL && ds <= TOL, "ellipse-p2: {df:e} {ds:e}");
    let mut ball = ell.clone();
    ball.theta = Shape::Ball(Ball::new(vec![0.02, -0.01], 0.15).unwrap());
    let (df, ds) = compare::<4, 2>(&ball, &st, 29, &[10_000]);
    assert!(df <= TOL && ds <= TOL, "ball p = 2: {df:e} {ds:e}");
    let (df, ds) = compare::<4, 4>(&example("ball-p4"), &st, 11, &[6_000]);
    assert!(df <= TOL && ds <= TOL, "ball-p4: {df:e} {ds:e}");
    let (df, ds) = compare::<6, 3>(&example("ellipsoid-p3"), &st, 9, &[4_000]);
    assert!(df <= TOL && ds <= TOL, "ellipsoid-p3: {df:e} {ds:e}");
    let (df, ds) = compare::<4, 2>(&example("lens-p2"), &st, 5, &[3_000]);
    assert!(df <= TOL && ds <= TOL, "lens-p2: {df:e} {ds:e}");
    let (df, ds) = compare::<4, 2>(&example("polytope-p2"), &st, 5, &[3_000]);
    assert!(df <= TOL && ds <= TOL, "polytope-p2: {df:e} {ds:e}");
}

#[test]
fn observed_runs_see_every_step_of_every_trajectory() {
    let sys = example("ellipse-p2");
    let st = CatchingUpSettings::default();
    let mut ens = Ensemble::new(&sys, &st).unwrap();
    let mut state = initial(&sys, 6, 0.2);
    let start = state.clone();
    let mut seen = Vec::new();
    ens.run_observed(0.5, &mut state, 700, |k, t, s| seen.push((k, t, s.z_of(5))));
    let mut sim = Simulator::new(&sys, &st).unwrap();
    let (mut x, mut z) = (start.x_of(5), start.z_of(5));
    let mut expect = Vec::new();
    sim.run(0.5, &mut x, &mut z, 700, |k, t, _, z| expect.push((k, t, z.to_vec())));
    assert_eq!(seen.len(), 700);
    for ((k1, t1, z1), (k2, t2, z2)) in seen.iter().zip(&expect) {
        assert_eq!((k1, t1), (k2, t2));
        for (a, b) in z1.iter().zip(z2) {
            assert!((a - b).abs() <= TOL * (1.0 + b.abs()), "step {k1}: {a} vs {b}");
        }
    }
    // observed and unobserved runs are the same computation
    let mut state2 = start.clone();
    ens.run(0.5, &mut state2, 700);
    assert_eq!(state, state2);
}

/// A size without a SIMD kernel (n = 7) runs one single path per trajectory.
#[test]
fn sizes_without_a_kernel_fall_back_to_the_single_path() {
    let mut sys = example("worked-example");
    let n = 7;
    sys.A = DMatrix::from_fn(n, n, |i, j| {
        if i == j {
            -1.0 - 0.1 * i as f64
        } else if j == i + 1 {
            0.5
        } else {
            0.0
        }
    });
    sys.B = DMatrix::from_fn(n, 1, |i, _| 1.0 / (1.0 + i as f64));
    sys.C = DMatrix::from_fn(1, n, |_, j| if j == 0 { 1.0 } else { 0.1 });
    sys.E = DMatrix::from_fn(n, 1, |i, _| if i == 0 { 1.0 } else { 0.0 });
    sys.x0 = DVector::zeros(n);
    sys.z0 = DVector::zeros(1);
    let st = CatchingUpSettings::default();
    let mut ens = Ensemble::new(&sys, &st).unwrap();
    assert!(!ens.is_simd());
    let mut state = initial(&sys, 3, 0.3);
    let start = state.clone();
    ens.run(0.0, &mut state, 2_000);
    let mut sim = Simulator::new(&sys, &st).unwrap();
    let refs: Vec<_> = (0..3)
        .map(|i| {
            let (mut x, mut z) = (start.x_of(i), start.z_of(i));
            sim.run(0.0, &mut x, &mut z, 2_000, |_, _, _, _| {});
            (x, z)
        })
        .collect();
    assert_eq!(max_rel_diff(&state, &refs), 0.0);
    let mut seen = 0;
    let mut obs = start.clone();
    ens.run_observed(0.0, &mut obs, 2_000, |_, _, _| seen += 1);
    assert_eq!(seen, 2_000);
    assert!(max_rel_diff(&obs, &refs) <= TOL);
}

#[test]
fn state_accessors_round_trip() {
    let mut s = EnsembleState::zeros(3, 2, 5);
    assert_eq!((s.len(), s.n(), s.p(), s.stride()), (5, 3, 2, 8));
    s.set(4, &[1.0, 2.0, 3.0], &[4.0, 5.0]);
    assert_eq!(s.x_of(4), vec![1.0, 2.0, 3.0]);
    assert_eq!(s.z_of(4), vec![4.0, 5.0]);
    assert_eq!(s.x_component(1), &[0.0, 0.0, 0.0, 0.0, 2.0]);
    assert!(s.all_finite());
    let r = EnsembleState::replicate(&[1.0, 2.0, 3.0], &[4.0, 5.0], 9);
    assert_eq!(r.stride(), 16);
    assert!((0..9).all(|i| r.x_of(i) == vec![1.0, 2.0, 3.0] && r.z_of(i) == vec![4.0, 5.0]));
}
