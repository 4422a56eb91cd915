//! Digital controllers in the loop (issue 28 item 2): the physical model of a carriage under a
//! sampled cascade (`[controller]`), refitted by `diagnose` on one kind of experiment,
//! predicts another kind.
//!
//! Fast tests use development seed 1. The measurement over fresh seeds is
//! `digital_controller_benchmark` (ignored): `cargo test -p discovery --release --test
//! digital_controller -- --ignored --nocapture`, seeds from `CASCADE_SEEDS` (default `1`),
//! plants per seed from `CASCADE_PLANTS` (default 4).
use discovery::bench_gen::servo_cascade::{self as sc, CascadeTruth, Experiment};
use discovery::{diagnose, DiagnoseSettings, InitialState, Recording};
use dynamics::extended::ExtendedModel;
use model::System;

/// The nominal's departure from the truth: mass +25 %, viscous x 1.6, Coulomb x 0.6.
fn nominal(tr: &CascadeTruth, kv: f64) -> System {
    model::parse_str(&sc::model_text(tr, 1.25 * tr.mass, 1.6 * tr.viscous, 0.6 * tr.coulomb, kv, sc::DELAY)).unwrap()
}

fn settings(max_effects: usize, substeps: Option<usize>) -> DiagnoseSettings {
    let mut s = DiagnoseSettings {
        initial_state: Some(InitialState { x0: vec![0.0, 0.0], z0: Some(vec![0.0]) }),
        max_effects,
        ..Default::default()
    };
    if let Some(k) = substeps {
        s.max_substeps = k;
        s.substep_ratio = 1e9; // start at the cap
    }
    s
}

/// RMSE of `sys` simulated (from rest) on the whole of `rec`.
fn rmse_on(sys: &System, rec: &Recording, substeps: usize) -> f64 {
    let w: Vec<f64> = rec.w.iter().map(|r| r[0]).collect();
    let y: Vec<f64> = rec.y.iter().map(|r| r[0]).collect();
    let o = ExtendedModel::new(sys, &[], rec.dt, substeps).unwrap().simulate(&w, rec.dt, &[0.0, 0.0]);
    (o.y.iter().zip(&y).map(|(a, b)| (a - b).powi(2)).sum::<f64>() / y.len() as f64).sqrt()
}

/// The fitted `M`, `Fv`, `Fc` and their 1-sigma.
fn physical(r: &discovery::Report) -> [(f64, f64); 3] {
    let get = |name: &str| {
        let v = r.nominal_refit.iter().find(|v| v.name == name);
        v.map_or((f64::NAN, f64::NAN), |v| (v.value, v.std))
    };
    [get("M"), get("Fv"), get("Fc")]
}

#[test]
fn the_refitted_cascade_model_predicts_the_other_experiment() {
    let (seed, idx) = (1, 0);
    let tr = sc::truth(seed, idx);
    let multi = sc::record(seed, idx, Experiment::Multisine);
    let tri = sc::record(seed, idx, Experiment::Triangle);
    let r = diagnose(&nominal(&tr, tr.kv), &multi, &settings(0, None)).unwrap();
    let p = physical(&r);
    eprintln!("{}\nsubsteps {}\n{:?}\ntruth {tr:?}", r.verdict, r.substeps, p);
    let fitted = r.fitted_model.as_ref().unwrap();
    let pred = rmse_on(fitted, &tri, r.substeps);
    let direct = diagnose(&nominal(&tr, tr.kv), &tri, &settings(0, None)).unwrap();
    let own = rmse_on(direct.fitted_model.as_ref().unwrap(), &tri, direct.substeps);
    eprintln!("prediction RMSE on the triangle {pred:e}, direct fit {own:e}, ratio {:.3}", pred / own);
    for ((v, _), truth) in p.iter().zip([tr.mass, tr.viscous, tr.coulomb]) {
        assert!((v / truth - 1.0).abs() < 0.05, "{v} against {truth}");
    }
    assert!(pred <= 1.2 * own, "{pred:e} against {own:e}");
}
