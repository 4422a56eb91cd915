//! Localisation of the mismatch: segment time by regime and report where the residual energy
//! concentrates.
//!
//! Residual energy per sample `epsilon_k = sum_i e_{k,i}^2 / var(y_i)`. For a regime `R` (a set
//! of samples) the report gives `share_energy = sum_{k in R} epsilon_k / sum_k epsilon_k`
//! against `share_time = |R| / N`; their ratio (the enrichment) is above 1 where the
//! mismatch concentrates. Regimes:
//! - `reversal`: within `+-half_width` of a sign change of the smoothed velocity of `y`;
//! - `contact` / `free`: the nominal model's play is in contact / free (only with a play);
//! - `input_extreme`: some input in the top or bottom 10 % of its range;
//! - `high_acceleration`: smoothed `|y''|` above its 90th percentile.
//!
//! Windows: runs where the moving average of `epsilon` (width `W`) exceeds twice its mean,
//! merged across gaps shorter than `W`, ranked by energy.
use serde::Serialize;

/// Share of residual energy against share of time in one regime.
#[derive(Debug, Clone, Serialize)]
pub struct RegimeShare {
    pub regime: String,
    pub share_time: f64,
    pub share_energy: f64,
    /// `share_energy / share_time`.
    pub enrichment: f64,
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

/// Localisation result.
#[derive(Debug, Clone, Serialize)]
pub struct Localisation {
    pub regimes: Vec<RegimeShare>,
    pub windows: Vec<Window>,
    /// Per-sample normalised residual energy (for plotting).
    #[serde(skip)]
    pub energy: Vec<f64>,
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

/// Regime masks (name, mask) for a recording.
pub fn regimes(
    t0: f64,
    dt: f64,
    y: &[f64],
    p: usize,
    w: &[f64],
    m: usize,
    contact: Option<&[bool]>,
    half_width: usize,
) -> Vec<(String, Vec<bool>)> {
    let _ = t0;
    let n = y.len() / p;
    let sw = (n / 200).max(5);
    let mut rev = vec![false; n];
    let mut acc_mask = vec![false; n];
    for i in 0..p {
        let yi: Vec<f64> = (0..n).map(|k| y[k * p + i]).collect();
        let ys = moving_average(&yi, sw);
        let v: Vec<f64> =
            (0..n).map(|k| if k == 0 || k + 1 == n { 0.0 } else { (ys[k + 1] - ys[k - 1]) / (2.0 * dt) }).collect();
        let vs = moving_average(&v, sw);
        let vscale = percentile(&vs.iter().map(|x| x.abs()).collect::<Vec<_>>(), 0.5);
        // A reversal: sign change of the smoothed velocity between two samples where the
        // speed exceeds 5 % of its median (ignore noise around rest).
        let mut last_sign = 0.0;
        for k in 1..n {
            if vs[k].abs() > 0.05 * vscale {
                let s = vs[k].signum();
                if last_sign != 0.0 && s != last_sign {
                    for j in k.saturating_sub(half_width)..(k + half_width + 1).min(n) {
                        rev[j] = true;
                    }
                }
                last_sign = s;
            }
        }
        let a: Vec<f64> =
            (0..n).map(|k| if k == 0 || k + 1 == n { 0.0 } else { (vs[k + 1] - vs[k - 1]) / (2.0 * dt) }).collect();
        let aa: Vec<f64> = moving_average(&a, sw).iter().map(|x| x.abs()).collect();
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
        for k in 0..n {
            ext[k] |= wj[k] >= hi - 0.1 * r || wj[k] <= lo + 0.1 * r;
        }
    }
    let mut out = vec![("reversal".to_string(), rev)];
    if let Some(c) = contact {
        out.push(("contact".to_string(), c.to_vec()));
        out.push(("free".to_string(), c.iter().map(|b| !b).collect()));
    }
    out.push(("input_extreme".to_string(), ext));
    out.push(("high_acceleration".to_string(), acc_mask));
    out
}

/// Localises residual `e = y - yhat` (flat, `p` outputs).
pub fn localise(
    t0: f64,
    dt: f64,
    y: &[f64],
    e: &[f64],
    p: usize,
    w: &[f64],
    m: usize,
    contact: Option<&[bool]>,
    half_width: usize,
    max_windows: usize,
) -> Localisation {
    let n = y.len() / p;
    let mut energy = vec![0.0; n];
    for i in 0..p {
        let mean = (0..n).map(|k| y[k * p + i]).sum::<f64>() / n as f64;
        let var = ((0..n).map(|k| (y[k * p + i] - mean).powi(2)).sum::<f64>() / n as f64).max(1e-300);
        for k in 0..n {
            energy[k] += e[k * p + i].powi(2) / var;
        }
    }
    let total = energy.iter().sum::<f64>().max(1e-300);
    let masks = regimes(t0, dt, y, p, w, m, contact, half_width);
    let regimes: Vec<RegimeShare> = masks
        .iter()
        .map(|(name, mask)| {
            let cnt = mask.iter().filter(|b| **b).count();
            let en: f64 = energy.iter().zip(mask).filter(|(_, b)| **b).map(|(e, _)| e).sum();
            let st = cnt as f64 / n as f64;
            let se = en / total;
            RegimeShare {
                regime: name.clone(),
                share_time: st,
                share_energy: se,
                enrichment: if st > 0.0 { se / st } else { 0.0 },
            }
        })
        .collect();
    let wlen = (n / 100).max(5);
    let sm = moving_average(&energy, wlen);
    let thr = 2.0 * total / n as f64;
    let mut runs: Vec<(usize, usize)> = Vec::new();
    let mut k = 0;
    while k < n {
        if sm[k] > thr {
            let s = k;
            while k < n && sm[k] > thr {
                k += 1;
            }
            match runs.last_mut() {
                Some(last) if s - last.1 < wlen => last.1 = k,
                _ => runs.push((s, k)),
            }
        } else {
            k += 1;
        }
    }
    let mut windows: Vec<Window> = runs
        .iter()
        .map(|&(s, e)| {
            let en: f64 = energy[s..e].iter().sum();
            let mut best = ("none".to_string(), 0.0, 0.0);
            for (name, mask) in &masks {
                let frac = mask[s..e].iter().filter(|b| **b).count() as f64 / (e - s) as f64;
                let base = mask.iter().filter(|b| **b).count() as f64 / n as f64;
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
    windows.sort_by(|a, b| b.share_energy.total_cmp(&a.share_energy));
    windows.truncate(max_windows);
    Localisation { regimes, windows, energy }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_a_burst_and_its_regime() {
        // y a sine, residual concentrated at the velocity reversals (peaks of the sine).
        let n = 2000;
        let dt = 0.01;
        let y: Vec<f64> = (0..n).map(|k| (k as f64 * dt).sin()).collect();
        let w = y.clone();
        let e: Vec<f64> = (0..n).map(|k| if (k as f64 * dt).cos().abs() < 0.1 { 0.1 } else { 0.001 }).collect();
        let l = localise(0.0, dt, &y, &e, 1, &w, 1, None, 10, 10);
        let rev = l.regimes.iter().find(|r| r.regime == "reversal").unwrap();
        assert!(rev.enrichment > 3.0, "{rev:?}");
        assert!(!l.windows.is_empty());
        let total: f64 = l.windows.iter().map(|w| w.share_energy).sum();
        assert!(total > 0.8, "{l:?}");
        // Negative control: uniform residual has no enrichment and no windows.
        let e2 = vec![0.01; n];
        let l2 = localise(0.0, dt, &y, &e2, 1, &w, 1, None, 10, 10);
        assert!(l2.windows.is_empty());
        assert!(l2.regimes.iter().all(|r| (r.enrichment - 1.0).abs() < 1e-9 || r.share_time == 0.0));
    }
}
