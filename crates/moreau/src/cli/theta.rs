//! `moreau theta FILE [--json] [--out FILE]`: the paper's bound theta (eq. (theta)) with every
//! intermediate quantity labelled by its equation and flagged verified / estimate, next to the
//! measured convergence exponent, path length per period and limsup |z'|.
use crate::commands::theta::{theta, ThetaOptions};
use crate::commands::Source;
use bounds::report::{fmt_value, render_table};
use bounds::ThetaReport;
use geometry::ConvexSet;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Debug, clap::Args)]
#[command(after_help = "Examples:
  moreau theta examples/worked-example.toml              # readable report, verdict, guidance
  moreau theta examples/worked-example.toml --explain    # plus what every row means
  moreau theta examples/worked-example.toml --brief      # only the verdict, a few lines
  moreau theta examples/ellipse-p2.toml --json --out theta.json --no-measure")]
pub struct Args {
    /// Model file (TOML) with a periodic input.
    pub file: PathBuf,
    /// Print one JSON object (stable snake_case keys) instead of the readable report.
    #[arg(long)]
    pub json: bool,
    /// Also write the JSON object to this file (atomically).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Skip the measured side (simulated pairs of trajectories).
    #[arg(long)]
    pub no_measure: bool,
    /// Measure again at a half and a quarter of the step, and at the quarter with a 100 times
    /// smaller separation, and widen the measured intervals by the changes (the catching-up
    /// step's error and the pairs' distance from the linearisation; eleven times the work).
    #[arg(long, conflicts_with = "no_measure")]
    pub step_check: bool,
    /// Skip the stationary set of Theorem 1.
    #[arg(long)]
    pub no_stationary: bool,
    /// After the report, explain every row in plain words (what it is, what to conclude).
    #[arg(long, conflicts_with = "brief")]
    pub explain: bool,
    /// Print only the verdict block (what is certified, theta_best, whether verified, the
    /// measured exponent): a few lines of at most 100 columns, without the table.
    #[arg(long, conflicts_with = "json")]
    pub brief: bool,
    /// Skip the design guidance printed when nothing is certified (which term blocks,
    /// sensitivities, smallest certifying amplitude: a few dozen bound computations).
    #[arg(long)]
    pub no_guidance: bool,
}

/// Width of the verdict block (`--brief` and the head of the report).
const VERDICT_WIDTH: usize = 100;

/// Appends `first` then `text` word-wrapped to [`VERDICT_WIDTH`] columns, continuation lines
/// indented by two spaces (a word longer than the width stays whole on its line).
fn push_wrapped(s: &mut String, first: &str, text: &str) {
    let mut line = String::from(first);
    let mut empty = true;
    for word in text.split_whitespace() {
        if !empty && line.len() + 1 + word.len() > VERDICT_WIDTH {
            s.push_str(&line);
            s.push('\n');
            line = String::from("  ");
        } else if !empty {
            line.push(' ');
        }
        line.push_str(word);
        empty = false;
    }
    s.push_str(&line);
    s.push('\n');
}

