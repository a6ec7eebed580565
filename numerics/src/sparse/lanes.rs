//! The triangular sweeps of the iteration matrix's factors by rows, two unknowns at a time.
//!
//! A column sweep is one long dependency chain through memory: each unknown waits for the store
//! of its neighbour's update, its reload and a multiply-add (~10 cycles), where an independent
//! multiply-add costs ~1. When a chain is eliminated from both ends at once (the two-front order
//! of [`super::two_front`]), the unknowns 2s and 2s + 1 belong to different fronts and the
//! factors' entries sit at even distances 2, 4, 6 from the diagonal. Then both unknowns of a pair
//! can be computed together, by rows, from the three pairs before them kept in registers: the
//! chain between consecutive pairs is one multiply-add in a register (lumped N = 40, n = 161:
//! see the module doc of `sparse` for the measured solve). Entries outside that band (where the
//! two fronts meet, or any other fill) are applied per row from memory, so the sweeps are exact
//! for any factors; [`LaneSweeps::worthwhile`] says whether the band holds enough of them to pay.

/// Pairs before (or after) a pair that its band reaches: entries at distances 2, 4, …, 2·BAND.
pub(super) const BAND: usize = 3;

/// L's and U's strict parts and U's inverse diagonal, rearranged for the paired row sweeps.
#[derive(Debug, Default)]
pub(super) struct LaneSweeps {
    lower: Triangle,
    upper: Triangle,
    /// U's inverse diagonal by pairs (1 for the padding unknown of an odd order).
    inv_diag: Vec<[f64; 2]>,
}

/// One triangular factor by rows: per pair s, the coefficients `band[s][k][lane]` of row
/// i = 2s + lane on unknown i ∓ 2(k + 1) (− for L, + for U), and the row's other entries in
/// compressed rows.
#[derive(Debug, Default)]
struct Triangle {
    band: Vec<[[f64; 2]; BAND]>,
    more_ptr: Vec<usize>,
    more_col: Vec<usize>,
    more_val: Vec<f64>,
    /// Pairs with entries outside the band, ascending.
    exceptional: Vec<usize>,
    /// Per entry of the factor's compressed columns: its slot, an index into the flattened band,
    /// or (from `6 × pairs` on) into `more_val`.
    slot: Vec<usize>,
}

impl Triangle {
    /// The slots of the compressed columns (`ptr`, `row`) of a strict triangle of order `n`
    /// padded to `pairs` pairs; `lower`: L (rows below the diagonal), else U.
    fn plan(&mut self, pairs: usize, ptr: &[usize], row: &[usize], lower: bool) {
        let n = ptr.len() - 1;
        self.band.clear();
        self.band.resize(pairs, [[0.0; 2]; BAND]);
        let band_len = 2 * BAND * pairs;
        let in_band = |i: usize, j: usize| {
            let d = i.abs_diff(j);
            (d.is_multiple_of(2) && d / 2 <= BAND).then(|| 2 * (BAND * (i / 2) + d / 2 - 1) + i % 2)
        };
        // Rows' other entries: counted, then placed in column order.
        self.more_ptr.clear();
        self.more_ptr.resize(2 * pairs + 1, 0);
        for j in 0..n {
            for &i in &row[ptr[j]..ptr[j + 1]] {
                debug_assert!(if lower { i > j } else { i < j });
                if in_band(i, j).is_none() {
                    self.more_ptr[i + 1] += 1;
                }
            }
        }
        for i in 0..2 * pairs {
            self.more_ptr[i + 1] += self.more_ptr[i];
        }
        self.exceptional.clear();
        self.exceptional
            .extend((0..pairs).filter(|&s| self.more_ptr[2 * s] < self.more_ptr[2 * s + 2]));
        let mut next = self.more_ptr.clone();
        self.more_col.clear();
        self.more_col.resize(self.more_ptr[2 * pairs], 0);
        self.more_val.clear();
        self.more_val.resize(self.more_col.len(), 0.0);
        self.slot.clear();
        for j in 0..n {
            for &i in &row[ptr[j]..ptr[j + 1]] {
                let slot = in_band(i, j).unwrap_or_else(|| {
                    let p = next[i];
                    next[i] += 1;
                    self.more_col[p] = j;
                    band_len + p
                });
                self.slot.push(slot);
            }
        }
    }

    /// The factor's values `val` (in its compressed-column order) into their slots.
    fn fill(&mut self, val: &[f64]) {
        let band = self.band.as_flattened_mut().as_flattened_mut();
        let band_len = band.len();
        for (&slot, &v) in self.slot.iter().zip(val) {
            if slot < band_len {
                band[slot] = v;
            } else {
                self.more_val[slot - band_len] = v;
            }
        }
    }

    /// Σ_j v_ij x_j over row i's entries outside the band.
    #[inline]
    fn more(&self, i: usize, x: &[f64]) -> f64 {
        let range = self.more_ptr[i]..self.more_ptr[i + 1];
        super::layout::gathered_dot(&self.more_col[range.clone()], &self.more_val[range], x)
    }
}

