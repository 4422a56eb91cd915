//! Figures at column width: every figure kind rendered at the size presets (`--size column`,
//! `--size two-column`) and at 360 x 240, its text boxes (as usvg lays them out with the
//! embedded DejaVu Sans, [`canvas::text_boxes`]) checked against each other and the page
//! ([`canvas::layout_defects`]); the text is 8-9 pt at the presets. Negative controls: the
//! checker flags overlapping and clipped text in a real rendering. The stacked figures of
//! `moreau diagnose --size column|two-column` likewise, with a y scale (two tick labels) in every
//! panel and the title 8-9 pt however tall the stack.
use bounds::{assemble, ThetaSettings};
use moreau::figures::canvas::{self, SizePreset, TextBox};
use moreau::figures::{diagnosis, psi, sweep, trajectory, tube, Element, Figure};
use moreau::sweep::table::AxisInfo;
use moreau::sweep::{Cell, Column, PointRecord, SweepResult};
use std::path::Path;

fn example(name: &str) -> model::System {
    model::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(name)).unwrap()
}

/// A two-axis sweep whose axes carry TeX labels (as a spec's `label` writes them).
fn two_axis_sweep() -> SweepResult {
    let (a, b) = (vec![0.5, 1.0, 2.0, 4.0], vec![-3.0, -2.25, -1.5]);
    let mut points = vec![];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            points.push(PointRecord {
                index: 3 * i + j,
                params: vec![*x, *y],
                cells: vec![Cell::Num(-0.01 * x * y.abs()), Cell::Num(-0.3 + 0.01 * y), Cell::Flag(*x > 0.7)],
                status: "ok".into(),
            });
        }
    }
    SweepResult {
        name: "theta vs gap size and stiffness".into(),
        spec_hash: "0".into(),
        model: "m".into(),
        evaluator: "theta".into(),
        axes: vec![
            AxisInfo { name: "theta.scale".into(), label: "$\\delta$ (m)".into(), values: a },
            AxisInfo { name: "plant.A[1][0]".into(), label: "$A_{21}$".into(), values: b },
        ],
        columns: vec![
            Column::number("theta", "$\\theta$"),
            Column::number("measured_rate", "measured"),
            Column::flag("certified", "certified"),
        ],
        total_points: 12,
        shard: None,
        table: Default::default(),
        points,
    }
}

/// Every figure kind of `moreau figure` and `moreau simulate`, with titles (the worst case).
fn every_figure() -> Vec<(String, Figure)> {
    let worked = example("worked-example.toml");
    let mut figs = vec![];
    let rep = assemble(&worked, &ThetaSettings::bound_only()).unwrap();
    figs.push(("psi".to_string(), psi::from_report(&rep)));
    for (name, sys) in [("tube-p1", &worked), ("tube-p2", &example("ellipse-p2.toml"))] {
        let settings = ThetaSettings::bound_only();
        let orbit = bounds::orbit::EtaOrbit::new(sys, &settings.orbit).unwrap();
        let t = bounds::tube::OutputTube::new(sys, &settings.tube).unwrap();
        let z = tube::periodic_z(sys, 500).unwrap();
        figs.push((name.to_string(), tube::tube_figure(sys, &orbit, &t, &z)));
    }
    let (yz, x) = trajectory::trajectory_figures(
        &worked,
        &trajectory::TrajectorySettings { t_end: Some(20.0), ..Default::default() },
    )
    .unwrap();
    figs.push(("trajectory-yz".to_string(), yz));
    figs.push(("trajectory-x".to_string(), x));
    let tr = dynamics::trajectory::simulate_model(&worked, 0.016000000000000014, 1000, 1).unwrap();
    figs.push((
        "simulate".to_string(),
        trajectory::simulation_figure(&worked, &tr, "catching-up, h = 0.016000000000000014"),
    ));
    let amp =
        SweepResult::read(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/sweeps/amplitude/sweep.json"))
            .unwrap();
    figs.push((
        "sweep".to_string(),
        sweep::sweep_figure(&amp, None, &["theta", "theta_best", "measured_rate"]).unwrap(),
    ));
    figs.push((
        "sweep-two-axes".to_string(),
        sweep::sweep_figure(&two_axis_sweep(), None, &["theta", "measured_rate"]).unwrap(),
    ));
    figs
}

/// The diagnosis of a recording of the BAM servo (computed once for the tests of this file).
fn servo_diagnosis() -> &'static discovery::Report {
    use moreau::commands::diagnose::{diagnose, DiagnoseOptions, RecordingSource};
    static REPORT: std::sync::OnceLock<discovery::Report> = std::sync::OnceLock::new();
    REPORT.get_or_init(|| {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        diagnose(
            &moreau::commands::Source::File(root.join("examples/real/bam-xl330-kp100.toml")),
            &RecordingSource::File(root.join("data/bam-servo/xl330-kp100-sin_sin.csv")),
            &DiagnoseOptions::default(),
        )
        .unwrap()
        .report
    })
}

