//! Localisation of the mismatch: segment time by regime and report where the residual energy
//! concentrates, against a null reference that says whether the concentration means anything.
//!
//! Two residuals are localised: the position residual `e = y - yhat` and the velocity residual
//! `e_v = v(y) - v(yhat) = v(e)`, `v` the filtered differentiation of the servo metrics
//! ([`metrics::velocity`]: 5-point moving average, then central difference), where friction
//! shows (a reversal changes the velocity residual far more than the position residual).
//! Residual energy per sample `epsilon_k = sum_i e_{k,i}^2 / var(y_i)` (velocity:
//! `sum_i e_v{k,i}^2 / var(v(y_i))`). For a regime `R` (a set of samples) the report gives
//! `share_energy = sum_{k in R} epsilon_k / sum_k epsilon_k` against `share_time = |R| / N`;
//! their ratio (the enrichment) is above 1 where the mismatch concentrates.
//!
//! **Null reference.** Residual energy is autocorrelated and so are the regime masks, so an
//! enrichment of 2 can arise by chance. The null is the energy series circularly shifted
//! against the masks ([`NULL_SHIFTS`] shifts spread evenly over `[s0, N - s0]`, `s0` the larger
//! of the energy's correlation length and the mask's mean run length): a shift keeps both
//! autocorrelations and breaks only their alignment. The report gives the null's 95 %
//! quantile of the enrichment and the p-value `(1 + #{null >= observed}) / (1 + shifts)`; a
//! regime is **enriched** only when `p <= LEVEL / R` (Bonferroni over the `R` testable
//! regimes of the residual). A periodic recording limits the test: shifts by a multiple of
//! the period realign the masks, so `p` cannot fall far below the fraction of such shifts.
//!
//! Regimes (masks depend on the recording, not on the residual):
//! - `reversal`: a sign change of the derived velocity `v(y)` (hysteresis: `|v|` above
//!   `max(5 % of median |v|, 3 noise sigma)` on both sides), widened to the whole low-speed
//!   run around it (`|v|` below the low-speed band `max(10 % of median |v|, the hysteresis)`)
//!   plus the differentiator's half-length (2 samples): sized by the velocity scale, not by
//!   a time constant of the model;
//! - `low_speed`: `|v|` below the low-speed band (reversals and sticking alike);
//! - `contact` / `free`: the nominal model's play is in contact / free (only with a play);
//! - `input_extreme`: some input in the top or bottom 10 % of its range;
//! - `high_acceleration`: `|v(v(y))|` (5-sample moving average) above its 90th percentile.
//!
//! Windows: runs where the moving average of `epsilon` over the **residual energy's
//! correlation length** `L` exceeds twice its mean, trimmed to the first and last sample whose
//! own energy exceeds that level, merged across gaps shorter than `L`, ranked by energy, kept
//! when they hold at least [`MIN_WINDOW_SHARE`] of the energy. `L`
//! is the full width at half height of the energy's autocorrelation (relative to lag 1, so a
//! white component within bursts does not shorten it): a residual made of bursts of `L`
//! samples gives windows of about `L` samples.
use crate::metrics;
use serde::Serialize;

/// Significance level of the enrichment test (family-wise over the regimes of one residual).
pub const LEVEL: f64 = 0.05;
/// Least share of the residual energy in a reported window.
pub const MIN_WINDOW_SHARE: f64 = 0.01;
/// Greatest number of circular shifts of the null reference.
pub const NULL_SHIFTS: usize = 999;

/// Share of residual energy against share of time in one regime, with the null reference.
#[derive(Debug, Clone, Serialize)]
pub struct RegimeShare {
    pub regime: String,
    pub share_time: f64,
    pub share_energy: f64,
    /// `share_energy / share_time`.
    pub enrichment: f64,
    /// 95 % quantile of the enrichment under the null (energy circularly shifted against the
    /// regime mask); `null` when the regime covers no or all samples.
    pub null_q95_enrichment: Option<f64>,
    /// One-sided p-value of the observed enrichment under the null.
    pub p_value: Option<f64>,
    /// `p_value <= LEVEL / R` (Bonferroni over the `R` testable regimes).
    pub enriched: bool,
}

