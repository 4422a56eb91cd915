//! Simulation-based properties: Theorem 1 (stat1), Lemma 2 (xX), Theorem 2 (path), (zinf) and
//! (QZdot), 2,000 cases each by default (short horizons, `h = T/2000` capped at `0.0025`, `n <= 4`;
//! Theorem 2 draws intervals, balls and ellipsoids, ball intersections are in the ignored
//! `theorem2_ball_intersections` test because their projection costs ~50x more). Change the
//! count with `THEOREMS_SIM_CASES` (Theorem 2, QZdot), `THEOREMS_THEOREM1_CASES`,
//! `THEOREMS_LEMMA2_CASES`. The negative controls must be caught.
use proptest::prelude::*;
use proptest::test_runner::{Config, FileFailurePersistence, TestCaseError, TestError, TestRunner};
use theorems::properties::{qzdot, theorem2, Eval, Variant};

fn cases() -> u32 {
    std::env::var("THEOREMS_SIM_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(2000).max(1)
}

fn config() -> Config {
    Config {
        cases: cases(),
        max_shrink_iters: 50,
        failure_persistence: Some(Box::new(FileFailurePersistence::Direct("proptest-regressions/dynamic.txt"))),
        source_file: Some(file!()),
        ..Config::default()
    }
}

fn holds(e: Eval) -> Result<(), TestCaseError> {
    prop_assert!(!e.violated(), "lhs = {:e} > rhs = {:e} + tol {:e}", e.lhs, e.rhs, e.tol);
    Ok(())
}

fn negative_control<C: std::fmt::Debug + Clone>(
    strategy: BoxedStrategy<C>,
    eval: fn(&C, Variant) -> Eval,
    cases: u32,
) -> C {
    let mut runner = TestRunner::new(Config { cases, ..config() });
    match runner.run(&strategy, |c| holds(eval(&c, Variant::NegativeControl))) {
        Err(TestError::Fail(_, minimal)) => {
            assert!(eval(&minimal, Variant::NegativeControl).violated());
            minimal
        }
        other => panic!("negative control not detected: {other:?}"),
    }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn theorem2_path_length(c in theorem2::strategy()) { holds(theorem2::eval_path(&c, Variant::Claim))?; }

    #[test]
    fn theorem2_zinf_speed(c in theorem2::strategy()) { holds(theorem2::eval_zinf(&c, Variant::Claim))?; }

    #[test]
    fn qzdot_pairs_of_trajectories(c in qzdot::strategy()) { holds(qzdot::eval(&c, Variant::Claim))?; }
}

/// Theorem 2 with ball-intersection backlash sets (slow projection): `cargo test -p theorems
/// --test dynamic -- --ignored` (`THEOREMS_SIM_CASES` cases).
#[test]
#[ignore]
fn theorem2_ball_intersections() {
    let strat = theorems::strategies::systems::system_params(&theorem2::config_ball_intersection());
    let mut runner = TestRunner::new(config());
    runner
        .run(&strat, |c| {
            holds(theorem2::eval_path(&c, Variant::Claim))?;
            holds(theorem2::eval_zinf(&c, Variant::Claim))
        })
        .unwrap();
}

#[test]
fn theorem2_path_negative_control_fails() {
    negative_control(theorem2::strategy(), theorem2::eval_path, 32);
}
#[test]
fn theorem2_zinf_negative_control_fails() {
    negative_control(theorem2::strategy(), theorem2::eval_zinf, 32);
}
#[test]
fn qzdot_negative_control_fails() {
    negative_control(qzdot::strategy(), qzdot::eval, 64);
}

/// Theorem 1 (stat1), p = 1: rest inside R(T), motion outside; 2,000 cases by default
/// (`THEOREMS_THEOREM1_CASES` to change).
#[test]
fn theorem1_rest_set_campaign() {
    let cases = std::env::var("THEOREMS_THEOREM1_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(2000u64).max(1);
    let prop = theorems::properties::theorem1::property();
    let settings = theorems::CampaignSettings { cases: Some(cases), ..Default::default() };
    let rep = theorems::run_property(&prop, &settings, &|_| {}).unwrap();
    eprintln!(
        "theorem1: {} cases, {} skipped, min slack {:e}, {:.2} s",
        rep.cases, rep.skipped, rep.min_slack, rep.seconds
    );
    assert_eq!(rep.violations, 0, "{:?}", rep.counterexample.map(|c| c.summary));
    assert!(rep.skipped * 2 < rep.cases, "too many skipped: {} of {}", rep.skipped, rep.cases);
    let neg = theorems::CampaignSettings { cases: Some(200), variant: Variant::NegativeControl, ..Default::default() };
    let rep = theorems::run_property(&prop, &neg, &|_| {}).unwrap();
    assert!(rep.violations > 0, "negative control (rest claimed outside R(T)) not caught");
}

/// The Theorem 1 campaign is not vacuous: both a rest point and an outside point occur often.
#[test]
fn theorem1_cases_exercise_both_sides() {
    use proptest::strategy::ValueTree;
    use theorems::properties::theorem1;
    let mut runner = TestRunner::deterministic();
    let (mut rest, mut out, mut empty, n) = (0, 0, 0, 400);
    for _ in 0..n {
        let c = theorem1::strategy().new_tree(&mut runner).unwrap().current();
        let sys = c.sys.build();
        if let Some(rs) = theorem1::rest_set(&sys, c.horizon) {
            let (r, o) = theorem1::points(&c, &sys, &rs);
            rest += r.is_some() as u32;
            out += o.is_some() as u32;
            empty += (rs.lower > rs.upper) as u32;
        }
    }
    eprintln!("theorem1: of {n} cases, {rest} with a rest point, {out} with an outside point, {empty} with R(T) empty");
    assert!(rest * 5 > n && out * 5 > n);
}

/// Lemma 2 (xX): tube about the linearised trajectory; 2,000 cases by default
/// (`THEOREMS_LEMMA2_CASES` to change).
#[test]
fn lemma2_tube_campaign() {
    let cases = std::env::var("THEOREMS_LEMMA2_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(2000u64).max(1);
    let prop = theorems::properties::lemma2::property();
    let settings = theorems::CampaignSettings { cases: Some(cases), ..Default::default() };
    let rep = theorems::run_property(&prop, &settings, &|_| {}).unwrap();
    eprintln!(
        "lemma2: {} cases, {} skipped, min slack {:e}, {:.2} s",
        rep.cases, rep.skipped, rep.min_slack, rep.seconds
    );
    assert_eq!(rep.violations, 0, "{:?}", rep.counterexample.map(|c| c.summary));
    assert_eq!(rep.skipped, 0);
    let neg = theorems::CampaignSettings { cases: Some(200), variant: Variant::NegativeControl, ..Default::default() };
    let rep = theorems::run_property(&prop, &neg, &|_| {}).unwrap();
    eprintln!("lemma2 negative control: {} of {} cases caught", rep.violations, rep.cases);
    assert!(rep.violations > 0, "negative control (Xi shrunk by 0.5) not caught");
}
