//! The linear part of eq. (xy), solved exactly: matrix exponentials and the step maps of the
//! integrators.
//! - [`expm`]: `e^{hA}`, `t Psi(tA)` (eq. (Psi)) and `int_0^h e^{(h-s)A} s ds` from one
//!   augmented matrix exponential.
//! - [`hold`]: [`hold::InputHold`], how `w` behaves between samples (first- or zero-order
//!   hold); the one hold type of the crate.
//! - [`step_map`]: exact step maps with `w` held or linearly interpolated.
pub mod expm;
pub mod hold;
pub mod step_map;
