//! The sharpened inputs of theta* against simulation (proofs-notes/theta-star.md):
//! - the speed bound with the backlash side pinned (p = 1, `bounds::beyond_paper::EngagedSpeed`):
//!   measured `limsup |z'| <= zdot_star_bound <= zdot_bound` (eq. (zinf));
//! - (path1-local), the partition bound with the step-length-dependent loss
//!   `min(d, diam Theta + dt D)`: measured path per period `>= path1_local_bound >= path1_bound`.
//!
//! Random p = 1 systems (Theta an interval or a 1-D ball, sine inputs; `C E` of either sign) plus the worked
//! example, each with the measured side (catching-up pairs, `dt = 1e-3`), compared at a relative
//! tolerance `1e-3` for the time step. Negative controls, each must be caught on some case:
//! the speed bound without the tube (`||eta_T'||_inf`, which drops `C F Xi_inf`) and the path
//! bound with the loss `diam Theta` only (which drops the tube's motion over a step).
//!
//! `SPEED_PATH_CASES=N` (default 12) random systems (about 0.5 s).
use bounds::orbit::{partition_bound_local, EtaOrbit};
use bounds::{assemble, ThetaSettings};
use dynamics::rate::lyapunov_exponent::RateSettings;
use geometry::ConvexSet;
use theorems::strategies::inputs::InputStrategyConfig;
use theorems::strategies::sets::{SetKind, SetStrategyConfig};
use theorems::strategies::systems::{system_params, SystemStrategyConfig};

fn wanted() -> usize {
    std::env::var("SPEED_PATH_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(12).max(1)
}

#[test]
fn pinned_speed_and_local_path_bound_simulations_with_controls() {
    let config = SystemStrategyConfig {
        max_n: 3,
        max_p: 1,
        mu: (-2.0, -0.5),
        theta: SetStrategyConfig {
            kinds: vec![SetKind::Interval, SetKind::Ball],
            max_dim: 1,
            max_cond: 5.0,
            scale_exp: 0.75,
        },
        input: InputStrategyConfig { amp_exp: (0.5, 1.5), ..Default::default() },
        ..Default::default()
    };
    let mut systems = vec![model::load(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/worked-example.toml"
    )))
    .expect("worked example")];
    systems.extend(theorems::strategies::draw(&system_params(&config), 11, wanted()).into_iter().map(|c| c.build()));
    let measure = RateSettings { periods: 20, transient_periods: 10, pairs: 1, ..Default::default() };
    let settings = ThetaSettings { stationary: None, measure: Some(measure), ..ThetaSettings::bound_only() };
    let (mut checked, mut sharper, mut speed_caught, mut path_caught) = (0, 0, 0, 0);
    for (i, sys) in systems.iter().enumerate() {
        let Ok(r) = assemble(sys, &settings) else { continue };
        let Some(m) = r.measured.as_ref() else { continue };
        if !(r.d_verified && r.orbit_verified && m.limsup_zdot.is_finite()) {
            continue;
        }
        checked += 1;
        let ce: f64 = (&sys.C * &sys.E)[(0, 0)];
        if m.limsup_zdot <= 0.0 || m.path_length_per_period <= 0.0 {
            continue; // the backlash rests in the periodic regime: nothing to compare
        }
        eprintln!(
            "case {i}: CE = {ce:+.3}, limsup |z'| {:.4} (||eta_T'|| {:.4}) <= pinned {:.4} <= (zinf) {:.4}; path {:.4} >= local {:.4} >= (path1) {:.4}",
            m.limsup_zdot, r.eta_dot_inf, r.zdot_star_bound, r.zdot_bound, m.path_length_per_period, r.path1_local_bound, r.path1_bound
        );
        assert!(r.zdot_star_bound <= r.zdot_bound, "case {i}: pinned speed bound above (zinf)");
        assert!(
            m.limsup_zdot <= r.zdot_star_bound * (1.0 + 1e-3),
            "case {i}: measured limsup |z'| {} above the pinned bound {}",
            m.limsup_zdot,
            r.zdot_star_bound
        );
        assert!(r.path1_local_bound >= r.path1_bound);
        assert!(
            m.path_length_per_period >= r.path1_local_bound * (1.0 - 1e-3),
            "case {i}: measured path {} below (path1-local) {}",
            m.path_length_per_period,
            r.path1_local_bound
        );
        if r.zdot_star_bound < r.zdot_bound * (1.0 - 1e-6) {
            sharper += 1;
        }
        // controls: claims that drop a term of the proof
        if m.limsup_zdot > r.eta_dot_inf * (1.0 + 1e-3) {
            speed_caught += 1;
        }
        let orbit = EtaOrbit::new(sys, &settings.orbit).expect("orbit");
        let idx = orbit.subsample(settings.path1_points);
        let eta: Vec<&[f64]> = idx.iter().map(|&k| orbit.eta[k].as_slice()).collect();
        let t: Vec<f64> = idx.iter().map(|&k| orbit.t[k]).collect();
        let diam = sys.theta.diameter().upper;
        let no_motion = partition_bound_local(&eta, &t, r.d, diam, 0.0);
        if m.path_length_per_period < no_motion * (1.0 - 1e-3) {
            path_caught += 1;
        }
    }
    eprintln!(
        "{checked} cases; pinned speed bound sharper than (zinf) on {sharper}; controls caught: speed {speed_caught}, path {path_caught}"
    );
    assert!(checked >= 3, "too few cases checked ({checked})");
    assert!(sharper > 0, "the pinned speed bound is never sharper than (zinf): nothing tested beyond it");
    assert!(speed_caught > 0, "negative control ||eta_T'||_inf (no tube term) not caught");
    assert!(path_caught > 0, "negative control (loss diam Theta only) not caught");
}