/// The figures of `moreau diagnose` (stacked panels, at their own sizes: no `--size`) on a
/// recording of the BAM servo.
fn diagnosis_figures() -> Vec<(String, Figure)> {
    moreau::figures::diagnosis::figures(servo_diagnosis())
}

#[test]
fn the_diagnosis_figures_at_the_column_presets_have_no_overlapping_or_clipped_text() {
    // `moreau diagnose --size column|two-column`: fit, residual and the zooms, each a stack
    let mut bad = vec![];
    let mut total = 0;
    for preset in [SizePreset::Column, SizePreset::TwoColumn] {
        let figs = diagnosis::figures_sized(servo_diagnosis(), Some(preset));
        assert!(figs.len() >= 3, "fit, residual and at least one zoom");
        for (name, f) in &figs {
            assert_eq!(f.size, diagnosis::stack_size(preset, f.panels().len()), "{name}");
            assert_eq!(f.size.0, preset.size().0, "{name}: the preset's width");
            let boxes = canvas::text_boxes(f).unwrap();
            assert!(boxes.len() >= 10, "{name} at {preset:?}: only {} texts", boxes.len());
            assert_eq!(boxes.iter().filter(|b| b.text.trim() == "t (s)").count(), 1, "{name}");
            let d = canvas::layout_defects(&boxes, f.size);
            total += d.len();
            bad.extend(d.into_iter().map(|d| format!("{name} {preset:?}: {d}")));
            // every panel has a y scale to read: at least two tick labels, right-aligned at the
            // panels' common left edge (each counted for the panel whose y label is nearest)
            // (the y labels' heights: their rotated lines, merged where they stand side by side)
            let mut rotated: Vec<(f64, f64)> = boxes
                .iter()
                .filter(|b| b.text.chars().count() >= 4 && b.y1 - b.y0 > b.x1 - b.x0)
                .map(|b| (b.y0, b.y1))
                .collect();
            rotated.sort_by(|a, b| a.0.total_cmp(&b.0));
            let mut y_labels: Vec<(f64, f64)> = vec![];
            for (y0, y1) in rotated {
                match y_labels.last_mut() {
                    Some(l) if y0 < l.1 => l.1 = l.1.max(y1),
                    _ => y_labels.push((y0, y1)),
                }
            }
            assert_eq!(y_labels.len(), f.panels().len(), "{name}: one y label per panel");
            let numbers: Vec<&TextBox> =
                boxes.iter().filter(|b| b.text.trim().replace('−', "-").parse::<f64>().is_ok()).collect();
            let shared = |x: f64| numbers.iter().filter(|b| (b.x1 - x).abs() < 0.6).count();
            let edge = numbers.iter().map(|b| b.x1).max_by_key(|&x| shared(x)).unwrap();
            let mut ticks = vec![0; y_labels.len()];
            for b in numbers.iter().filter(|b| (b.x1 - edge).abs() < 0.6) {
                let d = |k: usize| (0.5 * (y_labels[k].0 + y_labels[k].1) - 0.5 * (b.y0 + b.y1)).abs();
                ticks[(0..y_labels.len()).min_by(|&i, &j| d(i).total_cmp(&d(j))).unwrap()] += 1;
            }
            assert!(ticks.iter().all(|&k| k >= 2), "{name} at {preset:?}: y tick labels per panel {ticks:?}");
            // the text 8-9 pt, the title too, however tall the stack
            for b in &boxes {
                // tick labels (never rotated) by their height: `−1` is wider than tall
                let pt = if b.text.chars().count() <= 3 { (b.y1 - b.y0) / 1.164 } else { text_pt(b) };
                assert!((7.5..=9.05).contains(&pt), "{name} at {preset:?}: `{}` is {pt:.2} pt", b.text);
            }
            if std::env::var_os("MOREAU_FIGURE_DUMP").is_some() {
                let png = canvas::to_png_at_dpi(f, 200.0).unwrap();
                std::fs::write(format!("/tmp/diagnose-{name}-{}.png", f.size.0), png).unwrap();
            }
        }
    }
    eprintln!("{total} layout defects");
    assert!(bad.is_empty(), "{} layout defects:\n{}", bad.len(), bad.join("\n"));
    // negative control: the same check flags a zoom whose title is one word wider than the column
    let (_, zoom) = diagnosis::figures_sized(servo_diagnosis(), Some(SizePreset::Column))
        .into_iter()
        .find(|(n, _)| n == "zoom-1")
        .expect("a zoom");
    let mut f = zoom;
    f.title = "W".repeat(80);
    assert!(defects(&f).iter().any(|d| d.contains("is not inside")), "clipping not flagged");
}

