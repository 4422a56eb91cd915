//! `moreau figure --format pdf` (vector PDF, font embedded) and `--dpi` (PNG rasterised from the
//! SVG at dpi/96): the files are what they claim, and bad values are refused with no output.
use std::path::Path;
use std::process::Command;

fn moreau(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_moreau"))
        .args(args)
        .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .output()
        .unwrap()
}

/// Width and height from a PNG's IHDR chunk.
fn png_size(bytes: &[u8]) -> (u32, u32) {
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "not a PNG");
    let be = |b: &[u8]| u32::from_be_bytes([b[0], b[1], b[2], b[3]]);
    (be(&bytes[16..20]), be(&bytes[20..24]))
}

#[test]
fn pdf_is_vector_with_the_font_embedded_and_dpi_scales_the_png() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("fig");
    let o = moreau(&[
        "figure",
        "psi",
        "examples/worked-example.toml",
        "--format",
        "pdf,png",
        "--dpi",
        "192",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let files: Vec<_> = std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().path()).collect();
    let pdf = files.iter().find(|p| p.extension().is_some_and(|e| e == "pdf")).expect("a PDF");
    let bytes = std::fs::read(pdf).unwrap();
    assert!(bytes.starts_with(b"%PDF-"), "not a PDF");
    let text = String::from_utf8_lossy(&bytes);
    assert!(text.contains("/FontFile2") && text.contains("DejaVuSans"), "font not embedded");
    assert!(!text.contains("/Subtype /Image"), "the PDF must not be a raster image");
    let png = files.iter().find(|p| p.extension().is_some_and(|e| e == "png")).expect("a PNG");
    // 900 x 600 CSS pixels at 192 dpi: twice as many pixels each way
    assert_eq!(png_size(&std::fs::read(png).unwrap()), (1800, 1200));
    assert!(!files.iter().any(|p| p.extension().is_some_and(|e| e == "svg")), "only the formats asked for");
}

#[test]
fn bad_dpi_is_refused_and_leaves_no_output() {
    let dir = tempfile::tempdir().unwrap();
    for dpi in ["0", "-5", "1e9", "nan"] {
        let out = dir.path().join(format!("fig{dpi}"));
        let o = moreau(
            &["figure", "psi", "examples/worked-example.toml", "--format", "png", "--dpi", dpi, "--out"]
                .into_iter()
                .chain([out.to_str().unwrap()])
                .collect::<Vec<_>>(),
        );
        assert!(!o.status.success(), "--dpi {dpi} accepted");
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(err.contains("dpi") && !err.contains("panicked"), "--dpi {dpi}: {err}");
        assert!(!Path::new(&out).exists(), "--dpi {dpi} left {}", out.display());
    }
}

#[test]
fn trajectory_axes_carry_the_model_units() {
    let base =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/worked-example.toml")).unwrap();
    let settings = moreau::figures::trajectory::TrajectorySettings { t_end: Some(1.0), ..Default::default() };
    let sys = model::parse_str(&format!("{base}\n[signals]\ny = \"rad\"\nt = \"s\"\n")).unwrap();
    let (yz, xf) = moreau::figures::trajectory::trajectory_figures(&sys, &settings).unwrap();
    assert_eq!((yz.x_label.as_str(), yz.y_label.as_str(), xf.x_label.as_str()), ("t (s)", "y, z (rad)", "t (s)"));
    // control: without [signals] no unit is invented
    let plain = model::parse_str(&base).unwrap();
    let (yz, _) = moreau::figures::trajectory::trajectory_figures(&plain, &settings).unwrap();
    assert_eq!((yz.x_label.as_str(), yz.y_label.as_str()), ("t", "y, z"));
}

#[test]
fn size_presets_set_the_page_in_points_and_width_height_override_them() {
    let dir = tempfile::tempdir().unwrap();
    let page = |extra: &[&str], name: &str| {
        let out = dir.path().join(name);
        let mut args = vec!["figure", "psi", "examples/worked-example.toml", "--format", "pdf,png", "--out"];
        args.push(out.to_str().unwrap());
        args.extend(extra);
        let o = moreau(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let pdf = String::from_utf8_lossy(&std::fs::read(out.join("fig-psi1.pdf")).unwrap()).to_string();
        let media = pdf.split("/MediaBox [").nth(1).unwrap().split(']').next().unwrap().trim().to_string();
        (media, png_size(&std::fs::read(out.join("fig-psi1.png")).unwrap()))
    };
    // 3.5 in and 7.16 in wide pages; the PNG at 96 dpi has as many pixels as the page has points
    assert_eq!(page(&["--size", "column"], "a"), ("0 0 252 216".to_string(), (252, 216)));
    assert_eq!(page(&["--size", "two-column"], "b").0, "0 0 515 258");
    assert_eq!(page(&["--size", "column", "--height", "180"], "c").0, "0 0 252 180");
    // control: without a preset the page is the old default
    assert_eq!(page(&[], "d").0, "0 0 900 600");
    let o =
        moreau(&["figure", "psi", "examples/worked-example.toml", "--size", "column", "--width", "100", "--out", "x"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success()
            && err.contains("--width 100")
            && !Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../x")).exists(),
        "{err}"
    );
}

#[test]
fn tube_axes_carry_the_model_units_and_a_subscripted_xi_inf() {
    let base =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/worked-example.toml")).unwrap();
    let fig = |text: &str| {
        let sys = model::parse_str(text).unwrap();
        let s = bounds::ThetaSettings::bound_only();
        let orbit = bounds::orbit::EtaOrbit::new(&sys, &s.orbit).unwrap();
        let tube = bounds::tube::OutputTube::new(&sys, &s.tube).unwrap();
        let z = moreau::figures::tube::periodic_z(&sys, 200).unwrap();
        moreau::figures::tube::tube_figure(&sys, &orbit, &tube, &z)
    };
    let f = fig(&format!("{base}\n[signals]\ny = \"rad\"\nt = \"s\"\n"));
    assert_eq!((f.x_label.as_str(), f.y_label.as_str()), ("t (s)", "z, η_T (rad)"));
    assert!(f.title.contains("Ξ_∞") && !f.title.contains("Ξ∞"), "{}", f.title);
    // the subscript is drawn as one: no `_` and a separate `∞` text in the SVG
    let svg = moreau::figures::canvas::to_svg(&f).unwrap();
    assert!(svg.contains(">∞") || svg.contains("> ∞") || svg.contains("\n∞"), "∞ not a text of its own");
    assert!(!svg.contains("Ξ_") && !svg.contains("Ξ∞"));
    // control: without [signals] no unit is invented
    let f = fig(&base);
    assert_eq!((f.x_label.as_str(), f.y_label.as_str()), ("t", "z, η_T"));
}
