//! `moreau merge`: joins the result files of the shards of one sweep into one table. Refuses
//! files of different specs (spec hash), conflicting duplicates and, unless asked, missing
//! points.
use super::table::{PointRecord, SweepResult};
use super::SweepError;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Result files named by `inputs`: files as given, directories expanded to every `*.json`
/// file in them (sorted by name). Each must then be a result of the same sweep: a JSON file of
/// another sweep, or no sweep result at all, beside the shards is refused by [`merge`] rather
/// than left out unseen (a conflicting `extra.json` was once ignored because only `sweep*`
/// names were read).
pub fn collect_inputs(inputs: &[PathBuf]) -> Result<Vec<PathBuf>, SweepError> {
    let mut files = Vec::new();
    for p in inputs {
        if p.is_dir() {
            let rd = std::fs::read_dir(p).map_err(|source| SweepError::Io { path: p.clone(), source })?;
            let mut found: Vec<PathBuf> = rd
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|f| f.file_name().and_then(|n| n.to_str()).is_some_and(|n| n.ends_with(".json")))
                .collect();
            if found.is_empty() {
                return Err(SweepError::NothingToMerge { path: p.clone() });
            }
            found.sort();
            files.extend(found);
        } else {
            files.push(p.clone());
        }
    }
    if files.is_empty() {
        return Err(SweepError::NothingToMerge { path: PathBuf::from(".") });
    }
    Ok(files)
}

/// Merges result files of one spec. With `partial`, missing points are allowed.
pub fn merge(files: &[PathBuf], partial: bool) -> Result<SweepResult, SweepError> {
    let mut merged: Option<(PathBuf, SweepResult)> = None;
    let mut points: BTreeMap<usize, (PointRecord, PathBuf)> = BTreeMap::new();
    for f in files {
        let r = SweepResult::read(f)?;
        check_grid(&r, f)?;
        if let Some((first, m)) = &merged {
            if m.spec_hash != r.spec_hash {
                return Err(SweepError::MergeSpecMismatch {
                    a: first.clone(),
                    hash_a: m.spec_hash.clone(),
                    b: f.clone(),
                    hash_b: r.spec_hash.clone(),
                });
            }
            if m.axes != r.axes || m.total_points != r.total_points {
                return Err(SweepError::MergeGrid {
                    path: f.clone(),
                    reason: format!(
                        "its axes differ from those of {} although the spec hash is the same",
                        first.display()
                    ),
                });
            }
        }
        for p in &r.points {
            match points.get(&p.index) {
                Some((q, from)) if !same_record(q, p) => {
                    return Err(SweepError::MergeConflict { index: p.index, a: from.clone(), b: f.clone() })
                }
                Some(_) => {}
                None => {
                    points.insert(p.index, (p.clone(), f.clone()));
                }
            }
        }
        if merged.is_none() {
            merged = Some((f.clone(), r));
        }
    }
    let (_, mut m) = merged.ok_or_else(|| SweepError::NothingToMerge { path: PathBuf::from(".") })?;
    m.shard = None;
    m.points = points.into_values().map(|(p, _)| p).collect();
    let missing: Vec<usize> =
        (0..m.total_points).filter(|i| m.points.binary_search_by_key(i, |p| p.index).is_err()).collect();
    if !missing.is_empty() && !partial {
        return Err(SweepError::MergeIncomplete { missing: missing.len(), total: m.total_points, first: missing[0] });
    }
    Ok(m)
}

/// Checks a result file against its own grid: `total_points` is the product of the axis
/// lengths (and within the sweep limit), every point's parameters are the grid's values at
/// its index, and a shard holds only its own indices.
fn check_grid(r: &SweepResult, path: &Path) -> Result<(), SweepError> {
    let bad = |reason: String| SweepError::MergeGrid { path: path.to_path_buf(), reason };
    let product = r.axes.iter().fold(1u128, |acc, a| acc.saturating_mul(a.values.len() as u128));
    if product != r.total_points as u128 {
        return Err(bad(format!("total_points {} is not the product {product} of the axis lengths", r.total_points)));
    }
    if r.total_points > super::spec::MAX_POINTS {
        return Err(bad(format!("total_points {} exceeds the limit {}", r.total_points, super::spec::MAX_POINTS)));
    }
    for p in &r.points {
        let mut rem = p.index;
        let mut expected = vec![0.0; r.axes.len()];
        for (k, a) in r.axes.iter().enumerate().rev() {
            expected[k] = a.values[rem % a.values.len()];
            rem /= a.values.len();
        }
        if p.params.len() != expected.len() || p.params.iter().zip(&expected).any(|(x, y)| x.to_bits() != y.to_bits()) {
            return Err(bad(format!(
                "point {} has parameters {:?}, but the grid has {:?} at that index",
                p.index, p.params, expected
            )));
        }
        if let Some(s) = r.shard {
            if !s.contains(p.index) {
                return Err(bad(format!("point {} does not belong to its shard {}/{}", p.index, s.k, s.n)));
            }
        }
    }
    Ok(())
}

/// Equal records (NaN equal to NaN).
fn same_record(a: &PointRecord, b: &PointRecord) -> bool {
    a.index == b.index
        && a.status == b.status
        && a.params.len() == b.params.len()
        && a.params.iter().zip(&b.params).all(|(x, y)| x.to_bits() == y.to_bits())
        && a.cells.len() == b.cells.len()
        && a.cells.iter().zip(&b.cells).all(|(x, y)| match (x, y) {
            (super::eval::Cell::Num(x), super::eval::Cell::Num(y)) => {
                x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan())
            }
            _ => x == y,
        })
}

/// Merges and writes `sweep.{json,csv,md,tex}` into `out` (all or none).
pub fn merge_into(
    inputs: &[PathBuf],
    out: &Path,
    partial: bool,
    digits: Option<usize>,
) -> Result<(SweepResult, Vec<PathBuf>), SweepError> {
    let files = collect_inputs(inputs)?;
    let mut m = merge(&files, partial)?;
    let digits = digits.unwrap_or(m.table.digits);
    if !(1..=17).contains(&digits) {
        return Err(SweepError::BadDigits { digits: digits as i64, source_key: "--digits" });
    }
    m.table.digits = digits;
    let written = super::run::write_tables(&m, out, "sweep", digits)?;
    Ok((m, written))
}
