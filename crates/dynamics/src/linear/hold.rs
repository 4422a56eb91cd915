//! How the input `w` is represented between its samples over one step: the one hold type of
//! the workspace, declared with the input it interpolates ([`model::input::InputHold`]) and
//! used by the step maps ([`super::step_map`]), the catching-up scheme and the extended model.

pub use model::input::InputHold;
