//! `docs/sweep-spec.md` against the code: every ```toml block marked `# complete spec` is
//! accepted by the spec parser and by `moreau sweep` (as written on one point, and on the
//! whole grid with `[evaluate] measure = false`); blocks that claim to be a committed example
//! are that file verbatim; every `# rejected spec: MESSAGE` block fails with that message (and
//! a misspelt key made here from a complete block is rejected naming the key: the control);
//! every key, axis parameter and column the code accepts is documented, with the equation
//! numbers of `bounds::equations` and the bound directions of `bounds::report::defs`.
use moreau::sweep::theta_eval::{column_names, ThetaEvaluator};
use moreau::sweep::{Evaluator, SweepError, SweepSpec};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().unwrap()
}

fn doc() -> String {
    std::fs::read_to_string(root().join("docs/sweep-spec.md")).expect("docs/sweep-spec.md")
}

/// A fenced block of the page: its language, its text, and whether only blank lines separate
/// it from the block before it.
struct Block {
    lang: String,
    text: String,
    follows_previous: bool,
}

fn blocks(doc: &str) -> Vec<Block> {
    let mut out = Vec::new();
    let mut cur: Option<(String, Vec<&str>)> = None;
    let mut only_blank = false;
    for line in doc.lines() {
        match &mut cur {
            None => {
                if let Some(lang) = line.strip_prefix("```") {
                    cur = Some((lang.trim().to_string(), Vec::new()));
                } else if !line.trim().is_empty() {
                    only_blank = false;
                }
            }
            Some((lang, body)) => {
                if line.trim_end() == "```" {
                    out.push(Block { lang: lang.clone(), text: body.join("\n") + "\n", follows_previous: only_blank });
                    cur = None;
                    only_blank = true;
                } else {
                    body.push(line);
                }
            }
        }
    }
    assert!(cur.is_none(), "unclosed code block in docs/sweep-spec.md");
    out
}

fn first_line(text: &str) -> &str {
    text.lines().next().unwrap_or("")
}

fn complete_specs(doc: &str) -> Vec<String> {
    blocks(doc)
        .into_iter()
        .filter(|b| b.lang == "toml" && first_line(&b.text).starts_with("# complete spec"))
        .map(|b| b.text)
        .collect()
}

/// A directory holding copies of the example models and a `sweeps/` directory for the specs,
/// like `examples/` (so `model = "../worked-example.toml"` resolves as in the repository).
fn sandbox() -> tempfile::TempDir {
    let tmp = tempfile::tempdir().unwrap();
    for e in std::fs::read_dir(root().join("examples")).unwrap() {
        let p = e.unwrap().path();
        if p.is_file() && p.extension().is_some_and(|x| x == "toml") {
            std::fs::copy(&p, tmp.path().join(p.file_name().unwrap())).unwrap();
        }
    }
    std::fs::create_dir(tmp.path().join("sweeps")).unwrap();
    tmp
}

/// `moreau sweep sweeps/NAME.toml --out out-NAME -q ARGS` in `dir`.
fn sweep(dir: &Path, name: &str, text: &str, args: &[&str]) -> Output {
    let spec = format!("sweeps/{name}.toml");
    std::fs::write(dir.join(&spec), text).unwrap();
    let out = format!("out-{name}");
    let mut all = vec!["sweep", spec.as_str(), "--out", out.as_str(), "-q"];
    all.extend_from_slice(args);
    Command::new(env!("CARGO_BIN_EXE_moreau")).args(&all).current_dir(dir).output().unwrap()
}

/// Where the parser resolves `model` of a block without writing it: `examples/sweeps/`.
fn spec_path() -> PathBuf {
    root().join("examples/sweeps/doc-block.toml")
}

