//! A run from a perturbed initial state beside the run from the base state, until the two
//! merge: the initial-state columns of a finite-difference Jacobian.
//!
//! A stable plant forgets its initial state: a perturbation of `x0` decays, and once the
//! perturbed run's whole state (plant state, backlash output and its velocity, the outputs the
//! play's velocity estimate remembers, the contact flags) lies within a tolerance of the base
//! run's, the rest of the perturbed run is the base run's to that tolerance. On the speed
//! benchmark's 50,000-sample record a perturbation of `x0` decays by `1e-8` within 450-630
//! samples; a plant with an integrator or a play at rest never forgets it (the runs go on to
//! the end then). [`ExtendedModel::simulate_merging`] steps both runs sample by sample and
//! stops where they merge. Two runs cost twice one, so the base run goes on only while the
//! distance between the runs shrinks fast enough to merge early in the record (judged at
//! [`CHECKPOINTS`] points, [`worth_going_on`]); else the perturbed run finishes alone (the cost
//! of a plain run plus the samples run beside, at least a sixteenth of the record).
use super::model::ExtendedModel;
use super::simulate::{with_dims, InputDrive, Pieces, RunState, SimOutput};

/// How close the perturbed run's state must come to the base run's to count as merged, per
/// quantity (absolute): per state `x_i` the caller's tolerance; per output, for the backlash
/// output `z` and the outputs at the last two sub-step starts, `sum_i |C_ji| x_tol_i`; for the
/// backlash output's coasting velocity that over `dt`.
struct MergeTolerance {
    x: Vec<f64>,
    y: Vec<f64>,
    v: Vec<f64>,
}

impl MergeTolerance {
    fn new(ext: &ExtendedModel, x_tol: &[f64], dt: f64) -> Self {
        let n = ext.n;
        let y: Vec<f64> = (0..ext.p).map(|j| (0..n).map(|i| ext.C[j * n + i].abs() * x_tol[i]).sum()).collect();
        Self { x: x_tol.to_vec(), v: y.iter().map(|t| t / dt).collect(), y }
    }
}

/// A run beside the base run ([`ExtendedModel::simulate_merging`]).
#[derive(Debug, Clone)]
pub struct MergedRun {
    /// The perturbed run on samples `0..merged_at` (every sample where it did not merge); the
    /// entries after that are not written.
    pub out: SimOutput,
    /// The first sample from which the perturbed run is the base run's (within the tolerance).
    pub merged_at: Option<usize>,
}

impl ExtendedModel {
    /// The run from `(x0, z0)` beside the run from `(x0_base, z0)`, until their states are
    /// within `x_tol` of each other at a sample (per state; see [`MergeTolerance`] for the
    /// rest of the state and the module documentation); where they will not merge early in
    /// the record the perturbed run goes on alone. `None` with a `[controller]` (the
    /// sampled loop's state is not compared): run [`ExtendedModel::simulate_from`] then.
    pub fn simulate_merging(
        &self,
        w: &[f64],
        dt: f64,
        x0_base: &[f64],
        x0: &[f64],
        z0: Option<&[f64]>,
        x_tol: &[f64],
    ) -> Option<MergedRun> {
        if self.digital.is_some() || x_tol.len() != self.n {
            return None;
        }
        let tol = &MergeTolerance::new(self, x_tol, dt);
        Some(with_dims!(self.merge_run(w, dt, x0_base, x0, z0, tol)))
    }

    fn merge_run<const N: usize, const M: usize, const P: usize>(
        &self,
        w: &[f64],
        dt: f64,
        x0_base: &[f64],
        x0: &[f64],
        z0: Option<&[f64]>,
        tol: &MergeTolerance,
    ) -> MergedRun {
        let (n, m, p) = self.dims::<N, M, P>();
        let ns = w.len() / m;
        let mut out = SimOutput::zeros(ns, n, p);
        let (mut st, mut base) = (self.start(x0, z0), self.start(x0_base, z0));
        let pieces = Pieces::new(self);
        let mut drive_base = InputDrive::new(&self.input, w, dt, m, ns);
        let every = (ns / CHECKPOINTS).max(1);
        let first = distance(&st, &base, tol);
        let (mut beside, mut merged_at) = (true, None);
        self.run_samples::<N, M, P>(w, dt, &mut st, &mut out, |k, st| {
            if !beside {
                return true;
            }
            self.step_sample::<N, M, P>(&mut base, &mut drive_base, &pieces, k - 1);
            let d = distance(st, &base, tol);
            if d <= 1.0 {
                merged_at = Some(k);
                return false;
            }
            if k % every == 0 {
                beside = worth_going_on(first, d, k, ns);
            }
            true
        });
        MergedRun { out, merged_at }
    }
}

/// The runs are compared at this many checkpoints over the record ([`worth_going_on`]).
const CHECKPOINTS: usize = 32;

/// The share of the record within which the extrapolated decay must merge the runs for the
/// base run to go on ([`worth_going_on`]): two runs to the merge cost less than the plain run
/// where it comes before half the record; the extrapolation from the run so far comes late
/// (the early decay is the slowest: on the test plant below over 3,000 samples, the decay up to
/// sample 465 extrapolated to a merge at 1583, and the runs merged at 1395), so it is allowed
/// up to three quarters.
const MERGE_WITHIN: f64 = 0.75;