#[test]
fn the_stacked_diagnosis_figures_have_no_overlapping_or_clipped_text() {
    let figs = diagnosis_figures();
    assert!(figs.len() >= 3, "fit, residual and at least one zoom");
    let mut bad = vec![];
    for (name, f) in &figs {
        assert!(!f.below.is_empty(), "{name}: stacked panels");
        bad.extend(defects(f).into_iter().map(|d| format!("{name}: {d}")));
        // the x-axis label once, under the bottom panel
        let boxes = canvas::text_boxes(f).unwrap();
        assert_eq!(boxes.iter().filter(|b| b.text.trim() == "t (s)").count(), 1, "{name}");
    }
    assert!(bad.is_empty(), "{} layout defects:\n{}", bad.len(), bad.join("\n"));
}

fn sized(f: &Figure, size: (u32, u32)) -> Figure {
    let mut f = f.clone();
    f.size = size;
    f
}

fn defects(f: &Figure) -> Vec<String> {
    canvas::layout_defects(&canvas::text_boxes(f).unwrap(), f.size)
}

#[test]
fn every_figure_kind_at_the_column_presets_has_no_overlapping_or_clipped_text() {
    let sizes = [SizePreset::Column.size(), SizePreset::TwoColumn.size(), (360, 240), (900, 600)];
    assert_eq!(sizes[0], (252, 216));
    assert_eq!(sizes[1].0, 515, "7.16 in");
    let mut bad = vec![];
    let mut total = 0;
    for (name, f) in every_figure() {
        for size in sizes {
            let f = sized(&f, size);
            let boxes = canvas::text_boxes(&f).unwrap();
            assert!(boxes.len() >= 6, "{name} at {size:?}: only {} texts", boxes.len());
            let d = canvas::layout_defects(&boxes, size);
            total += d.len();
            bad.extend(d.into_iter().map(|d| format!("{name} {}x{}: {d}", size.0, size.1)));
        }
    }
    eprintln!("{total} layout defects");
    assert!(bad.is_empty(), "{} layout defects:\n{}", bad.len(), bad.join("\n"));
}

/// The font size of a rendered text in points: the height of its line box across the text (a
/// y label is rotated) is 1.164 em in DejaVu Sans (ascent 0.928 + descent 0.236).
fn text_pt(b: &TextBox) -> f64 {
    let (w, h) = (b.x1 - b.x0, b.y1 - b.y0);
    let em = if b.text.chars().count() <= 2 {
        w.max(h)
    } else if h > w {
        w
    } else {
        h
    };
    em / 1.164
}

