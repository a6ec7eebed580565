//! What a solve with a set of factors costs: the model by which the first factorisation picks
//! the cheapest of its candidate layouts.

use super::factors::Factors;

/// What a solve costs: the non-zeros of L and U (one multiply-add each), the longest dependency
/// chain of the two sweeps (unknowns, or with `paired` sweeps pairs of unknowns, that must wait
/// for one another) and the border's multiply-adds (C y, the k × k product and A⁻¹B x_B:
/// nnz(C) + k² + k n_interior, independent).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SolveCost {
    pub nonzeros: usize,
    pub chain: usize,
    pub border: usize,
    /// The sweeps run by rows in pairs ([`lanes`](super::lanes)): a link is a multiply-add in a register.
    pub paired: bool,
}

impl SolveCost {
    /// A link of a column sweep's chain (a store, its reload and a multiply-add on the critical
    /// path) costs about as much as 8 independent multiply-adds on current cores; the sweeps
    /// take whichever of the two bounds is larger. (The unpaired solve now sweeps by rows; the
    /// price is kept, so that the layouts chosen, and the results, stay as they were.)
    pub(super) const LINK: usize = 8;
    /// A link of the paired sweeps: one multiply-add's latency. (Lumped N = 40, n = 161: 0.55
    /// µs per solve against 1.23 µs by columns, gather and scatter included.)
    pub(super) const PAIRED_LINK: usize = 4;

    /// In independent multiply-adds.
    pub fn estimate(&self) -> usize {
        let link = if self.paired {
            Self::PAIRED_LINK
        } else {
            Self::LINK
        };
        (link * self.chain).max(self.nonzeros) + self.border
    }

    pub(super) fn of(f: &Factors, border: usize) -> Self {
        let n = f.u_inv_diag.len();
        // The diagonals of L (unit) and U count too.
        let nonzeros = f.l_row.len() + f.u_row.len() + 2 * n;
        if f.in_lanes {
            // One link per pair and sweep, and one per entry outside the band (read from memory).
            return Self {
                nonzeros,
                chain: f.lanes.padded_len() + f.lanes.outside_band(),
                border,
                paired: true,
            };
        }
        let mut ready = vec![0usize; n];
        let mut finish = vec![0usize; n];
        // Forward sweep in column order: x_i waits for every x_j with L_ij ≠ 0, j < i.
        let forward = Self::sweep(0..n, &mut ready, &mut finish, |j| {
            &f.l_row[f.l_ptr[j]..f.l_ptr[j + 1]]
        });
        ready.fill(0);
        // Backward sweep: x_i waits for every x_j with U_ij ≠ 0, j > i.
        let backward = Self::sweep((0..n).rev(), &mut ready, &mut finish, |j| {
            &f.u_row[f.u_ptr[j]..f.u_ptr[j + 1]]
        });
        Self {
            nonzeros,
            chain: forward + backward,
            border,
            paired: false,
        }
    }

    /// Columns the core overlaps at most: a column is a dozen or two micro-operations, the
    /// reorder window a few hundred. Independent chains far apart in the sweep's order (one
    /// cable's, then the other's) do not overlap; interleaved ones do.
    pub(super) const WINDOW: usize = 8;

    /// Length of a sweep's critical path in columns: column j finishes one step after the
    /// columns it reads, and not before the column `WINDOW` places earlier in the sweep.
    pub(super) fn sweep<'a>(
        order: impl Iterator<Item = usize>,
        ready: &mut [usize],
        finish: &mut [usize],
        updates: impl Fn(usize) -> &'a [usize],
    ) -> usize {
        let mut issued = Vec::with_capacity(ready.len());
        let mut longest = 0;
        for j in order {
            let window = issued
                .len()
                .checked_sub(Self::WINDOW)
                .map_or(0, |k| finish[issued[k]]);
            finish[j] = ready[j].max(window) + 1;
            longest = longest.max(finish[j]);
            for &i in updates(j) {
                ready[i] = ready[i].max(finish[j]);
            }
            issued.push(j);
        }
        longest
    }
}
