//! One module per result of the paper, each named after it. Every property has
//! - a proptest strategy of *parameters* (shrinkable),
//! - an evaluation `eval(case, Variant) -> Eval` of the claimed inequality,
//! - a negative control ([`Variant::NegativeControl`]): the same check with a deliberately
//!   wrong constant, sign or set, which must produce counterexamples,
//! - an export of a failing case to a file that reproduces it.
//!
//! Slack normalisation (unless a module says otherwise): for a claim `lhs <= rhs`,
//! `slack = (rhs - lhs) / (|lhs| + |rhs| + tol + tiny)` in `[-1, 1]`; a case is *violated* when
//! `lhs > rhs + tol` with `tol` a floating-point allowance ([`fp_tol`]) scaled with the
//! magnitudes involved, documented per property.
use proptest::strategy::{BoxedStrategy, Strategy, ValueTree};
use proptest::test_runner::{Config, TestRng, TestRunner};

pub mod lemma2;
pub mod lemma_a1;
pub mod lemma_a2;
pub mod lemma_b;
pub mod pp;
pub mod psi0;
pub mod qzdot;
pub mod rr;
pub mod simulation;
pub mod theorem1;
pub mod theorem2;
pub mod zy;

/// Whether to check the paper's claim or its negative control.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Variant {
    /// The inequality as stated in the paper.
    Claim,
    /// The inequality with a deliberately wrong constant, sign or set: must fail somewhere.
    NegativeControl,
}

/// Result of evaluating one case.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Eval {
    /// Left-hand side of `lhs <= rhs` (after the property's normalisation, if any).
    pub lhs: f64,
    /// Right-hand side.
    pub rhs: f64,
    /// Floating-point allowance: violated iff `lhs > rhs + tol`.
    pub tol: f64,
    /// The case does not satisfy the property's hypotheses (e.g. a simulation that did not
    /// reach the periodic regime); counted, not checked.
    pub skipped: bool,
}

/// Denominator guard of the normalised slack.
pub const TINY: f64 = 1e-300;

impl Eval {
    pub fn new(lhs: f64, rhs: f64, tol: f64) -> Self {
        Self { lhs, rhs, tol, skipped: false }
    }
    pub fn skipped() -> Self {
        Self { lhs: 0.0, rhs: 0.0, tol: 0.0, skipped: true }
    }
    /// `(rhs - lhs) / (|lhs| + |rhs| + tol + tiny)`; NaN counts as `-1` (a violation). The
    /// tolerance in the denominator keeps cases where both sides vanish up to rounding near 0
    /// (any value above `-1/2` is within the floating-point allowance).
    pub fn slack(&self) -> f64 {
        let s = (self.rhs - self.lhs) / (self.lhs.abs() + self.rhs.abs() + self.tol + TINY);
        if s.is_nan() {
            -1.0
        } else {
            s
        }
    }
    /// `lhs > rhs + tol`, or NaN on either side.
    pub fn violated(&self) -> bool {
        !self.skipped && !(self.lhs <= self.rhs + self.tol)
    }
}

/// Floating-point allowance `64 (p + 1) eps scale` used by the geometric properties: each side
/// is a short sum of products of quantities of size `<= scale`, computed from points that are
/// themselves accurate to a few ulps of the set's size.
pub fn fp_tol(scale: f64, p: usize) -> f64 {
    64.0 * (p as f64 + 1.0) * f64::EPSILON * scale
}

/// A file that reproduces a counterexample.
#[derive(Debug, Clone, PartialEq)]
pub struct Counterexample {
    /// File extension (`toml` for model files and geometric cases).
    pub extension: &'static str,
    /// File contents.
    pub text: String,
    /// One-line summary (lhs, rhs).
    pub summary: String,
}

/// One case's outcome (the brief's `CaseOutcome`).
#[derive(Debug, Clone)]
pub struct CaseOutcome {
    pub slack: f64,
    pub violated: bool,
    pub skipped: bool,
    /// Filled for violated cases.
    pub counterexample: Option<Counterexample>,
}

