//! The spatial lumped model's second-order form for the implicit integrator (MODELS.md §6):
//! R = diag(m) q'' − F(q, q', T), F the forces of the right-hand side (a stored node's force
//! projected on its reel line r_i, so its rows across the line read m q''_⊥ = 0 and it stays on
//! the line; a locked reel end has none, so its rows read m q'' = 0). The iteration matrix is
//! diag(m) plus the springs' analytic tangent stiffness and damping ([`super::tangent`]),
//! coloured central differences where a straddling spring's end sits at its pulley and as the
//! tests' reference; a reel driven by length adds its velocity loop's ∂R/∂q' on the
//! stored nodes ([`super::reel`]). Its pattern is the chains': each node's 3 × 3 block couples only to its two
//! neighbours along its cable (the straddling spring's ends are neighbours too), the effector to
//! the last node of every cable — the star of m arms meeting at the effector. The pattern does
//! not depend on which nodes are stored, so pulley events never change it.

use super::LumpedSpatial;
use cdpr_core::model::CableModel;
use cdpr_core::second_order::{MatrixCost, SecondOrderForm, spring_round_off};
use cdpr_numerics::differences::ColouredDifferences;
use nalgebra::Matrix3;

/// The refresh rule's price of an analytic matrix, in Newton iterations (the planar lumped
/// model's, measured there: the time is flat within ±1 % from 32 to 128).
const TANGENT_REFRESH_PRICE: u64 = 48;

/// Buffers of the second-order form (allocated once per model).
#[derive(Debug, Clone, Default, PartialEq)]
pub(super) struct ImplicitScratch {
    forces: Vec<f64>,
    differences: Option<ColouredDifferences>,
}

impl LumpedSpatial {
    /// Index into [`SecondOrderForm::iteration_pattern`] of entry (row axis `r`, column axis
    /// `c`) of the block coupling node `row` to node `col` of `cable` (equal or adjacent; the
    /// effector is node N). Per cable and node j: its own block, then (j, j + 1), then
    /// (j + 1, j), 9 entries each; the effector's own block last.
    pub(super) fn pattern_index(
        &self,
        cable: usize,
        row: usize,
        col: usize,
        r: usize,
        c: usize,
    ) -> usize {
        let n = self.elements;
        let slot = |j: usize| 27 * (cable * n + j);
        let within = 3 * r + c;
        if row == col {
            if row == n {
                27 * self.robot().cables() * n + within
            } else {
                slot(row) + within
            }
        } else if col == row + 1 {
            slot(row) + 9 + within
        } else {
            debug_assert_eq!(row, col + 1);
            slot(col) + 18 + within
        }
    }

    /// diag(m) in the order of the iteration pattern.
    pub(super) fn mass_matrix_into(&self, values: &mut [f64]) {
        let n = self.elements;
        values.fill(0.0);
        for cable in 0..self.robot().cables() {
            for j in 0..n {
                for r in 0..3 {
                    values[self.pattern_index(cable, j, j, r, r)] = self.node_mass;
                }
            }
        }
        for r in 0..3 {
            values[self.pattern_index(0, n, n, r, r)] = self.robot().effector_mass;
        }
    }

    /// The projection of node `j`'s force rows: r_i r_iᵀ for a stored node, 0 for one on a
    /// locked reel, I for a free node.
    pub(super) fn row_projection(&self, cable: usize, j: usize) -> Matrix3<f64> {
        if j < self.stored[cable] && self.drive != super::reel::ReelDrive::Tension {
            Matrix3::zeros()
        } else if j < self.stored[cable] {
            let r = self.reels[cable];
            r * r.transpose()
        } else {
            Matrix3::identity()
        }
    }

    fn residual_into(&mut self, state: &[f64], qdd: &[f64], tensions: &[f64], r: &mut [f64]) {
        let np = self.positions_len();
        let mut f = std::mem::take(&mut self.implicit.forces);
        f.resize(np, 0.0);
        self.forces(state, tensions, &mut f);
        let cables = np - 3;
        let m = self.node_mass;
        for i in 0..cables {
            r[i] = m * qdd[i] - f[i];
        }
        for i in cables..np {
            r[i] = self.robot().effector_mass * qdd[i] - f[i];
        }
        self.implicit.forces = f;
    }

    /// Whether the reels move the stored lines by the velocity loop of [`super::reel`].
    fn reels_driven(&self) -> bool {
        matches!(self.drive, super::reel::ReelDrive::Length { .. })
    }

    /// A reel driven by length gives each stored node a_j = v̇_i + (v_i − q'_j·r_i)/τ along
    /// r_i, so c_v ∂R/∂q'_j = c_v m r_i r_iᵀ/τ on its own block (v_i's dependence on the
    /// straddling spring's stretch, c_q m l̇0 ∂λ/∂q /(τ l0), is ~1e-3 of the mass at h = 1e-4 s
    /// and stays out, as Newton allows).
    fn add_reel_loop(&self, c_v: f64, values: &mut [f64]) {
        if !self.reels_driven() {
            return;
        }
        let g = c_v * self.node_mass / super::reel::REEL_TIME_CONSTANT;
        for cable in 0..self.robot().cables() {
            let reel = self.reels[cable];
            for j in 0..self.stored[cable] {
                for r in 0..3 {
                    for c in 0..3 {
                        values[self.pattern_index(cable, j, j, r, c)] += g * reel[r] * reel[c];
                    }
                }
            }
        }
    }

