//! The spatial FE robot's M q'' = F on a star of m arms meeting at the effector, solved in
//! O(N m) (the planar chain's FE.5.5 generalised).
//!
//! Unknowns: per arm i its N − 1 free nodes x_i (3 each), then the globals y = (P, l_1, ρ_1, …,
//! l_m, ρ_m). The node–node blocks of M are multiples of the 3×3 identity (FE.4: μ h c1, μ h c2
//! on a span of equal elements), so arm i's own block is T_i = t_i ⊗ I_3 with t_i a scalar
//! symmetric tridiagonal matrix; an arm couples to the globals only through its last node's
//! μ h c2 with P and its l_i column (μ α Δ, μ β Δ of each element). Eliminating each arm,
//! x_i = u_i − z_i ⊗ (c_P,i a_P) − v_i l_i'' with u_i = T_i⁻¹ f_i, v_i = T_i⁻¹ c_i and
//! z_i = t_i⁻¹ e_last (three Thomas sweeps per arm), leaves a dense symmetric system of
//! 3 + 2m ≤ 19 unknowns for P, l and ρ, solved by Cholesky. Nothing is allocated per solve.

use nalgebra::Vector3;

/// M and F of one assembly, and the solve's scratch.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct StarSystem {
    pub(super) arms: usize,
    /// Free nodes per arm, N − 1.
    pub(super) nodes: usize,
    /// Per arm and node (arm-major): t_i's diagonal [kg], the node forces [N], the l_i column [kg].
    pub(super) diag: Vec<f64>,
    pub(super) force: Vec<Vector3<f64>>,
    pub(super) l_column: Vec<Vector3<f64>>,
    /// Per arm and node k < N − 2: t_i's entry between nodes k and k + 1 [kg].
    pub(super) off: Vec<f64>,
    /// Per arm: the last free node's coupling with P (μ h c2) [kg] and P's l_i column [kg].
    pub(super) node_effector: Vec<f64>,
    pub(super) effector_l: Vec<Vector3<f64>>,
    /// Per arm: M's (l, l), (l, ρ), (ρ, ρ) entries [kg] and the l and ρ rows of F [N].
    pub(super) border: Vec<[f64; 5]>,
    /// The effector's mass entry (M plus its elements' share) [kg] and its force [N].
    pub(super) effector_mass: f64,
    pub(super) effector_force: Vector3<f64>,
    /// The l rows as assembled, held when the lengths are prescribed ([`Self::hold_l_rows`]):
    /// the l_i column per node, P's l_i column, and per arm (M_ll, F_l).
    held_l_column: Vec<Vector3<f64>>,
    held_effector_l: Vec<Vector3<f64>>,
    held_l_row: Vec<[f64; 2]>,
    /// Scratch: Thomas multipliers and pivots, u, v, z per node, the reduced system.
    multiplier: Vec<f64>,
    pivot: Vec<f64>,
    u: Vec<Vector3<f64>>,
    v: Vec<Vector3<f64>>,
    z: Vec<f64>,
    reduced: Vec<f64>,
    rhs: Vec<f64>,
}

impl StarSystem {
    /// A system of `arms` arms of `nodes` free nodes each.
    pub fn new(arms: usize, nodes: usize) -> Self {
        let all = arms * nodes;
        let g = 3 + 2 * arms;
        Self {
            arms,
            nodes,
            diag: vec![0.0; all],
            force: vec![Vector3::zeros(); all],
            l_column: vec![Vector3::zeros(); all],
            off: vec![0.0; all],
            node_effector: vec![0.0; arms],
            effector_l: vec![Vector3::zeros(); arms],
            border: vec![[0.0; 5]; arms],
            held_l_column: vec![Vector3::zeros(); all],
            held_effector_l: vec![Vector3::zeros(); arms],
            held_l_row: vec![[0.0; 2]; arms],
            effector_mass: 0.0,
            effector_force: Vector3::zeros(),
            multiplier: vec![0.0; all],
            pivot: vec![0.0; all],
            u: vec![Vector3::zeros(); all],
            v: vec![Vector3::zeros(); all],
            z: vec![0.0; all],
            reduced: vec![0.0; g * g],
            rhs: vec![0.0; g],
        }
    }

