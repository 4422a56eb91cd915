//! How the input `w` is represented between its samples over one step: the one hold type of
//! the step maps ([`super::step_map`]), the catching-up scheme and the extended model.

use serde::{Deserialize, Serialize};

/// How `w` behaves between its samples `w(t_k)`, `w(t_{k+1})`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum InputHold {
    /// `w(t_k + s) = w(t_k) + (s/h)(w(t_{k+1}) - w(t_k))`: linear interpolation between
    /// samples (first-order hold). Default.
    #[default]
    #[serde(rename = "Linear")]
    Foh,
    /// `w(t_k + s) = w(t_k)`: each sample held until the next (zero-order hold, a digital
    /// controller's command).
    #[serde(rename = "Held")]
    Zoh,
}

impl InputHold {
    /// `"foh"` or `"zoh"` (reports).
    pub fn name(&self) -> &'static str {
        match self {
            InputHold::Foh => "foh",
            InputHold::Zoh => "zoh",
        }
    }
}
