//! Structure-aware fuzzing of the front door: model files (`model::parse_str`), sweep specs
//! (`SweepSpec::parse`), CSV inputs (`Input::from_csv`), recordings (`Recording::parse_str`),
//! the play-width stand config and log (`discovery::play_width::robonine`). Each execution
//! mutates a seed of the committed corpus (`fuzz/corpus/<parser>/`): lines deleted, duplicated
//! or swapped, numbers replaced by hostile values (NaN, inf, 1e400, -0, huge integers, strings,
//! nested arrays), keys renamed, text truncated, bytes flipped or inserted. Every execution must
//! return (Ok or Err) without a panic; the slowest execution is reported.
//!
//! Default: 300 executions per parser. The campaign of issue 16 (10^6 per parser, hangs over
//! 1 s counted as failures): `FUZZ_EXECUTIONS=1000000 cargo test --release -p moreau --test
//! fuzz_parsers -- --nocapture` (figures in BENCHMARKS.md).
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;
use std::time::{Duration, Instant};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn executions() -> u64 {
    std::env::var("FUZZ_EXECUTIONS").ok().and_then(|s| s.parse().ok()).unwrap_or(300).max(1)
}

/// xorshift64*: deterministic, seedable.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545F4914F6CDD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

const HOSTILE: [&str; 22] = [
    "nan",
    "inf",
    "-inf",
    "1e400",
    "-1e400",
    "1e-320",
    "-0.0",
    "0",
    "-1",
    "1e300",
    "9223372036854775808",
    "18446744073709551616",
    "\"x\"",
    "[]",
    "[[1.0, 2.0], [3.0]]",
    "{}",
    "true",
    "0x10",
    "1e6",
    "1e-300",
    "-5",
    "\"\"",
];

/// One structure-aware mutation (1 to 4 operations) of `seed`.
fn mutate(seed: &str, rng: &mut Rng) -> String {
    let mut lines: Vec<String> = seed.lines().map(String::from).collect();
    for _ in 0..1 + rng.below(4) {
        if lines.is_empty() {
            lines.push(String::new());
        }
        let i = rng.below(lines.len());
        match rng.below(9) {
            0 => {
                lines.remove(i);
            }
            1 => {
                let l = lines[i].clone();
                lines.insert(i, l);
            }
            2 => {
                let j = rng.below(lines.len());
                lines.swap(i, j);
            }
            3 | 4 => {
                // replace one number (or value after `=` / `,`) by a hostile value
                let l = &lines[i];
                let starts: Vec<usize> = l
                    .char_indices()
                    .filter(|(k, c)| {
                        (c.is_ascii_digit() || *c == '-') && (*k == 0 || !l.as_bytes()[k - 1].is_ascii_alphanumeric())
                    })
                    .map(|(k, _)| k)
                    .collect();
                if !starts.is_empty() {
                    let s = starts[rng.below(starts.len())];
                    let e = l[s..]
                        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '.' || c == '-' || c == '+'))
                        .map(|x| s + x)
                        .unwrap_or(l.len());
                    let h = HOSTILE[rng.below(HOSTILE.len())];
                    lines[i] = format!("{}{}{}", &l[..s], h, &l[e..]);
                }
            }
            5 => {
                // rename a key
                if let Some(eq) = lines[i].find('=') {
                    let names = ["shape", "kind", "A", "x0", "dt", "period", "values", "parameter", "zz", "t_end"];
                    lines[i] = format!("{} {}", names[rng.below(names.len())], &lines[i][eq..]);
                }
            }
            6 => {
                // truncate the line
                let l = lines[i].clone();
                let cut = rng.below(l.len() + 1);
                let cut = (0..=cut).rev().find(|c| l.is_char_boundary(*c)).unwrap_or(0);
                lines[i] = l[..cut].to_string();
            }
            7 => {
                // flip or insert a byte (kept valid UTF-8: ASCII only)
                let b = [
                    b'"', b'[', b']', b'{', b'}', b',', b'=', b'\n', b'#', b'\\', b'\'', b'.', b'e', b'0', b' ', b'\t',
                ];
                let mut l = lines[i].clone().into_bytes();
                let at = rng.below(l.len() + 1);
                if rng.below(2) == 0 && at < l.len() && l[at].is_ascii() {
                    l[at] = b[rng.below(b.len())];
                } else {
                    l.insert(at.min(l.len()), b[rng.below(b.len())]);
                }
                lines[i] = String::from_utf8(l).unwrap_or_default();
            }
            _ => {
                // duplicate a whole block (repeated tables / rows)
                let j = rng.below(lines.len());
                let (a, b) = (i.min(j), i.max(j));
                let block: Vec<String> = lines[a..=b].to_vec();
                lines.extend(block);
            }
        }
    }
    let mut s = lines.join("\n");
    if rng.below(10) == 0 {
        let cut = rng.below(s.len() + 1);
        let cut = (0..=cut).rev().find(|c| s.is_char_boundary(*c)).unwrap_or(0);
        s.truncate(cut);
    }
    s
}

