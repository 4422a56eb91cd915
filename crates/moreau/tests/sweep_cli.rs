//! `moreau sweep`, `moreau merge`, `moreau figure` end to end with the real theta evaluator:
//! the committed example reproduces, shards merge to the unsharded table, bad input gives a
//! one-line error, exit code 2 and no output.
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().unwrap()
}

fn moreau(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_moreau")).args(args).current_dir(root()).output().unwrap()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn assert_one_line_error(o: &Output, needle: &str) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "stderr: {err}");
    assert_eq!(err.lines().count(), 1, "one line: {err}");
    assert!(err.starts_with("error: ") && err.contains(needle), "expected `{needle}` in: {err}");
}

/// The table with every value of magnitude below `1e-3` replaced by `tiny`. Those are theta
/// and theta_prof at the two smallest amplitudes, where nothing is certified and theta sits at
/// `psi(0)`, a few `1e-6` above 0 from a `beta` of about `1e-10`: the interior-point method's
/// stopping point there moves their third digit between a debug and a release build. Every
/// other number must match to the printed digits. Cells are split at `&` (LaTeX) and `|`
/// (Markdown).
fn blank_tiny(text: &str) -> String {
    let tiny = |v: f64| v != 0.0 && v.abs() < 1e-3;
    let blank = |cell: &str| {
        let t = cell.trim().trim_end_matches("\\\\").trim();
        match t.parse::<f64>() {
            Ok(v) if tiny(v) => cell.replacen(t, "tiny", 1),
            _ => cell.to_string(),
        }
    };
    text.lines()
        .map(|line| {
            let sep = if line.contains(" & ") { "&" } else { "|" };
            line.split(sep).map(blank).collect::<Vec<_>>().join(sep)
        })
        .collect::<Vec<_>>()
        .join("\n")
}

#[test]
fn blanking_keeps_every_value_above_the_noise_level() {
    let tex = "0.250 & 1.06e-5 & -5.14e-2 & 2.5e3 \\\\";
    assert_eq!(blank_tiny(tex), "0.250 & tiny & -5.14e-2 & 2.5e3 \\\\");
    assert_eq!(blank_tiny("| 0.250 | 6.57e-6 | -0.0514 |"), "| 0.250 | tiny | -0.0514 |");
    // negative control: a changed value above the noise level still differs
    assert_ne!(blank_tiny("| -0.0514 |"), blank_tiny("| -0.0515 |"));
    assert_ne!(blank_tiny("1 & -5.14e-2 \\\\"), blank_tiny("1 & -5.15e-2 \\\\"));
}

