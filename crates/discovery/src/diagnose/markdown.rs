//! `report.md`: the report rendered for reading ([`Report::to_markdown`]), one function per
//! section, and the number formats shared with the verdict.
use super::report::Report;
use crate::localise;
use crate::metrics;
use crate::select::NOMINAL_REFIT;

impl Report {
    /// `report.md`.
    pub fn to_markdown(&self, figures: &[(&str, &str)]) -> String {
        let mut s = String::new();
        s += &self.md_record();
        s += &self.md_fit();
        s += &self.md_residual_tests();
        s += &localise::markdown(
            [(&self.regimes, &self.windows), (&self.velocity_regimes, &self.velocity_windows)],
            &self.localisation.scales,
            &self.localisation.null,
            &self.units,
        );
        s += &self.md_remaining();
        s += &self.md_missing_inputs();
        s += &self.md_plant_parameters();
        s += &self.md_effects();
        s += &self.md_ranking();
        s += &self.md_notes_and_figures(figures);
        s
    }

    /// Title, verdict, record, hold, sub-steps, noise level and initial state.
    fn md_record(&self) -> String {
        let mut s = String::new();
        s += &format!("# Diagnosis of `{}` against `{}`\n\n", self.recording, self.model);
        s += &format!("**Verdict:** {}\n\n", self.verdict);
        s += &format!(
            "Record: {} samples, dt = {:.6} s{}; simulation with {} exact linear sub-step(s) per sample. Estimation segment t in [{:.4}, {:.4}] s, validation segment t in [{:.4}, {:.4}] s (never fitted; free-run simulation from the start of the record). Slowest time constant of the nominal loop: {:.4} s.\n\n",
            self.samples, self.dt, if self.resampled { " (resampled from irregular stamps)" } else { "" }, self.substeps, self.estimation_segment[0], self.estimation_segment[1], self.validation_segment[0], self.validation_segment[1], self.tau_slow
        );
        s += &format!(
            "Input hold: **{}**{}. Sub-steps by convergence: {} (changes k -> 2k: {}; tolerance {:.2e}, i.e. {} of the noise level; remaining discretisation error {:.2e}{}, worth at most {:.1} in BIC, added to the selection margin). Noise level (difference estimator): {}. Initial state: {}{}.\n\n",
            self.hold.chosen,
            self.hold.header(),
            self.substeps,
            self.discretisation.ladder.iter().map(|(k, c)| format!("{k}: {c:.2e}")).collect::<Vec<_>>().join(", "),
            self.discretisation.tolerance,
            "a tenth",
            self.discretisation.error_rms,
            if self.discretisation.converged { "" } else { " (NOT converged)" },
            self.delta_bic_discretisation,
            self.noise_level.iter().map(|v| format!("{v:.3e}")).collect::<Vec<_>>().join(", "),
            self.initial_state.source,
            self.initial_state.delta_bic_free.map_or(String::new(), |d| format!(" (estimating it instead would gain {d:.1} in BIC with the nominal model)"))
        );
        s
    }

    /// Fit on the validation segment, nominal and fitted.
    fn md_fit(&self) -> String {
        let mut s = String::new();
        s += "## Fit on the validation segment\n\n| | fit % | RMSE | velocity fit % | velocity RMSE |\n|---|---|---|---|---|\n";
        let vunits: Vec<String> = self.units.iter().map(|u| metrics::per_second(u)).collect();
        for (name, f) in [("nominal", &self.fit_before), ("fitted", &self.fit_after)] {
            s += &format!(
                "| {name} | {} | {} | {} | {} |\n",
                fmt_opt(&f.fit_percent),
                fmt_units(&f.rmse, &self.units),
                fmt_opt(&f.velocity_fit_percent),
                fmt_units(&f.velocity_rmse, &vunits)
            );
        }
        s += &format!(
            "\nHeadline ({}): {}. Velocity: derived from y by a 5-point moving average and a central difference, the same filter on measurement and simulation.\n\n",
            if self.headline_metric == "rmse" { "RMSE in the output's units" } else { "fit %" },
            self.headline
        );
        s
    }

