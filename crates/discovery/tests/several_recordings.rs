//! Several recordings of one machine (issue 28 item 3): one model fitted jointly, selected by
//! leave-one-recording-out validation (`discovery::diagnose::diagnose_recordings`).
//!
//! The machine: a position loop `x1' = x2, x2' = -c x2 + g k (w - x1)` with the loop gain's
//! factor `g` a named parameter freed by `[fit] free` (nominal 1). Two recordings of different
//! kinds (a multisine reference from rest, a smoothed square wave from an offset start), 10 s
//! at 100 Hz with white measurement noise.
use discovery::diagnose::{diagnose_recordings, JointReport};
use discovery::{DiagnoseSettings, DiscoveryError, Recording};
use dynamics::extended::ExtendedModel;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

const DT: f64 = 0.01;
const N: usize = 1000;

fn machine(g: f64) -> model::System {
    let text = format!(
        r#"name = "position loop"
[parameters]
g = {g}
k = 25.0
c = 4.0
[plant]
A = [[0, 1], [0, "-c"]]
B = [0, "g*k"]
C = [[1, 0]]
E = [0, "-g*k"]
[theta]
shape = "point"
[input]
kind = "zero"
[simulation]
dt = 0.01
t_end = 10.0
[fit]
free = ["g"]
[fit.bounds]
g = [0.2, 5.0]
[signals]
y = "m"
"#
    );
    model::model_file::parse_str(&text).unwrap()
}

/// The reference of each kind of experiment.
fn reference(kind: &str) -> Vec<f64> {
    reference_at(kind, DT, N)
}

/// The reference sampled every `dt` for `n` samples.
fn reference_at(kind: &str, dt: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| {
            let t = k as f64 * dt;
            match kind {
                "multisine" => 0.5 * (0.7 * t).sin() + 0.3 * (2.3 * t + 1.0).sin() + 0.2 * (5.1 * t).sin(),
                // a square wave of period 4 s, its edges smoothed over 0.2 s
                _ => 0.6 * ((2.0 * std::f64::consts::PI * t / 4.0).sin() * 8.0).tanh(),
            }
        })
        .collect()
}

/// A recording of the machine with loop-gain factor `g` (kind, initial state, noise seed).
fn record(g: f64, kind: &str, x0: [f64; 2], seed: u64) -> Recording {
    record_at(g, kind, x0, seed, DT, N)
}

/// As [`record`], sampled every `dt` for `n` samples.
fn record_at(g: f64, kind: &str, x0: [f64; 2], seed: u64, dt: f64, n: usize) -> Recording {
    let sys = machine(g);
    let w = reference_at(kind, dt, n);
    let sim = ExtendedModel::new(&sys, &[], dt, 20).unwrap().simulate(&w, dt, &x0);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let y: Vec<Vec<f64>> = sim.y.iter().map(|v| vec![v + 2e-3 * gauss(&mut rng)]).collect();
    let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
    Recording::from_samples(&format!("{kind}-g{g}-dt{dt}.csv"), &t, w.into_iter().map(|v| vec![v]).collect(), y, None)
}

/// A standard normal sample (Box-Muller).
fn gauss(rng: &mut ChaCha8Rng) -> f64 {
    use rand::Rng;
    let (u, v): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random::<f64>());
    (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
}

fn settings() -> DiagnoseSettings {
    DiagnoseSettings { max_effects: 1, ..Default::default() }
}

fn print(r: &JointReport) {
    eprintln!("{}", r.to_markdown());
}

#[test]
fn joint_fit_recovers_the_loop_gain_from_two_kinds_of_experiment() {
    let recs = [record(1.25, "multisine", [0.0, 0.0], 1), record(1.25, "square", [0.3, 0.0], 2)];
    let r = diagnose_recordings(&machine(1.0), &recs, &[], &settings()).unwrap();
    print(&r);
    assert!(r.selected.contains("nominal_refit"), "{}", r.verdict);
    let g = r.nominal_refit.iter().find(|v| v.name == "g").expect("g refitted");
    assert!((g.value / 1.25 - 1.0).abs() < 0.02, "g = {} +- {} against 1.25", g.value, g.std);
    assert!(g.std.is_finite() && g.std > 0.0);
    // Every recording is predicted better than by the nominal, left out too.
    for row in &r.recordings {
        assert!(row.rmse_joint[0] < 0.5 * row.rmse_nominal[0], "{row:?}");
        let left = row.rmse_left_out.as_ref().expect("two recordings: left-out RMSE");
        assert!(left[0] < 0.5 * row.rmse_nominal[0], "{row:?}");
        assert!(!row.worse_than_nominal);
    }
    // fitted.toml carries the joint value of g and reads back.
    let fitted = r.fitted_model.as_ref().unwrap();
    assert_eq!(fitted.fit.result.len(), 1);
    assert_eq!(fitted.fit.result[0].value, g.value);
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join(discovery::diagnose::FITTED_INPUT_FILE), fitted.input.samples_csv().unwrap())
        .unwrap();
    std::fs::write(dir.path().join("fitted.toml"), model::to_toml_string(fitted)).unwrap();
    model::load(&dir.path().join("fitted.toml")).unwrap();
}

