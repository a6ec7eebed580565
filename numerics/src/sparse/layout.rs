//! One layout of the iteration matrix: a border split, the interior's compressed columns in one
//! column order with its numeric LU, and the dense border eliminated by a Schur complement.

use super::SparseError;
use super::cost::SolveCost;
use super::factors::Factors;
use faer::Mat;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::solvers::DenseSolveCore;
use faer::perm::Perm;
use faer::sparse::linalg::lu;
use faer::sparse::linalg::lu::simplicial::{self, SimplicialLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};

/// Where a declared entry goes: the sparse block A (its compressed-column slot), the border
/// columns B (interior row, border index), rows C (their compressed-row slot) or D.
#[derive(Debug, Clone, Copy)]
pub(super) enum Slot {
    A(usize),
    B(usize, usize),
    C(usize),
    D(usize, usize),
}

/// One layout of S (n × n): a border split, the interior block A as a compressed-column matrix
/// in one column order with its numeric LU, and the dense border.
pub(super) struct Layout {
    pub(super) n: usize,
    /// Global index of each interior and each border unknown.
    pub(super) interior: Vec<usize>,
    pub(super) border: Vec<usize>,
    pub(super) pattern: SymbolicSparseColMat<usize>,
    pub(super) slot: Vec<Slot>,
    pub(super) values: Vec<f64>,
    /// B (interior × k, column-major; A⁻¹B goes to `b_pivoted`); C (k × interior) by compressed
    /// rows, as it has only the few entries of the pattern (a coupled unknown's row:
    /// its neighbours); D (k × k).
    pub(super) b: Vec<f64>,
    pub(super) c_ptr: Vec<usize>,
    pub(super) c_col: Vec<usize>,
    pub(super) c_val: Vec<f64>,
    pub(super) d: Mat<f64>,
    /// (D − C A⁻¹B)⁻¹ (k × k, row-major): the border is a handful of unknowns, so its inverse
    /// (by faer's LU) makes each solve's border step a k × k product instead of a dense solve
    /// with its ~100 ns of set-up.
    pub(super) schur_inverse: Vec<f64>,
    /// Column order of the interior (COLAMD's, or that taken from both ends).
    pub(super) col_perm: Perm<usize>,
    pub(super) numeric: SimplicialLu<usize, f64>,
    pub(super) row_perm: Vec<usize>,
    pub(super) row_perm_inv: Vec<usize>,
    pub(super) factor_memory: MemBuffer,
    pub(super) factors: Factors,
    /// `factors` hold a pivot sequence for this pattern (a refactorisation may reuse it).
    pub(super) pivots_valid: bool,
    /// Factorisations that pivoted (faer's), of all since the start.
    pub(super) pivotings: u64,
    pub(super) factorised: bool,
    pub(super) border_rhs: Vec<f64>,
    /// The solve works in the factors' pivot order and scatters once at the end: per position of
    /// that order, the unknown's index in S; per entry of C, the position of its column; and
    /// A⁻¹B (column-major) in that order. Set after each pivoting (the first two) and each
    /// factorisation (the last; B itself stays in A's numbering, where it is assembled).
    pub(super) pivoted_global: Vec<usize>,
    pub(super) c_at: Vec<usize>,
    pub(super) b_pivoted: Vec<f64>,
}

/// `order` taken from both ends at once: o_0, o_{n−1}, o_1, o_{n−2}, … On a chain that COLAMD
/// numbers end to end, two independent halves are eliminated side by side.
pub(super) fn two_front(order: &[usize]) -> Perm<usize> {
    let n = order.len();
    let forward: Vec<usize> = (0..n)
        .map(|k| {
            if k % 2 == 0 {
                order[k / 2]
            } else {
                order[n - 1 - k / 2]
            }
        })
        .collect();
    let mut inverse = vec![0usize; n];
    for (k, &c) in forward.iter().enumerate() {
        inverse[c] = k;
    }
    Perm::new_checked(forward.into_boxed_slice(), inverse.into_boxed_slice(), n)
}

/// The symbolic parts of a border split shared by its layouts (one per column order).
struct Parts {
    n: usize,
    interior: Vec<usize>,
    border: Vec<usize>,
    pattern: SymbolicSparseColMat<usize>,
    slot: Vec<Slot>,
    c_ptr: Vec<usize>,
    c_col: Vec<usize>,
}

