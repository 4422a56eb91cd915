//! `eta_T` in closed form for square waves and periodic CSV inputs (bounds::orbit::piecewise,
//! issue 29 item 2): the closed form against an independent fine-grid solution of the
//! linearised system, `osc` from below and `||eta_T'||_inf` from above against a much finer
//! sampling, the jumps of `eta_T'` at the input's edges (negative control: without them the
//! bound misses the supremum), and the whole theta certificate for a square wave.
use bounds::orbit::{EtaOrbit, OrbitSettings};
use dynamics::periodic::linearised::{linearised_periodic, LinearisedSettings};
use model::Input;

fn worked(input: &str) -> model::System {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/worked-example.toml")).unwrap();
    let text = text.replace("kind = \"sine\"", input);
    model::parse_str(&text).unwrap()
}

fn sup_norm(v: &[Vec<f64>]) -> f64 {
    v.iter().map(|x| x.iter().map(|y| y * y).sum::<f64>().sqrt()).fold(0.0, f64::max)
}

#[test]
fn square_wave_orbit_is_verified_and_encloses_a_fine_grid_solution() {
    for phase in [0.0, 0.7, 2.0] {
        let mut sys = worked("kind = \"square\"");
        if let Input::Square { phase: p, .. } = &mut sys.input {
            *p = phase;
        }
        let o = EtaOrbit::new(&sys, &OrbitSettings::default()).unwrap();
        assert!(o.verified, "{}", o.method);
        // C B = 0 here: eta_T' is continuous across the input's two edges
        assert_eq!(o.jumps.len(), 2);
        assert!(o.jumps.iter().all(|j| (j.before[0] - j.after[0]).abs() < 1e-9), "{:?}", o.jumps);
        // an independent solution: the first-order-hold grid map, 64 sub-steps per sample
        let lp = linearised_periodic(&sys, &LinearisedSettings { samples: 2000, substeps: 64 }).unwrap();
        let err = o.eta.iter().zip(&lp.eta).map(|(a, b)| (a[0] - b[0]).abs()).fold(0.0, f64::max);
        assert!(err < 1e-4, "phase {phase}: closed form vs grid differ by {err:e}");
        // finer sampling of the same closed form: osc below, sup |eta'| above
        let fine = EtaOrbit::new(&sys, &OrbitSettings { samples: 40_000 }).unwrap();
        assert!(o.osc <= fine.osc_sampled() * (1.0 + 1e-9), "{} > {}", o.osc, fine.osc_sampled());
        assert!(o.eta_dot_inf >= fine.eta_dot_sampled(), "{} < {}", o.eta_dot_inf, fine.eta_dot_sampled());
        assert!(
            o.eta_dot_inf <= 1.01 * fine.eta_dot_sampled(),
            "tight: {} vs {}",
            o.eta_dot_inf,
            fine.eta_dot_sampled()
        );
    }
}

#[test]
fn a_jump_of_eta_dot_is_taken_in_and_leaving_it_out_misses_the_supremum() {
    // x' = -x + w + 0 z, y = x: eta_T' = -eta_T + w jumps by 2 a at each edge of the square wave,
    // and its largest value is right after an edge, between two samples
    let text = "[plant]\nA = [[-1.0]]\nB = [[1.0]]\nC = [[1.0]]\nE = [[0.0]]\n[theta]\nshape = \"interval\"\nhalf_width = 0.1\n\
                [input]\nkind = \"square\"\namplitudes = [1.0]\nomega = 1.0\nphase = 0.3\n";
    let sys = model::parse_str(text).unwrap();
    let mut o = EtaOrbit::new(&sys, &OrbitSettings { samples: 200 }).unwrap();
    assert!(o.verified && o.jumps.len() == 2, "{} jumps", o.jumps.len());
    // the exact supremum: at the edge, eta_T = +-tanh(pi/2)-type value; from the jumps' values
    let exact = o.jumps.iter().flat_map(|j| [j.before[0].abs(), j.after[0].abs()]).fold(0.0, f64::max);
    assert!(o.eta_dot_inf >= exact, "{} < {exact}", o.eta_dot_inf);
    // negative control: the same samples without the jumps give a bound below the supremum
    o.jumps.clear();
    let without = o.eta_dot_cells(1).unwrap().0[0];
    assert!(without < exact, "without the jumps the cell bound {without} should miss {exact}");
}

