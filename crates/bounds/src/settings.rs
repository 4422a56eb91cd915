//! Settings of [`crate::assemble()`]: one plain struct with documented defaults (the tube
//! quadrature, the sphere maxima, the lambda search, the orbit samples, the path and profile
//! grids, and the two optional parts).
use crate::orbit::OrbitSettings;
use crate::stationary::RestSetSettings;
use crate::tube::TubeSettings;
use dynamics::rate::lyapunov_exponent::RateSettings;
use geometry::SphereMaxSettings;
use lmi::LambdaSearchSettings;

/// Settings of [`crate::assemble()`]. All parts have documented defaults; `measure = None` and
/// `stationary = None` skip the two costly optional parts (for sweeps).
#[derive(Debug, Clone)]
pub struct ThetaSettings {
    /// Tube quadrature (eqs. (Xinfsupp), (DXX)). Default [`TubeSettings::default`].
    pub tube: TubeSettings,
    /// Maxima over the unit sphere (eqs. (d), (zinf)) of sublinear functions
    /// ([`crate::tube::sublinear_sphere_max`]). Default: `tol_abs 1e-9`, `tol_rel 1e-6`,
    /// `max_evals 20_000` (the bounds stay valid, only wider, when the budget runs out).
    pub sphere: SphereMaxSettings,
    /// Outer search over `lambda` and the beta SDPs. Default [`LambdaSearchSettings::default`].
    pub lambda: LambdaSearchSettings,
    /// Orbit samples. Default [`OrbitSettings::default`] (2000 intervals).
    pub orbit: OrbitSettings,
    /// Grid points of the (path1) dynamic programme (`O(K^2)`). Default `600`.
    pub path1_points: usize,
    /// p = 1: steps of the engaged-history table over half a period
    /// ([`crate::beyond_paper::EngagedHistory`]; two finite-horizon kernels each). `0` disables it.
    /// Default `16`.
    pub engaged_history_steps: usize,
    /// Number of `eps` values of the (path2) packing search. Default `64`.
    pub packing_eps: usize,
    /// Cells of the time-resolved speed profile of `theta_profile` (must divide
    /// `orbit.samples`; otherwise the largest divisor below it is used). Default `400`.
    pub profile_cells: usize,
    /// Every `profile_stride`-th cell boundary is a candidate partition point of the
    /// `theta_profile` dynamic programme (`O((cells/stride)^2)` intervals). Default `4`.
    pub profile_stride: usize,
    /// Stationary set of Theorem 1; `None` skips it. Default `Some(RestSetSettings::default())`.
    pub stationary: Option<RestSetSettings>,
    /// Measured side (pairs of simulated trajectories); `None` skips it. Default:
    /// `dt = 1e-3`, 40 periods, 10 transient, 2 pairs.
    pub measure: Option<RateSettings>,
}

impl Default for ThetaSettings {
    fn default() -> Self {
        Self {
            tube: TubeSettings::default(),
            sphere: SphereMaxSettings { tol_abs: 1e-9, tol_rel: 1e-6, max_evals: 20_000 },
            lambda: LambdaSearchSettings::default(),
            orbit: OrbitSettings::default(),
            path1_points: 600,
            engaged_history_steps: 16,
            packing_eps: 64,
            profile_cells: 400,
            profile_stride: 4,
            stationary: Some(RestSetSettings::default()),
            measure: Some(RateSettings { periods: 40, transient_periods: 10, pairs: 2, ..Default::default() }),
        }
    }
}

impl ThetaSettings {
    /// Cheap settings for sweeps: no measurement, no stationary set.
    pub fn bound_only() -> Self {
        Self { stationary: None, measure: None, ..Default::default() }
    }
}