    /// Residual tests of the nominal model (and of the fitted one).
    fn md_residual_tests(&self) -> String {
        let mut s = String::new();
        s += "## Residual tests (nominal model)\n\n";
        let r = &self.residual_nominal;
        s += &format!(
            "- mean: {:.3e} against the 99 % bound {:.3e}: **{}**\n- whiteness: Q = {:.1} against the 99 % threshold {:.1} ({} lags of {} sample(s)): **{}**\n- input cross-correlation: Q = {} against {:.1}: **{}**\n- after fitting: white = {}, uncorrelated = {} (Q = {:.1}, cross Q = {})\n\n",
            r.mean, r.mean_bound, if r.zero_mean { "zero mean" } else { "offset" }, r.q_auto, r.q_auto_threshold, r.lags, r.lag_step, if r.white { "white" } else { "not white" }, fmt_vec(&r.q_cross), r.q_cross_threshold, if r.uncorrelated { "uncorrelated" } else { "correlated" },
            self.residual_fitted.white, self.residual_fitted.uncorrelated, self.residual_fitted.q_auto, fmt_vec(&self.residual_fitted.q_cross)
        );
        s
    }

    /// What the final model leaves unexplained (where it is incomplete).
    fn md_remaining(&self) -> String {
        if let Some(e) = self.residual_explained.as_ref().filter(|e| e.reason != "white" || !e.uncorrelated) {
            let text = e.text();
            let mut first = text.chars();
            let capital: String = first.next().map(|c| c.to_uppercase().chain(first).collect()).unwrap_or_default();
            return format!("\n## What is left\n\n{capital}; the model is not called incomplete.\n");
        }
        let Some(r) = &self.remaining else { return String::new() };
        let mut s = format!(
            "\n## Still missing\n\nThe final model's residual is not white (Q = {:.1} against the 99 % threshold {:.1}; {:.1} with an AR(1) noise colour of {} removed, {} with the input; {} with the input before) and its RMS is {} times the noise level: the model is incomplete. Where the residual left concentrates:\n\n",
            r.q_auto,
            r.q_auto_threshold,
            r.q_auto_ar1,
            r.ar1.iter().map(|x| format!("{x:.2}")).collect::<Vec<_>>().join(", "),
            if r.uncorrelated_ar1 { "uncorrelated" } else { "correlated" },
            if r.uncorrelated { "uncorrelated" } else { "correlated" },
            r.rms_over_noise.iter().map(|x| format!("{x:.2}")).collect::<Vec<_>>().join(", ")
        );
        if r.windows.is_empty() {
            s += "- no window stands out (spread over the record)\n";
        }
        for w in &r.windows {
            s += &format!(
                "- t = {:.4}-{:.4} s: {:.1} % of the energy in {:.1} % of the time, mostly {} ({:.0} %)\n",
                w.t_start,
                w.t_end,
                100.0 * w.share_energy,
                100.0 * w.share_time,
                w.dominant_regime,
                100.0 * w.dominant_fraction
            );
        }
        if !r.regimes.is_empty() {
            s += &format!(
                "- enriched regimes: {}\n",
                r.regimes
                    .iter()
                    .map(|g| format!("{} ({:.1} x the time share)", g.regime, g.enrichment))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
        s
    }

    /// Recorded signals that are not model inputs.
    fn md_missing_inputs(&self) -> String {
        let mut s = String::new();
        if !self.missing_inputs.is_empty() {
            s += "\n## Recorded signals that are not model inputs\n\nEach fed through the linearised nominal dynamics (on every state) and regressed on the nominal residual (estimation segment); reported missing when it explains at least half the residual and 10 points more than the best hypothesis of the library.\n\n| column | residual explained | best hypothesis (explains) | missing input |\n|---|---|---|---|\n";
            for c in &self.missing_inputs {
                s += &format!(
                    "| {} | {:.1} % | {} ({:.1} %) | {} |\n",
                    c.column,
                    100.0 * c.explained,
                    c.best_hypothesis,
                    100.0 * c.best_hypothesis_explained,
                    if c.missing { "**yes**" } else { "no" }
                );
            }
        }
        s
    }

    /// Plant parameters of the grey-box refit.
    fn md_plant_parameters(&self) -> String {
        let mut s = String::new();
        if !self.free_parameters.is_empty() {
            s += "\n## Plant parameters (grey-box refit)\n\n";
            if self.nominal_refit.is_empty() {
                s += &format!(
                    "Freed in the model file: {}. Refitting them was not selected (see `{NOMINAL_REFIT}` in the ranking): the nominal values stand.\n",
                    self.free_parameters.join(", ")
                );
            } else {
                s += "| parameter | nominal | fitted | 1 sigma | change | bounds |\n|---|---|---|---|---|---|\n";
                for v in &self.nominal_refit {
                    s += &format!(
                        "| {} | {} | {} | {} | {} | {} |\n",
                        v.name,
                        g4(v.nominal),
                        g4(v.value),
                        if v.std.is_finite() { format!("{:.2e}", v.std) } else { "undefined".into() },
                        v.relative_change.map_or("-".into(), |r| format!("{:+.2} %", 100.0 * r)),
                        v.bounds.map_or("-".into(), |(a, b)| format!("[{}, {}]", g4(a), g4(b)))
                    );
                }
            }
        }
        s
    }

    /// Effects added, with their uncertainty; ties.
    fn md_effects(&self) -> String {
        let mut s = String::new();
        s += "\n## Effects added\n\n";
        if self.effects.is_empty() {
            s += "None.\n\n";
        } else {
            s += &format!("Uncertainty: {}\n\n", self.uncertainty_method);
        }
        for e in &self.effects {
            s += &format!("- **{}**: {}\n", e.label, e.description);
            for (i, ((n, v), (_, u))) in e.params.iter().zip(&e.uncertainty).enumerate() {
                let part = |l: &[(String, f64)]| l.get(i).map_or(f64::NAN, |x| x.1);
                let (st, jk) = (part(&e.uncertainty_statistical), part(&e.uncertainty_jackknife));
                let sp = part(&e.uncertainty_stepping);
                s += &format!(
                    "  - {n} = {v:.6} +- {u:.2e} (1 sigma; statistical {st:.2e}, fold jackknife {}{})\n",
                    if jk.is_finite() { format!("{jk:.2e}") } else { "n/a".into() },
                    if sp.is_finite() { format!(", stepping {sp:.2e}") } else { String::new() }
                );
            }
            if let Some(d) = &e.derived {
                s += &format!(
                    "  - {} = {:.6} +- {:.2e} (derived; 1 sigma; statistical {:.2e}, fold jackknife {}{})\n",
                    d.name,
                    d.value,
                    d.uncertainty,
                    d.uncertainty_statistical,
                    if d.uncertainty_jackknife.is_finite() {
                        format!("{:.2e}", d.uncertainty_jackknife)
                    } else {
                        "n/a".into()
                    },
                    if d.uncertainty_stepping.is_finite() {
                        format!(", stepping {:.2e}", d.uncertainty_stepping)
                    } else {
                        String::new()
                    }
                );
            }
            if let Some((h, ps)) = &e.other_hold {
                for (n, v) in ps {
                    s += &format!("  - under the {h} hold instead: {n} = {v:.6}\n");
                }
            }
        }
        if !self.ties.is_empty() {
            s += &format!(
                "\nIndistinguishable on this recording (BIC within the tie margin): {}.\n",
                self.ties.join(", ")
            );
        }
        if !self.equivalents.is_empty() {
            s += &format!(
                "\nOther readings that fit as well (BIC within the tie margin of the selected model; the recording cannot tell them apart): {}.\n",
                self.equivalents
                    .iter()
                    .map(|e| format!("{} ({:+.1} in BIC)", e.label, e.delta_bic))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
        s
    }

    /// Ranking of all hypotheses.
    fn md_ranking(&self) -> String {
        let mut s = String::new();
        s += "\n## Ranking of all hypotheses\n\nSelection: BIC gain of at least the margin (plus the discretisation allowance) on the estimation segment, then blocked cross-validation over contiguous folds of the whole record (each held out in turn, the hypothesis and the model it extends refitted on the others). A stuck fit (zero gradient, clipped at a bound) is inconclusive, not evidence against its effect.\n\n| hypothesis | params | delta BIC | validation fit % | validation SSE ratio | CV SSE ratio | fit | evidence |\n|---|---|---|---|---|---|---|---|\n";
        for r in &self.ranking {
            let inconclusive = r.evidence.starts_with("inconclusive");
            let params = if r.refit {
                let nom: Vec<String> = r.nominal.iter().map(|v| g4(*v)).collect();
                let eff = fmt_e(&r.params);
                format!("{}plant: {}", if eff.is_empty() { String::new() } else { format!("{eff}; ") }, nom.join(", "))
            } else {
                fmt_e(&r.params)
            };
            s += &format!(
                "| {} | {} | {} | {} | {:.3} | {} | {:?} | {} |\n",
                r.label,
                params,
                if inconclusive { "n/a".to_string() } else { format!("{:.1}", r.delta_bic) },
                fmt_opt(&r.validation.fit_percent),
                r.validation_ratio,
                r.cv.as_ref().map_or("-".to_string(), |c| format!("{:.3} ({})", c.ratio, c.status)),
                r.status,
                r.evidence
            );
        }
        s
    }

    /// Notes and figures.
    fn md_notes_and_figures(&self, figures: &[(&str, &str)]) -> String {
        let mut s = String::new();
        if !self.notes.is_empty() {
            s += "\n## Notes\n\n";
            for n in &self.notes {
                s += &format!("- {n}\n");
            }
        }
        if !figures.is_empty() {
            s += "\n## Figures\n\n";
            for (f, cap) in figures {
                s += &format!("![{cap}]({f})\n\n");
            }
        }
        s
    }
}

/// Values with one decimal.
fn fmt_vec(v: &[f64]) -> String {
    v.iter().map(|x| format!("{x:.1}")).collect::<Vec<_>>().join(", ")
}

/// Fit % values, `undefined` where the measured segment is constant.
pub(super) fn fmt_opt(v: &[Option<f64>]) -> String {
    v.iter()
        .map(|x| x.map_or("undefined (constant output)".to_string(), |x| format!("{x:.1}")))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Four significant digits.
pub(super) fn g4(x: f64) -> String {
    if x == 0.0 {
        // log10(0) = -inf: the digit count below would overflow
        return format!("{x:.0}");
    }
    if (1e-3..1e5).contains(&x.abs()) {
        let d = (3 - x.abs().log10().floor() as i32).clamp(0, 6) as usize;
        format!("{x:.d$}")
    } else {
        format!("{x:.3e}")
    }
}

/// Values with their units (see [`metrics::fmt_quantity`]).
pub(super) fn fmt_units(v: &[f64], units: &[String]) -> String {
    v.iter()
        .enumerate()
        .map(|(i, x)| metrics::fmt_quantity(*x, units.get(i).map_or("", |s| s.as_str())))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Values in scientific notation (4 decimals).
fn fmt_e(v: &[f64]) -> String {
    v.iter().map(|x| format!("{x:.4e}")).collect::<Vec<_>>().join(", ")
}

#[cfg(test)]
mod tests {
    use super::g4;

    /// Found by the coverage-guided fuzzer (fuzz/regressions/diagnose/): a refitted nominal
    /// value of 0 overflowed the digit count (3 - log10(0) as i32) in debug builds.
    #[test]
    fn g4_prints_zero() {
        assert_eq!(g4(0.0), "0");
        assert_eq!(g4(-0.0), "-0");
        assert_eq!(g4(1.5), "1.500");
        assert_eq!(g4(2e-5), "2.000e-5");
    }
}
