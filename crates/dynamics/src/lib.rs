//! dynamics
#![allow(non_snake_case)]
pub mod error;
pub mod integrators;
pub mod linear;
pub use error::DynamicsError;
pub mod periodic;
pub mod rate;
pub mod trajectory;
