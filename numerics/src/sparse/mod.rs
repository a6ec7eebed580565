//! The Newton iteration matrix of the implicit integrator as a faer sparse LU (MODELS.md §6, FE.9.3).
//!
//! As in faer itself, the symbolic and the numeric work are kept apart: the pattern the system
//! declares is analysed once ([`IterationMatrix::new`]: border split, compressed columns,
//! fill-reducing ordering), and each refactorisation only recomputes the numbers into memory
//! allocated then, so the Newton solves allocate nothing.
//!
//! - Dense rows and columns are split off as a border and eliminated by a Schur complement
//!   (`layout`): one dense row makes the fill of LU with partial pivoting full, while with the
//!   border apart the interior's factors of a cable chain are banded and a step costs O(N).
//! - The first factorisation tries several layouts (COLAMD's order or the same order taken from
//!   both ends at once, each with or without the coupled unknowns in the border) and keeps the one
//!   whose factors promise the cheapest solve ([`SolveCost`]): the triangular sweeps of a chain are
//!   latency-bound, so two fronts side by side halve them.
//! - Later factorisations reuse the pivot sequence and recompute only the numbers (`factors`, as
//!   KLU's refactor), pivoting afresh through faer when a reused pivot falls below a tenth of its
//!   column.
//! - The solve sweeps the factors itself, by rows and two unknowns at a time where the two-front
//!   order puts the entries at even distances from the diagonal (`lanes`), by rows one unknown at
//!   a time otherwise (`rows`), in the column sweep's order of operations.
//!
//! `docs/numerics.md` explains each choice; `docs/performance.md` has the measurements.

mod cost;
mod factors;
mod lanes;
mod layout;
mod rows;

pub use cost::SolveCost;
use layout::Layout;

/// Why the iteration matrix could not be built or factorised.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SparseError {
    /// The declared pattern has an entry outside the n × n matrix.
    #[error("iteration pattern entry ({row}, {col}) outside the {n} × {n} matrix")]
    Pattern { row: usize, col: usize, n: usize },
    /// A coupled unknown named outside the n × n matrix.
    #[error("coupled unknown {index} outside the {n} × {n} matrix")]
    Coupled { index: usize, n: usize },
    /// faer refused the symbolic analysis or the numeric factorisation (e.g. a singular matrix).
    #[error("sparse LU failed: {0}")]
    Factorisation(String),
}

/// The iteration matrix S: candidate layouts until the first factorisation has picked the one
/// with the cheapest solve, then that layout alone.
pub struct IterationMatrix {
    candidates: Vec<Layout>,
}

impl IterationMatrix {
    /// Analyses the pattern `entries` (row, col) of an n × n matrix: the border (unknowns whose row
    /// or column holds more than max(32, 4 × the mean) entries), the interior's compressed
    /// columns and faer's COLAMD order, and from it the two candidate column orders, done once
    /// per pattern (the factors' structure appears at the first numeric factorisation).
    pub fn new(n: usize, entries: &[(usize, usize)]) -> Result<Self, SparseError> {
        Self::with_coupled(n, entries, &[])
    }

