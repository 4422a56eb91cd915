//! Fig. psi1: `psi(gamma)` of eq. (phipsi), its value `psi(0)` (eq. (psilim)), the limit
//! `-lambda`, the value `psi(gamma_inf)` and the chord over `[0, gamma_inf]` whose value at
//! `gamma_1` is `theta` (eq. (theta)); from a report, also the sharper certified bounds as
//! levels ([`from_report`]).
use super::canvas::{num_text, Element, Figure, BLUE, GREEN, GREY, ORANGE, PURPLE, RED};
use bounds::{Psi, ThetaReport};

/// Fig. psi1 from the function and the two gammas (`theta` is read off the chord).
pub fn psi_figure(psi: &Psi, gamma_1: f64, gamma_inf: f64) -> Figure {
    // with gamma_inf = 0 (R infinite, e.g. a polytope) show psi on its own scale
    let own = 4.0 * (psi.alpha.abs() + psi.lambda.abs() + psi.beta.abs().sqrt());
    let g_max = if gamma_inf.is_finite() && gamma_inf > 0.0 {
        1.6 * gamma_inf
    } else if own > 0.0 && own.is_finite() {
        own
    } else {
        1.0
    };
    let v = num_text;
    let k = 400;
    let curve: Vec<(f64, f64)> = (0..=k).map(|i| g_max * i as f64 / k as f64).map(|g| (g, psi.eval(g))).collect();
    let (p0, pinf) = (psi.at_zero(), psi.eval(gamma_inf));
    let theta = psi.theta(gamma_1, gamma_inf);
    // the paper's printed equation numbers, not its LaTeX labels
    let eq = |l: &str| bounds::equations::numbered(&format!("({l})"));
    let mut f = Figure::new(&format!("ψ(γ) of eq. {} and θ of eq. {}", eq("phipsi"), eq("theta")), "γ", "ψ(γ)");
    f.elements.push(Element::Line { label: "ψ(γ)".into(), pts: curve, color: BLUE, dashed: false });
    f.elements.push(Element::Line {
        label: format!("limit −λ = {}", v(psi.limit())),
        pts: vec![(0.0, psi.limit()), (g_max, psi.limit())],
        color: GREY,
        dashed: true,
    });
    f.elements.push(Element::Line {
        label: "chord over [0, γ_∞]".into(),
        pts: vec![(0.0, p0), (gamma_inf, pinf)],
        color: ORANGE,
        dashed: false,
    });
    f.elements.push(Element::Line {
        label: String::new(),
        pts: vec![(gamma_1, psi.limit()), (gamma_1, theta)],
        color: GREY,
        dashed: true,
    });
    f.elements.push(Element::Markers {
        label: String::new(),
        pts: vec![(0.0, p0), (gamma_inf, pinf)],
        text: if gamma_inf > 0.0 {
            vec![format!("ψ(0) = {}", v(p0)), format!("ψ(γ_∞) = {}", v(pinf))]
        } else {
            vec![format!("ψ(0) = ψ(γ_∞) = {} (γ_∞ = 0)", v(p0)), String::new()]
        },
        color: BLUE,
    });
    f.elements.push(Element::Markers {
        label: format!("θ = {} at γ₁ = {}", v(theta), v(gamma_1)),
        pts: vec![(gamma_1, theta)],
        text: vec!["θ".into()],
        color: RED,
    });
    f
}

/// Fig. psi1 of a theta report, with the sharper certified bounds drawn as levels: `theta_star`
/// (eq. (theta) with the strongest path bound, at its own `lambda`) and the best bound beyond
/// the paper (`theta_best` when it comes from `theta_profile` or `theta_engaged`), each only
/// when verified and below the paper's `theta`. They are not read off this `psi` (each has its
/// own `lambda` and `beta`); the levels show how far below the chord they certify.
pub fn from_report(r: &ThetaReport) -> Figure {
    let mut f = psi_figure(&r.psi(), r.gamma_1, r.gamma_inf);
    // the right end of the psi curve (the first element)
    let x_max = match f.elements.first() {
        Some(Element::Line { pts, .. }) => pts.last().map_or(1.0, |p| p.0),
        _ => 1.0,
    };
    let v = num_text;
    let mut levels = vec![];
    if r.theta_star_verified && r.theta_star < r.theta {
        levels.push((format!("θ* = {} with {}", v(r.theta_star), r.path_best_method), r.theta_star, GREEN));
    }
    if r.theta_best_verified && r.theta_best < r.theta.min(r.theta_star) {
        let name = match r.theta_best_method {
            "theta_profile" => Some("θ_{prof}"),
            "theta_engaged" => Some("θ_{eng}"),
            _ => None,
        };
        if let Some(name) = name {
            levels.push((format!("{name} = {} (beyond the paper)", v(r.theta_best)), r.theta_best, PURPLE));
        }
    }
    for (label, y, color) in levels {
        f.elements.push(Element::Line { label, pts: vec![(0.0, y), (x_max, y)], color, dashed: true });
    }
    f
}