impl LaneSweeps {
    /// Plans the sweeps for factors of order `n` with L's strict part (`l_ptr`, `l_row`) and U's
    /// (`u_ptr`, `u_row`) by compressed columns. Values come with [`Self::fill`].
    pub(super) fn plan(
        &mut self,
        l_ptr: &[usize],
        l_row: &[usize],
        u_ptr: &[usize],
        u_row: &[usize],
    ) {
        let n = l_ptr.len() - 1;
        let pairs = n.div_ceil(2);
        self.lower.plan(pairs, l_ptr, l_row, true);
        self.upper.plan(pairs, u_ptr, u_row, false);
        self.inv_diag.clear();
        self.inv_diag.resize(pairs, [1.0; 2]);
    }

    /// Length of the solution vector the sweeps work on: the order rounded up to pairs (the
    /// padding unknown's right-hand side must be 0).
    pub(super) fn padded_len(&self) -> usize {
        2 * self.inv_diag.len()
    }

    /// Entries of L and U outside the band.
    pub(super) fn outside_band(&self) -> usize {
        self.lower.more_col.len() + self.upper.more_col.len()
    }

    /// Whether the band holds the bulk of the factors: at most one entry in eight outside it
    /// (each costs a load from memory and a row loop on top of the band's work).
    pub(super) fn worthwhile(&self) -> bool {
        let outside = self.outside_band();
        let inside = self.lower.slot.len() + self.upper.slot.len() - outside;
        8 * outside <= inside
    }

    /// The factors' values: L's and U's strict parts in their compressed-column order, and U's
    /// inverse diagonal.
    pub(super) fn fill(&mut self, l_val: &[f64], u_val: &[f64], u_inv_diag: &[f64]) {
        self.lower.fill(l_val);
        self.upper.fill(u_val);
        for (pair, inv) in self.inv_diag.iter_mut().zip(u_inv_diag.chunks(2)) {
            pair[..inv.len()].copy_from_slice(inv);
        }
    }

    /// x ← U⁻¹ L⁻¹ x, x of [`Self::padded_len`].
    ///
    /// Runs of pairs within the band go through [`forward_run`] and [`backward_run`], whose loops
    /// hold the three neighbouring pairs in registers (a call in the loop, or an array rotated
    /// through the stack, would put them back in memory and the chain with them); the few pairs
    /// with entries outside the band are done one at a time in between.
    pub(super) fn solve(&self, x: &mut [f64]) {
        let pairs = self.inv_diag.len();
        assert_eq!(x.len(), 2 * pairs, "solution vector of the padded order");
        let (lower, upper) = (&self.lower, &self.upper);
        let mut near = [[0.0f64; 2]; BAND];
        let mut from = 0;
        for &e in &lower.exceptional {
            near = forward_run(&lower.band[from..e], &mut x[2 * from..2 * e], near);
            // Pair e: the band, then the rows' other entries (row 2e + 1 may read x_2e).
            let mut acc = band_step(&lower.band[e], [x[2 * e], x[2 * e + 1]], &near);
            acc[0] -= lower.more(2 * e, x);
            x[2 * e] = acc[0];
            acc[1] -= lower.more(2 * e + 1, x);
            x[2 * e + 1] = acc[1];
            near = [acc, near[0], near[1]];
            from = e + 1;
        }
        forward_run(&lower.band[from..], &mut x[2 * from..], near);
        let mut near = [[0.0f64; 2]; BAND];
        let mut to = pairs;
        for &e in upper.exceptional.iter().rev() {
            let run = e + 1..to;
            near = backward_run(
                &upper.band[run.clone()],
                &self.inv_diag[run],
                &mut x[2 * (e + 1)..2 * to],
                near,
            );
            // Pair e, backwards: row 2e + 1 first, as row 2e may read x_2e+1.
            let inv = self.inv_diag[e];
            let mut acc = band_step(&upper.band[e], [x[2 * e], x[2 * e + 1]], &near);
            acc[1] -= upper.more(2 * e + 1, x);
            x[2 * e + 1] = acc[1] * inv[1];
            acc[0] -= upper.more(2 * e, x);
            x[2 * e] = acc[0] * inv[0];
            near = [[x[2 * e], x[2 * e + 1]], near[0], near[1]];
            to = e;
        }
        backward_run(
            &upper.band[..to],
            &self.inv_diag[..to],
            &mut x[..2 * to],
            near,
        );
    }
}

/// A pair's right-hand side minus its band terms: `near[k]` is the pair k + 1 away. The nearest is
/// subtracted last, so that the chain from one pair to the next is one multiply-add.
#[inline(always)]
fn band_step(band: &[[f64; 2]; BAND], rhs: [f64; 2], near: &[[f64; 2]; BAND]) -> [f64; 2] {
    let mut acc = rhs;
    for k in (0..BAND).rev() {
        for lane in 0..2 {
            acc[lane] -= band[k][lane] * near[k][lane];
        }
    }
    acc
}

