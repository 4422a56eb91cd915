//! The selected model refitted and written out: its reported uncertainty ([`uncertainty`]:
//! statistical sigma or the jackknife's spread, the larger, with the stepping bias) and the fitted model
//! ([`fitted`]: its simulation and residual, the grey-box values, `fitted.toml`'s system with
//! the input file that replays the fit, and the effects as reported).
use super::pass::FinerFit;
use super::report::{DerivedParameter, FittedEffect, NominalValue, FITTED_INPUT_FILE};
use super::setup::Setup;
use crate::fit::jackknife::{self, Jackknife};
use crate::fit::FitResult;
use crate::hypothesis::Kind;
use crate::metrics::{self, Fit};
use crate::physics;
use crate::residual::ResidualTests;
use crate::select::{FitContext, Ranked};
use dynamics::extended::{InputHold, SimOutput};
use model::effects::Effect;
use model::{Input, SimDefaults, System};

/// The selected model's reported uncertainty.
pub(super) struct Uncertainty {
    /// The statistical sigma alone (effect parameters, freed nominal parameters).
    pub std_stat: (Vec<f64>, Vec<f64>),
    /// The jackknife over contiguous folds of the estimation segment, where computed.
    pub jack: Option<Jackknife>,
    /// The stepping part ([`stepping_part`]; effect parameters, freed nominal parameters),
    /// where the selected model was refitted at a finer stepping.
    pub stepping: Option<(Vec<f64>, Vec<f64>)>,
    /// What the reported sigma includes (report's `uncertainty_method`).
    pub method: String,
    /// Per selected effect, its main parameter where it is derived from several fitted ones
    /// ([`derived_main`]).
    pub derived: Vec<Option<DerivedParameter>>,
}

/// Reported uncertainty: the statistical sigma of the fit (the larger of Gauss-Newton and
/// the batch-means sandwich) or, where larger, the spread of a delete-a-group jackknife over
/// contiguous folds of the estimation segment (noise and model error: [`jackknife::combine`]),
/// with the bias of the fitter's own stepping added in quadrature ([`with_stepping`], from
/// `finer`: the selected model refitted at a finer stepping); `chosen`'s sigmas become the
/// combined ones.
pub(super) fn uncertainty(
    data: &Setup,
    ctx: &FitContext,
    chosen: Option<&mut Ranked>,
    finer: Option<&FinerFit>,
) -> Uncertainty {
    let s = data.s;
    let mut std_stat: (Vec<f64>, Vec<f64>) = (vec![], vec![]);
    let mut jack: Option<Jackknife> = None;
    let mut stepping: Option<(Vec<f64>, Vec<f64>)> = None;
    let mut derived = Vec::new();
    if let Some(c) = chosen {
        std_stat = (c.std.clone(), c.nominal_std.clone());
        if s.jackknife_iter > 0 && (!c.params.is_empty() || c.refit) {
            let nominal = c.refit.then_some(&c.nominal[..]);
            let j = jackknife::refit_folds(
                |f| ctx.with_refit(ctx.problem_on(vec![], c.parts.clone(), data.k_est, Some(f)), nominal),
                jackknife::Estimate { theta: &c.params, nominal: &c.nominal, x0: &c.x0 },
                &ctx.x_scale,
                data.k_est,
                s.cv_folds,
                s.jackknife_iter,
                &s.fit,
                s.parallel,
            );
            let g = j.estimates.len();
            for (sd, jd) in c.std.iter_mut().zip(&j.std) {
                *sd = jackknife::combine(*sd, jackknife::jackknife_part(*jd, g));
            }
            for (sd, jd) in c.nominal_std.iter_mut().zip(&j.nominal_std) {
                *sd = jackknife::combine(*sd, jackknife::jackknife_part(*jd, g));
            }
            jack = Some(j);
        }
        // The fitter's own stepping: the same model refitted at a finer stepping moves its
        // parameters by what the stepping biases them (issue 27 item 2: backlash inertia 2-4 %
        // low at 2 sub-steps, 3 sigma, and within 1 sigma of its 8-sub-step reading).
        if let Some(f) = finer
            .filter(|f| f.label == c.label && f.theta.len() == c.params.len() && f.nominal.len() == c.nominal.len())
        {
            let st = stepping_part(&c.params, &f.theta, f.substeps, f.substeps_fine);
            let sn = stepping_part(&c.nominal, &f.nominal, f.substeps, f.substeps_fine);
            for (sd, p) in c.std.iter_mut().zip(&st) {
                *sd = with_stepping(*sd, *p);
            }
            for (sd, p) in c.nominal_std.iter_mut().zip(&sn) {
                *sd = with_stepping(*sd, *p);
            }
            stepping = Some((st, sn));
        }
        derived = derived_main(c, jack.as_ref(), finer);
    }
    let jack_resolved = jack.as_ref().is_some_and(|j| j.estimates.len() >= 2);
    let stepping_text = match (&stepping, finer) {
        (Some(_), Some(f)) => format!(" The fitter's own stepping is included as a third part, s_step = |theta({k}) - theta({kf})| {kf}/({kf} - {k}): the selected model refitted at {kf} sub-steps per sample instead of {k} (the first-order stepping bias of the reading at {k}, extrapolated); 1 sigma = sqrt(max(s_stat, c s_jack)^2 + s_step^2).", k = f.substeps, kf = f.substeps_fine),
        _ => String::new(),
    };
    let method = format!(
        "1 sigma = max(s_stat, c s_jack): s_stat the larger of Gauss-Newton and a batch-means sandwich (noise, white or coloured), s_jack a delete-a-group jackknife over {} contiguous folds of the estimation segment (each left out in turn, the selected model refitted on the rest: the spread that model error causes across the record, noise included), c = t_{}(0.975) / 1.96 = {:.2} so that +-2 sigma keeps 95 % coverage with the jackknife's {} degrees of freedom; both parts count the noise, the jackknife also the model error, so the larger is taken. {}A model error that shifts every fold alike (a bias constant over the record) is not seen by any resampling and is not included.{stepping_text}",
        s.cv_folds,
        s.cv_folds - 1,
        jackknife::t_factor(s.cv_folds - 1),
        s.cv_folds - 1,
        match (&jack, jack_resolved) {
            (Some(_), true) => String::new(),
            (Some(j), false) => format!("Here the jackknife is not resolved ({} of {} fold refits moved from the full estimate, which is determined finer than the solver's steps): s_stat alone. ", j.estimates.len(), j.folds.len()),
            (None, _) => "The jackknife was not computed here (no effect parameters, or disabled): s_stat alone. ".into(),
        }
    );
    Uncertainty { std_stat, jack, stepping, method, derived }
}

