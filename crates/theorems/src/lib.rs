//! `theorems`: a property campaign for every result of the paper
//! (`../shared/paper/strongly-convex-backlash.tex`), shared by `cargo test -p theorems` and
//! `moreau check`.
//!
//! - [`strategies`]: seeded proptest strategies for random strongly convex sets and points with
//!   inward normals (`geometry::strategies`, feature `proptest-support`), Hurwitz systems with
//!   controlled `mu`, periodic inputs;
//! - [`properties`]: one module per result, named after it (`lemma_a2.rs` checks eq.
//!   (lem1:2)), each with a negative control that must fail; Lemma 2 and Theorem 2 check the
//!   production kernels of `bounds::tube` (the numbers `moreau theta` prints), not a copy;
//! - [`campaign`]: the deterministic runner (cases, minimum normalised slack, violations,
//!   shrunk counterexample).
//! - [`seeding`]: the deterministic ChaCha generator of a chunk of cases (`seed`, property
//!   name, chunk), used by the runner and by [`strategies::draw`].
//!
//! Layers, bottom up: `seeding` -> `strategies` -> `properties` -> `campaign`.
//!
//! Where each result is computed, tested and what the campaign found: `proofs-notes/`.
#![allow(non_snake_case)]

pub mod campaign;
pub mod properties;
pub mod seeding;
pub mod strategies;

pub use campaign::{registry, run, run_property, CampaignError, CampaignSettings, PropertyReport};
pub use properties::{CaseOutcome, Counterexample, Eval, Property, PropertyInfo, Variant};
