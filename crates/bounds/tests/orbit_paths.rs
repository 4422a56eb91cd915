//! eta_T closed form against the dynamics crate's samples, and the path-length bounds
//! (path), (path1), (path2) on curves with known answers.
#![allow(non_snake_case)]
use bounds::orbit::{packing_bound, partition_bound, path_bound, EtaOrbit, OrbitSettings};
use dynamics::periodic::linearised::{linearised_periodic, LinearisedSettings};

fn load(name: &str) -> model::System {
    model::load(std::path::Path::new(&format!("{}/../../examples/{name}", env!("CARGO_MANIFEST_DIR")))).unwrap()
}

#[test]
fn closed_form_orbit_agrees_with_dynamics_and_bounds_sampled_values() {
    for file in ["worked-example.toml", "ellipse-p2.toml"] {
        let sys = load(file);
        let o = EtaOrbit::new(&sys, &OrbitSettings { samples: 400 }).unwrap();
        let lp = linearised_periodic(&sys, &LinearisedSettings { samples: 400, ..Default::default() }).unwrap();
        for (a, b) in o.eta.iter().zip(&lp.eta) {
            assert!(geometry::linalg::dist(a, b) < 1e-9, "{file}: {a:?} vs {b:?}");
        }
        assert!(o.verified);
        // osc is the supremum over the whole orbit: no sample pair exceeds it.
        assert!(o.osc_sampled() <= o.osc * (1.0 + 1e-9), "{file}");
        assert!(o.osc >= o.osc_sampled() * (1.0 - 1e-4), "{file}");
        assert!(o.eta_dot_inf >= o.eta_dot_sampled(), "{file}: ||eta'|| upper bound below a sample");
        // Sine: osc / (T ||eta'||) = 1/pi exactly.
        assert!((o.osc / (o.period * o.eta_dot_inf) - 1.0 / std::f64::consts::PI).abs() < 1e-9);
    }
}

#[test]
fn path_bounds_on_a_circle() {
    // Unit circle sampled at 720 points (closed): (path1) with d = 0 is the inscribed polygon's
    // perimeter, (path) the diameter; with d = 2.5 > osc every bound vanishes.
    let K = 720;
    let pts: Vec<Vec<f64>> = (0..=K)
        .map(|k| {
            let a = std::f64::consts::TAU * k as f64 / K as f64;
            vec![a.cos(), a.sin()]
        })
        .collect();
    let refs: Vec<&[f64]> = pts.iter().map(|p| p.as_slice()).collect();
    let p1 = partition_bound(&refs, 0.0);
    assert!((p1 - std::f64::consts::TAU).abs() < 1e-4, "{p1}");
    assert_eq!(path_bound(2.0, 0.5), 1.5);
    let d = 0.5;
    let p1d = partition_bound(&refs, d);
    assert!(p1d >= path_bound(2.0, d) && p1d < std::f64::consts::TAU);
    let pk = packing_bound(&refs[..K], d, 2.0, 64);
    // (path2) is a special case of the cyclic (path1): never above the perimeter minus N d.
    assert!(pk.value > 0.0 && pk.value <= std::f64::consts::TAU - pk.count as f64 * d + 1e-9, "{pk:?}");
    assert_eq!(partition_bound(&refs, 2.5), 0.0);
    assert_eq!(packing_bound(&refs, 2.5, 2.0, 16).value, 0.0);
    // Negative control: a "packing" bound computed with too small a d exceeds the true one.
    assert!(packing_bound(&refs[..K], 0.0, 2.0, 64).value > pk.value);
}

#[test]
fn local_partition_bound_on_a_circle() {
    // Unit circle traversed once in T = 2 pi (speed 1). The loss min(d, w + dt D): with D = inf
    // it is (path1) with d; with a small D short steps lose about w, so the bound rises towards
    // the perimeter minus what the steps lose; never above the perimeter.
    let K = 720;
    let t: Vec<f64> = (0..=K).map(|k| std::f64::consts::TAU * k as f64 / K as f64).collect();
    let pts: Vec<Vec<f64>> = t.iter().map(|a| vec![a.cos(), a.sin()]).collect();
    let refs: Vec<&[f64]> = pts.iter().map(|p| p.as_slice()).collect();
    let (d, w) = (0.5, 0.1);
    let p1 = partition_bound(&refs, d);
    assert_eq!(bounds::orbit::partition_bound_local(&refs, &t, d, w, f64::INFINITY), p1);
    let local = bounds::orbit::partition_bound_local(&refs, &t, d, w, 0.05);
    assert!(local > p1 && local < std::f64::consts::TAU, "{local} vs (path1) {p1}");
    // each of N steps loses at least w: the bound is at most the perimeter minus w per step,
    // and at least it for the best N (here the chord sum of N equal steps minus N (w + D T/N))
    let best_equal = (1..=60)
        .map(|n| {
            let step = std::f64::consts::TAU / n as f64;
            n as f64 * (2.0 * (step / 2.0).sin() - (w + step * 0.05).min(d)).max(0.0)
        })
        .fold(0.0f64, f64::max);
    assert!(local >= best_equal * (1.0 - 1e-3), "{local} < {best_equal}");
    // negative control: the loss w alone (the tube frozen over a step) claims more than the
    // bound with the tube's motion, so the motion term is not inert
    assert!(bounds::orbit::partition_bound_local(&refs, &t, d, w, 0.0) > local);
    // mismatched times: no bound claimed
    assert_eq!(bounds::orbit::partition_bound_local(&refs, &t[..10], d, w, 0.05), 0.0);
}