/// Per effect of `c`, its main parameter where it is derived from several fitted parameters
/// (a Stribeck law's static level, a cogging force's amplitude: [`physics::derived_main`]),
/// with a sigma of the same three parts as the fitted parameters': statistical (the
/// linearised `sqrt(max(g' C_gn g, g' C_sw g))` with the fit's covariances), the jackknife
/// of the derived value over the fold estimates, and the stepping part of the derived value
/// at the finer stepping.
fn derived_main(c: &Ranked, jack: Option<&Jackknife>, finer: Option<&FinerFit>) -> Vec<Option<DerivedParameter>> {
    let finer = finer.filter(|f| f.label == c.label && f.theta.len() == c.params.len());
    let mut off = 0;
    c.parts
        .iter()
        .map(|h| {
            let k = h.k();
            let at = |t: &[f64]| physics::derived_main(h.kind, t).map(|d| d.1);
            let out = physics::derived_main(h.kind, &c.params[off..off + k]).map(|(name, value, g)| {
                let statistical = c.effect_covariance.as_ref().map_or(f64::NAN, |cov| cov.std_of(off, &g));
                let jackknife = jack.map_or(f64::NAN, |j| {
                    let rows: Vec<Vec<f64>> =
                        j.estimates.iter().filter_map(|r| r.get(off..off + k).and_then(at).map(|v| vec![v])).collect();
                    jackknife::jackknife_part(
                        jackknife::jackknife_std(&rows).first().copied().unwrap_or(f64::NAN),
                        rows.len(),
                    )
                });
                let stepping = finer.map_or(f64::NAN, |f| {
                    at(&f.theta[off..off + k])
                        .map_or(f64::NAN, |vf| stepping_part(&[value], &[vf], f.substeps, f.substeps_fine)[0])
                });
                let uncertainty = with_stepping(jackknife::combine(statistical, jackknife), stepping);
                DerivedParameter {
                    name: name.to_string(),
                    value,
                    uncertainty,
                    uncertainty_statistical: statistical,
                    uncertainty_jackknife: jackknife,
                    uncertainty_stepping: stepping,
                }
            });
            off += k;
            out
        })
        .collect()
}

