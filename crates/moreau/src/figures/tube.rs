//! Fig. loop: the orbit `eta_T` of the linearised system (eq. (etaT)), the tube
//! `eta_T(t) + C Xi_inf + Theta` (support function from eq. (Xinfsupp) plus `sigma_Theta`,
//! upper bounds, so the drawn tube contains the true one) and the simulated periodic `z`.
//! For `p = 1` against time over one period; for `p >= 2` in the plane of the first two
//! components of `z` (the tube's cross-sections drawn as circumscribed polygons at a subset of
//! orbit points).
use super::canvas::{Element, Figure, BLUE, RED};
use super::FigureError;
use bounds::orbit::EtaOrbit;
use bounds::tube::OutputTube;
use dynamics::integrators::catching_up::CatchingUpSettings;
use dynamics::periodic::poincare::{periodic_regime, PoincareSettings};
use model::System;
use nalgebra::DVector;

/// The simulated periodic `z` over one period.
#[derive(Debug, Clone)]
pub struct PeriodicZ {
    /// Times in `[0, T]`.
    pub t: Vec<f64>,
    pub z: Vec<Vec<f64>>,
    /// Whether the Poincare fixed-point iteration converged (otherwise the last iterate).
    pub converged: bool,
    /// `|P(s) - s|_inf` at the start state.
    pub residual: f64,
}

/// The periodic `z` over one period, from the Poincare fixed point of the catching-up scheme.
pub fn periodic_z(sys: &System, samples: usize) -> Result<PeriodicZ, FigureError> {
    let T = sys.period().ok_or(FigureError::NoPeriod { kind: sys.input.kind() })?;
    let reg = periodic_regime(sys, &PoincareSettings { dt: sys.sim.dt, ..Default::default() })?;
    let mut s = sys.clone();
    s.x0 = DVector::from_vec(reg.x0.clone());
    s.z0 = DVector::from_vec(reg.z0.clone());
    let every = (reg.steps_per_period / samples.max(1)).max(1);
    let tr = dynamics::trajectory::simulate_catching_up(
        &s,
        &CatchingUpSettings { dt: reg.h, ..Default::default() },
        reg.steps_per_period,
        every,
    )?;
    let t: Vec<f64> = tr.t.iter().map(|t| t.min(T)).collect();
    let z = (0..tr.len()).map(|i| tr.z_at(i).to_vec()).collect();
    let converged = reg.status == dynamics::periodic::poincare::FixedPointStatus::Converged;
    Ok(PeriodicZ { t, z, converged, residual: reg.residual })
}

/// Circumscribed polygon of the set with support function `h` in the plane of the first two
/// coordinates of R^p, from `k` directions: vertex `j` is where the support lines of
/// directions `j` and `j + 1` meet.
pub fn support_polygon(p: usize, k: usize, h: impl Fn(&[f64]) -> f64) -> Vec<(f64, f64)> {
    let dirs: Vec<(f64, f64)> =
        (0..k).map(|j| std::f64::consts::TAU * j as f64 / k as f64).map(|a| (a.cos(), a.sin())).collect();
    let vals: Vec<f64> = dirs
        .iter()
        .map(|&(c, s)| {
            let mut v = vec![0.0; p];
            v[0] = c;
            v[1] = s;
            h(&v)
        })
        .collect();
    (0..k)
        .map(|j| {
            let (a, b) = (dirs[j], dirs[(j + 1) % k]);
            let (ha, hb) = (vals[j], vals[(j + 1) % k]);
            let det = a.0 * b.1 - a.1 * b.0;
            ((ha * b.1 - hb * a.1) / det, (a.0 * hb - b.0 * ha) / det)
        })
        .collect()
}

/// Fig. loop for `sys`: the orbit `eta_T`, the tube cross-sections `C Xi_inf + Theta` (from
/// above) and the simulated periodic `z` (`z_periodic` from [`periodic_z`]).
pub fn tube_figure(sys: &System, orbit: &EtaOrbit, tube: &OutputTube, z_periodic: &PeriodicZ) -> Figure {
    let p = sys.p();
    let (tz, z) = (&z_periodic.t, &z_periodic.z);
    // units from the model's [signals] table where stated
    let unit = |u: &str| if u.is_empty() { String::new() } else { format!(" ({u})") };
    let (t_unit, z_unit) = (unit(&sys.signals.t), unit(sys.signals.y_common_unit()));
    let z_label = if z_periodic.converged {
        "z (simulated periodic regime)".to_string()
    } else {
        format!("z (fixed point NOT converged, residual {})", super::canvas::num_text(z_periodic.residual))
    };
    if p == 1 {
        let up: Vec<f64> = orbit.eta.iter().map(|e| e[0] + tube.support_upper(&[1.0])).collect();
        let lo: Vec<f64> = orbit.eta.iter().map(|e| e[0] - tube.support_upper(&[-1.0])).collect();
        let mut f = Figure::new(
            "Orbit η_T, tube η_T + C Ξ_∞ + Θ and periodic z over one period",
            &format!("t{t_unit}"),
            &format!("z, η_T{z_unit}"),
        );
        f.elements.push(Element::Band {
            label: "tube η_T + C Ξ_∞ + Θ".into(),
            x: orbit.t.clone(),
            lo,
            hi: up,
            color: BLUE,
        });
        f.elements.push(Element::Line {
            label: "η_T (linearised orbit)".into(),
            pts: orbit.t.iter().zip(&orbit.eta).map(|(&t, e)| (t, e[0])).collect(),
            color: BLUE,
            dashed: false,
        });
        f.elements.push(Element::Line {
            label: z_label.clone(),
            pts: tz.iter().zip(z).map(|(&t, z)| (t, z[0])).collect(),
            color: RED,
            dashed: false,
        });
        return f;
    }
    let mut f = Figure::new(
        "Orbit η_T, tube η_T + C Ξ_∞ + Θ and periodic z",
        &format!("z_1, η_{{T,1}}{}", unit(sys.signals.y_unit(0))),
        &format!("z_2, η_{{T,2}}{}", unit(sys.signals.y_unit(1))),
    );
    f.equal_aspect = true;
    let section = support_polygon(p, 96, |v| tube.support_upper(v));
    let m = orbit.eta.len();
    let count = 40.min(m);
    for (n, i) in (0..count).map(|j| j * (m - 1) / count.max(1)).enumerate() {
        let e = &orbit.eta[i];
        f.elements.push(Element::Polygon {
            label: if n == 0 { "cross-sections C Ξ_∞ + Θ".into() } else { String::new() },
            pts: section.iter().map(|&(x, y)| (x + e[0], y + e[1])).collect(),
            color: BLUE,
        });
    }
    f.elements.push(Element::Line {
        label: "η_T (linearised orbit)".into(),
        pts: orbit.eta.iter().map(|e| (e[0], e[1])).collect(),
        color: BLUE,
        dashed: false,
    });
    f.elements.push(Element::Line {
        label: z_label,
        pts: z.iter().map(|z| (z[0], z[1])).collect(),
        color: RED,
        dashed: false,
    });
    f
}