#[test]
fn complete_specs_are_accepted_by_the_parser_and_by_moreau_sweep() {
    let doc = doc();
    let specs = complete_specs(&doc);
    assert!(specs.len() >= 6, "only {} `# complete spec` blocks found", specs.len());
    let known = column_names();
    let tmp = sandbox();
    for (k, text) in specs.iter().enumerate() {
        let head = first_line(text);
        // a block that names a committed example is that file, verbatim
        if let Some(rest) = head.split_once("(= ").map(|(_, r)| r) {
            let file = rest.trim_end_matches(')').trim();
            let committed = std::fs::read_to_string(root().join(file)).unwrap();
            let body = text.split_once('\n').unwrap().1;
            assert_eq!(body.trim_end(), committed.trim_end(), "block {k} differs from {file}");
        }
        // the library: spec, [evaluate] and [table] columns
        let spec = SweepSpec::parse(text, &spec_path()).unwrap_or_else(|e| panic!("block {k} ({head}): {e}"));
        ThetaEvaluator::from_table(&spec.evaluate, &spec.path).unwrap_or_else(|e| panic!("block {k}: {e}"));
        for c in spec.table.columns.iter().flatten() {
            assert!(known.contains(&c.as_str()), "block {k}: unknown column {c}");
        }
        let n = spec.total_points();

        // the binary, as written (budget checks included), on point 0 only
        let shard = format!("0/{n}");
        let o = sweep(tmp.path(), &format!("b{k}"), text, &["--shard", &shard]);
        assert_eq!(o.status.code(), Some(0), "block {k}: {}", String::from_utf8_lossy(&o.stderr));
        let csv = std::fs::read_to_string(tmp.path().join(format!("out-b{k}/sweep-shard-0-of-{n}.csv"))).unwrap();
        assert_eq!(csv.lines().count(), 2, "block {k}: {csv}");

        // the binary on the whole grid, bound only
        let mut t: toml::Table = toml::from_str(text).unwrap();
        let ev = t.entry("evaluate").or_insert_with(|| toml::Value::Table(toml::Table::new()));
        ev.as_table_mut().unwrap().insert("measure".into(), toml::Value::Boolean(false));
        let o = sweep(tmp.path(), &format!("g{k}"), &toml::to_string(&t).unwrap(), &[]);
        assert_eq!(o.status.code(), Some(0), "block {k}: {}", String::from_utf8_lossy(&o.stderr));
        let csv = std::fs::read_to_string(tmp.path().join(format!("out-g{k}/sweep.csv"))).unwrap();
        assert_eq!(csv.lines().count(), n + 1, "block {k}");
        assert!(csv.lines().skip(1).all(|l| l.ends_with(",ok")), "block {k}: a point failed:\n{csv}");
        for f in ["sweep.json", "sweep.md", "sweep.tex"] {
            assert!(tmp.path().join(format!("out-g{k}")).join(f).is_file(), "block {k}: no {f}");
        }
    }
}

#[test]
fn rejected_specs_and_a_misspelt_key_fail_naming_the_key() {
    let doc = doc();
    let all = blocks(&doc);
    let tmp = sandbox();
    let mut rejected = 0;
    for (k, b) in all.iter().enumerate() {
        let Some(msg) = first_line(&b.text).strip_prefix("# rejected spec: ") else { continue };
        assert_eq!(b.lang, "toml");
        rejected += 1;
        let o = sweep(tmp.path(), "spec", &b.text, &[]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "block {k}: {err}");
        assert_eq!(err.lines().count(), 1, "block {k}: one line: {err}");
        assert!(err.starts_with("error: ") && err.contains(msg), "block {k}: expected `{msg}` in: {err}");
        assert!(!tmp.path().join("out-spec/sweep.json").exists(), "block {k}: output written");
        // the error shown right after the block is the one the program prints
        if let Some(next) = all.get(k + 1).filter(|n| n.lang == "text" && n.follows_previous) {
            assert_eq!(next.text.trim(), err.trim(), "the error shown after block {k}");
        }
        let lib = SweepSpec::parse(&b.text, &spec_path()).map(|_| ()).unwrap_err().to_string();
        assert!(lib.contains(msg), "block {k}: the parser says {lib}");
    }
    assert!(rejected >= 1, "no `# rejected spec` block in docs/sweep-spec.md");

    // control: a complete block with its first `parameter` misspelt is refused, naming the key
    let good = complete_specs(&doc).into_iter().next().unwrap();
    let bad = good.replacen("parameter =", "paramter =", 1);
    assert_ne!(bad, good);
    match SweepSpec::parse(&bad, &spec_path()) {
        Err(SweepError::UnknownKey { key, .. }) => assert_eq!(key, "axis[0].paramter"),
        other => panic!("misspelt key accepted or refused for another reason: {other:?}"),
    }
    let o = sweep(tmp.path(), "misspelt", &bad, &[]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("unknown key `axis[0].paramter`"), "{err}");
    assert!(!tmp.path().join("out-misspelt/sweep.json").exists());
}

/// The `allowed` list of the error for an unknown key in `text` (or in `[evaluate]`).
fn allowed_keys(text: &str) -> Vec<&'static str> {
    match SweepSpec::parse(text, &spec_path()) {
        Err(SweepError::UnknownKey { allowed, .. }) => allowed.split(", ").collect(),
        other => panic!("expected an unknown key error for {text:?}, got {other:?}"),
    }
}