/// The stepping part of the sigma of parameters `theta` fitted at `k` sub-steps per sample,
/// from the same model refitted at `k_f > k`: `|theta - theta_f| k_f / (k_f - k)`. The
/// fitter's plays and stick-slip are first order in the step, `theta(k) = theta_inf + b / k`,
/// so this is `|theta(k) - theta_inf|`, the bias of the reading at `k` (Richardson); `NaN`
/// where either reading is not finite (then not counted, as a jackknife that was not resolved).
pub fn stepping_part(theta: &[f64], theta_f: &[f64], k: usize, k_f: usize) -> Vec<f64> {
    let r = if k_f > k { k_f as f64 / (k_f - k) as f64 } else { f64::NAN };
    theta.iter().zip(theta_f).map(|(a, b)| (a - b).abs() * r).collect()
}

/// A sigma `sd` with the stepping part `step` ([`stepping_part`]) added in quadrature: a bias
/// of the fitter's own discretisation, independent of the noise and model-error scatter. A
/// `NaN` stepping part (no finer stepping) leaves `sd`.
pub fn with_stepping(sd: f64, step: f64) -> f64 {
    if !step.is_finite() {
        return sd;
    }
    (sd * sd + step * step).sqrt()
}

/// The fitted model.
pub(super) struct Fitted {
    /// The selected effects (model-file form).
    pub effects_chosen: Vec<Effect>,
    /// Its simulation (the nominal's where nothing is selected), validation fit and residual
    /// tests.
    pub fit_sim: SimOutput,
    pub fit_after: Fit,
    pub residual_fitted: ResidualTests,
    /// Grey-box refit: the freed nominal parameters as fitted (empty without one).
    pub nominal_refit: Vec<NominalValue>,
    /// `fitted.toml`.
    pub system: System,
    /// The effects as reported.
    pub effects: Vec<FittedEffect>,
}

/// The selected model (`chosen`, else the nominal fit `nom` with its simulation `nom_sim`) in
/// `ctx` under `hold`; notes on what `fitted.toml` cannot state go to `notes`.
pub(super) fn fitted(
    data: &Setup,
    ctx: &FitContext,
    hold: InputHold,
    nom: &FitResult,
    nom_sim: &SimOutput,
    chosen: Option<&Ranked>,
    unc: &Uncertainty,
    notes: &mut Vec<String>,
) -> Fitted {
    let (p, k_est, n_samp, dt) = (data.p, data.k_est, data.n_samp, data.dt);
    let (effects_chosen, x0_fit) = match chosen {
        Some(c) => {
            let pb = ctx.problem(vec![], c.parts.clone());
            (pb.effects(&c.params), c.x0.clone())
        }
        None => (vec![], nom.x0.clone()),
    };
    let fit_sim = match chosen {
        Some(c) => c.problem(ctx).simulate(&c.params, &c.x0, None),
        None => None,
    }
    .unwrap_or(nom_sim.clone());
    let mut fit_after = metrics::fit(&ctx.y, &fit_sim.y, p, k_est, n_samp, dt);
    fit_after.tracking_fit_percent =
        metrics::tracking_fit(&ctx.y, &fit_sim.y, &ctx.w, (p, ctx.m), &data.sys.signals.reference, k_est, n_samp);
    let e_fit: Vec<f64> = ctx.y.iter().zip(&fit_sim.y).map(|(a, b)| a - b).collect();
    let residual_fitted = data.residual_tests(&e_fit, &ctx.w);
    let nominal_refit = nominal_values(data, chosen, unc);
    let system = fitted_system(data, ctx, hold, chosen, &effects_chosen, &x0_fit, &nominal_refit, notes);
    let effects = match chosen {
        Some(c) => fitted_effects(c, unc, hold, dt),
        None => vec![],
    };
    Fitted { effects_chosen, fit_sim, fit_after, residual_fitted, nominal_refit, system, effects }
}

/// Grey-box refit: the fitted nominal parameters, each with its nominal value and
/// uncertainty (`[fit.result]`).
fn nominal_values(data: &Setup, chosen: Option<&Ranked>, unc: &Uncertainty) -> Vec<NominalValue> {
    match (chosen, &data.free_nominal) {
        (Some(c), Some(f)) if c.refit => f
            .params
            .iter()
            .enumerate()
            .map(|(i, fp)| NominalValue {
                name: fp.name.clone(),
                nominal: f.nominal[i],
                value: c.nominal[i],
                std: c.nominal_std[i],
                std_statistical: unc.std_stat.1.get(i).copied().unwrap_or(f64::NAN),
                std_jackknife: unc
                    .jack
                    .as_ref()
                    .and_then(|j| j.nominal_std.get(i).map(|v| jackknife::jackknife_part(*v, j.estimates.len())))
                    .unwrap_or(f64::NAN),
                relative_change: (f.nominal[i] != 0.0).then(|| c.nominal[i] / f.nominal[i] - 1.0),
                bounds: fp.bounds,
                correlation: crate::fit::levenberg_marquardt::correlations_with_others(
                    f.params.iter().map(|q| q.name.as_str()),
                    &c.nominal_correlation,
                    i,
                ),
            })
            .collect(),
        _ => vec![],
    }
}

