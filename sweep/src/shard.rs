//! Deterministic sharding: point i belongs to shard i mod N, so N independent jobs (a Slurm
//! array) cover the grid with no coordinator.

use crate::error::SweepError;
use std::fmt;

/// Shard I of N.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl Shard {
    /// The whole grid.
    pub const ALL: Shard = Shard { index: 0, count: 1 };

    /// Whether point `i` is this shard's.
    pub fn owns(&self, i: usize) -> bool {
        i % self.count == self.index
    }
}

impl std::str::FromStr for Shard {
    type Err = SweepError;
    /// `I/N` with 0 ≤ I < N (Slurm's `$SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT`).
    fn from_str(s: &str) -> Result<Self, SweepError> {
        let error = |message: &str| SweepError::Shard {
            given: s.into(),
            message: message.into(),
        };
        let (i, n) = s
            .split_once('/')
            .ok_or_else(|| error("write it I/N, e.g. 0/4"))?;
        let parse = |x: &str| x.trim().parse::<usize>();
        let (index, count) = match (parse(i), parse(n)) {
            (Ok(i), Ok(n)) => (i, n),
            _ => return Err(error("I and N must be non-negative integers")),
        };
        if count == 0 {
            return Err(error("N must be ≥ 1"));
        }
        if index >= count {
            return Err(error("I must be < N (shards are numbered 0 … N−1)"));
        }
        Ok(Shard { index, count })
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}
