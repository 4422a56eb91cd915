//! Long records (estimation segment >= `fit::LONG_RECORD` samples): the multi-start phase runs
//! on a leading third, the final iterations on the whole segment. The estimate must be the one
//! the whole-segment start phase finds (control: `long_record = usize::MAX`), and the truth.
mod common;
use discovery::fit::{self, FitSettings, LONG_RECORD};
use discovery::hypothesis::{self, Kind};
use dynamics::extended::ExtendedModel;
use model::effects::Effect;

fn mass() -> model::System {
    let text = "name = \"mass\"\n[plant]\nA = [[0.0, 1.0], [-4.0, -1.2]]\nB = [[0.0], [1.0]]\nC = [[1.0, 0.0]]\nE = [[0.0], [0.0]]\n[input]\nkind = \"sine\"\namplitudes = [1.0]\nomega = 1.0\n[initial]\nx0 = [0.0, 0.0]\nz0 = [0.0]\n";
    model::parse_str(text).unwrap()
}

#[test]
fn long_record_start_phase_finds_the_whole_segment_estimate() {
    let sys = mass();
    let (dt, level) = (0.02, 0.25);
    let n = LONG_RECORD * 3 / 2;
    let w: Vec<f64> = (0..n)
        .map(|k| {
            let t = k as f64 * dt;
            (0.9 * t).sin() + 0.5 * (2.3 * t + 1.0).sin() + 0.3 * (0.21 * t).sin()
        })
        .collect();
    let truth = [Effect::CoulombFriction { state: 1, level }];
    let y0 = ExtendedModel::new(&sys, &truth, dt, 2).unwrap().simulate(&w, dt, &[0.0, 0.0]).y;
    let yr = y0.iter().copied().fold(f64::NEG_INFINITY, f64::max) - y0.iter().copied().fold(f64::INFINITY, f64::min);
    let y: Vec<f64> =
        y0.iter().enumerate().map(|(k, v)| v + 0.01 * yr * (((k * 7919) % 1000) as f64 / 1000.0 - 0.5)).collect();
    let k_est = 7 * n / 10;
    assert!(k_est >= LONG_RECORD, "the case must take the long-record path");
    let scales = common::test_scales(yr, n, dt);
    let h = hypothesis::candidates(&sys, &scales)
        .into_iter()
        .find(|h| h.kind == Kind::CoulombFriction { state: 1 })
        .expect("Coulomb friction on the velocity state is a candidate");
    assert!(h.starts.len() > 1, "several starts: the start phase is used");
    let pb = common::scalar_problem(&sys, &h, &scales, &w, &y, k_est, 1.0 / yr, 2);
    let short = fit::fit(&pb, &[0.0, 0.0], &[], None, &FitSettings::default());
    let whole = fit::fit(&pb, &[0.0, 0.0], &[], None, &FitSettings { long_record: usize::MAX, ..Default::default() });
    let (a, b) = (short.theta[0], whole.theta[0]);
    eprintln!("level: short start phase {a} +- {}, whole {b} +- {}; truth {level}", short.std[0], whole.std[0]);
    // the residual and covariance are of the whole segment in both
    assert_eq!(short.n_res, whole.n_res);
    assert!((a - b).abs() <= 1e-3 * level, "estimates differ: {a} vs {b}");
    assert!((a - level).abs() <= 0.02 * level, "estimate {a} vs truth {level}");
    assert!(short.evaluations > 0 && whole.evaluations > 0);
}