/// A border split of the unknowns: which are border, and each one's index within its part.
struct Split<'a> {
    is_border: &'a [bool],
    local: &'a [usize],
}

impl Split<'_> {
    /// A's pattern by compressed columns (`col_ptr`, `row_idx`) in local numbering. `cells` is
    /// sorted by (col, row) and the interior keeps the global order, so the interior cells come
    /// out sorted by local column, then row.
    fn interior_columns(&self, cells: &[(usize, usize)], ni: usize) -> (Vec<usize>, Vec<usize>) {
        let (is_border, local) = (self.is_border, self.local);
        let mut col_ptr = vec![0usize; ni + 1];
        let mut row_idx = Vec::new();
        for &(c, r) in cells
            .iter()
            .filter(|(c, r)| !is_border[*c] && !is_border[*r])
        {
            col_ptr[local[c] + 1] += 1;
            row_idx.push(local[r]);
        }
        for c in 0..ni {
            col_ptr[c + 1] += col_ptr[c];
        }
        (col_ptr, row_idx)
    }

    /// C's pattern by compressed rows (border row, interior column): `c_ptr`, `c_col`.
    fn border_rows(&self, entries: &[(usize, usize)], k: usize) -> (Vec<usize>, Vec<usize>) {
        let (is_border, local) = (self.is_border, self.local);
        let mut c_cells: Vec<(usize, usize)> = entries
            .iter()
            .filter(|&&(r, c)| is_border[r] && !is_border[c])
            .map(|&(r, c)| (local[r], local[c]))
            .collect();
        c_cells.sort_unstable();
        c_cells.dedup();
        let mut c_ptr = vec![0usize; k + 1];
        for &(r, _) in &c_cells {
            c_ptr[r + 1] += 1;
        }
        for r in 0..k {
            c_ptr[r + 1] += c_ptr[r];
        }
        (c_ptr, c_cells.iter().map(|&(_, c)| c).collect())
    }

    /// Where each declared entry (row, col) goes in A, B, C or D.
    fn slots(
        &self,
        entries: &[(usize, usize)],
        (col_ptr, row_idx): (&[usize], &[usize]),
        (c_ptr, c_col): (&[usize], &[usize]),
    ) -> Vec<Slot> {
        let (is_border, local) = (self.is_border, self.local);
        entries
            .iter()
            .map(|&(r, c)| match (is_border[r], is_border[c]) {
                (false, false) => {
                    let (lr, lc) = (local[r], local[c]);
                    let column = &row_idx[col_ptr[lc]..col_ptr[lc + 1]];
                    Slot::A(
                        col_ptr[lc] + column.binary_search(&lr).unwrap_or_else(|_| unreachable!()),
                    )
                }
                (false, true) => Slot::B(local[r], local[c]),
                (true, false) => {
                    let (lr, lc) = (local[r], local[c]);
                    let row = &c_col[c_ptr[lr]..c_ptr[lr + 1]];
                    Slot::C(c_ptr[lr] + row.binary_search(&lc).unwrap_or_else(|_| unreachable!()))
                }
                (true, true) => Slot::D(local[r], local[c]),
            })
            .collect()
    }
}

impl Layout {
    /// The symbolic work for one border split: the compressed columns of the interior (`cells`:
    /// the pattern as sorted, deduplicated (col, row) with the diagonal) and faer's COLAMD order,
    /// done once; then a layout per candidate column order (COLAMD's, and the two-front one
    /// where it differs).
    pub(super) fn for_split(
        n: usize,
        entries: &[(usize, usize)],
        cells: &[(usize, usize)],
        is_border: &[bool],
    ) -> Result<Vec<Self>, SparseError> {
        let border: Vec<usize> = (0..n).filter(|&i| is_border[i]).collect();
        let interior: Vec<usize> = (0..n).filter(|&i| !is_border[i]).collect();
        // Local index of each global unknown within its part.
        let mut local = vec![0usize; n];
        for (k, &i) in interior.iter().enumerate() {
            local[i] = k;
        }
        for (k, &i) in border.iter().enumerate() {
            local[i] = k;
        }
        let split = Split {
            is_border,
            local: &local,
        };
        let (col_ptr, row_idx) = split.interior_columns(cells, interior.len());
        let (c_ptr, c_col) = split.border_rows(entries, border.len());
        let slot = split.slots(entries, (&col_ptr, &row_idx), (&c_ptr, &c_col));
        let ni = interior.len();
        let pattern = SymbolicSparseColMat::new_checked(ni, ni, col_ptr, None, row_idx);
        let symbolic = lu::factorize_symbolic_lu(pattern.as_ref(), Default::default())
            .map_err(|e| SparseError::Factorisation(format!("{e:?}")))?;
        let (forward, inverse) = symbolic.col_perm().arrays();
        let mut orders = vec![Perm::new_checked(forward.into(), inverse.into(), ni)];
        let both_ends = two_front(forward);
        if both_ends.as_ref().arrays().0 != forward {
            orders.push(both_ends);
        }
        let parts = Parts {
            n,
            interior,
            border,
            pattern,
            slot,
            c_ptr,
            c_col,
        };
        Ok(orders
            .into_iter()
            .map(|col_perm| Self::in_order(&parts, col_perm))
            .collect())
    }