/// The largest distance between `a` and `b` in units of `tol`, over every quantity that
/// carries the run on (1 or less: merged); infinite where the contact flags differ.
fn distance(a: &RunState, b: &RunState, tol: &MergeTolerance) -> f64 {
    if a.touching != b.touching {
        return f64::INFINITY;
    }
    let far = |u: &[f64], v: &[f64], t: &[f64]| {
        u.iter().zip(v).zip(t).map(|((x, y), t)| (x - y).abs() / t).fold(0.0, f64::max)
    };
    far(&a.x, &b.x, &tol.x)
        .max(far(&a.z, &b.z, &tol.y))
        .max(far(&a.y_start, &b.y_start, &tol.y))
        .max(far(&a.y_before, &b.y_before, &tol.y))
        .max(far(&a.v, &b.v, &tol.v))
}

/// Whether the base run goes on at sample `k` of `ns`, the distance between the runs `d` there
/// and `first` at the start. The decay is not steady (a sticking friction holds a difference
/// for a while): it is judged over the whole run so far. Up to `ns / 16` the base run goes
/// on; from there the distance must have fallen by a decade (a plant with an integrator never
/// forgets its initial state: it stops there, at a sixteenth of a run's extra cost); from
/// `ns / 8` the decay so far, extrapolated geometrically, must merge the runs within
/// [`MERGE_WITHIN`] of the record. Contact flags that differ (`d` infinite) defer the
/// judgement up to `ns / 8`.
fn worth_going_on(first: f64, d: f64, k: usize, ns: usize) -> bool {
    if 16 * k < ns {
        return true;
    }
    if !d.is_finite() {
        return 8 * k < ns;
    }
    if !(10.0 * d <= first) {
        return false;
    }
    if 8 * k < ns {
        return true;
    }
    let to_merge = k as f64 * first.ln() / (first / d).ln();
    to_merge <= MERGE_WITHIN * ns as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A damped two-state plant with a play and Coulomb friction, driven by two sines.
    fn plant() -> (ExtendedModel, Vec<f64>, f64) {
        let text = r#"
[plant]
A = [[0.0, 1.0], [-9.0, -6.0]]
B = [[0.0], [1.0]]
C = [[1.0, 0.0]]
E = [[0.0], [1.0]]
[theta]
shape = "interval"
half_width = 0.1
[[effects]]
kind = "coulomb_friction"
state = 1
level = 0.5
"#;
        let sys = model::parse_str(text).unwrap();
        let dt = 0.01;
        let w: Vec<f64> =
            (0..6000).map(|k| 8.0 * (0.7 * k as f64 * dt).sin() + 3.0 * (2.1 * k as f64 * dt).sin()).collect();
        (ExtendedModel::new(&sys, &[], dt, 4).unwrap(), w, dt)
    }

    /// The plant, its input, `dt`, the base state (rest) and the state perturbed by `1e-6`
    /// in its first component.
    fn perturbed() -> (ExtendedModel, Vec<f64>, f64, Vec<f64>, Vec<f64>) {
        let (ext, w, dt) = plant();
        let x0 = vec![0.0; ext.n];
        let mut xp = x0.clone();
        xp[0] += 1e-6;
        (ext, w, dt, x0, xp)
    }

    /// Before it merges the run is the plain run from the perturbed state, to the bit; where it
    /// merged, the plain run stays within the tolerance's order of the base run.
    #[test]
    fn a_merged_run_is_the_plain_run_up_to_the_merge() {
        let (ext, w, dt, x0, xp) = perturbed();
        let r = ext.simulate_merging(&w, dt, &x0, &xp, None, &vec![1e-14; ext.n]).unwrap();
        let plain = ext.simulate_from(&w, dt, &xp, None);
        let base = ext.simulate_from(&w, dt, &x0, None);
        let k = r.merged_at.expect("a stable plant forgets its initial state");
        assert!(k > 1 && k < w.len(), "{k}");
        assert!(plain.contact.iter().any(|c| *c) && plain.contact.iter().any(|c| !*c), "the play engages and frees");
        assert_eq!(&r.out.y[..k], &plain.y[..k]);
        let after = plain.y[k..].iter().zip(&base.y[k..]).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(after <= 1e-13, "{after}");
        // negative control: before the merge the runs differ by more than the tolerance
        assert!((plain.y[k / 2] - base.y[k / 2]).abs() > 1e-14);
    }

    /// A run that cannot merge goes on alone: the plain run whole.
    #[test]
    fn a_run_that_does_not_merge_is_the_plain_run() {
        let (ext, w, dt, x0, xp) = perturbed();
        let r = ext.simulate_merging(&w, dt, &x0, &xp, None, &vec![0.0; ext.n]).unwrap();
        assert_eq!(r.merged_at, None);
        assert_eq!(r.out.y, ext.simulate_from(&w, dt, &xp, None).y);
    }

    /// The base run goes on where the distance has shrunk fast enough to merge early in the
    /// record, not where it stalls or shrinks too slowly.
    #[test]
    fn the_base_run_goes_on_only_where_the_runs_will_merge_in_time() {
        // 1e8 -> 1e4 in 150 samples of 1000: at that rate merged at 300
        assert!(worth_going_on(1e8, 1e4, 150, 1000));
        assert!(worth_going_on(1e8, 1e4, 150, 500));
        // a decade in the first 70 of 1000 samples
        assert!(worth_going_on(1e8, 1e7, 70, 1000));
        // anything before a sixteenth of the record
        assert!(worth_going_on(1e8, 1e9, 50, 1000));
        // negative controls: the same rate with too little record left, no decade at a
        // sixteenth (an integrator), contact flags that still differ at an eighth
        assert!(!worth_going_on(1e8, 1e4, 150, 350));
        assert!(!worth_going_on(1e8, 2e7, 70, 1000));
        assert!(!worth_going_on(1e8, f64::INFINITY, 130, 1000));
    }
}
