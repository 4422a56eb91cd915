//! The documentation keeps its promises:
//!
//! - every relative link of `README.md`, `BENCHMARKS.md` and `docs/**/*.md` points at an
//!   existing file, and a `#anchor` into a Markdown page names one of its headings (GitHub's
//!   slugs); a broken link in an in-memory page is reported (control);
//! - every `moreau ...` line in a fenced `sh` block of the user guide (`docs/guide/*.md`) runs
//!   with the binary built for this test, in a temporary folder per page where `examples/` and
//!   `data/` are the repository's and each block headed `toml file=NAME` (any language) has
//!   been written as `NAME`. A command exits 0, or, with `# expect: fails` on its line, fails
//!   with one `error:` line. A block after `<!-- not run: REASON -->` is skipped. A plain
//!   block that starts with `$ moreau ...` is a sample of the output: the command is run and
//!   each line of the sample other than `...` must be a line of what it prints. A misspelt
//!   flag, a wrongly expected failure and a sample line the command does not print are
//!   reported (controls).
use std::collections::{BTreeMap, HashMap};
use std::path::{Component, Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().unwrap()
}

// ---------------------------------------------------------------- Markdown structure

/// Lines outside fenced code blocks, with their 1-based numbers.
fn prose_lines(text: &str) -> Vec<(usize, &str)> {
    let mut out = Vec::new();
    let mut fence: Option<&str> = None;
    for (i, line) in text.lines().enumerate() {
        let t = line.trim_start();
        match fence {
            Some(f) if t.starts_with(f) => fence = None,
            Some(_) => {}
            None if t.starts_with("```") => fence = Some("```"),
            None if t.starts_with("~~~") => fence = Some("~~~"),
            None => out.push((i + 1, line)),
        }
    }
    out
}

/// The line without its inline code spans (`...`).
fn without_code_spans(line: &str) -> String {
    let mut out = String::new();
    let mut in_code = false;
    for c in line.chars() {
        if c == '`' {
            in_code = !in_code;
        } else if !in_code {
            out.push(c);
        }
    }
    out
}

/// Link targets `[text](target)` and `![alt](target)` of a line (titles dropped).
fn link_targets(line: &str) -> Vec<String> {
    let line = without_code_spans(line);
    let mut out = Vec::new();
    let mut rest = line.as_str();
    while let Some(k) = rest.find("](") {
        let after = &rest[k + 2..];
        // the target ends at the `)` that closes the parenthesis (targets may hold `(...)`)
        let mut depth = 0usize;
        let mut end = None;
        for (j, c) in after.char_indices() {
            match c {
                '(' => depth += 1,
                ')' if depth == 0 => {
                    end = Some(j);
                    break;
                }
                ')' => depth -= 1,
                _ => {}
            }
        }
        let Some(end) = end else { break };
        let has_text = rest[..k].contains('[');
        let target = after[..end].trim().trim_start_matches('<').trim_end_matches('>');
        let target = target.split_whitespace().next().unwrap_or("");
        if has_text && !target.is_empty() {
            out.push(target.to_string());
        }
        rest = &after[end..];
    }
    out
}

/// GitHub's anchor of a heading: lower case, characters other than letters, digits, `-`, `_`
/// and spaces dropped, spaces made `-`.
fn slug(heading: &str) -> String {
    let mut s = String::new();
    for c in heading.trim().chars() {
        if c.is_alphanumeric() || c == '-' || c == '_' {
            s.extend(c.to_lowercase());
        } else if c == ' ' {
            s.push('-');
        }
    }
    s
}

/// Anchors of a page's headings (`#`-style, outside code), repeated ones numbered `-1`, `-2`.
fn anchors(text: &str) -> Vec<String> {
    let mut seen: HashMap<String, usize> = HashMap::new();
    let mut out = Vec::new();
    for (_, line) in prose_lines(text) {
        let t = line.trim_start();
        let hashes = t.chars().take_while(|&c| c == '#').count();
        if hashes == 0 || hashes > 6 || !t[hashes..].starts_with(' ') {
            continue;
        }
        let base = slug(&t[hashes..]);
        let n = seen.entry(base.clone()).or_insert(0);
        out.push(if *n == 0 { base.clone() } else { format!("{base}-{n}") });
        *n += 1;
    }
    out
}

