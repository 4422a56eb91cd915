//! What the reports of one plant share: the beta SDPs of the lambda searches
//! ([`lmi::BetaMemo`]) and the engaged history of `p = 1`
//! ([`crate::beyond_paper::engaged_speed::HistoryMemo`]). Neither depends on the input's
//! amplitude or frequency (the history not on the amplitude), so the guidance's bound
//! computations, a sweep worker's points and several reports of one model reuse them. Each
//! forgets what it holds when asked about another problem; every report through a memo is the
//! one [`crate::assemble()`] gives, bit for bit.
use crate::beyond_paper::engaged_speed::HistoryMemo;
use lmi::BetaMemo;

/// See the module docs.
#[derive(Debug, Default)]
pub struct Memo {
    pub beta: BetaMemo,
    pub history: HistoryMemo,
}

impl Memo {
    /// An empty memo.
    pub fn new() -> Self {
        Self::default()
    }
}
