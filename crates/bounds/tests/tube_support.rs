//! Lemma 2 tube: the enclosure of sigma_{C Xi_inf} against an independent quadrature, and the
//! inclusion x(t) - xi(t) in Xi(t) (eq. (xX)) along simulated trajectories, each with a
//! negative control.
#![allow(non_snake_case)]
use bounds::tube::{Horizon, TubeKernel, TubeSettings};
use dynamics::integrators::catching_up::CatchingUpSettings;
use dynamics::linear::expm::expm;
use geometry::{ConvexSet, Shape};
use nalgebra::DMatrix;

fn load(name: &str) -> model::System {
    model::load(std::path::Path::new(&format!("{}/../../examples/{name}", env!("CARGO_MANIFEST_DIR")))).unwrap()
}

/// delta int_0^S |C e^{sF} E| ds by composite Simpson with fresh matrix exponentials.
fn reference_p1(sys: &model::System, delta: f64) -> f64 {
    let F = sys.F();
    let (S, N) = (90.0, 180_000usize);
    let h = S / N as f64;
    let step = expm(&(&F * h));
    let mut P = DMatrix::<f64>::identity(2, 2);
    let mut acc = 0.0;
    for k in 0..=N {
        if k > 0 {
            P = &P * &step;
        }
        if k % 1000 == 0 {
            P = expm(&(&F * (k as f64 * h)));
        }
        let v = (&sys.C * &P * &sys.E)[(0, 0)].abs();
        let w = if k == 0 || k == N {
            1.0
        } else if k % 2 == 1 {
            4.0
        } else {
            2.0
        };
        acc += w * v;
    }
    delta * acc * h / 3.0
}

#[test]
fn xinf_support_encloses_an_independent_quadrature() {
    let sys = load("worked-example.toml");
    let k = TubeKernel::new(
        &sys.C,
        &sys.F(),
        &sys.E,
        &sys.theta,
        Horizon::Infinite,
        &TubeSettings { tol_abs: 1e-6, ..Default::default() },
    )
    .unwrap();
    let reference = reference_p1(&sys, 0.1);
    let b = k.support_bounds(&[1.0]);
    assert!(b.lower <= reference + 1e-9 && reference <= b.upper + 1e-9, "{b:?} vs {reference}");
    // width = trapezoid - midpoint difference + 2 remainders + tail: a few times tol_abs
    assert!(b.width() <= 3e-6, "{b:?}");
    // Negative control: the enclosure for a smaller Theta ([-0.09, 0.09]) excludes the reference.
    let small = Shape::Interval(geometry::Interval::symmetric(0.09).unwrap());
    let ks = TubeKernel::new(&sys.C, &sys.F(), &sys.E, &small, Horizon::Infinite, &TubeSettings::default()).unwrap();
    assert!(ks.support_upper(&[1.0]) < reference - 1e-4);
    // Finite horizon is below the infinite one and increases with t (0 in Theta).
    let k5 =
        TubeKernel::new(&sys.C, &sys.F(), &sys.E, &sys.theta, Horizon::Finite(5.0), &TubeSettings::default()).unwrap();
    let k10 =
        TubeKernel::new(&sys.C, &sys.F(), &sys.E, &sys.theta, Horizon::Finite(10.0), &TubeSettings::default()).unwrap();
    assert!(k5.support_upper(&[1.0]) < k10.support_bounds(&[1.0]).lower);
    assert!(k10.support_upper(&[1.0]) < b.lower);
    assert_eq!(k5.tail_bound(), 0.0);
}

/// Simulates x (with the backlash) and xi (Theta = {0}) from the same x0; returns x - xi at t.
fn deviation(sys: &model::System, t: f64, dt: f64) -> Vec<f64> {
    let steps = (t / dt).round() as usize;
    let cu = CatchingUpSettings { dt, ..Default::default() };
    let tr = dynamics::trajectory::simulate_catching_up(sys, &cu, steps, steps).unwrap();
    let mut lin = sys.clone();
    lin.theta = Shape::origin(sys.p());
    lin.z0 = &sys.C * &sys.x0;
    let tl = dynamics::trajectory::simulate_catching_up(&lin, &cu, steps, steps).unwrap();
    let (x, xi) = (tr.x_at(tr.len() - 1), tl.x_at(tl.len() - 1));
    x.iter().zip(xi).map(|(a, b)| a - b).collect()
}

#[test]
fn simulated_states_stay_in_the_tube_and_a_shrunken_tube_is_violated() {
    let sys = load("ellipse-p2.toml");
    let t = 6.0;
    let dev = deviation(&sys, t, 2e-4);
    let n = sys.n();
    let I = DMatrix::<f64>::identity(n, n);
    let k = TubeKernel::new(&I, &sys.F(), &sys.E, &sys.theta, Horizon::Finite(t), &TubeSettings::default()).unwrap();
    // A shrunken Theta (half the ellipse) for the negative control.
    let half = match &sys.theta {
        Shape::Ellipsoid(e) => {
            let M = DMatrix::from_row_slice(2, 2, e.matrix()) * 0.25;
            Shape::Ellipsoid(geometry::Ellipsoid::new(e.centre().to_vec(), &M).unwrap())
        }
        _ => unreachable!(),
    };
    let kh = TubeKernel::new(&I, &sys.F(), &sys.E, &half, Horizon::Finite(t), &TubeSettings::default()).unwrap();
    let mut worst_excess = f64::NEG_INFINITY;
    let mut control_excess = f64::NEG_INFINITY;
    let mut seed = 12345u64;
    for _ in 0..64 {
        let u: Vec<f64> = (0..n)
            .map(|_| {
                seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
            })
            .collect();
        let lhs: f64 = u.iter().zip(&dev).map(|(a, b)| a * b).sum();
        worst_excess = worst_excess.max(lhs - k.support_upper(&u));
        control_excess = control_excess.max(lhs - kh.support_upper(&u));
    }
    // Catching-up error at dt = 2e-4 is far below 1e-3.
    assert!(worst_excess <= 1e-3, "x - xi leaves the tube by {worst_excess}");
    assert!(control_excess > 1e-2, "negative control: the halved tube should be violated ({control_excess})");
    assert!(sys.theta.contains(&[0.0, 0.0], 0.0));
}