/// A time window where residual energy concentrates.
#[derive(Debug, Clone, Serialize)]
pub struct Window {
    pub t_start: f64,
    pub t_end: f64,
    pub share_energy: f64,
    pub share_time: f64,
    /// The regime most over-represented in the window (fraction of its samples).
    pub dominant_regime: String,
    pub dominant_fraction: f64,
}

/// The data-derived scales of the localisation.
#[derive(Debug, Clone, Serialize)]
pub struct Scales {
    /// Correlation length of the position residual energy (s): the windows' smoothing width
    /// and merge gap.
    pub correlation_length_s: f64,
    /// The same for the velocity residual energy (s).
    pub velocity_correlation_length_s: f64,
    /// Median speed `|v(y)|` per output (units of y per second).
    pub median_speed: Vec<f64>,
    /// Low-speed band per output (units of y per second): reversals and `low_speed`.
    pub low_speed_band: Vec<f64>,
    /// Mean duration of a reversal window (s; `null` without reversals).
    pub reversal_duration_s: Option<f64>,
}

/// How the null reference was drawn.
#[derive(Debug, Clone, Serialize)]
pub struct NullReference {
    pub method: &'static str,
    /// Greatest number of shifts per regime (fewer on short records).
    pub shifts: usize,
    /// Family-wise level; each regime is tested at `level / regimes_tested`.
    pub level: f64,
    pub regimes_tested: usize,
}

/// Localisation result.
#[derive(Debug, Clone, Serialize)]
pub struct Localisation {
    /// Position residual by regime.
    pub regimes: Vec<RegimeShare>,
    pub windows: Vec<Window>,
    /// Velocity residual by regime.
    pub velocity_regimes: Vec<RegimeShare>,
    pub velocity_windows: Vec<Window>,
    pub scales: Scales,
    pub null: NullReference,
    /// Per-sample normalised residual energy (for plotting).
    #[serde(skip)]
    pub energy: Vec<f64>,
    /// Per-sample normalised velocity residual energy.
    #[serde(skip)]
    pub velocity_energy: Vec<f64>,
}

fn moving_average(a: &[f64], w: usize) -> Vec<f64> {
    let n = a.len();
    let h = w / 2;
    let mut cs = vec![0.0; n + 1];
    for k in 0..n {
        cs[k + 1] = cs[k] + a[k];
    }
    (0..n)
        .map(|k| {
            let lo = k.saturating_sub(h);
            let hi = (k + h + 1).min(n);
            (cs[hi] - cs[lo]) / (hi - lo) as f64
        })
        .collect()
}

fn percentile(a: &[f64], q: f64) -> f64 {
    let mut s: Vec<f64> = a.iter().copied().filter(|x| x.is_finite()).collect();
    if s.is_empty() {
        return 0.0;
    }
    s.sort_by(f64::total_cmp);
    s[((s.len() - 1) as f64 * q).round() as usize]
}