/// `a/b/../c` -> `a/c` without touching the file system.
fn normalise(p: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in p.components() {
        match c {
            Component::ParentDir => {
                if !out.pop() {
                    out.push("..");
                }
            }
            Component::CurDir => {}
            other => out.push(other),
        }
    }
    out
}

/// What a link checker may ask about a path (relative to the repository root).
enum Target {
    Missing,
    Dir,
    File(String),
}

/// Broken links of `pages` (path relative to the root, text), one message each; `lookup`
/// answers for any other file.
fn broken_links(pages: &[(PathBuf, String)], lookup: &dyn Fn(&Path) -> Target) -> Vec<String> {
    let mut errors = Vec::new();
    for (page, text) in pages {
        let dir = page.parent().unwrap_or(Path::new(""));
        for (no, line) in prose_lines(text) {
            for target in link_targets(line) {
                if target.contains("://") || target.starts_with("mailto:") {
                    continue;
                }
                let (file, anchor) = match target.split_once('#') {
                    Some((f, a)) => (f, Some(a)),
                    None => (target.as_str(), None),
                };
                let where_ = format!("{}:{no}: link `{target}`", page.display());
                let (resolved, content) = if file.is_empty() {
                    (page.clone(), Target::File(text.clone()))
                } else {
                    let p = normalise(&dir.join(file));
                    if p.starts_with("..") {
                        errors.push(format!("{where_} leaves the repository"));
                        continue;
                    }
                    let t = pages
                        .iter()
                        .find(|(q, _)| *q == p)
                        .map_or_else(|| lookup(&p), |(_, s)| Target::File(s.clone()));
                    (p, t)
                };
                match (content, anchor) {
                    (Target::Missing, _) => errors.push(format!("{where_}: {} does not exist", resolved.display())),
                    (_, None) => {}
                    (Target::File(body), Some(a)) if resolved.extension().is_some_and(|e| e == "md") => {
                        if !anchors(&body).iter().any(|h| h == a) {
                            errors.push(format!("{where_}: no heading with anchor #{a} in {}", resolved.display()));
                        }
                    }
                    (_, Some(a)) => errors.push(format!("{where_}: anchor #{a} into a file that is not Markdown")),
                }
            }
        }
    }
    errors
}

/// Table rows whose code spans hold an unescaped `|`: GitHub splits the cell there.
fn broken_table_rows(page: &Path, text: &str) -> Vec<String> {
    let mut errors = Vec::new();
    for (no, line) in prose_lines(text) {
        if !line.trim_start().starts_with('|') {
            continue;
        }
        let mut in_code = false;
        let mut prev = ' ';
        for c in line.chars() {
            if c == '`' {
                in_code = !in_code;
            } else if c == '|' && in_code && prev != '\\' {
                errors.push(format!("{}:{no}: `|` inside a code span of a table row: write `\\|`", page.display()));
                break;
            }
            prev = c;
        }
    }
    errors
}

fn markdown_pages() -> Vec<(PathBuf, String)> {
    let root = root();
    let mut files = vec![PathBuf::from("README.md"), PathBuf::from("BENCHMARKS.md")];
    let mut stack = vec![PathBuf::from("docs")];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(root.join(&d)).unwrap() {
            let e = e.unwrap();
            let rel = d.join(e.file_name());
            if e.file_type().unwrap().is_dir() {
                stack.push(rel);
            } else if rel.extension().is_some_and(|x| x == "md") {
                files.push(rel);
            }
        }
    }
    files.sort();
    files.into_iter().map(|f| (f.clone(), std::fs::read_to_string(root.join(&f)).unwrap())).collect()
}

#[test]
fn every_relative_link_of_readme_benchmarks_and_docs_resolves() {
    let root = root();
    let pages = markdown_pages();
    assert!(pages.iter().any(|(p, _)| p == Path::new("docs/guide/README.md")), "the guide's index is missing");
    assert!(
        pages.len() >= 12,
        "README, BENCHMARKS and the guide's pages: {:?}",
        pages.iter().map(|p| &p.0).collect::<Vec<_>>()
    );
    let lookup = |p: &Path| {
        let abs = root.join(p);
        if abs.is_dir() {
            Target::Dir
        } else if abs.is_file() {
            // a binary file (an image) exists too; only Markdown pages are read for anchors
            Target::File(std::fs::read_to_string(&abs).unwrap_or_default())
        } else {
            Target::Missing
        }
    };
    let links: usize =
        pages.iter().map(|(_, t)| prose_lines(t).iter().map(|(_, l)| link_targets(l).len()).sum::<usize>()).sum();
    assert!(links >= 60, "only {links} links found: the extraction is broken");
    let mut errors = broken_links(&pages, &lookup);
    for (page, text) in &pages {
        errors.extend(broken_table_rows(page, text));
    }
    assert!(errors.is_empty(), "broken links or tables:\n{}", errors.join("\n"));
}

