//! Trajectories: `y = C x` and `z` against time (and the states `x` in a second figure), from
//! the catching-up scheme (eq. (zdot) discretised, NOTES.md) started at the model's `x0, z0`,
//! or the extended-model simulator for a model with `[[effects]]`; and
//! [`simulation_figure`], the plot `moreau simulate` writes beside `trajectory.csv`.
use super::canvas::{palette, Element, Figure};
use super::FigureError;
use dynamics::trajectory::Trajectory;
use model::System;

/// Settings of the trajectory figure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrajectorySettings {
    /// Final time; default: the model's `periods` periods (or its `t_end`, or 100).
    pub t_end: Option<f64>,
    /// Step; default: the model's `dt`.
    pub dt: Option<f64>,
    /// Points drawn per curve (at most). Default `4000`.
    pub max_points: usize,
}

impl Default for TrajectorySettings {
    fn default() -> Self {
        Self { t_end: None, dt: None, max_points: 4000 }
    }
}

/// Two figures: (`y` and `z` against `t`, `x` against `t`).
pub fn trajectory_figures(sys: &System, s: &TrajectorySettings) -> Result<(Figure, Figure), FigureError> {
    let dt = s.dt.unwrap_or(sys.sim.dt);
    let t_end = s.t_end.unwrap_or_else(|| match sys.period() {
        Some(T) => T * sys.sim.periods as f64,
        None => sys.sim.t_end.unwrap_or(100.0),
    });
    let steps = ((t_end / dt).ceil() as usize).max(1);
    let every = (steps / s.max_points.max(1)).max(1);
    let tr = dynamics::trajectory::simulate_model(sys, dt, steps, every)?;
    // units from the model's [signals] table where stated
    let unit = |u: &str| if u.is_empty() { String::new() } else { format!(" ({u})") };
    let t_label = format!("t{}", unit(&sys.signals.t));
    let mut yz = Figure::new(
        &format!("Trajectory of {}: y = C x and z", sys.name),
        &t_label,
        &format!("y, z{}", unit(sys.signals.y_common_unit())),
    );
    let mut xf = Figure::new(&format!("Trajectory of {}: state x", sys.name), &t_label, "x");
    let ys: Vec<Vec<f64>> = (0..tr.len()).map(|i| tr.y_at(&sys.C, i)).collect();
    let p = sys.p();
    for k in 0..p {
        let sub = if p > 1 { format!("_{}", k + 1) } else { String::new() };
        yz.elements.push(Element::Line {
            label: format!("y{sub}"),
            pts: tr.t.iter().zip(&ys).map(|(&t, y)| (t, y[k])).collect(),
            color: palette(2 * k),
            dashed: false,
        });
        yz.elements.push(Element::Line {
            label: format!("z{sub}"),
            pts: tr.t.iter().enumerate().map(|(i, &t)| (t, tr.z_at(i)[k])).collect(),
            color: palette(2 * k + 1),
            dashed: false,
        });
    }
    for k in 0..sys.n() {
        xf.elements.push(Element::Line {
            label: format!("x_{}", k + 1),
            pts: tr.t.iter().enumerate().map(|(i, &t)| (t, tr.x_at(i)[k])).collect(),
            color: palette(k),
            dashed: false,
        });
    }
    Ok((yz, xf))
}

/// The plot of `moreau simulate`: the inputs `w1..wm`, then `y_k` and `z_k` per output
/// against `t`, titled with the model's name and `method` (how it was simulated; its long
/// numbers, such as a step `h = 0.016000000000000014`, shortened to 4 significant digits),
/// axes in the model's `[signals]` units where stated.
pub fn simulation_figure(sys: &System, tr: &Trajectory, method: &str) -> Figure {
    let unit = |u: &str| if u.is_empty() { String::new() } else { format!(" ({u})") };
    // one unit on the y axis when every plotted signal has it (or the outputs' when no input has one)
    let ys = sys.signals.y_common_unit();
    let ws: Vec<&str> = (0..sys.m()).map(|j| sys.signals.w_unit(j)).collect();
    let y_unit = if ws.iter().all(|w| *w == ys) || ws.iter().all(|w| w.is_empty()) { ys } else { "" };
    let mut f = Figure::new(
        &format!("{} ({})", sys.name, short_numbers(method)),
        &format!("t{}", unit(&sys.signals.t)),
        &format!("w, y, z{}", unit(y_unit)),
    );
    f.size = (1000, 600);
    let mut line = |label: String, y: Vec<f64>| {
        let color = palette(f.elements.len());
        f.elements.push(Element::Line { label, pts: tr.t.iter().copied().zip(y).collect(), color, dashed: false });
    };
    // an input with a unit other than the axis's says it in its legend entry
    for (j, &w) in ws.iter().enumerate() {
        let own = if w != y_unit && !w.is_empty() { unit(w) } else { String::new() };
        line(format!("w_{}{own}", j + 1), (0..tr.len()).map(|i| tr.w_at(i)[j]).collect());
    }
    for j in 0..sys.p() {
        line(format!("y_{}", j + 1), (0..tr.len()).map(|i| tr.y_at(&sys.C, i)[j]).collect());
        line(format!("z_{}", j + 1), (0..tr.len()).map(|i| tr.z_at(i)[j]).collect());
    }
    f
}