    /// Zeroes M and F for the next assembly.
    pub fn clear(&mut self) {
        self.diag.fill(0.0);
        self.force.fill(Vector3::zeros());
        self.l_column.fill(Vector3::zeros());
        self.off.fill(0.0);
        self.node_effector.fill(0.0);
        self.effector_l.fill(Vector3::zeros());
        self.border.fill([0.0; 5]);
        self.effector_mass = 0.0;
        self.effector_force = Vector3::zeros();
    }

    /// Keeps the l rows as assembled, before a prescription of l'' overwrites them.
    pub fn hold_l_rows(&mut self) {
        self.held_l_column.copy_from_slice(&self.l_column);
        self.held_effector_l.copy_from_slice(&self.effector_l);
        for (held, b) in self.held_l_row.iter_mut().zip(&self.border) {
            *held = [b[0], b[3]];
        }
    }

    /// The held l rows' residual (M q'' − F)_l per arm at the accelerations of a solve (the
    /// force that imposes each l_i'' there) into `out` [N].
    pub fn held_l_residuals(
        &self,
        nodes: &[Vector3<f64>],
        effector: &Vector3<f64>,
        border: &[[f64; 2]],
        out: &mut [f64],
    ) {
        let nn = self.nodes;
        for (arm, q) in out.iter_mut().enumerate().take(self.arms) {
            let [m_ll, f_l] = self.held_l_row[arm];
            let span: f64 = (arm * nn..(arm + 1) * nn)
                .map(|k| self.held_l_column[k].dot(&nodes[k]))
                .sum();
            *q = span + self.held_effector_l[arm].dot(effector) + m_ll * border[arm][0] - f_l;
        }
    }

    /// Arm i's Thomas factorisation of t_i, then u_i, v_i and z_i; false if t_i is not
    /// positive definite.
    fn eliminate_arm(&mut self, arm: usize) -> bool {
        let (nn, o) = (self.nodes, arm * self.nodes);
        for k in 0..nn {
            let coupling = if k > 0 { self.off[o + k - 1] } else { 0.0 };
            let previous = if k > 0 {
                self.multiplier[o + k - 1]
            } else {
                0.0
            };
            let pivot = self.diag[o + k] - coupling * previous;
            if pivot.is_nan() || pivot <= 0.0 {
                return false;
            }
            self.pivot[o + k] = pivot;
            self.multiplier[o + k] = if k + 1 < nn {
                self.off[o + k] / pivot
            } else {
                0.0
            };
            let (fu, fv, fz) = if k > 0 {
                (self.u[o + k - 1], self.v[o + k - 1], self.z[o + k - 1])
            } else {
                (Vector3::zeros(), Vector3::zeros(), 0.0)
            };
            let last = if k + 1 == nn { 1.0 } else { 0.0 };
            self.u[o + k] = (self.force[o + k] - fu * coupling) / pivot;
            self.v[o + k] = (self.l_column[o + k] - fv * coupling) / pivot;
            self.z[o + k] = (last - fz * coupling) / pivot;
        }
        for k in (0..nn.saturating_sub(1)).rev() {
            let c = self.multiplier[o + k];
            let (u, v, z) = (self.u[o + k + 1], self.v[o + k + 1], self.z[o + k + 1]);
            self.u[o + k] -= u * c;
            self.v[o + k] -= v * c;
            self.z[o + k] -= z * c;
        }
        true
    }