/// Rows (`| `NAME` | ...`) of the first table under the heading `## TITLE`.
fn rows<'a>(doc: &'a str, title: &str) -> Vec<(&'a str, &'a str)> {
    let start = doc.find(&format!("\n## {title}\n")).unwrap_or_else(|| panic!("no section `{title}`"));
    let section = &doc[start + 1..];
    let section = &section[..section[3..].find("\n## ").map(|e| e + 3).unwrap_or(section.len())];
    section
        .lines()
        .filter_map(|l| {
            let name = l.strip_prefix("| `")?.split_once('`')?.0;
            Some((name, l))
        })
        .collect()
}

#[test]
fn every_key_parameter_and_column_is_documented() {
    let doc = doc();
    let model = "model = \"../worked-example.toml\"\n";
    let axis = "[[axis]]\nparameter = \"input.amplitude\"\n";

    // keys: the code's own `allowed` lists, provoked with an unknown key at each level
    let levels: Vec<(&str, Vec<&str>)> = vec![
        ("Top-level keys", allowed_keys(&format!("{model}zz = 1\n"))),
        ("`[[axis]]`", allowed_keys(&format!("{model}{axis}values = [1.0]\nzz = 1\n"))),
        ("Ranges", allowed_keys(&format!("{model}{axis}range = {{ from = 1, to = 2, count = 2, zz = 1 }}\n"))),
        ("`[table]`", allowed_keys(&format!("{model}{axis}values = [1.0]\n[table]\nzz = 1\n"))),
        ("`[evaluate]`", {
            let t: toml::Table = toml::from_str("zz = 1").unwrap();
            match ThetaEvaluator::from_table(&t, &spec_path()) {
                Err(SweepError::UnknownKey { allowed, .. }) => allowed.split(", ").collect(),
                Err(e) => panic!("{e}"),
                Ok(_) => panic!("[evaluate] zz accepted"),
            }
        }),
    ];
    for (section, keys) in &levels {
        assert!(!keys.is_empty());
        let documented = rows(&doc, section);
        for k in keys {
            if *section == "Ranges" {
                assert!(doc.contains(&format!("`{k}`")), "range key `{k}` is not documented");
            } else {
                assert!(documented.iter().any(|(n, _)| n == k), "key `{k}` has no row in section {section}");
            }
        }
    }

    // axis parameters: the code's list (its "unknown parameter" message), both ways
    let msg = SweepSpec::parse(&format!("{model}[[axis]]\nparameter = \"no.such\"\nvalues = [1.0]\n"), &spec_path())
        .map(|_| ())
        .unwrap_err()
        .to_string();
    let list = msg.split_once("known: ").unwrap().1.trim_end_matches(')');
    let known: Vec<&str> = list.split(", ").map(|p| p.trim_end_matches(" (0-based)")).collect();
    assert!(known.len() >= 11, "{known:?}");
    let params = rows(&doc, "Axis parameters");
    for p in &known {
        assert!(params.iter().any(|(n, _)| n == p), "parameter `{p}` has no row in `## Axis parameters`");
    }
    for (n, _) in &params {
        let concrete = n.replace("[i][j]", "[0][0]").replace("[k]", "[0]");
        assert!(moreau::sweep::axis::Parameter::parse(&concrete).is_ok(), "documented parameter `{n}` is refused");
    }

    // columns: the code's list, both ways, with kind, bound direction and equation numbers
    let cols = ThetaEvaluator::default().columns();
    let names = column_names();
    assert_eq!(cols.iter().map(|c| c.name.as_str()).collect::<Vec<_>>(), names);
    let documented = rows(&doc, "Columns");
    assert_eq!(
        documented.iter().map(|(n, _)| *n).collect::<Vec<_>>(),
        names,
        "the rows of `## Columns` must be the code's columns, in the code's order"
    );
    for c in &cols {
        let row = documented.iter().find(|(n, _)| *n == c.name).unwrap().1;
        let cells: Vec<&str> = row.split(" | ").map(str::trim).collect();
        assert_eq!(cells[1], c.kind.as_str(), "kind of `{}`", c.name);
        if let Some(def) = bounds::report::defs::by_key(&c.name) {
            assert_eq!(cells[2], def.kind.as_str(), "bound direction of `{}`", c.name);
            assert_eq!(cells[3], def.label, "equation label of `{}`", c.name);
            assert_eq!(cells[4], bounds::equations::numbered(def.label), "printed number of `{}`", c.name);
        }
    }
}

#[test]
fn the_page_is_linked_from_the_readme_and_the_help() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    assert!(readme.contains("(docs/sweep-spec.md)"), "README.md does not link docs/sweep-spec.md");
    let o = Command::new(env!("CARGO_BIN_EXE_moreau")).args(["sweep", "--help"]).output().unwrap();
    assert!(o.status.success());
    assert!(String::from_utf8_lossy(&o.stdout).contains("docs/sweep-spec.md"), "`moreau sweep --help` lacks the link");
}
