//! The LU factors of the interior with a fixed pivot sequence: taken over from faer after each
//! pivoting factorisation, refactorised on the known pattern, and swept by the solve.

use super::lanes::LaneSweeps;
use super::rows::RowSweeps;
use faer::perm::PermRef;
use faer::sparse::SymbolicSparseColMatRef;
use faer::sparse::linalg::lu::simplicial::SimplicialLu;

/// Smallest |pivot| a refactorisation accepts, relative to the largest entry below it in its
/// column (threshold partial pivoting's τ; 0.1 is UMFPACK's default): pivots
/// reused from an earlier factorisation whose column has grown past 10 × the pivot send the
/// factorisation back to faer to pivot afresh.
pub(super) const PIVOT_THRESHOLD: f64 = 0.1;

/// The LU factors P A Q = L U of the interior with the pivot sequence of the last pivoting
/// factorisation (faer's), refactorised for new values of the same pattern, and the solve.
///
/// Refactorisation (as KLU's `refactor`): with P and Q fixed, the factors' pattern is fixed too,
/// so a left-looking Gilbert–Peierls pass over the known pattern recomputes the numbers without
/// faer's depth-first searches and pivot choices (lumped N = 40 paper matrix: a factorisation,
/// Schur complement included, ~7 µs against ~19 µs). A pivot that fails [`PIVOT_THRESHOLD`], or
/// whose inverse overflows, makes it refuse, and the caller pivots afresh with faer.
///
/// Solve: U's diagonal inverted once per factorisation instead of divided at every solve, the
/// permutations folded into the gather and the scatter.
#[derive(Debug, Default)]
pub(super) struct Factors {
    /// Per permuted column j of A (original column Q(j)): (index into A's values, permuted row).
    pub(super) a_ptr: Vec<usize>,
    pub(super) a_entry: Vec<(usize, usize)>,
    /// L's strict lower part by columns.
    pub(super) l_ptr: Vec<usize>,
    pub(super) l_row: Vec<usize>,
    pub(super) l_val: Vec<f64>,
    /// U's strict upper part by columns, rows ascending, and U's inverse diagonal.
    pub(super) u_ptr: Vec<usize>,
    pub(super) u_row: Vec<usize>,
    pub(super) u_val: Vec<f64>,
    pub(super) u_inv_diag: Vec<f64>,
    /// Position in A's numbering of pivot row i (gather: x_i = b[gather_local[i]]).
    pub(super) gather_local: Vec<usize>,
    /// The same in the global numbering of S.
    pub(super) gather_global: Vec<usize>,
    /// Where unknown i of A sits in the solution of L U (scatter: y_i = x[scatter[i]]).
    pub(super) scatter: Vec<usize>,
    /// Scratch of the refactorisation (all zero between columns) and of the triangular solves.
    pub(super) work: Vec<f64>,
    pub(super) x: Vec<f64>,
    /// Scratch for sorting a column of U when adopting faer's factors (a column can be long: a
    /// layout without the coupled border has the effector's x column across the chain).
    pub(super) sort_scratch: Vec<(usize, f64)>,
    /// The same factors arranged for paired row sweeps, used by the solve when
    /// [`LaneSweeps::worthwhile`] (a two-front order).
    pub(super) lanes: LaneSweeps,
    pub(super) in_lanes: bool,
    /// The same factors by rows, used by the solve otherwise.
    rows: RowSweeps,
}