    /// Solves M q'' = F into the accelerations: `nodes` (arm-major, 3 per node), `effector` and
    /// per arm (l_i'', ρ_i''). False if M is not positive definite.
    pub fn solve(
        &mut self,
        nodes: &mut [Vector3<f64>],
        effector: &mut Vector3<f64>,
        border: &mut [[f64; 2]],
    ) -> bool {
        let (m, nn) = (self.arms, self.nodes);
        let g = 3 + 2 * m;
        self.reduced.fill(0.0);
        let mut mass = self.effector_mass;
        let mut pull = self.effector_force;
        for arm in 0..m {
            if !self.eliminate_arm(arm) {
                return false;
            }
            let o = arm * nn;
            let (l, r) = (3 + 2 * arm, 4 + 2 * arm);
            let [d_ll, d_lr, d_rr, f_l, f_r] = self.border[arm];
            let (mut s_ll, mut g_l) = (d_ll, f_l);
            for k in 0..nn {
                s_ll -= self.l_column[o + k].dot(&self.v[o + k]);
                g_l -= self.l_column[o + k].dot(&self.u[o + k]);
            }
            let mut s_pl = self.effector_l[arm];
            if nn > 0 {
                let c = self.node_effector[arm];
                let last = o + nn - 1;
                mass -= c * c * self.z[last];
                pull -= self.u[last] * c;
                s_pl -= self.v[last] * c;
            }
            for a in 0..3 {
                self.reduced[a * g + l] = s_pl[a];
                self.reduced[l * g + a] = s_pl[a];
            }
            self.reduced[l * g + l] = s_ll;
            self.reduced[l * g + r] = d_lr;
            self.reduced[r * g + l] = d_lr;
            self.reduced[r * g + r] = d_rr;
            self.rhs[l] = g_l;
            self.rhs[r] = f_r;
        }
        for a in 0..3 {
            self.reduced[a * g + a] = mass;
            self.rhs[a] = pull[a];
        }
        if !cholesky_solve(&mut self.reduced, &mut self.rhs, g) {
            return false;
        }
        let a_p = Vector3::new(self.rhs[0], self.rhs[1], self.rhs[2]);
        *effector = a_p;
        for (arm, accelerations) in border.iter_mut().enumerate().take(m) {
            let (l_acc, r_acc) = (self.rhs[3 + 2 * arm], self.rhs[4 + 2 * arm]);
            *accelerations = [l_acc, r_acc];
            let o = arm * nn;
            let c = self.node_effector[arm];
            for k in 0..nn {
                nodes[o + k] = self.u[o + k] - a_p * (self.z[o + k] * c) - self.v[o + k] * l_acc;
            }
        }
        true
    }
}