#[test]
fn text_is_8_to_9_pt_at_the_presets() {
    // font size from the rendered SVG: the height of a text's line box is 1.164 em in DejaVu
    // Sans (ascent 0.928 + descent 0.236)
    let f = &every_figure()[0].1;
    for preset in [SizePreset::Column, SizePreset::TwoColumn] {
        let boxes = canvas::text_boxes(&sized(f, preset.size())).unwrap();
        for b in &boxes {
            // subscripts are 70 % of their text; everything else 8-9 pt
            let pt = text_pt(b);
            assert!((5.5..=9.05).contains(&pt), "{preset:?}: `{}` is {pt:.2} pt", b.text);
        }
        let main = boxes.iter().filter(|b| (b.y1 - b.y0) / 1.164 >= 7.5).count();
        assert!(main * 2 > boxes.len(), "most text is 8-9 pt");
    }
}

#[test]
fn the_checker_flags_overlapping_and_clipped_text() {
    // the predicate itself
    let b = |text: &str, x0, y0, x1, y1| TextBox { text: text.into(), x0, y0, x1, y1 };
    let d = canvas::layout_defects(&[b("a", 10.0, 10.0, 30.0, 20.0), b("b", 25.0, 15.0, 40.0, 25.0)], (100, 100));
    assert_eq!(d.len(), 1, "{d:?}");
    assert!(
        canvas::layout_defects(&[b("a", 10.0, 10.0, 30.0, 20.0), b("b", 30.0, 10.0, 40.0, 20.0)], (100, 100))
            .is_empty(),
        "touching is not overlapping"
    );
    assert_eq!(canvas::layout_defects(&[b("a", 95.0, 10.0, 105.0, 20.0)], (100, 100)).len(), 1);
    // a real rendering that no layout can fix: marker labels packed closer than their width
    let mut f = Figure::new("packed", "x", "y");
    let pts: Vec<(f64, f64)> = (0..40).map(|k| (k as f64, 0.0)).collect();
    let text = (0..40).map(|k| format!("marker number {k}")).collect();
    f.elements.push(Element::Markers { label: String::new(), pts, text, color: canvas::BLUE });
    let d = defects(&sized(&f, (360, 240)));
    assert!(d.iter().any(|d| d.contains("overlaps `marker number")), "overlap not flagged: {d:?}");
    // and a title of one word wider than the page is clipped
    let mut f = sized(&every_figure()[0].1, SizePreset::Column.size());
    f.title = "W".repeat(80);
    let d = defects(&f);
    assert!(d.iter().any(|d| d.contains("is not inside")), "clipping not flagged: {d:?}");
}

#[test]
fn a_crowded_figure_keeps_its_text_apart_by_wrapping_labels_and_shortening_the_legend() {
    // 20 labelled curves and axis labels longer than the plot, at column width
    let mut f = Figure::new("many curves in a column-width figure", "", "");
    f.x_label = "time since the start of the recording of the servo under test (s)".into();
    f.y_label = "output of the first joint after the backlash, measured by the encoder (rad)".into();
    for k in 0..20 {
        let pts = (0..50).map(|i| (i as f64, (i as f64 * 0.1 + k as f64).sin())).collect();
        let label = format!("curve number {k} (long label)");
        f.elements.push(Element::Line { label, pts, color: canvas::palette(k), dashed: false });
    }
    for size in [SizePreset::Column.size(), SizePreset::TwoColumn.size(), (360, 240)] {
        let f = sized(&f, size);
        let boxes = canvas::text_boxes(&f).unwrap();
        let d = canvas::layout_defects(&boxes, size);
        assert!(d.is_empty(), "{size:?}: {d:?}");
        // at 3.5 in and 360 x 240 the legend does not fit: it says how many entries it leaves out
        let more = boxes.iter().any(|b| b.text.starts_with("+ ") && b.text.ends_with(" more"));
        assert_eq!(more, size != SizePreset::TwoColumn.size(), "{size:?}: `+ k more`");
        if std::env::var_os("MOREAU_FIGURE_DUMP").is_some() {
            std::fs::write(format!("/tmp/crowded-{}.png", size.0), canvas::to_png_at_dpi(&f, 250.0).unwrap()).unwrap();
        }
    }
}