/// Static description of a property.
#[derive(Debug, Clone, Copy)]
pub struct PropertyInfo {
    /// Short name used by `--only` (e.g. `lemma_a2`).
    pub name: &'static str,
    /// Equation label in the paper (e.g. `(lem1:2)`).
    pub label: &'static str,
    /// Result, in words.
    pub title: &'static str,
    /// Default number of cases in `moreau check` and in `cargo test` (cheap properties:
    /// thousands; simulation-based ones: 2,000, short horizons).
    pub default_cases: u64,
    /// What the negative control changes.
    pub negative_control: &'static str,
}

/// A property of the campaign (object safe so that other crates can register more).
pub trait Property: Send + Sync {
    fn info(&self) -> PropertyInfo;
    /// Generates one case from `rng` and evaluates it; a violated case comes back with its
    /// shrunk counterexample.
    fn check_case(&self, rng: &mut TestRng, variant: Variant) -> CaseOutcome {
        let r = self.run_cases(rng, 1, variant, &mut |_| {});
        CaseOutcome {
            slack: r.min_slack,
            violated: r.violations > 0,
            skipped: r.skipped > 0,
            counterexample: r.counterexample,
        }
    }
    /// Runs `cases` cases from `rng` (strategy built once), calling `progress(k)` every few
    /// cases with the number done since the last call.
    fn run_cases(&self, rng: &mut TestRng, cases: u64, variant: Variant, progress: &mut dyn FnMut(u64)) -> ChunkResult;
}

/// Aggregate of a run of cases.
#[derive(Debug, Clone)]
pub struct ChunkResult {
    pub cases: u64,
    pub skipped: u64,
    /// Minimum normalised slack over the checked (non-skipped) cases; `+inf` if none.
    pub min_slack: f64,
    pub violations: u64,
    /// Index (within the run) of the first violation and its shrunk counterexample.
    pub first_violation: Option<u64>,
    pub counterexample: Option<Counterexample>,
}

/// A property given by a strategy of parameters, an evaluation and an export.
pub struct Prop<C: Clone + std::fmt::Debug + 'static> {
    pub info: PropertyInfo,
    pub strategy: fn() -> BoxedStrategy<C>,
    pub eval: fn(&C, Variant) -> Eval,
    pub export: fn(&C, &Eval) -> Counterexample,
    /// Maximum shrink steps for a counterexample.
    pub max_shrink_iters: u32,
}

impl<C: Clone + std::fmt::Debug + 'static> Prop<C> {
    /// Shrinks a failing value tree (proptest's simplify / complicate loop).
    fn shrink(&self, mut tree: Box<dyn ValueTree<Value = C>>, variant: Variant) -> (C, Eval) {
        let mut best = tree.current();
        let mut best_eval = (self.eval)(&best, variant);
        let mut iters = 0;
        if !tree.simplify() {
            return (best, best_eval);
        }
        loop {
            iters += 1;
            if iters > self.max_shrink_iters {
                break;
            }
            let cand = tree.current();
            let e = (self.eval)(&cand, variant);
            let more = if e.violated() {
                best = cand;
                best_eval = e;
                tree.simplify()
            } else {
                tree.complicate()
            };
            if !more {
                break;
            }
        }
        (best, best_eval)
    }
}

fn runner_with(rng: TestRng) -> TestRunner {
    TestRunner::new_with_rng(Config { failure_persistence: None, ..Config::default() }, rng)
}

impl<C: Clone + std::fmt::Debug + Send + Sync + 'static> Property for Prop<C> {
    fn info(&self) -> PropertyInfo {
        self.info
    }
    fn run_cases(&self, rng: &mut TestRng, cases: u64, variant: Variant, progress: &mut dyn FnMut(u64)) -> ChunkResult {
        let strat = (self.strategy)();
        let mut runner = runner_with(rng.clone());
        let mut out = ChunkResult {
            cases: 0,
            skipped: 0,
            min_slack: f64::INFINITY,
            violations: 0,
            first_violation: None,
            counterexample: None,
        };
        let mut pending = 0;
        for k in 0..cases {
            let saved = runner.rng().clone();
            let tree = match strat.new_tree(&mut runner) {
                Ok(t) => t,
                Err(_) => {
                    out.skipped += 1;
                    continue;
                }
            };
            let case = tree.current();
            let e = (self.eval)(&case, variant);
            out.cases += 1;
            if e.skipped {
                out.skipped += 1;
            } else {
                out.min_slack = out.min_slack.min(e.slack());
                if e.violated() {
                    out.violations += 1;
                    if out.first_violation.is_none() {
                        out.first_violation = Some(k);
                        // regenerate the same tree from the saved state and shrink it
                        let mut r2 = runner_with(saved);
                        let tree2 = strat.new_tree(&mut r2).expect("same state, same tree");
                        let (small, se) = self.shrink(Box::new(tree2), variant);
                        out.counterexample = Some((self.export)(&small, &se));
                    }
                }
            }
            pending += 1;
            if pending == 64 {
                progress(pending);
                pending = 0;
            }
        }
        progress(pending);
        *rng = runner.rng().clone();
        out
    }
}

