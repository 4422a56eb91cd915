//! Reusable, seeded proptest strategies (module map: [`sets`], [`systems`], [`inputs`]).
//!
//! They generate parameters, not objects, so that shrinking moves towards simple cases;
//! every `*Params` has a `build` method.
pub mod inputs;
/// Random sets and points: `geometry::strategies` (feature `proptest-support`).
pub use geometry::strategies as sets;
pub mod systems;

/// `count` values drawn from `strategy` by a deterministic generator seeded with `seed`
/// (ChaCha), without shrinking: for callers that need sample cases but not the proptest
/// machinery (e.g. the driver's theta-vs-measured test).
pub fn draw<T: std::fmt::Debug>(strategy: &proptest::strategy::BoxedStrategy<T>, seed: u64, count: usize) -> Vec<T> {
    use proptest::strategy::{Strategy, ValueTree};
    let mut runner = proptest::test_runner::TestRunner::new_with_rng(
        proptest::test_runner::Config::default(),
        crate::seeding::chunk_rng(seed, "draw", 0),
    );
    (0..count).map(|_| strategy.new_tree(&mut runner).expect("strategies never reject").current()).collect()
}
