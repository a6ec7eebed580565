//! The Newton iteration matrix of the implicit integrator as a faer sparse LU (MODELS.md §6, FE.9.3).
//!
//! As in faer itself, the symbolic and the numeric work are kept apart: the pattern the model
//! declares is analysed once ([`IterationMatrix::new`]: compressed columns, fill-reducing ordering,
//! symbolic LU), and each refactorisation only recomputes the numbers into memory allocated then, so
//! the time-stepping loop allocates nothing.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::factor::PartialPivLuParams;
use faer::sparse::linalg::lu::{self, LuRef, NumericLu, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Par, Spec};

/// Why the iteration matrix could not be built or factorised.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SparseError {
    /// The declared pattern has an entry outside the n × n matrix.
    #[error("iteration pattern entry ({row}, {col}) outside the {n} × {n} matrix")]
    Pattern { row: usize, col: usize, n: usize },
    /// faer refused the symbolic analysis or the numeric factorisation (e.g. a singular matrix).
    #[error("sparse LU failed: {0}")]
    Factorisation(String),
}

/// S (n × n) in compressed-column form with its symbolic and numeric LU.
pub struct IterationMatrix {
    n: usize,
    pattern: SymbolicSparseColMat<usize>,
    /// Compressed-column slot of each declared entry (duplicates share a slot and are summed).
    slot: Vec<usize>,
    values: Vec<f64>,
    symbolic: SymbolicLu<usize>,
    numeric: NumericLu<usize, f64>,
    factor_memory: MemBuffer,
    solve_memory: MemBuffer,
    factorised: bool,
}

impl IterationMatrix {
    /// Analyses the pattern `entries` (row, col) of an n × n matrix: the symbolic factorisation,
    /// done once per pattern.
    pub fn new(n: usize, entries: &[(usize, usize)]) -> Result<Self, SparseError> {
        if let Some(&(row, col)) = entries.iter().find(|(r, c)| *r >= n || *c >= n) {
            return Err(SparseError::Pattern { row, col, n });
        }
        // Every diagonal entry is structurally present (S = M + …, M positive definite).
        let mut cells: Vec<(usize, usize)> = entries.iter().map(|&(r, c)| (c, r)).collect();
        cells.extend((0..n).map(|i| (i, i)));
        cells.sort_unstable();
        cells.dedup();
        let mut col_ptr = vec![0usize; n + 1];
        let mut row_idx = Vec::with_capacity(cells.len());
        for &(c, r) in &cells {
            col_ptr[c + 1] += 1;
            row_idx.push(r);
        }
        for c in 0..n {
            col_ptr[c + 1] += col_ptr[c];
        }
        let slot = entries
            .iter()
            .map(|&(r, c)| {
                let column = &row_idx[col_ptr[c]..col_ptr[c + 1]];
                col_ptr[c] + column.binary_search(&r).unwrap_or_else(|_| unreachable!())
            })
            .collect();
        let nnz = row_idx.len();
        let pattern = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        let symbolic = lu::factorize_symbolic_lu(pattern.as_ref(), Default::default())
            .map_err(|e| SparseError::Factorisation(format!("{e:?}")))?;
        let factor_memory = MemBuffer::new(StackReq::any_of(&[symbolic
            .factorize_numeric_lu_scratch::<f64>(
                Par::Seq,
                Spec::<PartialPivLuParams, f64>::default(),
            )]));
        let solve_memory = MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
        Ok(Self {
            n,
            pattern,
            slot,
            values: vec![0.0; nnz],
            symbolic,
            numeric: NumericLu::new(),
            factor_memory,
            solve_memory,
            factorised: false,
        })
    }

    /// Order n.
    pub fn order(&self) -> usize {
        self.n
    }

    /// Stored non-zeros (after merging duplicate entries and adding the diagonal).
    pub fn nonzeros(&self) -> usize {
        self.values.len()
    }

    /// Sets S from `entry_values`, given in the order of the pattern passed to [`Self::new`]
    /// (duplicates are summed), and factorises it numerically.
    pub fn factorise(&mut self, entry_values: &[f64]) -> Result<(), SparseError> {
        debug_assert_eq!(entry_values.len(), self.slot.len());
        self.values.fill(0.0);
        for (&slot, &v) in self.slot.iter().zip(entry_values) {
            self.values[slot] += v;
        }
        self.factorised = false;
        if self.values.iter().any(|v| !v.is_finite()) {
            return Err(SparseError::Factorisation(
                "non-finite entry in the iteration matrix".into(),
            ));
        }
        let matrix = SparseColMatRef::new(self.pattern.as_ref(), &self.values);
        self.symbolic
            .factorize_numeric_lu(
                &mut self.numeric,
                matrix,
                Par::Seq,
                MemStack::new(&mut self.factor_memory),
                Default::default(),
            )
            .map_err(|e| SparseError::Factorisation(format!("{e:?}")))?;
        self.factorised = true;
        Ok(())
    }

    /// Overwrites `rhs` with S⁻¹ rhs (the last factorisation).
    pub fn solve_in_place(&mut self, rhs: &mut [f64]) {
        debug_assert!(self.factorised);
        let lu = LuRef::new_unchecked(&self.symbolic, &self.numeric);
        let n = rhs.len();
        lu.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(rhs, n, 1),
            Par::Seq,
            MemStack::new(&mut self.solve_memory),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tridiagonal system with a duplicate entry against its dense solution.
    #[test]
    fn solves_a_tridiagonal_system_with_summed_duplicates() {
        let n = 6;
        let mut entries = Vec::new();
        let mut values = Vec::new();
        for i in 0..n {
            entries.push((i, i));
            values.push(2.0);
            entries.push((i, i)); // duplicate: summed to 4
            values.push(2.0);
            if i + 1 < n {
                entries.push((i, i + 1));
                values.push(-1.0);
                entries.push((i + 1, i));
                values.push(-1.5);
            }
        }
        let mut s = IterationMatrix::new(n, &entries).unwrap();
        s.factorise(&values).unwrap();
        let x: Vec<f64> = (0..n).map(|i| 1.0 + i as f64).collect();
        let mut b: Vec<f64> = (0..n)
            .map(|i| {
                4.0 * x[i]
                    - if i + 1 < n { x[i + 1] } else { 0.0 }
                    - if i > 0 { 1.5 * x[i - 1] } else { 0.0 }
            })
            .collect();
        s.solve_in_place(&mut b);
        for i in 0..n {
            // Well-conditioned 6 × 6: round-off only.
            assert!((b[i] - x[i]).abs() < 1e-13, "{i}: {} vs {}", b[i], x[i]);
        }
    }

    #[test]
    fn rejects_entries_outside_the_matrix() {
        assert!(matches!(
            IterationMatrix::new(3, &[(0, 3)]),
            Err(SparseError::Pattern {
                row: 0,
                col: 3,
                n: 3
            })
        ));
    }
}