/// Compiles a LaTeX table in a minimal document with booktabs and siunitx when pdflatex and
/// siunitx are installed (Debian: texlive-latex-base, texlive-science); `None` (and a note)
/// otherwise, `Some(success)` when it ran.
fn compile_table(tex: &str) -> Option<bool> {
    let have = |f: &str| Command::new("kpsewhich").arg(f).output().map(|o| o.status.success()).unwrap_or(false);
    if !(have("siunitx.sty") && have("booktabs.sty")) {
        eprintln!("pdflatex with siunitx and booktabs not installed: compile step skipped");
        return None;
    }
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("t.tex"), tex).unwrap();
    let doc = "\\documentclass{article}\n\\usepackage{booktabs,siunitx}\n\\begin{document}\n\\input{t.tex}\n\\end{document}\n";
    std::fs::write(dir.path().join("doc.tex"), doc).unwrap();
    let o = Command::new("pdflatex")
        .args(["-interaction=nonstopmode", "-halt-on-error", "doc.tex"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    if !o.status.success() {
        eprintln!("{}", String::from_utf8_lossy(&o.stdout).lines().rev().take(20).collect::<Vec<_>>().join("\n"));
    }
    Some(o.status.success())
}

#[test]
fn the_committed_latex_table_uses_siunitx_columns_and_compiles_when_latex_is_present() {
    let tex = std::fs::read_to_string(root().join("examples/sweeps/amplitude/sweep.tex")).unwrap();
    assert!(tex.contains("\\begin{tabular}{S[table-format=") && tex.contains("needs \\usepackage{booktabs,siunitx}"));
    // one notation per column: theta is scientific in every row, the path bound fixed in every row
    let rows: Vec<Vec<&str>> = tex
        .lines()
        .filter(|l| l.ends_with("\\\\") && !l.starts_with('{'))
        .map(|l| l.trim_end_matches("\\\\").split('&').map(str::trim).collect())
        .collect();
    assert_eq!(rows.len(), 10);
    assert!(rows.iter().all(|r| r[1].contains('e')), "theta column mixes notations");
    assert!(rows.iter().all(|r| !r[7].contains('e')), "path column mixes notations");
    if let Some(ok) = compile_table(&tex) {
        assert!(ok, "the committed table does not compile");
        // negative control: a column option siunitx does not know is an error
        let broken = tex.replacen("S[table-format=", "S[table-fromat=", 1);
        assert_eq!(compile_table(&broken), Some(false), "a broken table compiled");
    }
}

#[test]
fn example_sweep_reproduces_the_committed_latex_table() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("amp");
    let o = moreau(&["sweep", "examples/sweeps/amplitude.toml", "--out", s(&out), "--quiet", "--threads", "2"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in ["sweep.tex", "sweep.md"] {
        let fresh = blank_tiny(&std::fs::read_to_string(out.join(f)).unwrap());
        let reference = blank_tiny(&std::fs::read_to_string(root().join("examples/sweeps/amplitude").join(f)).unwrap());
        assert_eq!(fresh, reference, "{f} differs from the committed reference: if the change of theta is intended, regenerate with `moreau sweep examples/sweeps/amplitude.toml --out examples/sweeps/amplitude --fresh`");
    }
    // the bound holds where it is verified: theta >= measured exponent (both rates of decay)
    let r = moreau::sweep::SweepResult::read(&out.join("sweep.json")).unwrap();
    let col = |n: &str| r.columns.iter().position(|c| c.name == n).unwrap();
    for p in &r.points {
        if let (moreau::sweep::Cell::Num(theta), moreau::sweep::Cell::Num(rate)) =
            (&p.cells[col("theta")], &p.cells[col("measured_rate")])
        {
            assert!(theta >= rate, "point {}: theta {theta} below the measured exponent {rate}", p.index);
        }
    }
}

const SMALL: &str = "name = \"small\"\nmodel = \"MODEL\"\n[[axis]]\nparameter = \"input.amplitude\"\nvalues = [1.0, 2.0, 4.0]\n[evaluate]\nmeasure = false\n";

fn small_spec(dir: &Path, body: &str) -> PathBuf {
    let p = dir.join("spec.toml");
    std::fs::write(&p, body.replace("MODEL", s(&root().join("examples/worked-example.toml")))).unwrap();
    p
}

#[test]
fn shards_from_the_cli_merge_to_the_unsharded_table() {
    let tmp = tempfile::tempdir().unwrap();
    let spec = small_spec(tmp.path(), SMALL);
    let full = tmp.path().join("full");
    assert!(moreau(&["sweep", s(&spec), "--out", s(&full), "-q"]).status.success());
    let shards = tmp.path().join("shards");
    for k in ["0/2", "1/2"] {
        let o = moreau(&["sweep", s(&spec), "--out", s(&shards), "--shard", k, "-q"]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    let merged = tmp.path().join("merged");
    let o = moreau(&["merge", s(&shards), "--out", s(&merged)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for f in ["sweep.json", "sweep.csv", "sweep.md", "sweep.tex"] {
        assert_eq!(std::fs::read(full.join(f)).unwrap(), std::fs::read(merged.join(f)).unwrap(), "{f}");
    }
    // a merge of shards of different specs is refused and writes nothing
    let other = small_spec(&tmp.path().join("o").tap_mkdir(), &SMALL.replace("4.0", "5.0"));
    let oshards = tmp.path().join("oshards");
    assert!(moreau(&["sweep", s(&other), "--out", s(&oshards), "--shard", "1/2", "-q"]).status.success());
    let bad = tmp.path().join("bad");
    let o = moreau(&[
        "merge",
        s(&shards.join("sweep-shard-0-of-2.json")),
        s(&oshards.join("sweep-shard-1-of-2.json")),
        "--out",
        s(&bad),
    ]);
    assert_one_line_error(&o, "shards of different specs");
    assert!(!bad.exists());
}

trait TapMkdir {
    fn tap_mkdir(self) -> Self;
}
impl TapMkdir for PathBuf {
    fn tap_mkdir(self) -> Self {
        std::fs::create_dir_all(&self).unwrap();
        self
    }
}

#[test]
fn bad_sweep_input_gives_one_line_errors_and_no_output() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let cases = [
        (SMALL.replace("input.amplitude", "plant.A[0][7]"), "outside the 2x2 matrix"),
        (SMALL.replace("input.amplitude", "plant.K[0][0]"), "`plant.K[0][0]`: unknown parameter"),
        (SMALL.replace("values = [1.0, 2.0, 4.0]", "range = { from = 1.0, to = 0.0, step = 0.1 }"), "empty range"),
        (SMALL.replace("measure = false", "measure = \"yes\""), "evaluate.measure"),
    ];
    for (body, needle) in cases {
        let spec = small_spec(tmp.path(), &body);
        assert_one_line_error(&moreau(&["sweep", s(&spec), "--out", s(&out), "-q"]), needle);
        assert!(!out.exists(), "nothing written for `{needle}`");
    }
    let spec = small_spec(tmp.path(), SMALL);
    assert_one_line_error(&moreau(&["sweep", s(&spec), "--out", s(&out), "--shard", "2/2"]), "bad shard `2/2`");
    assert_one_line_error(&moreau(&["sweep", s(&spec), "--out", s(&out), "--digits", "0"]), "--digits 0");
    assert!(!out.exists());
    // a good table is not replaced by another spec's
    assert!(moreau(&["sweep", s(&spec), "--out", s(&out), "-q"]).status.success());
    let before = std::fs::read(out.join("sweep.tex")).unwrap();
    let other = small_spec(tmp.path(), &SMALL.replace("4.0", "6.0"));
    assert_one_line_error(&moreau(&["sweep", s(&other), "--out", s(&out), "-q"]), "different sweep");
    assert_eq!(std::fs::read(out.join("sweep.tex")).unwrap(), before);
}

#[test]
fn figures_are_written_as_svg_and_png_with_text() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("fig");
    for kind in ["psi", "tube", "trajectory"] {
        let o = moreau(&["figure", kind, "examples/worked-example.toml", "--out", s(&out)]);
        assert!(o.status.success(), "{kind}: {}", String::from_utf8_lossy(&o.stderr));
    }
    for (stem, text) in
        [("fig-psi1", "ψ(γ)"), ("fig-loop", "Orbit η"), ("trajectory-yz", "y = C x"), ("trajectory-x", "x₁")]
    {
        let svg = std::fs::read_to_string(out.join(format!("{stem}.svg"))).unwrap();
        assert!(svg.contains("<text") && svg.contains(text), "{stem}.svg lacks `{text}`");
        // the font travels with the file (a data URL of DejaVu Sans), not just its name
        assert!(svg.contains("@font-face{font-family:\"DejaVu Sans\"") && svg.contains("data:font/ttf;base64,AAEAAA"));
        let png = std::fs::read(out.join(format!("{stem}.png"))).unwrap();
        assert!(png.starts_with(b"\x89PNG") && png.len() > 10_000, "{stem}.png");
    }
    let o = moreau(&["figure", "sweep", "examples/sweeps/amplitude", "--out", s(&out)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.join("sweep-theta-theta_best-measured_rate.svg").exists());
    // the bounds (about -0.02) and the measured exponent (about -0.3) on one axis, whose ratio
    // the reader compares, named by the spec's and the columns' labels
    let tex = std::fs::read_to_string(out.join("sweep-theta-theta_best-measured_rate.tex")).unwrap();
    assert_eq!(tex.matches("\\begin{axis}").count(), 1, "{tex}");
    assert!(tex.contains("ylabel={convergence exponent}") && tex.contains("xlabel={$a$}"), "{tex}");
    for entry in ["{$\\theta$}", "{$\\theta_{\\mathrm{best}}$}", "{measured exponent}"] {
        assert!(tex.contains(&format!("\\addlegendentry{entry}")), "no legend entry {entry}: {tex}");
    }
    let o = moreau(&["figure", "sweep", "examples/sweeps/amplitude", "--out", s(&out), "--columns", "theta,nonsense"]);
    assert_one_line_error(&o, "no numeric column `nonsense`");
}