/// Solves the symmetric positive definite `a` (n × n, row-major, overwritten by its Cholesky
/// factor) x = b in place of `b`; false if `a` is not positive definite.
fn cholesky_solve(a: &mut [f64], b: &mut [f64], n: usize) -> bool {
    for j in 0..n {
        let mut d = a[j * n + j];
        for k in 0..j {
            d -= a[j * n + k] * a[j * n + k];
        }
        if d.is_nan() || d <= 0.0 {
            return false;
        }
        let d = d.sqrt();
        a[j * n + j] = d;
        for i in j + 1..n {
            let mut s = a[i * n + j];
            for k in 0..j {
                s -= a[i * n + k] * a[j * n + k];
            }
            a[i * n + j] = s / d;
        }
    }
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= a[i * n + k] * b[k];
        }
        b[i] = s / a[i * n + i];
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= a[k * n + i] * b[k];
        }
        b[i] = s / a[i * n + i];
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::DMatrix;

    /// The star's elimination against a dense LU of the same M on random SPD data (diagonally
    /// dominant node blocks, a border that keeps M positive definite), for 1–5 arms of 0–6 nodes.
    #[test]
    fn star_solve_is_the_dense_solve() {
        let mut seed = 0.37f64;
        let mut next = || {
            seed = (seed * 9301.0 + 49297.0) % 233280.0;
            seed / 233280.0 - 0.5
        };
        for arms in 1..=5 {
            for nodes in 0..=6 {
                let mut s = StarSystem::new(arms, nodes);
                let n = 3 * arms * nodes + 3 + 2 * arms;
                let mut dense = DMatrix::<f64>::zeros(n, n);
                let mut f = nalgebra::DVector::<f64>::zeros(n);
                let node = |arm: usize, k: usize| 3 * (arm * nodes + k);
                let (p0, b0) = (3 * arms * nodes, 3 * arms * nodes + 3);
                s.effector_mass = 2.0 + next();
                for a in 0..3 {
                    s.effector_force[a] = next();
                    dense[(p0 + a, p0 + a)] = s.effector_mass;
                    f[p0 + a] = s.effector_force[a];
                }
                for arm in 0..arms {
                    let (l, r) = (b0 + 2 * arm, b0 + 2 * arm + 1);
                    for k in 0..nodes {
                        let i = arm * nodes + k;
                        s.diag[i] = 1.0 + 0.1 * next();
                        s.force[i] = Vector3::new(next(), next(), next());
                        s.l_column[i] = Vector3::new(next(), next(), next()) * 0.1;
                        if k + 1 < nodes {
                            s.off[i] = 0.2 * next();
                        }
                        for a in 0..3 {
                            dense[(node(arm, k) + a, node(arm, k) + a)] = s.diag[i];
                            f[node(arm, k) + a] = s.force[i][a];
                            dense[(node(arm, k) + a, l)] = s.l_column[i][a];
                            dense[(l, node(arm, k) + a)] = s.l_column[i][a];
                            if k + 1 < nodes {
                                dense[(node(arm, k) + a, node(arm, k + 1) + a)] = s.off[i];
                                dense[(node(arm, k + 1) + a, node(arm, k) + a)] = s.off[i];
                            }
                        }
                    }
                    s.node_effector[arm] = 0.2 * next();
                    s.effector_l[arm] = Vector3::new(next(), next(), next()) * 0.1;
                    s.border[arm] = [3.0, 0.3 * next(), 1.5, next(), next()];
                    for a in 0..3 {
                        if nodes > 0 {
                            let last = node(arm, nodes - 1) + a;
                            dense[(last, p0 + a)] = s.node_effector[arm];
                            dense[(p0 + a, last)] = s.node_effector[arm];
                        }
                        dense[(p0 + a, l)] = s.effector_l[arm][a];
                        dense[(l, p0 + a)] = s.effector_l[arm][a];
                    }
                    let [ll, lr, rr, fl, fr] = s.border[arm];
                    dense[(l, l)] = ll;
                    dense[(l, r)] = lr;
                    dense[(r, l)] = lr;
                    dense[(r, r)] = rr;
                    f[l] = fl;
                    f[r] = fr;
                }
                let expected = dense.clone().lu().solve(&f).unwrap();
                let mut nodes_acc = vec![Vector3::zeros(); arms * nodes];
                let mut p_acc = Vector3::zeros();
                let mut border = vec![[0.0; 2]; arms];
                assert!(s.solve(&mut nodes_acc, &mut p_acc, &mut border));
                let scale = expected.amax();
                let mut worst = 0.0f64;
                for arm in 0..arms {
                    for k in 0..nodes {
                        for a in 0..3 {
                            let e = expected[node(arm, k) + a];
                            worst = worst.max((nodes_acc[arm * nodes + k][a] - e).abs());
                        }
                    }
                    worst = worst.max((border[arm][0] - expected[b0 + 2 * arm]).abs());
                    worst = worst.max((border[arm][1] - expected[b0 + 2 * arm + 1]).abs());
                }
                for a in 0..3 {
                    worst = worst.max((p_acc[a] - expected[p0 + a]).abs());
                }
                assert!(worst <= 1e-12 * scale, "{arms} arms × {nodes}: {worst:e}");
            }
        }
    }
}