#[test]
fn a_broken_link_or_anchor_is_reported() {
    let page = "# Title\n\n## A `code` heading: with (punctuation)\n\n## A `code` heading: with (punctuation)\n\
                [ok](#title) [ok](#a-code-heading-with-punctuation-1) [ok](other.md#second-part) \
                ![img](pic.png) [web](https://example.org/x) `[not a link](nowhere.md)`\n\
                ```\n[in code](nowhere.md)\n```\n\
                [missing](nowhere.md) [bad anchor](other.md#third) [bad here](#nope) [up](../../outside.md)\n";
    let other = "# Other\n## Second part\n";
    let pages =
        vec![(PathBuf::from("docs/page.md"), page.to_string()), (PathBuf::from("docs/other.md"), other.to_string())];
    let lookup = |p: &Path| if p == Path::new("docs/pic.png") { Target::File(String::new()) } else { Target::Missing };
    let errors = broken_links(&pages, &lookup);
    assert_eq!(errors.len(), 4, "{errors:#?}");
    assert!(errors[0].contains("nowhere.md") && errors[0].contains("docs/page.md:10"), "{errors:#?}");
    assert!(errors[1].contains("#third"), "{errors:#?}");
    assert!(errors[2].contains("#nope"), "{errors:#?}");
    assert!(errors[3].contains("leaves the repository"), "{errors:#?}");
    assert_eq!(
        slug("What `moreau theta` says, and what the numbers mean"),
        "what-moreau-theta-says-and-what-the-numbers-mean"
    );
    assert_eq!(slug("`[input]`: w(t)"), "input-wt");
    let table = "| a | `\\|x\\|` |\n| b | `|x|` |\n`|x|` outside a table\n";
    let rows = broken_table_rows(Path::new("t.md"), table);
    assert!(rows.len() == 1 && rows[0].starts_with("t.md:2:"), "{rows:#?}");
}

// ---------------------------------------------------------------- commands of the guide

#[derive(Debug, PartialEq)]
enum Item {
    /// A block headed `LANG file=NAME`: written as NAME before the commands after it.
    File { name: String, body: String },
    /// A `moreau ...` line of an `sh` block (continuations joined).
    Command { line: usize, text: String, expect_fail: bool },
    /// A plain block starting with `$ moreau ...`: the command and the lines it must print.
    Sample { line: usize, text: String, expected: Vec<String> },
}