/// `fitted.toml`'s system: the model file's with the fitted nominal parameters (grey-box
/// refit), the selected effects, the fitted initial state, and the recording's input.
fn fitted_system(
    data: &Setup,
    ctx: &FitContext,
    hold: InputHold,
    chosen: Option<&Ranked>,
    effects_chosen: &[Effect],
    x0_fit: &[f64],
    nominal_refit: &[NominalValue],
    notes: &mut Vec<String>,
) -> System {
    let sys = data.sys;
    let mut fitted_sys = sys.clone();
    // Grey-box refit: the fitted nominal parameters replace the model file's, and each is
    // recorded with its nominal value and uncertainty (`[fit.result]`).
    if let (Some(f), false) = (&data.free_nominal, nominal_refit.is_empty()) {
        match f.apply(&fitted_sys, &nominal_refit.iter().map(|v| v.value).collect::<Vec<_>>()) {
            Ok(s) => fitted_sys = s,
            Err(e) => notes.push(format!("the refitted parameters are not written to the fitted model: {e}")),
        }
        fitted_sys.fit.result = nominal_refit
            .iter()
            .map(|v| model::model_file::FitRecord {
                name: v.name.clone(),
                nominal: v.nominal,
                value: v.value,
                std: v.std,
                correlation: v.correlation.clone(),
            })
            .collect();
    }
    fitted_sys.effects.list.extend(effects_chosen.iter().cloned());
    fitted_sys.x0 = nalgebra::DVector::from_column_slice(x0_fit);
    fitted_sys.z0 = match &data.z0 {
        Some(z) => nalgebra::DVector::from_column_slice(z),
        None => &fitted_sys.C * &fitted_sys.x0,
    };
    fitted_sys.name = format!("{} (fitted by moreau diagnose)", sys.name);
    replay_input(data, ctx, hold, chosen, &mut fitted_sys, notes);
    fitted_sys
}

/// The recording's input (on the uniform grid the fit used, time from 0) and the fit's
/// step, so that `moreau simulate fitted.toml` reproduces the fitted curve. The model
/// file's input is interpolated linearly between its samples: a zero-order hold is
/// written as two samples per interval (at t_k and one sub-step before t_{k+1}), so that
/// only the last sub-step of each interval ramps.
/// Per-input effects (several inputs) are applied to the written input: the input the
/// plant sees on the sub-step grid, written as samples of that grid.
fn replay_input(
    data: &Setup,
    ctx: &FitContext,
    hold: InputHold,
    chosen: Option<&Ranked>,
    fitted_sys: &mut System,
    notes: &mut Vec<String>,
) {
    let (m, n_samp, dt, substeps) = (data.m, data.n_samp, data.dt, ctx.substeps);
    let input_ops = match chosen {
        Some(c) => ctx.problem(vec![], c.parts.clone()).input_ops(&c.params),
        None => vec![],
    };
    let (w_rows, n_rows, dt_rows, sub_rows): (Vec<Vec<f64>>, usize, f64, usize) = if input_ops.is_empty() {
        (data.rec.w.clone(), n_samp, dt, substeps)
    } else {
        let wf = crate::fit::input_effects::transform(&ctx.w, m, dt, substeps, hold, &input_ops);
        let nf = wf.len() / m;
        notes.push(format!(
            "{} act(s) on one input only, which a model file cannot state: fitted.toml's input file ({FITTED_INPUT_FILE}) holds the input as the plant sees it (after these effects, on the grid of {substeps} sub-step(s) per sample), and its effect list omits them.",
            input_ops.iter().map(|o| o.0.label(o.1)).collect::<Vec<_>>().join(", ")
        ));
        (wf.chunks(m).map(|r| r.to_vec()).collect(), nf, dt / substeps as f64, 1)
    };
    let sub_w = sub_rows.max(2);
    let h_sub = dt_rows / sub_w as f64;
    let (t_in, w_in): (Vec<f64>, Vec<Vec<f64>>) = match hold {
        InputHold::Foh => ((0..n_rows).map(|k| k as f64 * dt_rows).collect(), w_rows),
        InputHold::Zoh => {
            let mut t = Vec::with_capacity(2 * n_rows);
            let mut wv = Vec::with_capacity(2 * n_rows);
            for (k, row) in w_rows.iter().enumerate() {
                t.push(k as f64 * dt_rows);
                wv.push(row.clone());
                if k + 1 < n_rows {
                    t.push((k + 1) as f64 * dt_rows - h_sub);
                    wv.push(row.clone());
                }
            }
            (t, wv)
        }
    };
    fitted_sys.input = Input::Samples {
        path: FITTED_INPUT_FILE.into(),
        t: t_in,
        w: w_in,
        period: None,
        hold: model::input::InputHold::Foh,
    };
    let sim_dt = if hold == InputHold::Zoh { h_sub } else { dt_rows / sub_rows as f64 };
    fitted_sys.sim = SimDefaults { dt: sim_dt, periods: 1, t_end: Some((n_samp - 1) as f64 * dt) };
    if hold == InputHold::Zoh {
        notes.push(format!(
            "fitted.toml replays the held input with linear interpolation over the last of {sub_w} sub-steps of each sample (its input file has two points per sample): `moreau simulate` reproduces the fit up to that ramp."
        ));
    }
}