    /// A layout of the split `parts` with the interior's columns in `col_perm`'s order, its
    /// numeric buffers allocated once.
    fn in_order(parts: &Parts, col_perm: Perm<usize>) -> Self {
        let (ni, k) = (parts.interior.len(), parts.border.len());
        let nc = parts.c_col.len();
        Self {
            n: parts.n,
            interior: parts.interior.clone(),
            border: parts.border.clone(),
            pattern: parts.pattern.clone(),
            slot: parts.slot.clone(),
            values: vec![0.0; parts.pattern.row_idx().len()],
            b: vec![0.0; ni * k],
            c_val: vec![0.0; nc],
            c_ptr: parts.c_ptr.clone(),
            c_col: parts.c_col.clone(),
            d: Mat::zeros(k, k),
            schur_inverse: vec![0.0; k * k],
            col_perm,
            numeric: SimplicialLu::new(),
            row_perm: vec![0; ni],
            row_perm_inv: vec![0; ni],
            factor_memory: MemBuffer::new(simplicial::factorize_simplicial_numeric_lu_scratch::<
                usize,
                f64,
            >(ni, ni)),
            factors: Factors::default(),
            pivots_valid: false,
            pivotings: 0,
            factorised: false,
            border_rhs: vec![0.0; k],
            pivoted_global: vec![0; ni],
            c_at: vec![0; nc],
            b_pivoted: vec![0.0; ni * k],
        }
    }

    /// S from `entry_values` (pattern order, duplicates summed), factorised.
    pub(super) fn factorise(&mut self, entry_values: &[f64]) -> Result<(), SparseError> {
        debug_assert_eq!(entry_values.len(), self.slot.len());
        self.factorised = false;
        self.assemble(entry_values);
        if entry_values.iter().any(|v| !v.is_finite()) {
            return Err(SparseError::Factorisation(
                "non-finite entry in the iteration matrix".into(),
            ));
        }
        let pivoted = !(self.pivots_valid && self.factors.refactor(&self.values));
        if pivoted {
            self.pivot_and_factorise()?;
        }
        if !self.border.is_empty() {
            self.eliminate_border()?;
        }
        self.factorised = true;
        self.pivotings += u64::from(pivoted);
        Ok(())
    }

    /// A, B, C and D from `entry_values`, duplicates summed.
    fn assemble(&mut self, entry_values: &[f64]) {
        let ni = self.interior.len();
        self.values.fill(0.0);
        self.b.fill(0.0);
        self.c_val.fill(0.0);
        self.d.fill(0.0);
        for (&slot, &v) in self.slot.iter().zip(entry_values) {
            match slot {
                Slot::A(s) => self.values[s] += v,
                Slot::B(i, j) => self.b[j * ni + i] += v,
                Slot::C(p) => self.c_val[p] += v,
                Slot::D(i, j) => self.d[(i, j)] += v,
            }
        }
    }

