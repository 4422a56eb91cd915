//! Development aid: one benchmark case, its ranking, and a profile of the estimation cost
//! along the true effect's main parameter (initial state refitted at each point).
//! Usage: `cargo run --release -p discovery --example probe backlash_inertia 1 3`.
use discovery::bench_gen;
use discovery::fit::{self, FitSettings, Problem};
use discovery::hypothesis::Scales;
use discovery::simulate::StepMaps;
use model::effects::Effect;

fn main() {
    let a: Vec<String> = std::env::args().collect();
    if a.len() != 4 {
        eprintln!("usage: cargo run --release -p discovery --example probe CLASS SEED INDEX");
        std::process::exit(2);
    }
    let class: &'static str = Box::leak(a[1].clone().into_boxed_str());
    let seed: u64 = a[2].parse().unwrap();
    let idx: usize = a[3].parse().unwrap();
    let case = bench_gen::generate(class, seed, idx);
    println!("{} truth {:?}", case.description, case.truth);
    let rep = discovery::diagnose(&case.nominal, &case.recording, &Default::default()).unwrap();
    println!("selected {} ties {:?}", rep.selected(), rep.ties);
    for e in &rep.effects {
        println!("  {} {:?} +- {:?}", e.label, e.params, e.uncertainty);
    }
    for r in rep.ranking.iter().take(8) {
        println!(
            "  {:40} {:?} std {:?} dBIC {:.1} vr {:.3} {:?}",
            r.label, r.params, r.std, r.delta_bic, r.validation_ratio, r.status
        );
    }
    if a.len() > 4 {
        // Profile: scale factors of the truth.
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
        };
        let truth = case.truth.clone().unwrap();
        let x0: Vec<f64> = sys.x0.iter().copied().collect();
        let xs: Vec<f64> = x0.iter().map(|_| 0.1).collect();
        for f in [0.5, 0.6, 0.7, 0.8, 0.9, 0.95, 1.0, 1.05, 1.1, 1.2, 1.3, 1.5, 2.0] {
            let e = match &truth {
                Effect::BacklashInertia { mass, damping } => {
                    Effect::BacklashInertia { mass: mass * f, damping: *damping }
                }
                Effect::GapWidth { relative_change } => Effect::GapWidth { relative_change: relative_change * f },
                _ => panic!(),
            };
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
            };
            let r = fit::fit(&pb, &x0, &xs, None, &FitSettings::default());
            println!("  f {f:.2}: sse {:.4}", r.sse);
        }
    }
}
