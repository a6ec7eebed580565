//! The free elements' blocks of the iteration matrix in lanes: [`super::blocks`]' differencing
//! of the element kernel in each block's 7 local unknowns (r_a, r_b, l_i), every free element of
//! every arm at once. One probe — a local unknown of one kind (position, velocity or
//! acceleration) moved in every element by that element's own step — is one evaluation of the
//! kernel in lanes ([`super::lanes::Rows::evaluate`]); each element's step, width and
//! differences are the scalar [`FeSpatial::local_matrix`]'s, in its order, so every block is
//! its matrix bit for bit (a test below checks it).
//!
//! Why: a matrix differences its m N free elements 36 times each; one element at a time that
//! is the iteration matrix's largest cost, and the kernel's vector width sits idle.

use super::FeSpatial;
use super::lanes::{Coefficients, Inputs, Length, Rows};
use cdpr_numerics::differences::central_step;

/// A block's weighted derivative matrix, local[row][col].
pub(super) type LocalMatrix = [[f64; 7]; 7];

/// Local unknowns of every free element: node a's and node b's positions, velocities and
/// accelerations (x, y, z each), then l, l', l''.
const COLUMNS: usize = 21;

/// The free elements' local unknowns, probes and matrices (allocated once), element i =
/// cable N + e − 1.
#[derive(Debug, Clone, PartialEq, Default)]
pub(super) struct BlockLanes {
    coefficients: Coefficients,
    base: Vec<Vec<f64>>,
    /// Each element's smooth reach (the position steps' limit), probe and width.
    limit: Vec<f64>,
    up: Vec<f64>,
    down: Vec<f64>,
    width: Vec<f64>,
    rows_base: Rows,
    rows_up: Rows,
    rows_down: Rows,
    pub matrices: Vec<LocalMatrix>,
}

/// Where local unknown `col` (0 … 6) of kind `which` (0: q, 1: q', 2: q'') sits in the columns.
fn column(which: usize, col: usize) -> usize {
    match col {
        0..3 => 3 * which + col,
        3..6 => 9 + 3 * which + col - 3,
        _ => 18 + which,
    }
}

impl BlockLanes {
    fn new(model: &FeSpatial) -> Self {
        let (m, n) = (model.robot.cables(), model.elements);
        let len = m * n;
        let per_element = (0..len).map(|i| (&model.coefficients[i % n], Length::Free(n)));
        Self {
            coefficients: Coefficients::new(per_element),
            base: vec![vec![0.0; len]; COLUMNS],
            limit: vec![0.0; len],
            up: vec![0.0; len],
            down: vec![0.0; len],
            width: vec![0.0; len],
            rows_base: Rows::new(len),
            rows_up: Rows::new(len),
            rows_down: Rows::new(len),
            matrices: vec![[[0.0; 7]; 7]; len],
        }
    }

    /// The kernel's inputs: the base columns, column `moved` (if any) replaced by `by`.
    fn inputs<'a>(base: &'a [Vec<f64>], moved: Option<(usize, &'a [f64])>) -> Inputs<'a> {
        let pick = |k: usize| match moved {
            Some((c, by)) if c == k => by,
            _ => &base[k][..],
        };
        Inputs {
            a: std::array::from_fn(pick),
            b: std::array::from_fn(|k| pick(9 + k)),
            l: pick(18),
            l_rate: pick(19),
            l_acceleration: pick(20),
        }
    }
}

impl FeSpatial {
    /// w_q ∂R/∂q + w_v ∂R/∂q' + w_a ∂R/∂q'' of every free element's block at (state, qdd)
    /// (`weights` = [w_q, w_v, w_a]) into the lanes' `matrices`, as
    /// [`FeSpatial::local_matrix`] differences each block.
    pub(super) fn free_block_matrices(&mut self, state: &[f64], qdd: &[f64], weights: [f64; 3]) {
        let mut lanes = std::mem::take(&mut self.block_lanes);
        if lanes.matrices.is_empty() {
            lanes = BlockLanes::new(self);
        }
        self.gather_free_blocks(&mut lanes, state, qdd);
        let (mat, damping) = (self.material, self.axial_damping);
        let k = &lanes.coefficients;
        lanes
            .rows_base
            .evaluate(k, &mat, damping, &BlockLanes::inputs(&lanes.base, None));
        lanes.matrices.fill([[0.0; 7]; 7]);
        for col in 0..7 {
            for (which, weight) in weights.into_iter().enumerate() {
                if weight == 0.0 {
                    continue;
                }
                let c = column(which, col);
                let x = &lanes.base[c];
                let central = which != 2;
                for (i, &x) in x.iter().enumerate() {
                    if central {
                        let limit = if which == 0 {
                            lanes.limit[i]
                        } else {
                            f64::INFINITY
                        };
                        let step = central_step(x, limit);
                        lanes.up[i] = x + step;
                        lanes.down[i] = x - step;
                        lanes.width[i] = lanes.up[i] - lanes.down[i];
                    } else {
                        lanes.up[i] = x + x.abs().max(1.0);
                        lanes.width[i] = lanes.up[i] - x;
                    }
                }
                let up = BlockLanes::inputs(&lanes.base, Some((c, &lanes.up)));
                lanes.rows_up.evaluate(k, &mat, damping, &up);
                if central {
                    let down = BlockLanes::inputs(&lanes.base, Some((c, &lanes.down)));
                    lanes.rows_down.evaluate(k, &mat, damping, &down);
                }
                let minus = if central {
                    &lanes.rows_down
                } else {
                    &lanes.rows_base
                };
                for (i, matrix) in lanes.matrices.iter_mut().enumerate() {
                    let (plus, minus) = (lanes.rows_up.local(i), minus.local(i));
                    for row in 0..7 {
                        matrix[row][col] += weight * (plus[row] - minus[row]) / lanes.width[i];
                    }
                }
            }
        }
        self.block_lanes = lanes;
    }

