//! `--format pgf` equivalent: every figure is also written as pgfplots code (`.tex`) and CSV.
//! The code is ASCII, balanced and has one `\addplot` per element; when `pdflatex` and
//! pgfplots are installed (Debian: texlive-latex-base, texlive-pictures), it must compile.
use bounds::{assemble, ThetaSettings};
use moreau::figures::{pgf, psi};
use std::process::Command;

fn psi_figure() -> moreau::figures::Figure {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/worked-example.toml");
    let sys = model::load(std::path::Path::new(path)).unwrap();
    let rep = assemble(&sys, &ThetaSettings::bound_only()).unwrap();
    psi::from_report(&rep)
}

/// Compiles `tex` (a figure's pgfplots code) in a minimal document when pdflatex is installed:
/// the folder and a function that runs pdflatex on a file in it; `None` (and a note) without it.
fn latex(tex: &str) -> Option<(tempfile::TempDir, impl Fn(&str) -> std::process::Output)> {
    let have_latex = Command::new("pdflatex").arg("--version").output().map(|o| o.status.success()).unwrap_or(false);
    if !have_latex {
        eprintln!("pdflatex not installed: compile step skipped");
        return None;
    }
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("fig.tex"), tex).unwrap();
    let doc = "\\documentclass{article}\n\\usepackage{pgfplots}\n\\pgfplotsset{compat=1.11}\n\\begin{document}\n\\input{fig.tex}\n\\end{document}\n";
    std::fs::write(dir.path().join("doc.tex"), doc).unwrap();
    let path = dir.path().to_path_buf();
    let run = move |name: &str| {
        Command::new("pdflatex")
            .args(["-interaction=nonstopmode", "-halt-on-error", name])
            .current_dir(&path)
            .output()
            .unwrap()
    };
    let out = run("doc.tex");
    assert!(
        out.status.success() && dir.path().join("doc.pdf").exists(),
        "pdflatex failed:\n{}",
        String::from_utf8_lossy(&out.stdout).lines().rev().take(25).collect::<Vec<_>>().join("\n")
    );
    Some((dir, run))
}

#[test]
fn sweep_figure_as_pgfplots_has_one_axis_with_the_spec_labels_and_compiles_when_latex_is_present() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/sweeps/amplitude/sweep.json");
    let r = moreau::sweep::SweepResult::read(std::path::Path::new(path)).unwrap();
    let f = moreau::figures::sweep::sweep_figure(&r, None, &["theta", "theta_best", "measured_rate"]).unwrap();
    assert!(f.below.is_empty(), "every bound and the measured exponent on one axis");
    let tex = pgf::to_pgf(&f);
    assert!(tex.is_ascii());
    assert_eq!(tex.matches("\\begin{axis}").count(), 1);
    assert_eq!(tex.matches('{').count(), tex.matches('}').count(), "unbalanced braces");
    assert_eq!(tex.matches("\\addplot").count(), f.elements.len());
    assert!(pgf::to_csv(&f).lines().count() > 3 * 9);
    // the spec's TeX labels as written, not code names
    assert!(tex.contains("xlabel={$a$}"), "the axis label of the spec");
    assert!(tex.contains("\\addlegendentry{$\\theta_{\\mathrm{best}}$}"), "the column's TeX name");
    assert!(!tex.contains("theta\\_best") && !tex.contains("measured\\_rate"), "code names in the figure");
    latex(&tex);
}

#[test]
fn psi_figure_as_pgfplots_is_ascii_balanced_and_compiles_when_latex_is_present() {
    let f = psi_figure();
    let tex = pgf::to_pgf(&f);
    assert!(tex.is_ascii(), "non-ASCII in the pgf code");
    assert_eq!(tex.matches('{').count(), tex.matches('}').count(), "unbalanced braces");
    assert_eq!(tex.matches("\\addplot").count(), f.elements.len());
    assert!(tex.contains("\\psi") && tex.contains("\\gamma") && tex.contains("\\begin{axis}"));
    let csv = pgf::to_csv(&f);
    assert!(csv.lines().count() > 400 && csv.starts_with("element,label,x,y"));

    let Some((dir, run)) = latex(&tex) else { return };
    // Negative control: a broken figure (an unescaped special character) must not compile.
    std::fs::write(dir.path().join("fig.tex"), tex.replacen("\\addlegendentry{", "\\addlegendentry{50% & #", 1))
        .unwrap();
    assert!(!run("doc.tex").status.success(), "a broken pgf file compiled: the check cannot fail");
}

#[test]
fn psi_figure_of_a_report_draws_the_sharper_certified_bounds_as_levels() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/worked-example.toml");
    let sys = model::load(std::path::Path::new(path)).unwrap();
    let rep = assemble(&sys, &ThetaSettings::bound_only()).unwrap();
    let f = psi::from_report(&rep);
    let level = |prefix: &str| {
        f.elements.iter().find_map(|e| match e {
            moreau::figures::Element::Line { label, pts, .. } if label.starts_with(prefix) => Some(pts.clone()),
            _ => None,
        })
    };
    // theta_star and the best bound beyond the paper, verified and below the paper's theta
    assert!(rep.theta_star_verified && rep.theta_star < rep.theta);
    let star = level("θ* =").expect("theta_star level");
    assert!(star.iter().all(|p| p.1 == rep.theta_star) && star[0].0 == 0.0 && star[1].0 > rep.gamma_inf);
    let best = level(match rep.theta_best_method {
        "theta_engaged" => "θ_{eng} =",
        _ => "θ_{prof} =",
    })
    .expect("best-bound level");
    assert!(best.iter().all(|p| p.1 == rep.theta_best) && rep.theta_best < rep.theta_star);
    // negative control: without the verified flags no level is drawn
    let mut unverified = rep.clone();
    unverified.theta_star_verified = false;
    unverified.theta_best_verified = false;
    let g = psi::from_report(&unverified);
    assert!(g.elements.len() + 2 == f.elements.len(), "{} vs {}", g.elements.len(), f.elements.len());
}

#[test]
fn every_figure_kind_as_pgfplots_is_ascii_and_compiles_when_latex_is_present() {
    let load = |name: &str| {
        model::load(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(name)).unwrap()
    };
    let mut figs = vec![psi_figure()];
    for name in ["worked-example.toml", "ellipse-p2.toml"] {
        let sys = load(name);
        let s = ThetaSettings::bound_only();
        let orbit = bounds::orbit::EtaOrbit::new(&sys, &s.orbit).unwrap();
        let tube = bounds::tube::OutputTube::new(&sys, &s.tube).unwrap();
        let z = moreau::figures::tube::periodic_z(&sys, 200).unwrap();
        figs.push(moreau::figures::tube::tube_figure(&sys, &orbit, &tube, &z));
    }
    let settings = moreau::figures::trajectory::TrajectorySettings { t_end: Some(10.0), ..Default::default() };
    let (yz, x) = moreau::figures::trajectory::trajectory_figures(&load("worked-example.toml"), &settings).unwrap();
    figs.extend([yz, x]);
    for f in &figs {
        let tex = pgf::to_pgf(f);
        assert!(tex.is_ascii() && !tex.contains('?'), "non-ASCII or unmapped character in:\n{tex}");
        assert_eq!(tex.matches('{').count(), tex.matches('}').count(), "unbalanced braces");
        latex(&tex);
    }
}
