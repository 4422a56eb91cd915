//! Reusable, seeded proptest strategies (module map: [`sets`], [`systems`], [`inputs`]).
//!
//! They generate parameters, not objects, so that shrinking moves towards simple cases;
//! every `*Params` has a `build` method.
pub mod inputs;
pub mod sets;
pub mod systems;
