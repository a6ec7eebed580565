//! The triangular sweeps of the iteration matrix's factors by rows, for factors the paired
//! sweeps of [`super::lanes`] do not suit (the spatial star's arms, any other order).
//!
//! A column sweep updates x in memory: every entry is a load, a multiply-add and a store, and an
//! unknown's updates chain through its stores and reloads. By rows, an unknown is accumulated in
//! a register from unknowns already final, and stored once. Each row takes its entries in the
//! order the column sweep applies them — L's by ascending column, U's by descending — so every
//! unknown sees the same subtractions in the same order: the same bits as by columns. The rows
//! themselves are taken level by level ([`Rows::schedule`]), so that independent rows overlap.

/// One strict triangle of the factors by rows, and where each of its column-ordered entries
/// goes.
#[derive(Debug, Default)]
struct Rows {
    ptr: Vec<usize>,
    col: Vec<usize>,
    val: Vec<f64>,
    /// Per entry of the factor's compressed columns: its position in `col` and `val`.
    slot: Vec<usize>,
    /// The order the sweep takes the rows in ([`Rows::schedule`]).
    order: Vec<usize>,
}

impl Rows {
    /// The row pattern of a triangle given by compressed columns (`ptr`, `row`) over `n`
    /// unknowns, each row's entries in the order the columns are visited (`columns`, the
    /// sweep's own order), the rows scheduled by level.
    fn plan(
        &mut self,
        n: usize,
        ptr: &[usize],
        row: &[usize],
        columns: impl Iterator<Item = usize> + Clone,
    ) {
        let mut next = vec![0usize; n + 1];
        for &i in row {
            next[i + 1] += 1;
        }
        for i in 0..n {
            next[i + 1] += next[i];
        }
        self.ptr.clear();
        self.ptr.extend_from_slice(&next);
        self.col.clear();
        self.col.resize(row.len(), 0);
        self.val.clear();
        self.val.resize(row.len(), 0.0);
        self.slot.clear();
        self.slot.resize(row.len(), 0);
        for j in columns.clone() {
            let column = ptr[j]..ptr[j + 1];
            for (k, &i) in column.clone().zip(&row[column]) {
                self.slot[k] = next[i];
                self.col[next[i]] = j;
                next[i] += 1;
            }
        }
        self.schedule(n, columns);
    }

    /// The rows ordered by level — a row's level one more than the highest level of the rows
    /// whose unknowns it reads, found in the sweep's own order `sweep` — then by index. Every
    /// row still comes after the rows it reads, so each unknown is the same number; rows of
    /// one level do not read each other, so their chains of subtractions (the sweep's
    /// latency: each row waits on the last unknown it reads) overlap in the processor. On the
    /// spatial star that interleaves the arms, which the elimination takes one after another.
    fn schedule(&mut self, n: usize, sweep: impl Iterator<Item = usize>) {
        let mut level = vec![0usize; n];
        for i in sweep {
            let entries = &self.col[self.ptr[i]..self.ptr[i + 1]];
            level[i] = entries.iter().map(|&c| level[c] + 1).max().unwrap_or(0);
        }
        self.order.clear();
        self.order.extend(0..n);
        self.order.sort_by_key(|&i| (level[i], i));
        // The rows stored in that order, so the sweep reads its entries front to back.
        let mut ptr = Vec::with_capacity(n + 1);
        ptr.push(0);
        let mut col = Vec::with_capacity(self.col.len());
        let mut moved = vec![0usize; self.col.len()];
        for &i in &self.order {
            let row = self.ptr[i]..self.ptr[i + 1];
            for (to, &c) in moved[row.clone()].iter_mut().zip(&self.col[row]) {
                *to = col.len();
                col.push(c);
            }
            ptr.push(col.len());
        }
        for s in &mut self.slot {
            *s = moved[*s];
        }
        (self.ptr, self.col) = (ptr, col);
    }

    /// The values of the factor's compressed columns, moved to their rows.
    fn fill(&mut self, val: &[f64]) {
        for (&s, &v) in self.slot.iter().zip(val) {
            self.val[s] = v;
        }
    }

    /// The update of the row at place k of the sweep: `x_i` less each entry times its (final)
    /// unknown, in order.
    #[inline(always)]
    fn reduce(&self, k: usize, x: &[f64], mut xi: f64) -> f64 {
        let (start, end) = (self.ptr[k], self.ptr[k + 1]);
        for (&c, &v) in self.col[start..end].iter().zip(&self.val[start..end]) {
            xi -= v * x[c];
        }
        xi
    }
}