/// The files and commands of a guide page in order; blocks after `<!-- not run: ... -->`
/// left out. Errors: a marker without a reason or not followed by a block.
fn guide_items(text: &str) -> Result<Vec<Item>, String> {
    let lines: Vec<&str> = text.lines().collect();
    let mut items = Vec::new();
    let mut skip_next = false;
    let mut i = 0;
    while i < lines.len() {
        let t = lines[i].trim();
        if let Some(rest) = t.strip_prefix("<!-- not run:") {
            let start = i;
            let mut reason = rest.to_string();
            while !lines[i].contains("-->") {
                i += 1;
                if i == lines.len() {
                    return Err(format!("line {}: unclosed `<!-- not run:` comment", start + 1));
                }
                reason.push_str(lines[i]);
            }
            if reason.trim().trim_end_matches("-->").trim().is_empty() {
                return Err(format!("line {}: `<!-- not run:` without a reason", start + 1));
            }
            i += 1;
            while i < lines.len() && lines[i].trim().is_empty() {
                i += 1;
            }
            if i == lines.len() || !lines[i].trim_start().starts_with("```") {
                return Err(format!("line {}: `<!-- not run:` not followed by a code block", start + 1));
            }
            skip_next = true;
            continue;
        }
        if let Some(info) = t.strip_prefix("```") {
            let lang = info.split_whitespace().next().unwrap_or("");
            let file = info.split_whitespace().find_map(|w| w.strip_prefix("file=")).map(str::to_string);
            let open = i;
            let mut body = Vec::new();
            i += 1;
            while i < lines.len() && !lines[i].trim_start().starts_with("```") {
                body.push((i + 1, lines[i]));
                i += 1;
            }
            if i == lines.len() {
                return Err(format!("line {}: unclosed code block", open + 1));
            }
            i += 1;
            if std::mem::take(&mut skip_next) {
                continue;
            }
            if let Some(name) = file {
                let mut text: String = body.iter().map(|(_, l)| format!("{l}\n")).collect();
                if text.is_empty() {
                    text.push('\n');
                }
                items.push(Item::File { name, body: text });
            }
            if lang.is_empty() {
                let first = body.first().map_or("", |(_, l)| l.trim());
                // the README writes the command as `cargo run --release -- ...`
                if let Some(cmd) =
                    first.strip_prefix("$ moreau ").or_else(|| first.strip_prefix("$ cargo run --release -- "))
                {
                    let expected =
                        body[1..].iter().map(|(_, l)| l.trim_end().to_string()).filter(|l| l.trim() != "...").collect();
                    items.push(Item::Sample { line: body[0].0, text: format!("moreau {cmd}"), expected });
                }
            }
            if lang == "sh" {
                let mut k = 0;
                while k < body.len() {
                    let (no, first) = body[k];
                    let mut cmd = first.trim().to_string();
                    while cmd.ends_with('\\') && k + 1 < body.len() {
                        cmd.pop();
                        k += 1;
                        cmd = format!("{} {}", cmd.trim_end(), body[k].1.trim());
                    }
                    k += 1;
                    let cmd = cmd.strip_prefix("$ ").unwrap_or(&cmd).to_string();
                    if cmd.starts_with("moreau ") {
                        let expect_fail = cmd.contains("# expect: fails");
                        items.push(Item::Command { line: no, text: cmd, expect_fail });
                    }
                }
            }
            continue;
        }
        i += 1;
    }
    Ok(items)
}

/// Runs a page's items in a fresh folder; one message per command that does not behave.
fn run_page(page: &str, items: &[Item]) -> Vec<String> {
    let root = root();
    let dir = tempfile::tempdir().unwrap();
    let work = dir.path();
    for shared in ["examples", "data"] {
        std::os::unix::fs::symlink(root.join(shared), work.join(shared)).unwrap();
    }
    let bin = work.join(".bin");
    std::fs::create_dir(&bin).unwrap();
    std::os::unix::fs::symlink(env!("CARGO_BIN_EXE_moreau"), bin.join("moreau")).unwrap();
    let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap_or_default());
    let mut failures = Vec::new();
    for item in items {
        match item {
            Item::File { name, body } => {
                let p = work.join(name);
                assert!(
                    !name.contains("..") && !Path::new(name).is_absolute(),
                    "{page}: file={name} must stay in the folder"
                );
                if let Some(parent) = p.parent() {
                    std::fs::create_dir_all(parent).unwrap();
                }
                std::fs::write(p, body).unwrap();
            }
            Item::Sample { line, text, expected } => {
                let out = Command::new("bash")
                    .args(["-c", text])
                    .current_dir(work)
                    .env("PATH", &path)
                    .env("OPENBLAS_NUM_THREADS", "1")
                    .output()
                    .expect("bash runs");
                let stdout = String::from_utf8_lossy(&out.stdout);
                let printed: Vec<&str> = stdout.lines().map(str::trim_end).collect();
                let at = format!("{page}:{line}: sample of `{text}`");
                if !out.status.success() {
                    failures.push(format!("{at}: the command failed ({})", out.status));
                }
                for want in expected.iter().filter(|w| !printed.contains(&w.as_str())) {
                    failures.push(format!("{at}: the command does not print the line {want:?}"));
                }
            }
            Item::Command { line, text, expect_fail } => {
                let out = Command::new("bash")
                    .args(["-c", text])
                    .current_dir(work)
                    .env("PATH", &path)
                    .env("OPENBLAS_NUM_THREADS", "1")
                    .output()
                    .expect("bash runs");
                let stderr = String::from_utf8_lossy(&out.stderr);
                let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
                let at = format!("{page}:{line}: `{text}`");
                if *expect_fail {
                    let one_error = lines.len() == 1 && lines[0].starts_with("error: ");
                    if out.status.success() || !one_error {
                        failures.push(format!(
                            "{at} should fail with one `error:` line, got {} and stderr {stderr:?}",
                            out.status
                        ));
                    }
                } else if !out.status.success() {
                    failures.push(format!(
                        "{at} failed ({}): {}",
                        out.status,
                        lines.iter().rev().take(3).rev().cloned().collect::<Vec<_>>().join(" | ")
                    ));
                }
            }
        }
    }
    failures
}