/// `toml` text of a geometric counterexample: the set as a model file's `[theta]` table (same
/// keys, so it can be pasted into a model) and the points as `[points]`.
pub fn geometric_counterexample(
    set: &geometry::Shape,
    points: &[(&str, &[f64])],
    e: &Eval,
    property: &str,
) -> Counterexample {
    let mut root = toml::Table::new();
    root.insert("property".into(), toml::Value::String(property.into()));
    root.insert("lhs".into(), toml::Value::Float(e.lhs));
    root.insert("rhs".into(), toml::Value::Float(e.rhs));
    root.insert("tol".into(), toml::Value::Float(e.tol));
    root.insert("set_description".into(), toml::Value::String(geometry::ConvexSet::describe(set)));
    if let Some(t) = theta_table(set) {
        root.insert("theta".into(), t);
    }
    let mut pts = toml::Table::new();
    for (name, v) in points {
        pts.insert((*name).into(), toml::Value::Array(v.iter().map(|x| toml::Value::Float(*x)).collect()));
    }
    root.insert("points".into(), toml::Value::Table(pts));
    Counterexample {
        extension: "toml",
        text: toml::to_string(&root).unwrap_or_default(),
        summary: format!(
            "lhs = {:.6e} > rhs = {:.6e} (tol {:.1e}) on {}",
            e.lhs,
            e.rhs,
            e.tol,
            geometry::ConvexSet::describe(set)
        ),
    }
}

/// The model-file `[theta]` table of a set containing the origin (through a carrier system,
/// so the keys are exactly those `model::parse_str` reads).
pub fn theta_table(set: &geometry::Shape) -> Option<toml::Value> {
    use geometry::ConvexSet;
    use nalgebra::{DMatrix, DVector};
    let p = set.dim();
    let sys = model::System::builder()
        .name("carrier")
        .A(-DMatrix::identity(p, p))
        .B(DMatrix::zeros(p, 1))
        .C(DMatrix::identity(p, p))
        .E(DMatrix::zeros(p, p))
        .theta(set.clone())
        .input(model::Input::Zero { m: 1 })
        .x0(DVector::zeros(p))
        .z0(DVector::zeros(p))
        .build()
        .ok()?;
    let t: toml::Table = toml::from_str(&model::to_toml_string(&sys)).ok()?;
    t.get("theta").cloned()
}

/// Model-file counterexample for properties on a system.
pub fn system_counterexample(sys: &model::System, e: &Eval, property: &str, extra: &str) -> Counterexample {
    let mut text = format!(
        "# counterexample to {property}: lhs = {:e}, rhs = {:e}, tol = {:e}\n# {extra}\n# reproduce: moreau simulate / moreau check --only {property} on this model\n",
        e.lhs, e.rhs, e.tol
    );
    text.push_str(&model::to_toml_string(sys));
    Counterexample {
        extension: "toml",
        text,
        summary: format!("lhs = {:.6e} > rhs = {:.6e} (tol {:.1e}); {extra}", e.lhs, e.rhs, e.tol),
    }
}

/// Common imports of the property modules.
pub(crate) mod sets_prelude {
    pub use super::{
        fp_tol, geometric_counterexample, system_counterexample, Counterexample, Eval, Prop, PropertyInfo, Variant,
    };
    pub use crate::strategies::sets::*;
    pub use geometry::linalg::{dist, dot, norm};
    pub use geometry::ConvexSet;
    pub use proptest::prelude::*;
}