/// L's and U's strict parts by rows.
#[derive(Debug, Default)]
pub(super) struct RowSweeps {
    lower: Rows,
    upper: Rows,
}

impl RowSweeps {
    /// The row patterns of L's and U's strict parts given by compressed columns: L's rows
    /// ascending in their columns, U's descending (the column sweeps' orders).
    pub(super) fn plan(&mut self, l: (&[usize], &[usize]), u: (&[usize], &[usize])) {
        let n = l.0.len() - 1;
        self.lower.plan(n, l.0, l.1, 0..n);
        self.upper.plan(n, u.0, u.1, (0..n).rev());
    }

    /// The factors' values, after each factorisation.
    pub(super) fn fill(&mut self, l_val: &[f64], u_val: &[f64]) {
        self.lower.fill(l_val);
        self.upper.fill(u_val);
    }

    /// x ← U⁻¹ L⁻¹ x, L with a unit diagonal, U's diagonal given inverted.
    pub(super) fn solve(&self, x: &mut [f64], u_inv_diag: &[f64]) {
        for (k, &i) in self.lower.order.iter().enumerate() {
            x[i] = self.lower.reduce(k, x, x[i]);
        }
        for (k, &i) in self.upper.order.iter().enumerate() {
            x[i] = self.upper.reduce(k, x, x[i]) * u_inv_diag[i];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::RowSweeps;
    use proptest::prelude::*;

    /// x ← U⁻¹ L⁻¹ x by columns (the sweeps the rows replace), the reference.
    fn by_columns(
        l: (&[usize], &[usize], &[f64]),
        u: (&[usize], &[usize], &[f64]),
        inv: &[f64],
        x: &mut [f64],
    ) {
        for j in 0..x.len() {
            let xj = x[j];
            for k in l.0[j]..l.0[j + 1] {
                x[l.1[k]] -= l.2[k] * xj;
            }
        }
        for j in (0..x.len()).rev() {
            let xj = x[j] * inv[j];
            x[j] = xj;
            for k in u.0[j]..u.0[j + 1] {
                x[u.1[k]] -= u.2[k] * xj;
            }
        }
    }

    /// Compressed columns of a strict triangle of `n` unknowns: entry (i, j) present where
    /// `mask` says so, below the diagonal (`lower`) or above it, rows ascending per column.
    fn triangle(
        n: usize,
        mask: &[bool],
        values: &[f64],
        lower: bool,
    ) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
        let (mut ptr, mut row, mut val) = (vec![0], Vec::new(), Vec::new());
        for j in 0..n {
            for i in 0..n {
                let inside = if lower { i > j } else { i < j };
                if inside && mask[i * n + j] {
                    row.push(i);
                    val.push(values[i * n + j]);
                }
            }
            ptr.push(row.len());
        }
        (ptr, row, val)
    }

    proptest! {
        /// Any pattern and values (magnitudes over twelve decades, so that the order of the
        /// subtractions shows in the last bits): the rows give the columns' result bit for bit.
        #[test]
        fn rows_equal_columns_bit_for_bit(
            n in 1usize..24,
            mask in proptest::collection::vec(proptest::bool::weighted(0.3), 576),
            values in proptest::collection::vec(-1.0f64..1.0, 576),
            scales in proptest::collection::vec(-6i32..6, 576),
            b in proptest::collection::vec(-1.0f64..1.0, 24),
            inv in proptest::collection::vec(0.5f64..2.0, 24),
        ) {
            let v: Vec<f64> = values.iter().zip(&scales).map(|(v, &e)| v * 10f64.powi(e)).collect();
            let l = triangle(n, &mask, &v, true);
            let u = triangle(n, &mask, &v, false);
            let mut expected = b[..n].to_vec();
            by_columns((&l.0, &l.1, &l.2), (&u.0, &u.1, &u.2), &inv[..n], &mut expected);
            let mut rows = RowSweeps::default();
            rows.plan((&l.0, &l.1), (&u.0, &u.1));
            rows.fill(&l.2, &u.2);
            let mut x = b[..n].to_vec();
            rows.solve(&mut x, &inv[..n]);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            prop_assert_eq!(bits(&x), bits(&expected));
        }
    }
}
