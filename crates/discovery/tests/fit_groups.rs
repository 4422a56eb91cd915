//! A fit from several groups of starts (`fit::fit_groups`, the pair search's joint fits, issue
//! 27 item 5): one group reads as `fit` from the same starts, bit for bit; several groups are
//! pooled, screened and end at the best start's point, refined once, at less cost than one fit
//! per group.
mod common;
use discovery::fit::{self, FitSettings, FitStatus, PartStarts};

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

#[test]
fn groups_of_starts_end_at_the_best_group_refined_once() {
    let level = 0.25;
    let data = common::CoulombMass::new(level, 2000);
    let h = &data.hypothesis;
    let pb = data.problem();
    let (x0, xs) = ([0.0, 0.0], [0.2, 0.2]);
    let s = FitSettings::default();
    let same = |a: &fit::FitResult, b: &fit::FitResult| {
        bits(&a.theta) == bits(&b.theta) && bits(&a.x0) == bits(&b.x0) && a.sse.to_bits() == b.sse.to_bits()
    };

    // One group: `fit` from the same starts (the part's grid; a warm start).
    let grid = fit::fit(&pb, &x0, &xs, None, &s);
    assert!(same(&fit::fit_groups(&pb, &x0, &xs, &[vec![None]], &s), &grid));
    let near = [1.1 * level];
    let warm = fit::fit(&pb, &x0, &xs, Some(&near), &s);
    assert!(same(&fit::fit_groups(&pb, &x0, &xs, &[vec![Some(near.to_vec())]], &s), &warm));
    assert!((warm.theta[0] - level).abs() < 0.05 * level, "estimate {} vs truth {level}", warm.theta[0]);

    // Two groups, a far start and a near one, with a start phase too short to bring the far
    // start in: the fit ends where the near group leads, whichever comes first.
    let short = FitSettings { max_iter_start: 1, ..s.clone() };
    let far = [20.0 * level];
    let groups: Vec<PartStarts> = vec![vec![Some(far.to_vec())], vec![Some(near.to_vec())]];
    let both = fit::fit_groups(&pb, &x0, &xs, &groups, &short);
    let swapped = fit::fit_groups(&pb, &x0, &xs, &[groups[1].clone(), groups[0].clone()], &short);
    let near_alone = fit::fit(&pb, &x0, &xs, Some(&near), &short);
    let far_alone = fit::fit(&pb, &x0, &xs, Some(&far), &short);
    assert!(both.status == FitStatus::Converged || both.status == FitStatus::MaxIterations, "{:?}", both.status);
    assert!(same(&both, &near_alone) && same(&swapped, &near_alone));
    // the groups run side by side or one after the other: the same point
    let serial = fit::fit_groups(&pb, &x0, &xs, &groups, &FitSettings { parallel: false, ..short.clone() });
    assert!(same(&serial, &both));
    // refined once: fewer simulations than the two fits it replaces
    assert!(
        both.evaluations < near_alone.evaluations + far_alone.evaluations,
        "{} evaluations against {} + {}",
        both.evaluations,
        near_alone.evaluations,
        far_alone.evaluations
    );
    // control: the comparison sees another end point (the far start refined alone)
    assert!(!same(&far_alone, &near_alone), "the far start must end elsewhere for this test to tell");

    // More starts than are kept: the part's grid beside the far start, pooled and screened by
    // their first cost; the fit still finds the level.
    let pooled: Vec<PartStarts> = vec![vec![None], vec![Some(far.to_vec())]];
    let n_grid = h.starts.len() + 1;
    assert!(n_grid > fit::levenberg_marquardt::POOLED_KEPT_STARTS, "{n_grid} starts");
    let p = fit::fit_groups(&pb, &x0, &xs, &pooled, &s);
    assert!((p.theta[0] - level).abs() < 0.05 * level, "estimate {} vs truth {level}", p.theta[0]);
    assert!(p.sse <= 1.0001 * grid.sse, "pooled {} against the grid's {}", p.sse, grid.sse);
}
