//! The analytic iteration matrix of the spatial lumped lines, S = diag(m) − c_v ∂F/∂q' −
//! c_q ∂F/∂q (MODELS.md §6), spring by spring: each spring's end forces F_a, F_b (a = P_j,
//! b = P_{j+1}) differentiated by its end positions (and velocities, for damped springs:
//! [`crate::damped`]), each block's rows projected as the node's forces are. Undamped springs
//! keep the planar model's blocks in 3-D: a taut chord's K = k u uᵀ + (T/λ)(I − u uᵀ); the
//! straddling spring's ∂F_a/∂a = −k u_a u_aᵀ − (T/|A − a|)(I − u_a u_aᵀ), ∂F_a/∂b = −k u_a u_bᵀ.

use super::LumpedSpatial;
use crate::damped::{AtPulley, SpringBlocks, damped_blocks, undamped_blocks};
use nalgebra::Matrix3;

impl LumpedSpatial {
    /// S into `values` (the iteration pattern's order). False where a straddling end sits
    /// exactly at its pulley (the caller then differences the residual).
    pub(super) fn tangent_matrix(
        &self,
        state: &[f64],
        c_v: f64,
        c_q: f64,
        values: &mut [f64],
    ) -> bool {
        let n = self.elements;
        self.mass_matrix_into(values);
        for cable in 0..self.robot.cables() {
            // The stored rows' projection (the same for every stored node of the cable); a free
            // node's and the effector's rows are taken as they are (I B is B, bit for bit).
            let stored = self.stored[cable];
            let projection = self.row_projection(cable, 0);
            let project = |row: usize, block: &Matrix3<f64>| {
                if row < stored {
                    projection * block
                } else {
                    *block
                }
            };
            for j in 0..n {
                let blocks = match self.spring_blocks(state, cable, j) {
                    Ok(Some(blocks)) => blocks,
                    Ok(None) => continue,
                    Err(AtPulley) => return false,
                };
                let pairs = [(j, j), (j, j + 1), (j + 1, j), (j + 1, j + 1)];
                for (k, (row, col)) in pairs.into_iter().enumerate() {
                    let projected = project(row, &blocks.position[k]);
                    let damped = blocks.rate.as_ref().map(|rate| project(row, &rate[k]));
                    // The block's nine entries are consecutive, row by row.
                    let block = &mut values[self.pattern_index(cable, row, col, 0, 0)..][..9];
                    for r in 0..3 {
                        for c in 0..3 {
                            let entry = &mut block[3 * r + c];
                            *entry -= c_q * projected[(r, c)];
                            if let Some(damped) = &damped {
                                *entry -= c_v * damped[(r, c)];
                            }
                        }
                    }
                }
            }
        }
        true
    }

    /// The derivatives of spring j of `cable` (None while it pulls nothing).
    fn spring_blocks(
        &self,
        state: &[f64],
        cable: usize,
        j: usize,
    ) -> Result<Option<SpringBlocks<3>>, AtPulley> {
        let pulley = (j + 1 == self.stored[cable]).then(|| self.pulley(cable));
        if self.damping == 0.0 {
            let ends = (self.node(state, cable, j), self.node(state, cable, j + 1));
            return undamped_blocks(ends, pulley, (self.stiffness, self.segment));
        }
        let ends = [j, j + 1].map(|k| {
            (
                self.node(state, cable, k),
                self.node_velocity(state, cable, k),
            )
        });
        damped_blocks(ends, pulley, (self.stiffness, self.segment, self.damping))
    }
}