#[test]
fn a_periodic_csv_input_is_verified_and_close_to_the_sine_it_samples() {
    let dir = tempfile::tempdir().unwrap();
    let sys = worked_csv(dir.path(), 256, "foh");
    let o = EtaOrbit::new(&sys, &OrbitSettings::default()).unwrap();
    assert!(o.verified, "{}", o.method);
    let sine = EtaOrbit::new(&worked("kind = \"sine\""), &OrbitSettings::default()).unwrap();
    assert!((o.osc / sine.osc - 1.0).abs() < 2e-3, "{} vs {}", o.osc, sine.osc);
    assert!((o.eta_dot_inf / sine.eta_dot_inf - 1.0).abs() < 5e-3, "{} vs {}", o.eta_dot_inf, sine.eta_dot_inf);
    assert!(sup_norm(&o.deta) <= o.eta_dot_inf);
}

#[test]
fn the_worked_example_under_a_square_wave_is_certified() {
    let sys = worked("kind = \"square\"");
    let r = bounds::assemble(&sys, &bounds::ThetaSettings::bound_only()).unwrap();
    assert!(r.theta_verified && r.theta < 0.0, "theta {} verified {}", r.theta, r.theta_verified);
    // negative control: a wider gap than the square wave certifies is not certified
    let mut wide = sys.clone();
    wide.theta = geometry::Shape::Interval(geometry::Interval::symmetric(3.0).unwrap());
    wide.z0 = &wide.C * &wide.x0;
    let r = bounds::assemble(&wide, &bounds::ThetaSettings::bound_only()).unwrap();
    assert!(!(r.theta_verified && r.theta < 0.0), "theta {} with a gap of 6", r.theta);
}

/// The worked example with a periodic CSV input sampling `sin` at `n` points, `hold` as given.
fn worked_csv(dir: &std::path::Path, n: usize, hold: &str) -> model::System {
    let period = std::f64::consts::TAU;
    let mut csv = String::from("t,w\n");
    for k in 0..n {
        let t = k as f64 * period / n as f64;
        csv += &format!("{t},{}\n", t.sin());
    }
    std::fs::write(dir.join("w.csv"), csv).unwrap();
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/worked-example.toml")).unwrap();
    let start = text.find("[input]").unwrap();
    let end = start + text[start..].find("\n[").unwrap_or(text.len() - start);
    let input = format!("[input]\nkind = \"csv\"\nfile = \"w.csv\"\nperiod = {period}\nhold = \"{hold}\"\n");
    std::fs::write(dir.join("m.toml"), format!("{}{input}{}", &text[..start], &text[end..])).unwrap();
    model::load(&dir.join("m.toml")).unwrap()
}

#[test]
fn a_zero_order_held_csv_input_is_verified_and_encloses_a_fine_grid_solution() {
    let dir = tempfile::tempdir().unwrap();
    let sys = worked_csv(dir.path(), 32, "zoh");
    let Input::Samples { hold, .. } = &sys.input else { panic!() };
    assert_eq!(*hold, model::input::InputHold::Zoh);
    let o = EtaOrbit::new(&sys, &OrbitSettings::default()).unwrap();
    assert!(o.verified, "{}", o.method);
    // one edge per sample (the input jumps at each), C B = 0: eta_T' continuous across them
    assert_eq!(o.jumps.len(), 32);
    // an independent solution: the first-order-hold grid map, 64 sub-steps per sample
    let lp = linearised_periodic(&sys, &LinearisedSettings { samples: 2000, substeps: 64 }).unwrap();
    let err = o.eta.iter().zip(&lp.eta).map(|(a, b)| (a[0] - b[0]).abs()).fold(0.0, f64::max);
    assert!(err < 1e-4, "closed form vs grid differ by {err:e}");
    let fine = EtaOrbit::new(&sys, &OrbitSettings { samples: 16_000 }).unwrap();
    assert!(o.osc <= fine.osc_sampled() * (1.0 + 1e-9), "{} > {}", o.osc, fine.osc_sampled());
    assert!(o.eta_dot_inf >= fine.eta_dot_sampled(), "{} < {}", o.eta_dot_inf, fine.eta_dot_sampled());
    // negative control: the same samples read with the default linear interpolation give
    // another orbit (the held input lags by half a sample)
    let foh = EtaOrbit::new(&worked_csv(dir.path(), 32, "foh"), &OrbitSettings::default()).unwrap();
    let apart = o.eta.iter().zip(&foh.eta).map(|(a, b)| (a[0] - b[0]).abs()).fold(0.0, f64::max);
    assert!(apart > 100.0 * err.max(1e-6), "zoh and foh orbits differ by only {apart:e}");
    // and the whole certificate
    let r = bounds::assemble(&sys, &bounds::ThetaSettings::bound_only()).unwrap();
    assert!(r.theta_verified && r.theta < 0.0, "theta {} verified {}", r.theta, r.theta_verified);
}
