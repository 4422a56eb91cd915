//! Time integrators of the closed loop (xy), (yz), (zdot).
//! - [`catching_up`]: Moreau's catching-up scheme with the exact linear step (any `Theta`).
//! - [`ensemble`]: catching-up for many trajectories of one system at once (SIMD lanes).
//! - [`event_driven`]: the reference integrator for accuracy studies (interval, ball, ellipsoid).
pub mod catching_up;
pub mod ensemble;
pub mod event_driven;