/// `text` with every number of more than 4 significant digits written with 4 (`h =
/// 0.016000000000000014` -> `h = 0.01600`), minus as U+2212; the rest unchanged.
pub fn short_numbers(text: &str) -> String {
    let mut out = String::new();
    let chars: Vec<char> = text.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let starts = chars[i].is_ascii_digit() && (i == 0 || !(chars[i - 1].is_alphanumeric() || chars[i - 1] == '_'));
        if !starts {
            out.push(chars[i]);
            i += 1;
            continue;
        }
        let mut j = i;
        while j < chars.len() && (chars[j].is_ascii_digit() || chars[j] == '.') {
            j += 1;
        }
        if j < chars.len() && (chars[j] == 'e' || chars[j] == 'E') {
            let mut k = j + 1;
            if k < chars.len() && (chars[k] == '-' || chars[k] == '+') {
                k += 1;
            }
            if k < chars.len() && chars[k].is_ascii_digit() {
                while k < chars.len() && chars[k].is_ascii_digit() {
                    k += 1;
                }
                j = k;
            }
        }
        let tok: String = chars[i..j].iter().collect();
        let digits = tok.split(['e', 'E']).next().unwrap_or("").trim_start_matches(['0', '.']).replace('.', "").len();
        match tok.parse::<f64>() {
            Ok(v) if digits > 4 => out.push_str(&super::canvas::num_text(v)),
            _ => out.push_str(&tok),
        }
        i = j;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::figures::canvas;

    #[test]
    fn the_simulate_plot_renders_svg_and_png_with_text() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/worked-example.toml");
        let sys = model::load(std::path::Path::new(path)).unwrap();
        let tr = dynamics::trajectory::simulate_model(&sys, 0.01, 300, 1).unwrap();
        let f = simulation_figure(&sys, &tr, "catching-up, h = 1e-2");
        let labels: Vec<&str> = f.elements.iter().map(|e| e.label_and_color().0).collect();
        assert_eq!(labels, ["w_1", "y_1", "z_1"]);
        let svg = canvas::to_svg(&f).unwrap();
        assert!(svg.contains("<svg") && svg.contains("<text") && svg.contains("catching-up"));
        // a long step in the method is shortened; the rest of the text is kept
        assert_eq!(short_numbers("catching-up, h = 1.6000000000000014e-2"), "catching-up, h = 0.01600");
        assert_eq!(short_numbers("event-driven, 40 events, p_2 = 0.25"), "event-driven, 40 events, p_2 = 0.25");
        let f2 = simulation_figure(&sys, &tr, "catching-up, h = 1.6000000000000014e-2");
        assert_eq!(f2.title, format!("{} (catching-up, h = 0.01600)", sys.name));
        // [signals] units on the axes
        let text = std::fs::read_to_string(path).unwrap();
        let with_units =
            model::parse_str(&format!("{text}\n[signals]\ny = \"rad\"\nw = \"rad\"\nt = \"s\"\n")).unwrap();
        let f3 = simulation_figure(&with_units, &tr, "m");
        assert_eq!((f3.x_label.as_str(), f3.y_label.as_str()), ("t (s)", "w, y, z (rad)"));
        assert_eq!((f.x_label.as_str(), f.y_label.as_str()), ("t", "w, y, z"), "no unit invented");
        let dir = tempfile::tempdir().unwrap();
        let png = dir.path().join("a.png");
        canvas::write_png(&f, &png).unwrap();
        assert!(std::fs::metadata(&png).unwrap().len() > 1000);
        // negative control: nothing finite to draw is an error, not an empty picture
        let mut empty = f.clone();
        for e in &mut empty.elements {
            if let Element::Line { pts, .. } = e {
                pts.iter_mut().for_each(|p| p.1 = f64::NAN);
            }
        }
        assert!(canvas::to_svg(&empty).is_err());
    }
}
