//! The O(N) mass-matrix solve of MODELS.md FE.5.5, allocation-free.
//!
//! In chain order (cable 1 nodes 1…N−1, P, cable 2 nodes N−1…1, then the border (l1, ρ1, l2, ρ2))
//! the mass matrix is
//!
//! ```text
//!     M = [ B    C ]    B = M_1D ⊗ I2 (M_1D: (2N−1)² SPD tridiagonal, x and z decoupled),
//!         [ C^T  D ]    C: the columns l_1, l_2 (the ρ columns are zero), D: the border block.
//! ```
//!
//! M q'' = F is solved by the Schur complement on the border: u = B⁻¹F_r, Y = B⁻¹C (one
//! factorisation of M_1D, six right-hand sides swept together), S = D − CᵀY, border'' =
//! S⁻¹(F_border − Cᵀu), r'' = u − Y l''. Why not a dense or banded solve: B is the same tridiagonal
//! matrix for x and z, and the border is at most 4 wide, so this is ~30 flops per node.

use cdpr_numerics::small_cholesky;

/// Largest border (l1, ρ1, l2, ρ2 for the elastic stored cable; l1, l2 for the rigid one).
pub const MAX_BORDER: usize = 4;

/// The assembled system M q'' = F in the block form of FE.5.5, with its solve scratch.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ChainSystem {
    /// Chain nodes 2N − 1.
    pub nodes: usize,
    /// Border unknowns (4 or 2).
    pub border: usize,
    /// Border index of l_1 and l_2 (the only border columns C has).
    pub l_index: [usize; 2],
    /// M_1D diagonal [kg].
    pub diag: Vec<f64>,
    /// M_1D off-diagonal: `off[j]` couples chain nodes j and j + 1 [kg].
    pub off: Vec<f64>,
    /// Right-hand sides swept through B⁻¹ together, per node: F_x, F_z [N], then the columns
    /// C_{l1} (x, z) and C_{l2} (x, z) [kg]; overwritten with B⁻¹ of each by [`ChainSystem::solve`].
    pub rhs: Vec<[f64; 6]>,
    /// The border block D [kg (lengths)], symmetric, row-major.
    pub d: [[f64; MAX_BORDER]; MAX_BORDER],
    /// Border forces F_border [N].
    pub f_border: [f64; MAX_BORDER],
    /// Factorisation scratch: the LDLᵀ multipliers and pivots of M_1D.
    mult: Vec<f64>,
    pivot: Vec<f64>,
    /// The columns of C, kept through the solve (C_{l1} x, z, C_{l2} x, z).
    c: Vec<[f64; 4]>,
}

impl ChainSystem {
    pub fn new(nodes: usize, border: usize, l_index: [usize; 2]) -> Self {
        Self {
            nodes,
            border,
            l_index,
            diag: vec![0.0; nodes],
            off: vec![0.0; nodes.saturating_sub(1)],
            rhs: vec![[0.0; 6]; nodes],
            d: [[0.0; MAX_BORDER]; MAX_BORDER],
            f_border: [0.0; MAX_BORDER],
            mult: vec![0.0; nodes],
            pivot: vec![0.0; nodes],
            c: vec![[0.0; 4]; nodes],
        }
    }

    /// Zeroes M and F before an assembly.
    pub fn clear(&mut self) {
        self.diag.fill(0.0);
        self.off.fill(0.0);
        self.rhs.fill([0.0; 6]);
        self.d = [[0.0; MAX_BORDER]; MAX_BORDER];
        self.f_border = [0.0; MAX_BORDER];
    }

    /// Solves M q'' = F (FE.5.5): node accelerations into `ax`, `az` [m/s²] (chain order) and the
    /// border accelerations into `border` [m/s²]. Returns false if M is not positive definite.
    pub fn solve(&mut self, ax: &mut [f64], az: &mut [f64], border: &mut [f64]) -> bool {
        let n = self.nodes;
        for (c, r) in self.c.iter_mut().zip(&self.rhs) {
            *c = [r[2], r[3], r[4], r[5]];
        }
        // LDLᵀ of the tridiagonal M_1D and the forward sweep of all six right-hand sides.
        self.pivot[0] = self.diag[0];
        for j in 1..n {
            let m = self.off[j - 1] / self.pivot[j - 1];
            self.mult[j] = m;
            self.pivot[j] = self.diag[j] - m * self.off[j - 1];
            let prev = self.rhs[j - 1];
            let cur = &mut self.rhs[j];
            for k in 0..6 {
                cur[k] -= m * prev[k];
            }
        }
        // Backward sweep: rhs ← B⁻¹ rhs.
        {
            let p = 1.0 / self.pivot[n - 1];
            self.rhs[n - 1].iter_mut().for_each(|v| *v *= p);
        }
        for j in (0..n - 1).rev() {
            let next = self.rhs[j + 1];
            let (o, p) = (self.off[j], 1.0 / self.pivot[j]);
            let cur = &mut self.rhs[j];
            for k in 0..6 {
                cur[k] = (cur[k] - o * next[k]) * p;
            }
        }
        // Schur complement on the border: S = D − CᵀY, g = F_border − Cᵀu.
        let nb = self.border;
        let mut s = self.d;
        let mut g = self.f_border;
        let [l1, l2] = self.l_index;
        let (mut c11, mut c12, mut c22, mut g1, mut g2) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for (c, r) in self.c.iter().zip(&self.rhs) {
            c11 += c[0] * r[2] + c[1] * r[3];
            c12 += c[0] * r[4] + c[1] * r[5];
            c22 += c[2] * r[4] + c[3] * r[5];
            g1 += c[0] * r[0] + c[1] * r[1];
            g2 += c[2] * r[0] + c[3] * r[1];
        }
        s[l1][l1] -= c11;
        s[l1][l2] -= c12;
        s[l2][l1] -= c12;
        s[l2][l2] -= c22;
        g[l1] -= g1;
        g[l2] -= g2;
        if !cholesky_solve(&mut s, &mut g, nb) {
            return false;
        }
        border[..nb].copy_from_slice(&g[..nb]);
        let (a1, a2) = (g[l1], g[l2]);
        for (j, r) in self.rhs.iter().enumerate() {
            ax[j] = r[0] - r[2] * a1 - r[4] * a2;
            az[j] = r[1] - r[3] * a1 - r[5] * a2;
        }
        self.pivot.iter().all(|p| *p > 0.0)
    }
}

/// Solves the SPD system `a x = b` of size `n` ≤ 4 in place (`b` ← x) by Cholesky; false if `a` is
/// not positive definite.
// Triangular substitutions read as index arithmetic; iterator chains would hide the L_ij pattern.
#[allow(clippy::needless_range_loop)]
fn cholesky_solve(
    a: &mut [[f64; MAX_BORDER]; MAX_BORDER],
    b: &mut [f64; MAX_BORDER],
    n: usize,
) -> bool {
    if !small_cholesky::factor(a, n, 0.0) {
        return false;
    }
    for i in 0..n {
        let mut v = b[i];
        for k in 0..i {
            v -= a[i][k] * b[k];
        }
        b[i] = v / a[i][i];
    }
    for i in (0..n).rev() {
        let mut v = b[i];
        for k in i + 1..n {
            v -= a[k][i] * b[k];
        }
        b[i] = v / a[i][i];
    }
    true
}