    /// S by coloured central differences of the residual (any damping).
    pub fn differenced_matrix(
        &mut self,
        state: &[f64],
        qdd: &[f64],
        tensions: &[f64],
        c_v: f64,
        c_q: f64,
        values: &mut [f64],
    ) -> MatrixCost {
        let mut differences = match self.implicit.differences.take() {
            Some(d) => d,
            None => {
                let np = self.positions_len();
                let mut mass = vec![self.node_mass; np];
                mass[np - 3..].fill(self.robot().effector_mass);
                ColouredDifferences::new(np, &self.iteration_pattern()).with_diagonal_mass(&mass)
            }
        };
        self.smooth_reach(state, differences.step_limits_mut());
        let c_v = if self.damping == 0.0 && !self.reels_driven() {
            0.0
        } else {
            c_v
        };
        let evals = differences.fill(
            &mut |s, a, r| self.residual_into(s, a, tensions, r),
            state,
            qdd,
            c_v,
            c_q,
            values,
        );
        self.implicit.differences = Some(differences);
        MatrixCost::differences(evals)
    }
}

impl SecondOrderForm for LumpedSpatial {
    fn dofs(&self) -> usize {
        self.positions_len()
    }

    fn effector_coordinate(&self, k: usize) -> usize {
        self.index(0, self.elements, k)
    }

    /// The commanded tension pulls each reel end P_0 along r_i: its three rows.
    fn tension_rows(&self) -> Vec<usize> {
        (0..self.robot().cables())
            .flat_map(|cable| (0..3).map(move |axis| (cable, axis)))
            .filter(|&(cable, axis)| self.reels[cable][axis] != 0.0)
            .map(|(cable, axis)| self.index(cable, 0, axis))
            .collect()
    }

    fn iteration_pattern(&self) -> Vec<(usize, usize)> {
        let n = self.elements;
        let m = self.robot().cables();
        let mut pattern = vec![(0, 0); 27 * m * n + 9];
        for cable in 0..m {
            for j in 0..n {
                for (row, col) in [(j, j), (j, j + 1), (j + 1, j)] {
                    for r in 0..3 {
                        for c in 0..3 {
                            pattern[self.pattern_index(cable, row, col, r, c)] =
                                (self.index(cable, row, r), self.index(cable, col, c));
                        }
                    }
                }
            }
        }
        for r in 0..3 {
            for c in 0..3 {
                pattern[self.pattern_index(0, n, n, r, c)] =
                    (self.index(0, n, r), self.index(0, n, c));
            }
        }
        pattern
    }

    fn residual(&mut self, state: &[f64], qdd: &[f64], tensions: &[f64], r: &mut [f64]) {
        self.residual_into(state, qdd, tensions, r);
    }

    fn residual_round_off(&self, state: &[f64]) -> f64 {
        spring_round_off(self.stiffness, &state[..self.positions_len()])
    }

    /// The stored nodes' rows are the reel's acceleration ([`super::reel`]) when driven.
    fn follows_driven_reels(&self) -> bool {
        true
    }

    /// As the planar model's: a quarter of the smallest |λ − l0| of the springs at a node (and of
    /// T/k0 for damped springs, whose clip at T = 0 moves with λ̇), and ε^(1/3) of the distance
    /// to the pulley at the straddling spring's ends.
    fn smooth_reach(&self, state: &[f64], out: &mut [f64]) {
        let n = self.elements;
        out.fill(f64::INFINITY);
        for cable in 0..self.robot().cables() {
            let r = self.stored[cable];
            for j in 0..n {
                let (length, rate) = if self.damping == 0.0 {
                    (self.spring_length(state, cable, j), 0.0)
                } else {
                    let (length, rate, _, _) = self.spring(state, cable, j);
                    (length, rate)
                };
                let spring = (self.stiffness, self.segment, self.damping);
                let straddle = (j + 1 == r).then(|| {
                    let ends = [j, j + 1].map(|node| self.node(state, cable, node));
                    (self.pulley(cable), ends)
                });
                let limit = crate::damped::chain_reach(spring, (length, rate), straddle);
                for node in [j, j + 1] {
                    for axis in 0..3 {
                        let i = self.index(cable, node, axis);
                        out[i] = out[i].min(limit);
                    }
                }
            }
        }
    }

    /// Analytic ([`super::tangent`]), or coloured central differences where a straddling
    /// spring's end sits exactly at its pulley.
    fn iteration_matrix(
        &mut self,
        state: &[f64],
        qdd: &[f64],
        tensions: &[f64],
        c_v: f64,
        c_q: f64,
        values: &mut [f64],
    ) -> MatrixCost {
        if self.tangent_matrix(state, c_v, c_q, values) {
            self.add_reel_loop(c_v, values);
            return MatrixCost::without_residuals(TANGENT_REFRESH_PRICE);
        }
        self.differenced_matrix(state, qdd, tensions, c_v, c_q, values)
    }
}