    /// Each free element's local unknowns (its pulley node at rest for e = 1) and smooth reach.
    fn gather_free_blocks(&self, lanes: &mut BlockLanes, state: &[f64], qdd: &[f64]) {
        let (n, np) = (self.elements, self.positions_len());
        let sources = [&state[..np], &state[np..], qdd];
        for cable in 0..self.robot.cables() {
            let li = self.l_index(cable);
            for e in 1..=n {
                let i = cable * n + e - 1;
                let b = if e == n {
                    self.effector_index(0)
                } else {
                    self.node_index(cable, e, 0)
                };
                for (q, source) in sources.iter().enumerate() {
                    for axis in 0..3 {
                        lanes.base[3 * q + axis][i] = if e > 1 {
                            source[self.node_index(cable, e - 1, axis)]
                        } else if q == 0 {
                            self.pulley(cable)[axis]
                        } else {
                            0.0
                        };
                        lanes.base[9 + 3 * q + axis][i] = source[b + axis];
                    }
                    lanes.base[18 + q][i] = source[li];
                }
                lanes.limit[i] = self.element_reach(&self.free_element(state, cable, e));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::blocks::Block;
    use super::*;
    use crate::element::Material;
    use crate::params::FeMass;
    use cdpr_core::robot::Robot;
    use nalgebra::Vector3;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Every free element's block from the lanes is the scalar differencing's
        /// (`local_matrix`) bit for bit, on 3 … 8 cables of N = 1 … 9 elements, at random
        /// states around straight spans (nodes moved by up to 1 cm, random rates and
        /// accelerations), damped or not, lumped or consistent mass, over random weights (one
        /// of them 0 at times: its probes are skipped in both).
        #[test]
        fn lanes_blocks_are_the_scalar_blocks_bit_for_bit(
            cables in 3usize..9,
            n in 1usize..10,
            lumped in any::<bool>(),
            damped in any::<bool>(),
            w_q in prop_oneof![Just(0.0), 1e-8f64..1e-6],
            w_v in 1e-5f64..1e-3,
            values in prop::collection::vec(-1.0f64..1.0, 64),
        ) {
            let weights = [w_q, w_v, 1.0];
            let value = |k: usize| values[k % values.len()];
            let anchors: Vec<Vector3<f64>> = (0..cables)
                .map(|c| {
                    let t = std::f64::consts::TAU * c as f64 / cables as f64;
                    Vector3::new(1.5 * t.cos(), 1.5 * t.sin(), if c % 2 == 0 { 2.0 } else { -0.1 })
                })
                .collect();
            let robot = Robot::new(&anchors, 1.0, 9.81).unwrap();
            let reels = vec![Vector3::new(0.0, 0.0, 1.0); cables];
            let mass = if lumped { FeMass::Lumped } else { FeMass::Consistent };
            let material = Material { ea: 2.0e4, mu: 1.0e-3, gravity: 9.81 };
            let damping = if damped { 8.5 } else { 0.0 };
            let mut model = FeSpatial::new(robot, reels, mass, n, 4.0, material, damping);
            let np = model.positions_len();
            let mut state = vec![0.0; 2 * np];
            let p = Vector3::new(0.1 * value(0), 0.1 * value(1), 0.5 + 0.1 * value(2));
            for cable in 0..cables {
                let a = model.pulley(cable);
                for k in 1..n {
                    let at = a + (p - a) * (k as f64 / n as f64);
                    for axis in 0..3 {
                        state[model.node_index(cable, k, axis)] = at[axis] + 0.01 * value(3 * k + axis + cable);
                    }
                }
                let li = model.l_index(cable);
                state[li] = (p - a).norm() * (1.0 - 1e-3 * (1.0 + value(cable)));
                state[li + 1] = 0.5;
            }
            for axis in 0..3 {
                state[model.effector_index(axis)] = p[axis];
            }
            for (k, v) in state[np..].iter_mut().enumerate() {
                *v = 0.05 * value(k + 7);
            }
            let qdd: Vec<f64> = (0..np).map(|k| value(k + 11)).collect();
            model.free_block_matrices(&state, &qdd, weights);
            for cable in 0..cables {
                for e in 1..=n {
                    let block = Block::Free { cable, e };
                    let (dofs, len) = model.block_dofs(block);
                    let local = model.gather(block, &dofs, &state, &qdd);
                    let scalar = model.local_matrix(block, &dofs[..len], &local, weights);
                    let lanes = model.block_lanes.matrices[cable * n + e - 1];
                    for row in (0..7).filter(|&r| dofs[r].is_some()) {
                        for col in (0..7).filter(|&c| dofs[c].is_some()) {
                            prop_assert_eq!(
                                lanes[row][col].to_bits(), scalar[row][col].to_bits(),
                                "cable {} element {} entry ({}, {}): {:e} vs {:e}",
                                cable, e, row, col, lanes[row][col], scalar[row][col]
                            );
                        }
                    }
                }
            }
        }
    }
}