/// L's sweep over a run of pairs within the band (`x` their pairs), from the three pairs before
/// the run; returns the run's last three.
fn forward_run(
    band: &[[[f64; 2]; BAND]],
    x: &mut [f64],
    near: [[f64; 2]; BAND],
) -> [[f64; 2]; BAND] {
    let [mut p0, mut p1, mut p2] = near;
    for (b, pair) in band.iter().zip(x.chunks_exact_mut(2)) {
        let acc = band_step(b, [pair[0], pair[1]], &[p0, p1, p2]);
        pair.copy_from_slice(&acc);
        (p2, p1, p0) = (p1, p0, acc);
    }
    [p0, p1, p2]
}

/// U's sweep over a run of pairs within the band, backwards, from the three pairs after the run;
/// returns the run's first three.
fn backward_run(
    band: &[[[f64; 2]; BAND]],
    inv_diag: &[[f64; 2]],
    x: &mut [f64],
    near: [[f64; 2]; BAND],
) -> [[f64; 2]; BAND] {
    let [mut p0, mut p1, mut p2] = near;
    for ((b, inv), pair) in band.iter().zip(inv_diag).zip(x.chunks_exact_mut(2)).rev() {
        let acc = band_step(b, [pair[0], pair[1]], &[p0, p1, p2]);
        let solved = [acc[0] * inv[0], acc[1] * inv[1]];
        pair.copy_from_slice(&solved);
        (p2, p1, p0) = (p1, p0, solved);
    }
    [p0, p1, p2]
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A strict triangle of order n by compressed columns (rows ascending), from the entries
    /// (i, j, v) that fall on its side of the diagonal.
    fn columns(
        n: usize,
        entries: &[(usize, usize, f64)],
        lower: bool,
    ) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
        let mut dense = vec![None; n * n];
        for &(i, j, v) in entries {
            let (i, j) = (i % n, j % n);
            if (lower && i > j) || (!lower && i < j) {
                dense[j * n + i] = Some(v);
            }
        }
        let (mut ptr, mut row, mut val) = (vec![0], Vec::new(), Vec::new());
        for j in 0..n {
            for i in 0..n {
                if let Some(v) = dense[j * n + i] {
                    row.push(i);
                    val.push(v);
                }
            }
            ptr.push(row.len());
        }
        (ptr, row, val)
    }

    proptest! {
        /// The paired row sweeps solve L U x = b for any strict triangles, in the band or out of
        /// it (odd distances, far entries, odd orders), as plain dense substitution does.
        /// Entries ≤ 0.3 and diagonals ≥ 1 keep the triangles well conditioned, so the two
        /// orders of summation agree to 1e-12 relative.
        #[test]
        fn paired_sweeps_match_dense_substitution(
            n in 1usize..24,
            entries in prop::collection::vec((0usize..24, 0usize..24, -0.3f64..0.3), 0..80),
            near in prop::collection::vec((0usize..24, 1usize..=BAND, -0.3f64..0.3), 0..40),
            diag in prop::collection::vec(1.0f64..3.0, 24),
            b in prop::collection::vec(-1.0f64..1.0, 24),
        ) {
            // Band entries (i, i ± 2k) as well as arbitrary ones.
            let mut all = entries.clone();
            for &(i, k, v) in &near {
                let (i, d) = (i % n, 2 * k);
                if i + d < n {
                    all.push((i + d, i, v));
                    all.push((i, i + d, v));
                }
            }
            let (l_ptr, l_row, l_val) = columns(n, &all, true);
            let (u_ptr, u_row, u_val) = columns(n, &all, false);
            let inv: Vec<f64> = diag[..n].iter().map(|d| 1.0 / d).collect();
            let mut sweeps = LaneSweeps::default();
            sweeps.plan(&l_ptr, &l_row, &u_ptr, &u_row);
            sweeps.fill(&l_val, &u_val, &inv);
            let mut x = vec![0.0; sweeps.padded_len()];
            x[..n].copy_from_slice(&b[..n]);
            sweeps.solve(&mut x);
            // Dense substitution by columns: L unit lower, U = strict + diag.
            let mut y = b[..n].to_vec();
            for j in 0..n {
                for k in l_ptr[j]..l_ptr[j + 1] {
                    y[l_row[k]] -= l_val[k] * y[j];
                }
            }
            for j in (0..n).rev() {
                y[j] *= inv[j];
                for k in u_ptr[j]..u_ptr[j + 1] {
                    y[u_row[k]] -= u_val[k] * y[j];
                }
            }
            let scale = y.iter().fold(1.0f64, |m, v| m.max(v.abs()));
            for i in 0..n {
                prop_assert!((x[i] - y[i]).abs() <= 1e-12 * scale, "{}: {} vs {}", i, x[i], y[i]);
            }
            if n % 2 == 1 {
                prop_assert_eq!(x[n], 0.0, "the padding unknown stays 0");
            }
        }
    }
}