#[test]
fn a_refit_that_helps_its_recording_and_hurts_the_other_is_refused() {
    // The first recording's machine runs with a loop gain 25 % above the second's (as after a
    // change between the experiments): its own refit improves it and worsens the second
    // recording, so it is reported and not adopted, and the nominal stands.
    let recs = [record(1.25, "multisine", [0.0, 0.0], 3), record(1.0, "square", [0.3, 0.0], 4)];
    let r = diagnose_recordings(&machine(1.0), &recs, &[], &settings()).unwrap();
    print(&r);
    let own = r.own_fits.iter().find(|o| o.recording == recs[0].source).expect("the first recording selects a refit");
    assert!(own.improves_own, "{own:?}");
    assert_eq!(own.worsens, vec![recs[1].source.clone()], "{own:?}");
    assert!(own.note.contains("not adopted"), "{}", own.note);
    assert!(r.candidates.iter().all(|c| !c.accepted), "{:?}", r.candidates);
    assert_eq!(r.selected, "nominal", "{}", r.verdict);
    assert!(r.recordings.iter().all(|row| !row.worse_than_nominal));
    assert!(r.nominal_refit.is_empty());
}

#[test]
fn validate_on_recording_refuses_a_model_that_worsens_it() {
    // One recording fitted on (its refit g = 1.25), one validated on from the nominal machine.
    let fit = [record(1.25, "multisine", [0.0, 0.0], 5)];
    let val = [record(1.0, "square", [0.0, 0.0], 6)];
    let r = diagnose_recordings(&machine(1.0), &fit, &val, &settings()).unwrap();
    print(&r);
    assert_eq!(r.recordings[1].role, "validation");
    assert_eq!(r.selected, "nominal", "{}", r.verdict);
    assert!(r.notes.iter().any(|n| n.contains("not adopted")), "{:?}", r.notes);
    // Negative control: a validation recording of the same machine adopts the refit.
    let val_same = [record(1.25, "square", [0.0, 0.0], 6)];
    let r = diagnose_recordings(&machine(1.0), &fit, &val_same, &settings()).unwrap();
    assert!(r.selected.contains("nominal_refit"), "{}", r.verdict);
    assert!(r.recordings[1].rmse_joint[0] < 0.5 * r.recordings[1].rmse_nominal[0]);
}

#[test]
fn recordings_with_different_signals_are_refused_by_name() {
    let a = record(1.0, "multisine", [0.0, 0.0], 7);
    let t: Vec<f64> = (0..N).map(|k| k as f64 * DT).collect();
    let w: Vec<Vec<f64>> = reference("square").into_iter().map(|v| vec![v, 0.5 * v]).collect();
    let y: Vec<Vec<f64>> = a.y.clone();
    let b = Recording::from_samples("two-inputs.csv", &t, w, y, None);
    let e = diagnose_recordings(&machine(1.0), &[a.clone(), b], &[], &settings()).unwrap_err();
    assert!(matches!(e, DiscoveryError::RecordingsDiffer { .. }), "{e}");
    let msg = e.to_string();
    assert!(msg.contains("two-inputs.csv") && msg.contains("inputs") && !msg.contains('\n'), "{msg}");
    let e = diagnose_recordings(&machine(1.0), &[], &[a], &settings()).unwrap_err();
    assert!(matches!(e, DiscoveryError::NoRecording), "{e}");
}

#[test]
fn recordings_at_different_sample_rates_and_lengths_fit_one_machine() {
    // 100 Hz for 10 s and 40 Hz for 15 s, the second also validated on a 50 Hz recording.
    let recs = [record(1.25, "multisine", [0.0, 0.0], 8), record_at(1.25, "square", [0.2, 0.0], 9, 0.025, 600)];
    let val = [record_at(1.25, "multisine", [0.0, 0.1], 10, 0.02, 500)];
    let r = diagnose_recordings(&machine(1.0), &recs, &val, &settings()).unwrap();
    print(&r);
    let g = r.nominal_refit.iter().find(|v| v.name == "g").expect("g refitted");
    assert!((g.value / 1.25 - 1.0).abs() < 0.02, "g = {} against 1.25", g.value);
    assert_eq!(r.recordings.iter().map(|x| x.samples).collect::<Vec<_>>(), vec![1000, 600, 500]);
    for row in &r.recordings {
        assert!(row.rmse_joint[0] < 0.5 * row.rmse_nominal[0], "{row:?}");
    }
}