/// The verdict block that leads the report and is all of `--brief`: what is certified, the best
/// bound `theta_best` and whether it is verified, the verdict sentence and the measured side, in
/// lines of at most [`VERDICT_WIDTH`] columns.
pub fn render_verdict(rep: &ThetaReport) -> String {
    let mut s = String::new();
    let what = if rep.convergence_guaranteed && rep.effects.is_empty() {
        "convergence CERTIFIED"
    } else {
        "NOTHING certified"
    };
    s.push_str(&format!(
        "Verdict: {what}; theta_best = {} = {} ({})\n",
        rep.theta_best_method,
        fmt_value(rep.theta_best),
        if rep.theta_best_verified { "verified bound" } else { "NOT verified" }
    ));
    let verdict = if !rep.effects.is_empty() {
        format!(
            "theta = {} is the NOMINAL model's bound, NOT verified for this model: its effects ({}) are outside the paper's class; no convergence guarantee.",
            fmt_value(rep.theta),
            rep.effects.join(", ")
        )
    } else if rep.convergence_guaranteed && rep.theta_best_method != "theta" {
        format!(
            "{m} = {} < 0 (verified; paper's theta = {}): every trajectory converges to the unique T-periodic regime, Lyapunov exponent <= {m}.",
            fmt_value(rep.theta_best),
            fmt_value(rep.theta),
            m = rep.theta_best_method
        )
    } else if rep.convergence_guaranteed {
        format!(
            "theta = {} < 0 (verified): every trajectory converges to the unique T-periodic regime, Lyapunov exponent <= theta.",
            fmt_value(rep.theta)
        )
    } else if rep.theta < 0.0 {
        format!("theta = {} < 0 but NOT verified (see the flags in the table): no guarantee.", fmt_value(rep.theta))
    } else if rep.R.is_infinite() {
        format!(
            "theta = psi(0) = {} >= 0: Theta is not strongly convex, and then no certificate of this kind exists (psi(0) >= 0 for every admissible Pi, proofs-notes/psi0.md).",
            fmt_value(rep.theta)
        )
    } else {
        format!(
            "theta = {} >= 0: the bound does not guarantee convergence (psi(0) = {}; kappa = gamma_1/gamma_inf = {}; theta < 0 needs psi(0) < kappa lambda/(1 - kappa)).",
            fmt_value(rep.theta),
            fmt_value(rep.psi_0),
            fmt_value(rep.kappa)
        )
    };
    push_wrapped(&mut s, "  ", &verdict);
    if let Some(m) = &rep.measured {
        push_wrapped(&mut s, "", &format!(
            "Reality: measured exponent {} (95% CI [{}, {}]); path length/period {} vs bounds (path) {}, (path1) {}, (path2) {}; limsup |z'| {} vs (zinf) {}, pinned {}.\n",
            fmt_value(m.rate),
            fmt_value(m.ci_low),
            fmt_value(m.ci_high),
            fmt_value(m.path_length_per_period),
            fmt_value(rep.path_bound),
            fmt_value(rep.path1_bound),
            fmt_value(rep.path2.value),
            fmt_value(m.limsup_zdot),
            fmt_value(rep.zdot_bound),
            fmt_value(rep.zdot_star_bound)
        ));
    }
    s
}

/// `x` rounded down (`up = false`) or up to 7 decimals, so that a printed enclosure still
/// contains the computed one.
fn directed_7(x: f64, up: bool) -> String {
    let s = 1e7;
    let mut v = if up { (x * s).ceil() / s } else { (x * s).floor() / s };
    if up && v < x {
        v += 1.0 / s;
    } else if !up && v > x {
        v -= 1.0 / s;
    }
    format!("{v:.7}")
}

/// The line of the verified Floquet exponent (issue 30): `floquet_exponent [lo, hi] (verified)`
/// (printed outward to 7 decimals), with the bracket `[floquet_lo, theta_best]` of the
/// convergence exponent when both are proven; otherwise why not, with the measured dominant
/// multiplier (labelled as a measurement) or else the floating-point estimate when there is one.
pub fn render_floquet(rep: &ThetaReport, f: &bounds::beyond_paper::floquet::FloquetEnclosure) -> String {
    let [lo, hi] = f.floquet_exponent;
    let text = if f.verified {
        let bracket = if rep.theta_best_verified && rep.theta_best < 0.0 && rep.effects.is_empty() {
            format!(
                "; the convergence exponent lies in [floquet_lo, theta_best] = [{}, {}]",
                directed_7(lo, false),
                fmt_value(rep.theta_best)
            )
        } else {
            String::new()
        };
        format!("floquet_exponent [{}, {}] (verified{bracket})", directed_7(lo, false), directed_7(hi, true))
    } else {
        let reason = f.reason.as_deref().unwrap_or("unknown");
        let measured = rep.measured.as_ref().and_then(|m| m.multiplier);
        if let Some([e, lo, hi]) = measured {
            format!(
                "floquet_exponent not verified ({reason}); measured from simulated pairs (not a proof): {} (95% CI [{}, {}])",
                fmt_value(e),
                fmt_value(lo),
                fmt_value(hi)
            )
        } else if f.estimate.is_finite() {
            format!(
                "floquet_exponent [{e}, {e}] (not verified: {reason}; floating-point estimate)",
                e = fmt_value(f.estimate)
            )
        } else {
            format!("floquet_exponent n/a (not verified: {reason})")
        }
    };
    let mut s = String::new();
    push_wrapped(&mut s, "", &text);
    s
}

