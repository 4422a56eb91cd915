//! Figure construction (data, not pixels): the circumscribed cross-section polygon of the
//! tube, Fig. psi1's reference values, sweep curves grouped by the other axes.
use bounds::Psi;
use moreau::figures::{psi::psi_figure, sweep::sweep_figure, tube::support_polygon, Element, FigureError};
use moreau::sweep::table::AxisInfo;
use moreau::sweep::{Cell, Column, PointRecord, SweepResult};

#[test]
fn support_polygon_circumscribes_the_set() {
    // disc of radius 2 centred at (1, -1) in R^3 (third coordinate ignored by the projection)
    let h = |v: &[f64]| v[0] - v[1] + 2.0 * (v[0] * v[0] + v[1] * v[1]).sqrt();
    let k = 64;
    let poly = support_polygon(3, k, h);
    assert_eq!(poly.len(), k);
    let r_max = 2.0 / (std::f64::consts::PI / k as f64).cos();
    for &(x, y) in &poly {
        let r = ((x - 1.0).powi(2) + (y + 1.0).powi(2)).sqrt();
        assert!(r >= 2.0 - 1e-12 && r <= r_max + 1e-12, "vertex at distance {r}");
    }
    // negative control: a polygon built from a too-small support function misses the disc
    let small = support_polygon(3, k, |v: &[f64]| h(v) - 0.1);
    assert!(small.iter().any(|&(x, y)| ((x - 1.0).powi(2) + (y + 1.0).powi(2)).sqrt() < 2.0));
}

#[test]
fn psi_figure_shows_the_chord_and_theta() {
    let psi = Psi { alpha: 0.0, lambda: 0.3, beta: 0.024 };
    let (g1, ginf) = (4.29, 18.8);
    let f = psi_figure(&psi, g1, ginf);
    let theta = psi.theta(g1, ginf);
    let mut saw_theta = false;
    let mut saw_chord = false;
    for e in &f.elements {
        match e {
            Element::Markers { pts, label, .. } if label.starts_with("θ") => {
                saw_theta = true;
                assert_eq!(pts[0], (g1, theta));
            }
            Element::Line { pts, label, .. } if label.starts_with("chord") => {
                saw_chord = true;
                assert_eq!(pts[0], (0.0, psi.at_zero()));
                assert_eq!(pts[1], (ginf, psi.eval(ginf)));
            }
            _ => {}
        }
    }
    assert!(saw_theta && saw_chord);
    let ((_, _), (y0, y1)) = f.ranges().unwrap();
    assert!(y0 < -0.3 && y1 > psi.at_zero(), "the limit -lambda and psi(0) are in view");
}

fn two_axis_result() -> SweepResult {
    let mut points = vec![];
    let (a, b) = (vec![1.0, 2.0, 3.0], vec![10.0, 20.0]);
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            points.push(PointRecord {
                index: 2 * i + j,
                params: vec![*x, *y],
                cells: vec![Cell::Num(x * y), Cell::Num(-x), Cell::Flag(true)],
                status: "ok".into(),
            });
        }
    }
    SweepResult {
        name: "t".into(),
        spec_hash: "0".into(),
        model: "m".into(),
        evaluator: "e".into(),
        axes: vec![
            AxisInfo { name: "input.amplitude".into(), label: "$a$".into(), values: a },
            AxisInfo { name: "input.omega".into(), label: "$w$".into(), values: b },
        ],
        columns: vec![
            Column::number("theta", "t"),
            Column::number("measured_rate", "m"),
            Column::flag("theta_verified", "v"),
        ],
        total_points: 6,
        shard: None,
        table: Default::default(),
        points,
    }
}

#[test]
fn sweep_figure_has_one_curve_per_column_and_group() {
    let r = two_axis_result();
    let f = sweep_figure(&r, None, &["theta", "measured_rate"]).unwrap();
    // theta and the measured rate on one y axis, one curve per value of the other axis, axes
    // and legend named by the spec's labels
    assert!(f.below.is_empty(), "one axis");
    let lines: Vec<&Element> = f.elements.iter().filter(|e| matches!(e, Element::Line { .. })).collect();
    assert_eq!(lines.len(), 4, "2 columns x 2 values of the other axis");
    if let Element::Line { pts, label, .. } = lines[0] {
        assert_eq!(pts, &vec![(1.0, 10.0), (2.0, 20.0), (3.0, 30.0)]);
        assert_eq!(label, "t, $w$ = 10");
    }
    assert_eq!((f.x_label.as_str(), f.y_label.as_str()), ("$a$", "convergence exponent"));
    // negative control: an axis without a label is named by its parameter
    let mut unlabelled = r.clone();
    unlabelled.axes[0].label.clear();
    assert_eq!(sweep_figure(&unlabelled, None, &["theta"]).unwrap().x_label, "input.amplitude");
    let f = sweep_figure(&r, Some("input.omega"), &["theta"]).unwrap();
    assert_eq!(f.elements.iter().filter(|e| matches!(e, Element::Line { .. })).count(), 3);
    assert!(matches!(sweep_figure(&r, Some("plant.A[0][0]"), &["theta"]), Err(FigureError::UnknownAxis { .. })));
    assert!(
        matches!(sweep_figure(&r, None, &["theta_verified"]), Err(FigureError::UnknownColumn { .. })),
        "flags are not plotted"
    );
}