impl Factors {
    /// Takes over faer's factors of A (`pattern`) and their pivot sequence, after each pivoting
    /// factorisation: O(n + non-zeros) and a sort of each column of U.
    pub(super) fn adopt(
        &mut self,
        lu: &SimplicialLu<usize, f64>,
        pattern: SymbolicSparseColMatRef<'_, usize>,
        row_perm: &[usize],
        row_perm_inv: &[usize],
        col_perm: PermRef<'_, usize>,
        interior: &[usize],
    ) {
        let n = lu.nrows();
        let (forward, col_inv) = col_perm.arrays();
        self.a_ptr.clear();
        self.a_ptr.push(0);
        self.a_entry.clear();
        let (col_ptr, row_idx) = (pattern.col_ptr(), pattern.row_idx());
        for &c in forward {
            self.a_entry
                .extend((col_ptr[c]..col_ptr[c + 1]).map(|p| (p, row_perm_inv[row_idx[p]])));
            self.a_ptr.push(self.a_entry.len());
        }
        let l = lu.l_factor_unsorted();
        let (l_ptr, l_row, l_val) = (l.symbolic().col_ptr(), l.symbolic().row_idx(), l.val());
        let u = lu.u_factor_unsorted();
        let (u_ptr, u_row, u_val) = (u.symbolic().col_ptr(), u.symbolic().row_idx(), u.val());
        for v in [&mut self.l_ptr, &mut self.u_ptr] {
            v.clear();
            v.push(0);
        }
        self.l_row.clear();
        self.l_val.clear();
        self.u_row.clear();
        self.u_val.clear();
        self.u_inv_diag.clear();
        for j in 0..n {
            // L's unit diagonal is the first entry of its column: left out.
            for k in l_ptr[j] + 1..l_ptr[j + 1] {
                self.l_row.push(l_row[k]);
                self.l_val.push(l_val[k]);
            }
            self.l_ptr.push(self.l_row.len());
            // U's diagonal is the last entry of its column (kept as its inverse); the rest
            // sorted for the refactorisation's left-looking order.
            let start = self.u_row.len();
            let last = u_ptr[j + 1] - 1;
            self.u_row.extend_from_slice(&u_row[u_ptr[j]..last]);
            self.u_val.extend_from_slice(&u_val[u_ptr[j]..last]);
            let (rows, vals) = (&mut self.u_row[start..], &mut self.u_val[start..]);
            self.sort_scratch.clear();
            self.sort_scratch
                .extend(rows.iter().copied().zip(vals.iter().copied()));
            self.sort_scratch.sort_unstable_by_key(|&(r, _)| r);
            for ((r, v), &(sr, sv)) in rows.iter_mut().zip(vals.iter_mut()).zip(&self.sort_scratch)
            {
                (*r, *v) = (sr, sv);
            }
            self.u_ptr.push(self.u_row.len());
            self.u_inv_diag.push(1.0 / u_val[last]);
        }
        self.gather_local.clear();
        self.gather_local.extend_from_slice(row_perm);
        self.gather_global.clear();
        self.gather_global
            .extend(row_perm.iter().map(|&i| interior[i]));
        self.scatter.clear();
        self.scatter.extend_from_slice(col_inv);
        self.lanes
            .plan(&self.l_ptr, &self.l_row, &self.u_ptr, &self.u_row);
        self.in_lanes = self.lanes.worthwhile();
        if self.in_lanes {
            self.lanes.fill(&self.l_val, &self.u_val, &self.u_inv_diag);
        } else {
            self.rows
                .plan((&self.l_ptr, &self.l_row), (&self.u_ptr, &self.u_row));
            self.rows.fill(&self.l_val, &self.u_val);
        }
        self.x.clear();
        self.x.resize(self.lanes.padded_len(), 0.0);
        self.work.clear();
        self.work.resize(n, 0.0);
    }

    /// Recomputes L and U for A's new `values` with the adopted pivots. False (factors left
    /// invalid) if a pivot fails [`PIVOT_THRESHOLD`] or is not finite: the caller pivots afresh.
    pub(super) fn refactor(&mut self, values: &[f64]) -> bool {
        let n = self.u_inv_diag.len();
        let x = &mut self.work;
        for j in 0..n {
            for &(p, i) in &self.a_entry[self.a_ptr[j]..self.a_ptr[j + 1]] {
                x[i] = values[p];
            }
            // Left-looking: x ← L(0..j)⁻¹ x over U's pattern in column j, in ascending order (a
            // row is final once every earlier column of L has updated it).
            for q in self.u_ptr[j]..self.u_ptr[j + 1] {
                let k = self.u_row[q];
                let xk = x[k];
                self.u_val[q] = xk;
                x[k] = 0.0;
                for t in self.l_ptr[k]..self.l_ptr[k + 1] {
                    x[self.l_row[t]] -= self.l_val[t] * xk;
                }
            }
            let pivot = x[j];
            x[j] = 0.0;
            let below = &self.l_row[self.l_ptr[j]..self.l_ptr[j + 1]];
            let largest = below.iter().fold(0.0f64, |m, &i| m.max(x[i].abs()));
            let inv = 1.0 / pivot;
            if !(inv.is_finite() && pivot.abs() >= PIVOT_THRESHOLD * largest) {
                for &i in below {
                    x[i] = 0.0;
                }
                // Columns j + 1… were never written: clear what this one scattered.
                return false;
            }
            self.u_inv_diag[j] = inv;
            for t in self.l_ptr[j]..self.l_ptr[j + 1] {
                let i = self.l_row[t];
                self.l_val[t] = x[i] * inv;
                x[i] = 0.0;
            }
        }
        if self.in_lanes {
            self.lanes.fill(&self.l_val, &self.u_val, &self.u_inv_diag);
        } else {
            self.rows.fill(&self.l_val, &self.u_val);
        }
        true
    }

    /// A y = b, with b in A's own numbering or (`global`) the interior entries of a vector in
    /// the numbering of S: the gather, then L's and U's sweeps. y is left in the pivot order
    /// (y_i at position `scatter[i]`) for the caller to scatter.
    pub(super) fn solve_pivoted(&mut self, b: &[f64], global: bool) -> &mut [f64] {
        let gather = if global {
            &self.gather_global
        } else {
            &self.gather_local
        };
        for (x, &g) in self.x.iter_mut().zip(gather) {
            *x = b[g];
        }
        let n = self.u_inv_diag.len();
        if self.in_lanes {
            // The padding unknown of an odd order (if any) must enter as 0: a solve that
            // overflowed leaves it 0 · ∞ = NaN, which would poison every later solve.
            self.x[n..].fill(0.0);
            self.lanes.solve(&mut self.x);
        } else {
            self.rows.solve(&mut self.x[..n], &self.u_inv_diag);
        }
        &mut self.x[..n]
    }
}
