//! Development aid: one benchmark case, its ranking, and a profile of the estimation cost
//! along the true effect's main parameter (initial state refitted at each point).
//! Usage: `[HOLD=zoh|foh] [SUB=N] cargo run --release -p discovery --example probe backlash_inertia 1 3 [classic|digital|mixed] [profile]`
//! (`CLASS` may be a pair `a+b` of the pair benchmark).
use discovery::bench_gen::{self, Case};
use discovery::fit::{self, FitSettings, Problem};
use discovery::hypothesis::Scales;
use discovery::Report;
use dynamics::extended::{InputHold, StepMaps};
use model::effects::Effect;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    if a.len() < 4 {
        eprintln!(
            "usage: cargo run --release -p discovery --example probe CLASS SEED INDEX [classic|digital|mixed] [profile]"
        );
        std::process::exit(2);
    }
    let class: &'static str = Box::leak(a[1].clone().into_boxed_str());
    let seed: u64 = a[2].parse().unwrap();
    let idx: usize = a[3].parse().unwrap();
    let profile = a.get(4).and_then(|s| bench_gen::Profile::parse(s)).unwrap_or(bench_gen::Profile::Classic);
    // `a+b`: a case of the pair benchmark (`bench_gen::generate_pair`)
    let case = match class.split_once('+') {
        Some((a, b)) => bench_gen::generate_pair([a, b], seed, idx, profile).expect("a pair that can co-occur"),
        None => bench_gen::generate_profile(class, seed, idx, profile),
    };
    println!("{} truth {:?}", case.description, case.truths);
    let hold = requested_hold();
    let s = discovery::DiagnoseSettings {
        input_hold: hold.map_or(discovery::HoldChoice::Auto, discovery::HoldChoice::Fixed),
        ..Default::default()
    };
    let rep =
        discovery::diagnose(&case.nominal, &case.recording, &discovery::bench::with_case_start(&case, &s)).unwrap();
    print_report(&rep);
    if a.len() > 5 {
        print_profile(&case, hold.unwrap_or(InputHold::Foh));
    }
}

/// `HOLD=zoh|foh`: the hold given instead of chosen from the data.
fn requested_hold() -> Option<InputHold> {
    match std::env::var("HOLD").as_deref() {
        Ok("zoh") => Some(InputHold::Zoh),
        Ok("foh") => Some(InputHold::Foh),
        _ => None,
    }
}

/// The selection, hold, stepping, residual, notes, effects and the ranking's first 40 rows.
fn print_report(rep: &Report) {
    println!("selected {} ties {:?}; verdict {}", rep.selected(), rep.ties, rep.verdict);
    println!(
        "hold {:?}; substeps {} ladder {:?} err {:.3e} tol {:.3e}; final {:?}; dBIC_disc {:.1}; noise {:?}; x0 {:?}",
        rep.hold,
        rep.substeps,
        rep.discretisation.ladder,
        rep.discretisation.error_rms,
        rep.discretisation.tolerance,
        rep.discretisation_final.as_ref().map(|d| (d.substeps, d.error_rms, d.ladder.clone())),
        rep.delta_bic_discretisation,
        rep.noise_level,
        rep.initial_state
    );
    println!(
        "residual nominal white {} unc {} zm {} Q {:.1}",
        rep.residual_nominal.white,
        rep.residual_nominal.uncorrelated,
        rep.residual_nominal.zero_mean,
        rep.residual_nominal.q_auto
    );
    for n in &rep.notes {
        println!("  note: {n}");
    }
    for e in &rep.effects {
        println!("  {} {:?} +- {:?}", e.label, e.params, e.uncertainty);
    }
    for r in rep.ranking.iter().take(40) {
        println!(
            "  {:40} {:?} std {:?} dBIC {:.1} vr {:.3} {:?} {} cv {:?}",
            r.label,
            r.params,
            r.std,
            r.delta_bic,
            r.validation_ratio,
            r.status,
            r.evidence,
            r.cv.as_ref().map(|c| (c.ratio, c.max_fold_share, c.status))
        );
    }
}