/// The readable report: the header, the verdict block ([`render_verdict`]) and the Floquet line
/// ([`render_floquet`], when computed), the table of every quantity, the stationary set and the
/// notes.
pub fn render(
    rep: &ThetaReport,
    theta_desc: &str,
    floquet: Option<&bounds::beyond_paper::floquet::FloquetEnclosure>,
) -> String {
    let mut s = String::new();
    s.push_str(&format!(
        "moreau theta: {}\n  n = {}, m = {}, p = {}, T = {:.6}, Theta = {}\n\n",
        rep.name, rep.n, rep.m, rep.p, rep.period, theta_desc
    ));
    s.push_str(&render_verdict(rep));
    if let Some(f) = floquet {
        s.push_str(&render_floquet(rep, f));
    }
    s.push('\n');
    s.push_str(&render_table(&rep.quantities()));
    s.push('\n');
    if let Some(st) = &rep.stationary {
        let state = match st.empty {
            Some(true) => format!(
                "empty (slack s* = {}{})",
                fmt_value(st.slack),
                if st.verified { ", proven" } else { ", solver estimate" }
            ),
            Some(false) => format!(
                "nonempty: z0 = {:?} stays at rest over [0, T] (simulated drift {})",
                st.point.as_deref().unwrap_or(&[]),
                st.max_drift.map(fmt_value).unwrap_or_else(|| "n/a".into())
            ),
            None => "undecided (grid point did not stay at rest in simulation)".into(),
        };
        s.push_str(&format!("Stationary set R(T) (Thm 1, (stat1)): {state}\n"));
        match st.phi.first_singular {
            Some(t) => s.push_str(&format!("Phi(t) (eq. (Phi)) becomes singular at t = {t:.6}\n")),
            None => {
                s.push_str(&format!("Phi(t) (eq. (Phi)) nonsingular on [0, T] (min sigma {:.3e})\n", st.phi.min_sigma))
            }
        }
    }
    for n in &rep.notes {
        s.push_str(&format!("note: {n}\n"));
    }
    s
}

/// The glossary of `--explain`: one paragraph per reported row.
pub fn explain(rep: &ThetaReport) -> String {
    let mut s =
        String::from("\nWhat the rows mean (equation numbers as printed in the paper, source labels in brackets):\n");
    for q in rep.quantities() {
        if let Some(g) = bounds::report::glossary(q.key) {
            s.push_str(&format!("- {} {} [{}]: {g}\n", q.symbol, q.equation, q.label));
        }
    }
    s.push_str("A row is 'verified' when the number is a proven bound in the stated direction (rounding included); 'estimate' rows are measured or sampled and bound nothing.\n");
    s
}

pub fn run(a: &Args) -> anyhow::Result<ExitCode> {
    // `--brief` prints no guidance: computed only when a JSON object carries it
    let guidance = !a.no_guidance && (!a.brief || a.out.is_some());
    let o = ThetaOptions { measure: !a.no_measure, stationary: !a.no_stationary, guidance, step_check: a.step_check };
    // refused before the work, not after it
    crate::output::register_input(&a.file);
    if let Some(out) = &a.out {
        crate::output::check_writable(out)?;
    }
    let run = theta(&Source::File(a.file.clone()), &o)?;
    let json = serde_json::to_string_pretty(&run.to_json()?)?;
    if let Some(out) = &a.out {
        crate::output::write_atomic(out, json.as_bytes())?;
    }
    if a.json {
        println!("{json}");
    } else if a.brief {
        print!("{}", render_verdict(&run.report));
        if let Some(f) = &run.floquet {
            print!("{}", render_floquet(&run.report, f));
        }
    } else {
        print!("{}", render(&run.report, &run.sys.theta.describe(), run.floquet.as_ref()));
        if let Some(g) = &run.guidance {
            print!("{}", g.render());
        }
        if a.explain {
            print!("{}", explain(&run.report));
        }
    }
    Ok(ExitCode::SUCCESS)
}