/// Correlation length of `a` in samples: `2 l + 1`, `l` the last lag before the
/// autocorrelation (relative to its lag-1 value, so a white component does not shorten it)
/// first falls below one half; 1 when `a` is white (lag-1 autocorrelation below `3 / sqrt N`).
/// Lags are searched by doubling, then bisection (`O(N log L)`), up to `N / 4`.
pub fn correlation_length(a: &[f64]) -> usize {
    let n = a.len();
    if n < 16 {
        return 1;
    }
    let mean = a.iter().sum::<f64>() / n as f64;
    let d: Vec<f64> = a.iter().map(|x| x - mean).collect();
    let c0: f64 = d.iter().map(|x| x * x).sum();
    if c0 <= 0.0 || !c0.is_finite() {
        return 1;
    }
    let acf = |lag: usize| d.iter().zip(&d[lag..]).map(|(a, b)| a * b).sum::<f64>() / c0;
    let r1 = acf(1);
    if r1 < 3.0 / (n as f64).sqrt() {
        return 1;
    }
    let half = 0.5 * r1;
    let max_lag = n / 4;
    let (mut lo, mut hi) = (1usize, 2usize);
    while hi <= max_lag && acf(hi) >= half {
        lo = hi;
        hi *= 2;
    }
    if hi > max_lag {
        return 2 * max_lag + 1;
    }
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if acf(mid) >= half {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    2 * lo + 1
}

/// Regime masks (name, mask) for a recording, with the velocity scales per output
/// (median speed, low-speed band) and the mean reversal duration in samples.
#[allow(clippy::type_complexity)]
pub fn regimes(
    dt: f64,
    y: &[f64],
    p: usize,
    w: &[f64],
    m: usize,
    contact: Option<&[bool]>,
) -> (Vec<(String, Vec<bool>)>, Vec<f64>, Vec<f64>, Option<f64>) {
    let n = y.len() / p.max(1);
    let mut rev = vec![false; n];
    let mut slow = vec![false; n];
    let mut acc_mask = vec![false; n];
    let (mut speeds, mut bands) = (vec![], vec![]);
    let (mut rev_len, mut rev_count) = (0usize, 0usize);
    for i in 0..p {
        let yi = metrics::column(y, p, i, 0, n);
        let v = metrics::velocity(&yi, dt);
        let vabs: Vec<f64> = v.iter().map(|x| x.abs()).collect();
        let vmed = percentile(&vabs[1..n.saturating_sub(1).max(1)], 0.5);
        // noise of y from its second differences (MAD), through the differentiator's white
        // noise gain 1 / (5 dt)
        let d2: Vec<f64> = (1..n.saturating_sub(1)).map(|k| (yi[k + 1] - 2.0 * yi[k] + yi[k - 1]).abs()).collect();
        let sigma_y = 1.4826 * percentile(&d2, 0.5) / 6f64.sqrt();
        let hyst = (0.05 * vmed).max(3.0 * sigma_y / (5.0 * dt));
        let band = (0.1 * vmed).max(hyst);
        speeds.push(vmed);
        bands.push(band);
        // (the first and last velocity are 0 by construction, not a measured rest)
        for k in 1..n.saturating_sub(1) {
            slow[k] |= vabs[k] < band;
        }
        // reversals: sign changes between samples above the hysteresis, widened to the
        // low-speed run around them and by the differentiator's half-length
        let mut last: Option<(usize, f64)> = None;
        for k in 1..n.saturating_sub(1) {
            if vabs[k] <= hyst {
                continue;
            }
            let s = v[k].signum();
            if let Some((kl, sl)) = last {
                if s != sl {
                    let mut lo = kl;
                    while lo > 0 && vabs[lo] < band {
                        lo -= 1;
                    }
                    let mut hi = k;
                    while hi + 1 < n && vabs[hi] < band {
                        hi += 1;
                    }
                    let (lo, hi) = (lo.saturating_sub(2), (hi + 2).min(n - 1));
                    rev_len += hi - lo + 1;
                    rev_count += 1;
                    for r in &mut rev[lo..=hi] {
                        *r = true;
                    }
                }
            }
            last = Some((k, s));
        }
        let a = metrics::velocity(&v, dt);
        let aa: Vec<f64> = moving_average(&a.iter().map(|x| x.abs()).collect::<Vec<_>>(), 5);
        let thr = percentile(&aa, 0.9);
        for k in 0..n {
            acc_mask[k] |= aa[k] > thr;
        }
    }
    let mut ext = vec![false; n];
    for j in 0..m {
        let wj: Vec<f64> = (0..n).map(|k| w[k * m + j]).collect();
        let lo = wj.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = wj.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let r = hi - lo;
        if r <= 0.0 {
            continue;
        }
        for k in 0..n {
            ext[k] |= wj[k] >= hi - 0.1 * r || wj[k] <= lo + 0.1 * r;
        }
    }
    let mut out = vec![("reversal".to_string(), rev), ("low_speed".to_string(), slow)];
    if let Some(c) = contact {
        out.push(("contact".to_string(), c.to_vec()));
        out.push(("free".to_string(), c.iter().map(|b| !b).collect()));
    }
    out.push(("input_extreme".to_string(), ext));
    out.push(("high_acceleration".to_string(), acc_mask));
    let rev_mean = (rev_count > 0).then(|| rev_len as f64 / rev_count as f64);
    (out, speeds, bands, rev_mean)
}

/// Mean length of the runs of `true` in `mask` (0 without any).
fn mean_run(mask: &[bool]) -> f64 {
    let runs = mask.iter().enumerate().filter(|(k, b)| **b && (*k == 0 || !mask[k - 1])).count();
    let cnt = mask.iter().filter(|b| **b).count();
    if runs == 0 {
        0.0
    } else {
        cnt as f64 / runs as f64
    }
}

/// Shares of `energy` per regime with the circular-shift null (`corr` = the energy's
/// correlation length in samples).
fn shares(energy: &[f64], masks: &[(String, Vec<bool>)], corr: usize) -> Vec<RegimeShare> {
    let n = energy.len();
    let total = energy.iter().sum::<f64>();
    let mut cs2 = vec![0.0; 2 * n + 1];
    for k in 0..2 * n {
        cs2[k + 1] = cs2[k] + energy[k % n];
    }
    let testable = masks
        .iter()
        .filter(|(_, mk)| {
            let c = mk.iter().filter(|b| **b).count();
            c > 0 && c < n
        })
        .count()
        .max(1);
    masks
        .iter()
        .map(|(name, mask)| {
            // the mask as runs [a, b), the energy as prefix sums over two periods: a shifted
            // share costs one subtraction per run
            let mut runs: Vec<(usize, usize)> = vec![];
            for (k, _) in mask.iter().enumerate().filter(|(_, b)| **b) {
                match runs.last_mut() {
                    Some(r) if r.1 == k => r.1 = k + 1,
                    _ => runs.push((k, k + 1)),
                }
            }
            let count_in = runs.iter().map(|r| r.1 - r.0).sum::<usize>();
            let st = count_in as f64 / n as f64;
            let share_at = |s: usize| runs.iter().map(|&(a, b)| cs2[b + s] - cs2[a + s]).sum::<f64>() / total;
            let se = if total > 0.0 { share_at(0) } else { 0.0 };
            let mut out = RegimeShare {
                regime: name.clone(),
                share_time: st,
                share_energy: se,
                enrichment: if st > 0.0 { se / st } else { 0.0 },
                null_q95_enrichment: None,
                p_value: None,
                enriched: false,
            };
            if count_in == 0 || count_in == n || total <= 0.0 || !total.is_finite() {
                return out;
            }
            let s0 = (corr as f64).max(mean_run(mask)).ceil().max(1.0) as usize;
            if n <= 2 * s0 + 1 {
                return out;
            }
            let span = n - 2 * s0;
            let count = NULL_SHIFTS.min(span + 1);
            let null: Vec<f64> = (0..count)
                .map(|j| {
                    let s = s0 + if count > 1 { j * span / (count - 1) } else { 0 };
                    share_at(s) / st
                })
                .collect();
            let ge = null.iter().filter(|&&x| x >= out.enrichment * (1.0 - 1e-12)).count();
            let pv = (1 + ge) as f64 / (1 + count) as f64;
            out.null_q95_enrichment = Some(percentile(&null, 0.95));
            out.p_value = Some(pv);
            out.enriched = out.enrichment > 1.0 && pv <= LEVEL / testable as f64;
            out
        })
        .collect()
}

/// Windows of concentrated energy (see the module documentation); `wlen` the smoothing width
/// (the energy's correlation length, at least 3 samples).
fn windows(
    t0: f64,
    dt: f64,
    energy: &[f64],
    masks: &[(String, Vec<bool>)],
    wlen: usize,
    max_windows: usize,
) -> Vec<Window> {
    let n = energy.len();
    let total = energy.iter().sum::<f64>().max(1e-300);
    let sm = moving_average(energy, wlen);
    let thr = 2.0 * total / n as f64;
    let mut runs: Vec<(usize, usize)> = Vec::new();
    let mut k = 0;
    while k < n {
        if sm[k] > thr {
            let s = k;
            while k < n && sm[k] > thr {
                k += 1;
            }
            // trim to the samples whose own energy exceeds the level
            let (mut a, mut b) = (s, k);
            if let (Some(f), Some(l)) =
                (energy[s..k].iter().position(|&e| e > thr), energy[s..k].iter().rposition(|&e| e > thr))
            {
                a = s + f;
                b = s + l + 1;
            }
            match runs.last_mut() {
                Some(last) if a.saturating_sub(last.1) < wlen => last.1 = b,
                _ => runs.push((a, b)),
            }
        } else {
            k += 1;
        }
    }
    let bases: std::collections::HashMap<&str, f64> = masks
        .iter()
        .map(|(name, mask)| (name.as_str(), mask.iter().filter(|b| **b).count() as f64 / n as f64))
        .collect();
    let mut out: Vec<Window> = runs
        .iter()
        .map(|&(s, e)| {
            let en: f64 = energy[s..e].iter().sum();
            let mut best = ("none".to_string(), 0.0, 0.0);
            for (name, mask) in masks {
                let frac = mask[s..e].iter().filter(|b| **b).count() as f64 / (e - s) as f64;
                let base = bases[name.as_str()];
                let lift = if base > 0.0 { frac / base } else { 0.0 };
                if frac > 0.5 && lift > best.2 {
                    best = (name.clone(), frac, lift);
                }
            }
            Window {
                t_start: t0 + dt * s as f64,
                t_end: t0 + dt * (e - 1) as f64,
                share_energy: en / total,
                share_time: (e - s) as f64 / n as f64,
                dominant_regime: best.0,
                dominant_fraction: best.1,
            }
        })
        .collect();
    // a window worth zooming on holds at least MIN_WINDOW_SHARE of the energy (a white
    // residual's chance excursions hold far less)
    out.retain(|w| w.share_energy >= MIN_WINDOW_SHARE);
    out.sort_by(|a, b| b.share_energy.total_cmp(&a.share_energy));
    out.truncate(max_windows);
    out
}

/// Per-sample energy of a residual `e` (flat, `p` columns) normalised by the variance of
/// each column of `scale_of`.
fn energy_of(e: &[f64], scale_of: &[Vec<f64>], p: usize, n: usize) -> Vec<f64> {
    let mut energy = vec![0.0; n];
    for (i, col) in scale_of.iter().enumerate() {
        let mean = col.iter().sum::<f64>() / n as f64;
        let var = (col.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64).max(1e-300);
        for k in 0..n {
            energy[k] += e[k * p + i].powi(2) / var;
        }
    }
    energy
}

/// Localises residual `e = y - yhat` (flat, `p` outputs) and its velocity residual.
#[allow(clippy::too_many_arguments)]
pub fn localise(
    t0: f64,
    dt: f64,
    y: &[f64],
    e: &[f64],
    p: usize,
    w: &[f64],
    m: usize,
    contact: Option<&[bool]>,
    max_windows: usize,
) -> Localisation {
    let n = y.len() / p.max(1);
    let ycols: Vec<Vec<f64>> = (0..p).map(|i| metrics::column(y, p, i, 0, n)).collect();
    let vcols: Vec<Vec<f64>> = ycols.iter().map(|c| metrics::velocity(c, dt)).collect();
    let mut ev = vec![0.0; n * p];
    for i in 0..p {
        for (k, x) in metrics::velocity(&metrics::column(e, p, i, 0, n), dt).into_iter().enumerate() {
            ev[k * p + i] = x;
        }
    }
    let energy = energy_of(e, &ycols, p, n);
    let velocity_energy = energy_of(&ev, &vcols, p, n);
    let (masks, speeds, bands, rev_mean) = regimes(dt, y, p, w, m, contact);
    let corr = correlation_length(&energy);
    let vcorr = correlation_length(&velocity_energy);
    let regimes = shares(&energy, &masks, corr);
    let velocity_regimes = shares(&velocity_energy, &masks, vcorr);
    let regimes_tested = masks
        .iter()
        .filter(|(_, mk)| {
            let c = mk.iter().filter(|b| **b).count();
            c > 0 && c < n
        })
        .count();
    Localisation {
        windows: windows(t0, dt, &energy, &masks, corr.max(3), max_windows),
        velocity_windows: windows(t0, dt, &velocity_energy, &masks, vcorr.max(3), max_windows),
        regimes,
        velocity_regimes,
        scales: Scales {
            correlation_length_s: corr as f64 * dt,
            velocity_correlation_length_s: vcorr as f64 * dt,
            median_speed: speeds,
            low_speed_band: bands,
            reversal_duration_s: rev_mean.map(|r| r * dt),
        },
        null: NullReference {
            method: "circular shifts of the residual energy against the regime masks",
            shifts: NULL_SHIFTS,
            level: LEVEL,
            regimes_tested,
        },
        energy,
        velocity_energy,
    }
}

/// The report's "Where the mismatch is" section: per residual (position, velocity) the
/// regimes against the null and the windows; `units` of the outputs.
pub fn markdown(
    parts: [(&Vec<RegimeShare>, &Vec<Window>); 2],
    scales: &Scales,
    null: &NullReference,
    units: &[String],
) -> String {
    let speed = |v: &[f64]| {
        v.iter()
            .enumerate()
            .map(|(i, x)| metrics::fmt_quantity(*x, &metrics::per_second(units.get(i).map_or("", |s| s.as_str()))))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut s = format!(
        "## Where the mismatch is\n\nScales from the data: residual energy correlation length {:.4} s (position) and {:.4} s (velocity), the windows' smoothing width; median speed {}, low-speed band {}; reversal windows {}. Null reference: {} ({} shifts at most, each at least the correlation length and the regime's mean run), which keeps both autocorrelations; a regime is **enriched** when its p-value is at most {} / {} (Bonferroni over the regimes tested).\n\n",
        scales.correlation_length_s,
        scales.velocity_correlation_length_s,
        speed(&scales.median_speed),
        speed(&scales.low_speed_band),
        scales.reversal_duration_s.map_or("none found".to_string(), |d| format!("{d:.4} s long on average")),
        null.method,
        null.shifts,
        null.level,
        null.regimes_tested.max(1),
    );
    for ((regimes, windows), what) in parts.into_iter().zip([
        "position residual",
        "velocity residual (derived velocity, 5-point moving average and central difference)",
    ]) {
        s += &format!("**{what}**\n\n| regime | share of time | share of residual energy | enrichment | null 95 % | p | enriched |\n|---|---|---|---|---|---|---|\n");
        for g in regimes {
            s += &format!(
                "| {} | {:.1} % | {:.1} % | {:.2} | {} | {} | {} |\n",
                g.regime,
                100.0 * g.share_time,
                100.0 * g.share_energy,
                g.enrichment,
                g.null_q95_enrichment.map_or("-".into(), |q| format!("{q:.2}")),
                g.p_value.map_or("-".into(), |p| format!("{p:.3}")),
                if g.enriched { "**yes**" } else { "no" }
            );
        }
        if windows.is_empty() {
            s += "\nNo window holds more than twice the mean energy.\n\n";
            continue;
        }
        s += "\n| window | start (s) | end (s) | share of energy | share of time | dominant regime |\n|---|---|---|---|---|---|\n";
        for (i, w) in windows.iter().enumerate() {
            s += &format!(
                "| {} | {:.4} | {:.4} | {:.1} % | {:.1} % | {} ({:.0} %) |\n",
                i + 1,
                w.t_start,
                w.t_end,
                100.0 * w.share_energy,
                100.0 * w.share_time,
                w.dominant_regime,
                100.0 * w.dominant_fraction
            );
        }
        s += "\n";
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn gauss(r: &mut ChaCha8Rng) -> f64 {
        // Box-Muller
        let (u1, u2): (f64, f64) = (r.random::<f64>().max(1e-300), r.random());
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }

    /// A non-periodic position (two incommensurate sines) and its velocity.
    fn motion(n: usize, dt: f64) -> (Vec<f64>, Vec<f64>) {
        let y: Vec<f64> = (0..n).map(|k| k as f64 * dt).map(|t| t.sin() + 0.45 * (2.37 * t + 0.4).sin()).collect();
        let v: Vec<f64> =
            (0..n).map(|k| k as f64 * dt).map(|t| t.cos() + 0.45 * 2.37 * (2.37 * t + 0.4).cos()).collect();
        (y, v)
    }

    #[test]
    fn finds_a_burst_and_its_regime() {
        // y a sine, residual concentrated at the velocity reversals (peaks of the sine).
        let n = 2000;
        let dt = 0.01;
        let y: Vec<f64> = (0..n).map(|k| (k as f64 * dt).sin()).collect();
        let w = y.clone();
        let e: Vec<f64> = (0..n).map(|k| if (k as f64 * dt).cos().abs() < 0.1 { 0.1 } else { 0.001 }).collect();
        let l = localise(0.0, dt, &y, &e, 1, &w, 1, None, 10);
        let rev = l.regimes.iter().find(|r| r.regime == "reversal").unwrap();
        assert!(rev.enrichment > 3.0, "{rev:?}");
        assert!(!l.windows.is_empty());
        let total: f64 = l.windows.iter().map(|w| w.share_energy).sum();
        assert!(total > 0.8, "{l:?}");
        // Negative control: uniform residual has no enrichment and no windows.
        let e2 = vec![0.01; n];
        let l2 = localise(0.0, dt, &y, &e2, 1, &w, 1, None, 10);
        assert!(l2.windows.is_empty());
        assert!(l2.regimes.iter().all(|r| (r.enrichment - 1.0).abs() < 1e-9 || r.share_time == 0.0));
        assert!(l2.regimes.iter().all(|r| !r.enriched), "{:?}", l2.regimes);
    }

    #[test]
    fn reversal_energy_beats_the_circular_shift_null_and_white_noise_does_not() {
        let (n, dt) = (6000, 0.005);
        let (y, v) = motion(n, dt);
        let w = y.clone();
        let mut r = ChaCha8Rng::seed_from_u64(7);
        // Friction-like residual: a velocity-residual burst at each slow passage (|v| small),
        // on a white background (noise 1e-4, bursts 2e-3 with random sign per sample).
        let vmed = percentile(&v.iter().map(|x| x.abs()).collect::<Vec<_>>(), 0.5);
        let e: Vec<f64> = (0..n).map(|k| if v[k].abs() < 0.1 * vmed { 2e-3 } else { 1e-4 } * gauss(&mut r)).collect();
        let l = localise(0.0, dt, &y, &e, 1, &w, 1, None, 5);
        let rev = l.regimes.iter().find(|g| g.regime == "reversal").unwrap();
        let q95 = rev.null_q95_enrichment.unwrap();
        assert!(rev.enriched && rev.enrichment > 5.0 && rev.enrichment > 2.0 * q95, "{rev:?}");
        assert!(rev.p_value.unwrap() <= 0.002, "{rev:?}");
        assert!(rev.share_time > 0.02 && rev.share_time < 0.2, "{rev:?}");
        let vrev = l.velocity_regimes.iter().find(|g| g.regime == "reversal").unwrap();
        assert!(vrev.enriched, "{vrev:?}");
        assert!(l.scales.reversal_duration_s.is_some_and(|d| d > 5.0 * dt), "{:?}", l.scales);
        // Negative control: white noise independent of the regimes is enriched nowhere, in
        // either residual, for any of five seeds (the family-wise level is 5 %).
        let mut flagged = 0;
        for seed in 0..5 {
            let mut r = ChaCha8Rng::seed_from_u64(100 + seed);
            let e: Vec<f64> = (0..n).map(|_| 1e-3 * gauss(&mut r)).collect();
            let l = localise(0.0, dt, &y, &e, 1, &w, 1, None, 5);
            // and no window: chance excursions hold less than MIN_WINDOW_SHARE each
            assert!(l.windows.is_empty() && l.velocity_windows.is_empty(), "{:?}", l.windows);
            for g in l.regimes.iter().chain(&l.velocity_regimes) {
                assert!(g.null_q95_enrichment.is_some(), "{g:?}");
                flagged += usize::from(g.enriched);
            }
        }
        assert_eq!(flagged, 0);
        // A smooth (autocorrelated) residual unrelated to the motion: enrichment can stray
        // from 1, the null follows it.
        let e: Vec<f64> = (0..n).map(|k| 1e-3 * (0.173 * k as f64 * dt * 6.0).sin()).collect();
        let l = localise(0.0, dt, &y, &e, 1, &w, 1, None, 5);
        assert!(l.regimes.iter().all(|g| !g.enriched), "{:?}", l.regimes);
    }

    #[test]
    fn window_size_follows_the_residual_correlation_length() {
        let (n, dt) = (8000, 0.001);
        let (y, _) = motion(n, dt);
        let w = y.clone();
        for burst in [40usize, 150] {
            let mut r = ChaCha8Rng::seed_from_u64(burst as u64);
            let mut e: Vec<f64> = (0..n).map(|_| 1e-5 * gauss(&mut r)).collect();
            // bursts of white noise of `burst` samples, spaced 600-1000 samples apart
            let mut starts = vec![];
            let mut k = 300;
            while k + burst < n {
                starts.push(k);
                for x in &mut e[k..k + burst] {
                    *x = 1e-3 * gauss(&mut r);
                }
                k += burst + 600 + (r.random::<f64>() * 400.0) as usize;
            }
            let l = localise(0.0, dt, &y, &e, 1, &w, 1, None, 20);
            let corr = l.scales.correlation_length_s / dt;
            // the energy's full width at half height; bursts covering a sixth of the record
            // lower the half-height crossing by about that fraction (40: 37, 150: 107 samples)
            assert!(corr > 0.6 * burst as f64 && corr < 1.2 * burst as f64, "burst {burst}: correlation length {corr}");
            assert_eq!(l.windows.len(), starts.len().min(20), "burst {burst}: {:?}", l.windows);
            for win in &l.windows {
                let len = (win.t_end - win.t_start) / dt + 1.0;
                assert!((len - burst as f64).abs() < 0.2 * burst as f64, "burst {burst}: window {win:?}");
            }
        }
        // White residual: correlation length one sample, no window.
        let mut r = ChaCha8Rng::seed_from_u64(3);
        assert_eq!(correlation_length(&(0..4000).map(|_| gauss(&mut r).powi(2)).collect::<Vec<_>>()), 1);
    }
}