    /// A's numeric LU by faer with a new pivot sequence, adopted into `factors`, and the
    /// solve's scatter maps for that sequence.
    fn pivot_and_factorise(&mut self) -> Result<(), SparseError> {
        self.pivots_valid = false;
        let matrix = SparseColMatRef::new(self.pattern.as_ref(), &self.values);
        simplicial::factorize_simplicial_numeric_lu(
            &mut self.row_perm,
            &mut self.row_perm_inv,
            &mut self.numeric,
            matrix,
            self.col_perm.as_ref(),
            MemStack::new(&mut self.factor_memory),
        )
        .map_err(|e| SparseError::Factorisation(format!("{e:?}")))?;
        self.factors.adopt(
            &self.numeric,
            self.pattern.as_ref(),
            &self.row_perm,
            &self.row_perm_inv,
            self.col_perm.as_ref(),
            &self.interior,
        );
        // faer takes a zero pivot when a column has nothing else to offer (it does not report
        // singularity): its inverse is infinite.
        if self.factors.u_inv_diag.iter().any(|d| !d.is_finite()) {
            return Err(SparseError::Factorisation(
                "singular iteration matrix (zero pivot)".into(),
            ));
        }
        self.pivots_valid = true;
        let at = &self.factors.scatter;
        for (&g, &s) in self.interior.iter().zip(at) {
            self.pivoted_global[s] = g;
        }
        for (c, &j) in self.c_at.iter_mut().zip(&self.c_col) {
            *c = at[j];
        }
        Ok(())
    }

    /// A⁻¹B in the factors' pivot order (as the solve uses it), then the inverse of the Schur
    /// complement D − C A⁻¹B.
    fn eliminate_border(&mut self) -> Result<(), SparseError> {
        let (ni, k) = (self.interior.len(), self.border.len());
        for (pivoted, column) in self
            .b_pivoted
            .chunks_exact_mut(ni)
            .zip(self.b.chunks_exact(ni))
        {
            pivoted.copy_from_slice(self.factors.solve_pivoted(column, false));
        }
        let mut schur = self.d.clone();
        for i in 0..k {
            let range = self.c_ptr[i]..self.c_ptr[i + 1];
            let (at, c) = (&self.c_at[range.clone()], &self.c_val[range]);
            for j in 0..k {
                schur[(i, j)] -= gathered_dot(at, c, &self.b_pivoted[j * ni..(j + 1) * ni]);
            }
        }
        let inverse = schur.partial_piv_lu().inverse();
        for i in 0..k {
            for j in 0..k {
                self.schur_inverse[i * k + j] = inverse[(i, j)];
            }
        }
        if self.schur_inverse.iter().any(|v| !v.is_finite()) {
            return Err(SparseError::Factorisation(
                "singular Schur complement of the border".into(),
            ));
        }
        Ok(())
    }

    pub(super) fn solve_cost(&self) -> SolveCost {
        let (k, ni) = (self.border.len(), self.interior.len());
        SolveCost::of(&self.factors, k * ni + self.c_val.len() + k * k)
    }

    /// Overwrites `rhs` with S⁻¹ rhs (the last factorisation). In the factors' pivot order
    /// throughout, scattered once (the same operations in the same order as in A's numbering).
    pub(super) fn solve_in_place(&mut self, rhs: &mut [f64]) {
        debug_assert!(self.factorised);
        let ni = self.interior.len();
        // y = A⁻¹ r_A, gathered from the global numbering.
        let y = self.factors.solve_pivoted(rhs, true);
        let k = self.border.len();
        if k > 0 {
            // x_B = (D − C A⁻¹B)⁻¹ (r_B − C y), x_A = y − A⁻¹B x_B.
            for (b, &i) in self.border.iter().enumerate() {
                let range = self.c_ptr[b]..self.c_ptr[b + 1];
                let c_y = gathered_dot(&self.c_at[range.clone()], &self.c_val[range], y);
                self.border_rhs[b] = rhs[i] - c_y;
            }
            for (j, &i) in self.border.iter().enumerate() {
                let x: f64 = self.schur_inverse[j * k..(j + 1) * k]
                    .iter()
                    .zip(&self.border_rhs)
                    .map(|(s, r)| s * r)
                    .sum();
                rhs[i] = x;
                let col = &self.b_pivoted[j * ni..(j + 1) * ni];
                for (y, a) in y.iter_mut().zip(col) {
                    *y -= a * x;
                }
            }
        }
        for (v, &g) in y.iter().zip(&self.pivoted_global) {
            rhs[g] = *v;
        }
    }
}

/// Σ_k values_k x_(index_k): a sparse row (or column) times a dense vector.
#[inline]
pub(super) fn gathered_dot(index: &[usize], values: &[f64], x: &[f64]) -> f64 {
    index.iter().zip(values).map(|(&j, v)| v * x[j]).sum()
}
