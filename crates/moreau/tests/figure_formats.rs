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