#[test]
fn every_command_of_the_guide_runs() {
    let dir = root().join("docs/guide");
    let mut pages: BTreeMap<String, String> = BTreeMap::new();
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "md") {
            pages.insert(
                format!("docs/guide/{}", p.file_name().unwrap().to_string_lossy()),
                std::fs::read_to_string(&p).unwrap(),
            );
        }
    }
    let mut failures = Vec::new();
    let mut commands = 0;
    for (page, text) in &pages {
        let items = guide_items(text).unwrap_or_else(|e| panic!("{page}: {e}"));
        commands += items.iter().filter(|i| matches!(i, Item::Command { .. } | Item::Sample { .. })).count();
        failures.extend(run_page(page, &items));
    }
    // the README's output sample (its cargo commands themselves are CI's, not run here)
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let samples: Vec<Item> =
        guide_items(&readme).unwrap().into_iter().filter(|i| matches!(i, Item::Sample { .. })).collect();
    assert!(!samples.is_empty(), "README.md shows what `moreau theta` prints");
    failures.extend(run_page("README.md", &samples));
    assert!(commands >= 40, "only {commands} commands found in the guide: the extraction is broken");
    assert!(failures.is_empty(), "commands of the guide that do not behave:\n{}", failures.join("\n"));
}

#[test]
fn the_guide_extraction_and_runner_report_what_they_should() {
    let page = "Intro `moreau not-a-command`\n\n\
                ```toml file=m.toml\nname = \"x\"\n```\n\n\
                ```sh\n$ moreau validate m.toml   # comment\nmoreau theta m.toml \\\n    --json\nls\n```\n\n\
                <!-- not run: a reason\n  on two lines -->\n```sh\nmoreau check --cases 1000000000\n```\n\n\
                ```sh\nmoreau validate x.toml # expect: fails\n```\n\
                ```\n$ moreau validate m.toml\n...\n  n = 2\n```\n";
    let items = guide_items(page).unwrap();
    assert_eq!(
        items,
        vec![
            Item::File { name: "m.toml".into(), body: "name = \"x\"\n".into() },
            Item::Command { line: 8, text: "moreau validate m.toml   # comment".into(), expect_fail: false },
            Item::Command { line: 9, text: "moreau theta m.toml --json".into(), expect_fail: false },
            Item::Command { line: 21, text: "moreau validate x.toml # expect: fails".into(), expect_fail: true },
            Item::Sample { line: 24, text: "moreau validate m.toml".into(), expected: vec!["  n = 2".into()] },
        ]
    );
    assert!(guide_items("<!-- not run: -->\n```sh\nmoreau x\n```\n").is_err(), "a marker needs a reason");
    assert!(
        guide_items("<!-- not run: slow -->\ntext\n```sh\nmoreau x\n```\n").is_err(),
        "a marker belongs to a block"
    );
    assert!(guide_items("```sh\nmoreau x\n").is_err(), "an unclosed block is an error");

    // controls of the runner: a misspelt flag fails, a command that succeeds although marked
    // to fail is reported, a right one passes
    let cmd = |line, text: &str, expect_fail| Item::Command { line, text: text.into(), expect_fail };
    let failures = run_page(
        "control.md",
        &[
            cmd(1, "moreau theta examples/worked-example.toml --jsn", false),
            cmd(2, "moreau validate examples/worked-example.toml # expect: fails", true),
            cmd(3, "moreau validate examples/worked-example.toml", false),
            cmd(4, "moreau validate examples/missing.toml # expect: fails", true),
            Item::Sample {
                line: 5,
                text: "moreau validate examples/worked-example.toml".into(),
                expected: vec!["  n = 2, m = 1, p = 1".into(), "  n = 3, m = 1, p = 1".into()],
            },
        ],
    );
    assert_eq!(failures.len(), 3, "{failures:#?}");
    assert!(failures[2].contains("control.md:5") && failures[2].contains("n = 3"), "{failures:#?}");
    assert!(failures[0].contains("control.md:1") && failures[0].contains("--jsn"), "{failures:#?}");
    assert!(failures[1].contains("control.md:2") && failures[1].contains("should fail"), "{failures:#?}");
}
