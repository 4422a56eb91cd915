//! The linear part of eq. (xy), solved exactly: matrix exponentials and the step maps of the
//! integrators.
pub mod expm;
pub mod step_map;
