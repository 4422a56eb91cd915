//! theta >= measured exponent whenever `theta < 0` is verified (eq. (theta) against eq. (VV)).
//!
//! Random systems from `theorems::strategies::systems` (p = 1, interval Theta, sine inputs)
//! plus the worked example; `theta` is assembled by `bounds::assemble` (bound only,
//! cheap) and, for the candidates with `theta < 0` verified, the measured side (pairs of
//! catching-up trajectories) is added. Claim: `ci_high <= theta` (the whole 95% CI of the
//! measured exponent lies below the bound), for theta, theta* and theta_profile (the bounds
//! beyond the paper). Negative control: the too-small bound `theta - 1`
//! must be caught (`ci_low > theta - 1`) on some case.
//!
//! Default: at most `4` verified random cases (drawn from at most 40 candidates); raise with
//! `THETA_VS_MEASURED_CASES=N` (then `10 N` candidates).
use bounds::{assemble, ThetaSettings};
use dynamics::rate::lyapunov_exponent::RateSettings;
use theorems::strategies::inputs::InputStrategyConfig;
use theorems::strategies::sets::{SetKind, SetStrategyConfig};
use theorems::strategies::systems::{system_params, SystemStrategyConfig};

fn wanted() -> usize {
    std::env::var("THETA_VS_MEASURED_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(4).max(1)
}

fn config() -> SystemStrategyConfig {
    SystemStrategyConfig {
        max_n: 3,
        max_p: 1,
        mu: (-2.0, -0.5),
        theta: SetStrategyConfig { kinds: vec![SetKind::Interval], max_dim: 1, max_cond: 5.0, scale_exp: 0.75 },
        input: InputStrategyConfig { amp_exp: (0.0, 1.3), ..Default::default() },
        ..Default::default()
    }
}

/// `(name, theta, ci_low, ci_high)` of the verified `theta < 0` cases.
fn verified_cases() -> (Vec<(String, f64, f64, f64)>, usize) {
    let want = wanted();
    let mut systems = vec![model::load(std::path::Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/worked-example.toml"
    )))
    .expect("worked example")];
    systems.extend(theorems::strategies::draw(&system_params(&config()), 7, 10 * want).into_iter().map(|c| c.build()));
    let measure = RateSettings { periods: 30, transient_periods: 10, pairs: 2, ..Default::default() };
    let mut out = Vec::new();
    let mut tried = 0;
    for (i, sys) in systems.iter().enumerate() {
        if out.len() > want {
            break;
        }
        tried += 1;
        let Ok(b) = assemble(sys, &ThetaSettings::bound_only()) else { continue };
        if !(b.theta < 0.0 && b.theta_verified) {
            continue;
        }
        let full =
            assemble(sys, &ThetaSettings { stationary: None, measure: Some(measure.clone()), ..Default::default() })
                .expect("assembled once already");
        let m = full.measured.expect("measured side computed");
        out.push((format!("case {i} (n = {}, mu = {:.3})", sys.n(), full.mu), full.theta, m.ci_low, m.ci_high));
        if full.theta_star_verified {
            out.push((format!("case {i} theta* (n = {})", sys.n()), full.theta_star, m.ci_low, m.ci_high));
        }
        if full.theta_profile_verified {
            out.push((format!("case {i} theta_profile (n = {})", sys.n()), full.theta_profile, m.ci_low, m.ci_high));
        }
        if full.theta_engaged_verified {
            out.push((format!("case {i} theta_engaged (n = {})", sys.n()), full.theta_engaged, m.ci_low, m.ci_high));
        }
    }
    (out, tried)
}

#[test]
fn theta_bounds_measured_exponent_and_control_is_caught() {
    let (cases, tried) = verified_cases();
    for (name, theta, lo, hi) in &cases {
        eprintln!(
            "{name}: theta = {theta:.5}, measured 95% CI [{lo:.5}, {hi:.5}], slack theta - ci_high = {:.5}",
            theta - hi
        );
    }
    eprintln!("{} verified theta < 0 cases of {tried} tried", cases.len());
    assert!(cases.len() >= 2, "too few verified theta < 0 cases ({}) to test anything", cases.len());
    for (name, theta, _, hi) in &cases {
        assert!(hi <= theta, "{name}: measured exponent CI upper end {hi} > theta {theta}");
    }
    // negative control: theta - 1 is too small a bound, the measurement must reject it
    let caught = cases.iter().filter(|(_, theta, lo, _)| *lo > theta - 1.0).count();
    eprintln!("negative control theta - 1: caught on {caught} of {}", cases.len());
    assert!(caught > 0, "negative control theta - 1 not caught");
}