    /// As [`Self::new`], with layouts that also put the `coupled` unknowns in the border (see the
    /// module documentation); the first factorisation keeps whichever solves cheapest.
    pub fn with_coupled(
        n: usize,
        entries: &[(usize, usize)],
        coupled: &[usize],
    ) -> Result<Self, SparseError> {
        if let Some(&(row, col)) = entries.iter().find(|(r, c)| *r >= n || *c >= n) {
            return Err(SparseError::Pattern { row, col, n });
        }
        if let Some(&index) = coupled.iter().find(|&&i| i >= n) {
            return Err(SparseError::Coupled { index, n });
        }
        let mut cells: Vec<(usize, usize)> = entries.iter().map(|&(r, c)| (c, r)).collect();
        // Every diagonal entry is structurally present (S = M + …, M positive definite).
        cells.extend((0..n).map(|i| (i, i)));
        cells.sort_unstable();
        cells.dedup();
        let (mut per_row, mut per_col) = (vec![0usize; n], vec![0usize; n]);
        for &(c, r) in &cells {
            per_row[r] += 1;
            per_col[c] += 1;
        }
        let dense_limit = (4 * cells.len() / n.max(1)).max(32);
        let dense: Vec<bool> = (0..n)
            .map(|i| per_row[i].max(per_col[i]) > dense_limit)
            .collect();
        let mut splits = vec![dense.clone()];
        let mut with_coupled = dense;
        for &i in coupled {
            with_coupled[i] = true;
        }
        // Only a split that adds border unknowns and leaves an interior is a new candidate.
        if with_coupled != splits[0] && with_coupled.iter().any(|&border| !border) {
            splits.push(with_coupled);
        }
        let mut candidates = Vec::new();
        let mut first_error = None;
        for is_border in &splits {
            match Layout::for_split(n, entries, &cells, is_border) {
                Ok(layouts) => candidates.extend(layouts),
                Err(e) => {
                    first_error.get_or_insert(e);
                }
            }
        }
        match first_error {
            Some(e) if candidates.is_empty() => Err(e),
            _ => Ok(Self { candidates }),
        }
    }

    /// The layout in use (the first candidate until the first factorisation has chosen).
    fn layout(&self) -> &Layout {
        &self.candidates[0]
    }

    /// Order n.
    pub fn order(&self) -> usize {
        self.layout().n
    }

    /// Stored non-zeros of the sparse interior block (after merging duplicate entries and adding
    /// the diagonal).
    pub fn nonzeros(&self) -> usize {
        self.layout().values.len()
    }

    /// Unknowns eliminated through the dense border (dense rows or columns, coupled unknowns).
    pub fn border(&self) -> &[usize] {
        &self.layout().border
    }

    /// Factorisations of the layout in use that chose their pivots (faer's); the others reused
    /// the last pivot sequence (see [`Factors::refactor`](factors::Factors::refactor)).
    pub fn pivotings(&self) -> u64 {
        self.layout().pivotings
    }

    /// Rows the last pivoting factorisation moved off the diagonal (0: the pivots stayed there).
    pub fn rows_exchanged(&self) -> usize {
        let gather = &self.layout().factors.gather_local;
        gather.iter().enumerate().filter(|&(i, &g)| i != g).count()
    }

    /// What a solve costs with the factors in use (after a factorisation).
    pub fn solve_cost(&self) -> SolveCost {
        self.layout().solve_cost()
    }

    /// Sets S from `entry_values`, given in the order of the pattern passed to [`Self::new`]
    /// (duplicates are summed), and factorises it numerically. The first call factorises every
    /// candidate layout and keeps the one with the cheapest [`SolveCost`] (ties: the earlier in
    /// the order dense-only border before coupled, COLAMD before two fronts); a layout that fails
    /// is dropped unless all do. A singular interior or Schur complement is an error (the caller
    /// decides whether a shorter step helps).
    pub fn factorise(&mut self, entry_values: &[f64]) -> Result<(), SparseError> {
        if self.candidates.len() == 1 {
            return self.candidates[0].factorise(entry_values);
        }
        let mut best: Option<(usize, usize)> = None;
        let mut first_error = None;
        for (i, layout) in self.candidates.iter_mut().enumerate() {
            match layout.factorise(entry_values) {
                Ok(()) => {
                    let cost = layout.solve_cost().estimate();
                    if best.is_none_or(|(c, _)| cost < c) {
                        best = Some((cost, i));
                    }
                }
                Err(e) => {
                    first_error.get_or_insert(e);
                }
            }
        }
        match best {
            Some((_, i)) => {
                self.candidates.swap(0, i);
                self.candidates.truncate(1);
                Ok(())
            }
            None => Err(first_error.unwrap_or(SparseError::Factorisation("no layout".into()))),
        }
    }

    /// Overwrites `rhs` with S⁻¹ rhs (the last factorisation).
    pub fn solve_in_place(&mut self, rhs: &mut [f64]) {
        self.candidates[0].solve_in_place(rhs);
    }
}