/// The true effect scaled by `f` along its main parameter (`None` where that makes no valid
/// effect, or the class has no profile).
fn scaled(truth: &Effect, f: f64) -> Option<Effect> {
    Some(match truth {
        Effect::BacklashInertia { mass, damping } => Effect::BacklashInertia { mass: mass * f, damping: *damping },
        Effect::GapWidth { relative_change } => Effect::GapWidth { relative_change: relative_change * f },
        // the static excess over the sliding level scaled (f = 0.5: Coulomb friction; below,
        // the breakaway would fall under the sliding level)
        Effect::StribeckFriction { state, level, static_level, stribeck_velocity, viscous } if f >= 0.5 => {
            Effect::StribeckFriction {
                state: *state,
                level: *level,
                static_level: level + (static_level - level) * (f - 0.5) * 2.0,
                stribeck_velocity: *stribeck_velocity,
                viscous: *viscous,
            }
        }
        Effect::CoulombFriction { state, level } => Effect::CoulombFriction { state: *state, level: level * f },
        // the asymmetry scaled about the mean level (f = 0: Coulomb friction)
        Effect::AsymmetricCoulomb { state, level_positive, level_negative } => {
            let mean = 0.5 * (level_positive + level_negative);
            Effect::AsymmetricCoulomb {
                state: *state,
                level_positive: mean + (level_positive - mean) * f,
                level_negative: mean + (level_negative - mean) * f,
            }
        }
        _ => return None,
    })
}

/// The estimation SSE with the true effect scaled by each factor of a grid (`SUB=N` sub-steps,
/// else enough for the plant's fastest mode, at most 8), the initial state refitted.
fn print_profile(case: &Case, hold: InputHold) {
    let sys = &case.nominal;
    let rec = &case.recording;
    let n = rec.len();
    let w: Vec<f64> = rec.w.iter().flatten().copied().collect();
    let y: Vec<f64> = rec.y.iter().flatten().copied().collect();
    let k_est = (n as f64 * 0.7).round() as usize;
    let mean = y.iter().sum::<f64>() / n as f64;
    let sd = (y.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n as f64).sqrt();
    let fast = sys.eig_F().iter().map(|c| c.norm()).fold(0.0, f64::max);
    let sub = std::env::var("SUB")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(((rec.dt * fast * 10.0).ceil() as usize).clamp(1, 8));
    println!("substeps {sub}");
    let maps = StepMaps::new(&sys.F(), &sys.B, &sys.E, rec.dt / sub as f64);
    let sc = Scales {
        y_range: vec![1.0],
        w_range: vec![1.0],
        w_absmax: 1.0,
        tau_slow: 1.0,
        dt: rec.dt,
        duration: rec.duration(),
        ..Default::default()
    };
    let truth = case.truth.clone().unwrap();
    if scaled(&truth, 1.0).is_none() {
        eprintln!("no profile for {truth:?}");
        return;
    }
    let x0: Vec<f64> = sys.x0.iter().copied().collect();
    let xs: Vec<f64> = x0.iter().map(|_| 0.1).collect();
    for f in [0.0, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95, 1.0, 1.05, 1.1, 1.2, 1.3, 1.5, 1.8, 2.0, 2.5] {
        let Some(e) = scaled(&truth, f) else { continue };
        let pb = Problem {
            sys,
            fixed: vec![e],
            parts: vec![],
            scales: &sc,
            w: &w,
            y: &y,
            m: 1,
            p: 1,
            dt: rec.dt,
            k_est,
            weights: vec![1.0 / sd],
            maps: maps.clone(),
            substeps: sub,
            hold,
            z0: None,
            exclude: None,
            refit: None,
        };
        let r = fit::fit(&pb, &x0, &xs, None, &FitSettings::default());
        println!("  f {f:.2}: sse {:.4}", r.sse);
    }
}
