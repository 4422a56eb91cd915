//! Check that a periodic state lies in the localisation set (loc):
//! `x(0) in xi_T(0) + Xi_inf`, `z(0) in C x(0) + Theta`, with the support function of
//! `Xi_inf` from eq. (Xinfsupp): `sigma(u) = int_0^inf sigma_Theta(E^T e^{sF^T} u) ds`.
//!
//! `x - xi_T(0) in Xi_inf` iff `u . (x - xi_T(0)) <= sigma(u)` for every `u`; this checks it for
//! the `2n` coordinate directions and `random_directions` seeded random unit vectors, with
//! `sigma` from above by the certified quadrature of [`TubeKernel`] (`L = I_n`), the same kernel
//! as the bounds of `theta`. A numerical CHECK of a necessary condition (not a certificate): it
//! reports the worst margin.
use crate::error::BoundsError;
use crate::tube::{Horizon, TubeKernel, TubeSettings};
use geometry::ConvexSet;
use model::System;
use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use serde::Serialize;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalisationSettings {
    /// Random unit directions besides `+-e_i`. Default `64`.
    pub random_directions: usize,
    /// Seed of the directions. Default `7`.
    pub seed: u64,
    /// Quadrature of (Xinfsupp). Default: `tol_abs = 1e-7` per unit direction.
    pub tube: TubeSettings,
    /// Accept margins down to `-tol_abs (1 + |x|)` (rounding of the periodic state). Default `1e-6`.
    pub tol_abs: f64,
}

impl Default for LocalisationSettings {
    fn default() -> Self {
        Self {
            random_directions: 64,
            seed: 7,
            tube: TubeSettings { tol_abs: 1e-7, ..TubeSettings::default() },
            tol_abs: 1e-6,
        }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LocalisationCheck {
    /// All directions passed and `z - C x in Theta`.
    pub inside: bool,
    /// `min_u sigma(u) - u . (x - xi_T(0))` over the tested directions.
    pub worst_margin: f64,
    pub worst_direction: Vec<f64>,
    /// `z(0) - C x(0) in Theta` (to `1e-9`).
    pub q_in_theta: bool,
    pub directions: usize,
}

/// Checks (loc) for the periodic state `(x, z)` given `xi_T(0)`.
pub fn check_localisation(
    sys: &System,
    xi_T0: &[f64],
    x: &[f64],
    z: &[f64],
    settings: &LocalisationSettings,
) -> Result<LocalisationCheck, BoundsError> {
    let n = sys.n();
    let I = DMatrix::<f64>::identity(n, n);
    let sup = TubeKernel::new(&I, &sys.F(), &sys.E, &sys.theta, Horizon::Infinite, &settings.tube)?;
    let d: Vec<f64> = x.iter().zip(xi_T0).map(|(a, b)| a - b).collect();
    let mut dirs: Vec<Vec<f64>> = Vec::new();
    for i in 0..n {
        for s in [1.0, -1.0] {
            let mut e = vec![0.0; n];
            e[i] = s;
            dirs.push(e);
        }
    }
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(settings.seed);
    for _ in 0..settings.random_directions {
        let v: Vec<f64> = (0..n).map(|_| rng.random::<f64>() * 2.0 - 1.0).collect();
        let nv = geometry::linalg::norm(&v).max(1e-300);
        dirs.push(v.iter().map(|a| a / nv).collect());
    }
    let mut worst = f64::INFINITY;
    let mut worst_dir = vec![0.0; n];
    for u in &dirs {
        let m = sup.support_upper(u) - geometry::linalg::dot(u, &d);
        if m < worst {
            worst = m;
            worst_dir = u.clone();
        }
    }
    let q: Vec<f64> = (DVector::from_column_slice(z) - &sys.C * DVector::from_column_slice(x)).as_slice().to_vec();
    let q_in = sys.theta.contains(&q, 1e-9);
    let tol = settings.tol_abs * (1.0 + geometry::linalg::norm(x));
    Ok(LocalisationCheck {
        inside: q_in && worst >= -tol,
        worst_margin: worst,
        worst_direction: worst_dir,
        q_in_theta: q_in,
        directions: dirs.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use dynamics::periodic::linearised::{linearised_periodic, LinearisedSettings};
    use dynamics::periodic::poincare::{periodic_regime, PoincareSettings};

    #[test]
    fn periodic_state_is_inside_and_a_far_point_is_not() {
        let sys = model::parse_str(include_str!("../../../../examples/worked-example.toml")).unwrap();
        let r = periodic_regime(&sys, &PoincareSettings::default()).unwrap();
        let L = linearised_periodic(&sys, &LinearisedSettings { samples: 10, substeps: 1 }).unwrap();
        let c = check_localisation(&sys, L.xi0(), &r.x0, &r.z0, &LocalisationSettings::default()).unwrap();
        assert!(c.inside, "{c:?}");
        // sigma_{Xi_inf}(e_1) for the worked example: int_0^inf 0.1 |(e^{sF} E)_1| ds, finite, > 0
        let I = DMatrix::<f64>::identity(2, 2);
        let sup =
            TubeKernel::new(&I, &sys.F(), &sys.E, &sys.theta, Horizon::Infinite, &TubeSettings::default()).unwrap();
        let s1 = sup.support_upper(&[1.0, 0.0]);
        assert!(s1 > 0.01 && s1 < 1.0, "{s1}");
        // negative control: move x by twice the width of Xi_inf along e_1
        let far = vec![r.x0[0] + 2.0 * s1 + 0.01, r.x0[1]];
        let zf = vec![far[0] + (r.z0[0] - r.x0[0])];
        let c2 = check_localisation(&sys, L.xi0(), &far, &zf, &LocalisationSettings::default()).unwrap();
        assert!(!c2.inside && c2.worst_margin < 0.0, "{c2:?}");
    }
}