fn corpus(name: &str) -> Vec<String> {
    let dir = root().join("fuzz/corpus").join(name);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    let seeds: Vec<String> = files.iter().map(|p| std::fs::read_to_string(p).unwrap()).collect();
    assert!(!seeds.is_empty(), "empty corpus {name}");
    seeds
}

/// Runs `target` on mutations of the corpus; returns (executions, Ok count, slowest).
fn fuzz(name: &str, seed: u64, mut target: impl FnMut(&str) -> bool) -> (u64, u64, Duration) {
    let seeds = corpus(name);
    // the seeds themselves parse (the corpus is meaningful)
    for (i, s) in seeds.iter().enumerate() {
        assert!(target(s), "{name}: corpus seed {i} does not parse");
    }
    let mut rng = Rng(seed | 1);
    let (mut ok, mut slowest) = (0, Duration::ZERO);
    let n = executions();
    for k in 0..n {
        let text = mutate(&seeds[rng.below(seeds.len())], &mut rng);
        let t0 = Instant::now();
        let r = catch_unwind(AssertUnwindSafe(|| target(&text)));
        let dt = t0.elapsed();
        match r {
            Ok(true) => ok += 1,
            Ok(false) => {}
            Err(_) => panic!("{name}: execution {k} panicked on input:\n{text}"),
        }
        slowest = slowest.max(dt);
        if n >= 100_000 {
            assert!(dt < Duration::from_secs(1), "{name}: execution {k} took {dt:?} (a hang) on:\n{text}");
        }
    }
    eprintln!("fuzz {name}: {n} executions, {ok} accepted, slowest {slowest:?}");
    (n, ok, slowest)
}

#[test]
fn model_files() {
    let (n, ok, _) = fuzz("model", 11, |t| model::parse_str(t).is_ok());
    assert!(ok < n, "every mutation accepted: the mutator does nothing");
}

#[test]
fn sweep_specs() {
    // the base model path of the seeds resolves relative to examples/sweeps/
    let at = root().join("examples/sweeps/fuzz.toml");
    let (n, ok, _) = fuzz("sweep", 12, |t| moreau::sweep::spec::SweepSpec::parse(t, &at).is_ok());
    assert!(ok < n);
}

#[test]
fn csv_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("w.csv");
    let (n, ok, _) = fuzz("csv", 13, |t| {
        std::fs::write(&p, t).unwrap();
        model::Input::from_csv(&p, None, model::input::InputHold::Foh).is_ok()
    });
    assert!(ok < n);
}

#[test]
fn recordings() {
    let (n, ok, _) = fuzz("recording", 14, |t| discovery::Recording::parse_str(t, "fuzz").is_ok());
    assert!(ok < n);
}

#[test]
fn play_width_config_and_log() {
    use discovery::play_width::robonine::{parse_log, StandConfig};
    let (n, ok, _) = fuzz("playwidth-config", 15, |t| StandConfig::from_json_str(t).is_ok());
    assert!(ok < n);
    let (n, ok, _) = fuzz("playwidth-log", 16, |t| parse_log(t, "fuzz", &[3, 5]).is_ok());
    assert!(ok < n);
}

/// Control: the harness does catch a panic (a target that panics on a mutation fails the run).
#[test]
fn a_panicking_parser_is_caught() {
    let r = catch_unwind(|| {
        fuzz("model", 17, |t| {
            if t.contains("nan") {
                panic!("boom");
            }
            true
        })
    });
    assert!(r.is_err(), "the harness missed a panic");
}

/// Regression from the 10^6 campaign: an axis of 1.3 M values (`to = 1e6, step = 0.75`) was
/// validated value by value (2.9 s) before the soft point limit refused it; it is now refused
/// before the values are built.
#[test]
fn found_large_axis_is_refused_before_expansion() {
    let at = root().join("examples/sweeps/fuzz.toml");
    let spec = "name = \"x\"\nmodel = \"../worked-example.toml\"\n[[axis]]\nparameter = \"plant.A[1][0]\"\nrange = { from = -3.0, to = 1e6, step = 0.75 }\n";
    let e = moreau::sweep::spec::SweepSpec::parse(spec, &at).unwrap_err();
    assert!(e.to_string().contains("more than the limit 1000000"), "{e}");
}
