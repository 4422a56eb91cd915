//! Certified beta SDPs remembered by the requested `lambda`, for several lambda searches over
//! one problem.
//!
//! The beta SDP at a given `lambda` (eq. (bet) under (ALI)) does not depend on the objective
//! `theta(lambda, beta)` a search minimises, so a second search with another objective (the
//! bounds beyond the paper run up to three) re-uses every `lambda` it meets again: the whole
//! grid, and the golden-section steps while its comparisons agree with the first search's.
//! The memo is keyed by the problem `(F, E, C)` and the SDP settings as well: asked about
//! another plant, it forgets what it had, so a stale answer is never returned; other settings
//! (the retry with a larger (ALI) margin on stiff plants) are remembered beside the first. Every remembered value is
//! the same certified result (or the same error) a fresh solve gives, bit for bit.
use crate::beta_sdp::{certified_checked, BetaSdpSettings, CertifiedBeta};
use crate::error::Result;
use nalgebra::DMatrix;
use std::collections::HashMap;

/// See the module docs.
#[derive(Debug, Default)]
pub struct BetaMemo {
    plant: Option<[DMatrix<f64>; 3]>,
    /// Per SDP settings, the answers by the bits of the requested lambda.
    by_settings: Vec<(BetaSdpSettings, HashMap<u64, Result<CertifiedBeta>>)>,
    solves: usize,
    hits: usize,
}

impl BetaMemo {
    /// An empty memo.
    pub fn new() -> Self {
        Self::default()
    }

    /// SDPs solved (and verified) through this memo.
    pub fn solves(&self) -> usize {
        self.solves
    }

    /// Requests answered from the memo without a solve.
    pub fn hits(&self) -> usize {
        self.hits
    }

    /// The certified beta at `lambda` (`mu` the spectral abscissa of `F`, already checked by
    /// the caller), solved once per problem and `lambda`.
    pub(crate) fn certified(
        &mut self,
        F: &DMatrix<f64>,
        E: &DMatrix<f64>,
        C: &DMatrix<f64>,
        lambda: f64,
        mu: f64,
        settings: &BetaSdpSettings,
    ) -> Result<CertifiedBeta> {
        let same_plant = self.plant.as_ref().is_some_and(|[f, e, c]| f == F && e == E && c == C);
        if !same_plant {
            self.by_settings.clear();
            self.plant = Some([F.clone(), E.clone(), C.clone()]);
        }
        let k = match self.by_settings.iter().position(|(s, _)| s == settings) {
            Some(k) => k,
            None => {
                self.by_settings.push((settings.clone(), HashMap::new()));
                self.by_settings.len() - 1
            }
        };
        let by_lambda = &mut self.by_settings[k].1;
        if let Some(r) = by_lambda.get(&lambda.to_bits()) {
            self.hits += 1;
            return r.clone();
        }
        self.solves += 1;
        let r = certified_checked(F, E, C, lambda, mu, settings);
        by_lambda.insert(lambda.to_bits(), r.clone());
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixtures::paper_example;
    use crate::spectral_abscissa::hurwitz_mu;

    #[test]
    fn remembers_per_lambda_and_forgets_on_another_problem() {
        let (F, E, C) = paper_example();
        let mu = hurwitz_mu(&F).unwrap();
        let s = BetaSdpSettings::default();
        let mut memo = BetaMemo::new();
        let a = memo.certified(&F, &E, &C, 0.1, mu, &s).unwrap();
        let b = memo.certified(&F, &E, &C, 0.1, mu, &s).unwrap();
        assert_eq!(a, b);
        assert_eq!((memo.solves(), memo.hits()), (1, 1));
        // the same answer as a solve without memo, bit for bit
        assert_eq!(a, certified_checked(&F, &E, &C, 0.1, mu, &s).unwrap());
        // another lambda: a solve
        memo.certified(&F, &E, &C, 0.2, mu, &s).unwrap();
        assert_eq!((memo.solves(), memo.hits()), (2, 1));
        // negative control: another plant at a remembered lambda is solved, not answered from
        // the memo (its beta differs)
        let F2 = &F * 2.0;
        let mu2 = hurwitz_mu(&F2).unwrap();
        let c = memo.certified(&F2, &E, &C, 0.1, mu2, &s).unwrap();
        assert_eq!((memo.solves(), memo.hits()), (3, 1));
        assert_ne!(c.solution.beta, a.solution.beta);
        // other settings: solved again, and both kept
        let mut s2 = s.clone();
        s2.tol_ali_margin_rel *= 10.0;
        let d = memo.certified(&F2, &E, &C, 0.1, mu2, &s2).unwrap();
        assert_eq!((memo.solves(), memo.hits()), (4, 1));
        assert_eq!(memo.certified(&F2, &E, &C, 0.1, mu2, &s).unwrap(), c);
        assert_eq!(memo.certified(&F2, &E, &C, 0.1, mu2, &s2).unwrap(), d);
        assert_eq!((memo.solves(), memo.hits()), (4, 3));
    }
}