/// The selected effects as reported: parameters, their 1-sigma and its parts; an input
/// delay with its equivalent under the other hold.
fn fitted_effects(c: &Ranked, unc: &Uncertainty, hold: InputHold, dt: f64) -> Vec<FittedEffect> {
    let (std_stat, jack) = (&unc.std_stat, &unc.jack);
    let mut off = 0;
    c.parts
        .iter()
        .enumerate()
        .map(|(j, h)| {
            let k = h.k();
            let fe = FittedEffect {
                kind: h.kind.name().into(),
                label: h.kind.label(),
                description: h.kind.description(),
                params: h.names.iter().zip(&c.params[off..off + k]).map(|(n, v)| (n.to_string(), *v)).collect(),
                uncertainty: h.names.iter().zip(&c.std[off..off + k]).map(|(n, v)| (n.to_string(), *v)).collect(),
                uncertainty_statistical: h
                    .names
                    .iter()
                    .enumerate()
                    .map(|(i, n)| (n.to_string(), std_stat.0.get(off + i).copied().unwrap_or(f64::NAN)))
                    .collect(),
                uncertainty_stepping: h
                    .names
                    .iter()
                    .enumerate()
                    .map(|(i, n)| {
                        let part = unc.stepping.as_ref().and_then(|st| st.0.get(off + i).copied());
                        (n.to_string(), part.unwrap_or(f64::NAN))
                    })
                    .collect(),
                uncertainty_jackknife: h
                    .names
                    .iter()
                    .enumerate()
                    .map(|(i, n)| {
                        let part = jack
                            .as_ref()
                            .and_then(|j| j.std.get(off + i).map(|v| jackknife::jackknife_part(*v, j.estimates.len())));
                        (n.to_string(), part.unwrap_or(f64::NAN))
                    })
                    .collect(),
                other_hold: (h.kind == Kind::InputDelay).then(|| {
                    let d = c.params[off];
                    let (name, v) = match hold {
                        InputHold::Zoh => ("foh", d + 0.5 * dt),
                        InputHold::Foh => ("zoh", (d - 0.5 * dt).max(0.0)),
                    };
                    (name.to_string(), vec![("delay".to_string(), v)])
                }),
                derived: unc.derived.get(j).cloned().flatten(),
            };
            off += k;
            fe
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::stepping_part;

    #[test]
    fn stepping_part_extrapolates_a_first_order_bias() {
        // theta(k) = 2 + 0.8 / k: the reading at 2 sub-steps is 0.4 off; refitted at 8 it moves
        // 0.3, and 0.3 * 8 / 6 = 0.4 is the whole bias (the move alone would claim 0.3).
        let at = |k: usize| 2.0 + 0.8 / k as f64;
        let p = stepping_part(&[at(2)], &[at(8)], 2, 8)[0];
        assert!((p - 0.4).abs() < 1e-12, "{p}");
        assert_eq!(stepping_part(&[1.0, -3.0], &[1.0, -3.0], 4, 16), vec![0.0, 0.0]);
        // No finer stepping: undefined (not counted).
        assert!(stepping_part(&[1.0], &[1.1], 4, 4)[0].is_nan());
    }
}
