//! `--shard K/N`: shard `K` (0-based, so `$SLURM_ARRAY_TASK_ID` with `--array=0-(N-1)`) of `N`
//! takes the points with `index % N == K` (round robin, which balances cheap and expensive
//! regions of the grid).
use super::SweepError;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    pub k: usize,
    pub n: usize,
}

impl Shard {
    pub fn new(k: usize, n: usize) -> Result<Self, SweepError> {
        if n == 0 || k >= n {
            return Err(SweepError::BadShard { text: format!("{k}/{n}") });
        }
        Ok(Self { k, n })
    }
    /// Parses `K/N`.
    pub fn parse(text: &str) -> Result<Self, SweepError> {
        let bad = || SweepError::BadShard { text: text.to_string() };
        let (k, n) = text.split_once('/').ok_or_else(bad)?;
        let k: usize = k.trim().parse().map_err(|_| bad())?;
        let n: usize = n.trim().parse().map_err(|_| bad())?;
        Self::new(k, n).map_err(|_| bad())
    }
    pub fn contains(&self, index: usize) -> bool {
        index % self.n == self.k
    }
    /// File stem of this shard's outputs, `sweep-shard-K-of-N`.
    pub fn stem(&self) -> String {
        format!("sweep-shard-{}-of-{}", self.k, self.n)
    }
}

impl std::str::FromStr for Shard {
    type Err = SweepError;
    fn from_str(s: &str) -> Result<Self, SweepError> {
        Shard::parse(s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_and_partition() {
        assert_eq!(Shard::parse("2/5").unwrap(), Shard { k: 2, n: 5 });
        for bad in ["5/5", "6/5", "0/0", "1", "a/2", "-1/3", "1/2/3"] {
            assert!(matches!(Shard::parse(bad), Err(SweepError::BadShard { .. })), "{bad}");
        }
        let n = 4;
        for i in 0..100 {
            assert_eq!((0..n).filter(|&k| Shard::new(k, n).unwrap().contains(i)).count(), 1);
        }
    }
}
