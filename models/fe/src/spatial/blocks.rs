//! The spatial FE robot's iteration matrix S = ∂R/∂q'' + c_v ∂R/∂q' + c_q ∂R/∂q element by
//! element, as the planar model's (`crate::implicit`): R sums additive blocks — each free
//! element in its 7 local unknowns (r_a, r_b, l_i; r_a fixed at the pulley for e = 1), each
//! stored element in (ρ_i, l_i), the effector's own mass and weight in its 3 — so differencing
//! the element kernel ([`element::residual_at_chord`], the one R is summed from, axial damping
//! included) in its local unknowns and adding the blocks gives the global S at O(m N) kernel
//! calls. The free elements' blocks are differenced all at once in lanes
//! ([`super::block_lanes`]); the scalar [`FeSpatial::local_matrix`] differences the stored
//! elements' and the effector's, and is the lanes' reference in their test. Coloured
//! differences of the whole residual need one assembly per colour and, the l_i columns being
//! dense in their span, far more colours (242 residual sweeps per matrix at N = 10 with
//! damping, against ~36 sweeps' worth of kernels here). The commanded tensions enter R
//! linearly and drop out.

use super::FeSpatial;
use crate::element::{self, Chord, ElementState};
use cdpr_core::second_order::SecondOrderForm;
use cdpr_numerics::differences::central_step;
use nalgebra::Vector3;

/// Most local unknowns of a block (a free element's).
const LOCAL: usize = 7;

/// One additive block of R.
#[derive(Debug, Clone, Copy)]
pub(super) enum Block {
    /// Free element e (1 … N) of a cable: local (r_a, r_b, l).
    Free { cable: usize, e: usize },
    /// The stored element: local (ρ, l).
    Stored { cable: usize },
    /// The effector's own mass and weight: local (x, y, z).
    Effector,
}

/// Local unknowns of a block and their global indices (None: the fixed pulley node).
pub(super) type LocalDofs = [Option<usize>; LOCAL];

/// A block's local positions, velocities and accelerations.
pub(super) type Local = [[f64; LOCAL]; 3];

impl FeSpatial {
    fn blocks(&self) -> impl Iterator<Item = Block> + '_ {
        (0..self.robot.cables())
            .flat_map(|cable| {
                (1..=self.elements)
                    .map(move |e| Block::Free { cable, e })
                    .chain([Block::Stored { cable }])
            })
            .chain([Block::Effector])
    }

    pub(super) fn block_dofs(&self, block: Block) -> (LocalDofs, usize) {
        let mut dofs = [None; LOCAL];
        match block {
            Block::Free { cable, e } => {
                for axis in 0..3 {
                    dofs[axis] = (e > 1).then(|| self.node_index(cable, e - 1, axis));
                    dofs[3 + axis] = Some(if e == self.elements {
                        self.effector_index(axis)
                    } else {
                        self.node_index(cable, e, axis)
                    });
                }
                dofs[6] = Some(self.l_index(cable));
                (dofs, 7)
            }
            Block::Stored { cable } => {
                dofs[0] = Some(self.l_index(cable) + 1);
                dofs[1] = Some(self.l_index(cable));
                (dofs, 2)
            }
            Block::Effector => {
                for (axis, dof) in dofs.iter_mut().enumerate().take(3) {
                    *dof = Some(self.effector_index(axis));
                }
                (dofs, 3)
            }
        }
    }

    /// The block's local unknowns from the global state; the pulley node sits still at A_i.
    pub(super) fn gather(
        &self,
        block: Block,
        dofs: &LocalDofs,
        state: &[f64],
        qdd: &[f64],
    ) -> Local {
        let np = self.positions_len();
        let mut local = [[0.0; LOCAL]; 3];
        for (k, dof) in dofs.iter().enumerate() {
            match (dof, block) {
                (Some(g), _) => {
                    local[0][k] = state[*g];
                    local[1][k] = state[np + g];
                    local[2][k] = qdd[*g];
                }
                (None, Block::Free { cable, .. }) if k < 3 => {
                    local[0][k] = self.pulley(cable)[k];
                }
                (None, _) => {}
            }
        }
        local
    }

    /// Largest step over which the block's forces are smooth in its positions: its element's
    /// reach ([`FeSpatial::element_reach`]).
    fn block_step_limit(&self, block: Block, local: &Local) -> f64 {
        match block {
            Block::Free { .. } | Block::Stored { .. } => {
                self.element_reach(&self.block_element(block, local))
            }
            Block::Effector => f64::INFINITY,
        }
    }

    /// The element state of a free or stored block at its local unknowns.
    fn block_element(&self, block: Block, [q, v, _]: &Local) -> ElementState<3> {
        let vector = |x: &[f64; LOCAL], k: usize| Vector3::new(x[k], x[k + 1], x[k + 2]);
        match block {
            Block::Stored { cable } => {
                let (pulley, reel) = (self.pulley(cable), self.reels[cable]);
                ElementState::new(
                    (pulley + reel * q[0], reel * v[0]),
                    (pulley, Vector3::zeros()),
                    v[1],
                    self.modelled_length - q[1],
                    -1.0,
                )
            }
            _ => {
                let n = self.elements as f64;
                ElementState::new(
                    (vector(q, 0), vector(v, 0)),
                    (vector(q, 3), vector(v, 3)),
                    v[6],
                    q[6] / n,
                    1.0 / n,
                )
            }
        }
    }

    /// The block's part of R (the tensions left out: they do not depend on the unknowns).
    fn block_residual(&self, block: Block, local: &Local) -> [f64; LOCAL] {
        let a = &local[2];
        let vector = |x: &[f64; LOCAL], k: usize| Vector3::new(x[k], x[k + 1], x[k + 2]);
        let mut r = [0.0; LOCAL];
        match block {
            Block::Free { e, .. } => {
                let s = self.block_element(block, local);
                let (ra, rb, rl) = element::residual_at_chord(
                    &self.material,
                    &self.coefficients[e - 1],
                    &s,
                    self.axial_damping,
                    Chord::of(&s),
                    vector(a, 0),
                    vector(a, 3),
                    a[6],
                );
                r[..3].copy_from_slice(ra.as_slice());
                r[3..6].copy_from_slice(rb.as_slice());
                r[6] = rl;
            }
            Block::Stored { cable } => {
                let reel = self.reels[cable];
                let s = self.block_element(block, local);
                let (r_reel, _, r_l) = element::residual_at_chord(
                    &self.material,
                    &self.stored_coefficients,
                    &s,
                    self.axial_damping,
                    Chord::of(&s),
                    reel * a[0],
                    Vector3::zeros(),
                    a[1],
                );
                r[0] = r_reel.dot(&reel);
                r[1] = r_l;
            }
            Block::Effector => {
                let m = self.robot.effector_mass;
                r[0] = m * a[0];
                r[1] = m * a[1];
                r[2] = m * (a[2] + self.material.gravity);
            }
        }
        r
    }

    /// Where each block's (row, col) entries go in [`SecondOrderForm::iteration_pattern`],
    /// block after block, row-major over the block's present unknowns.
    fn block_slots(&self) -> Vec<usize> {
        let pattern = self.iteration_pattern();
        let mut slots = Vec::new();
        for block in self.blocks() {
            let (dofs, len) = self.block_dofs(block);
            for row in dofs[..len].iter().flatten() {
                for col in dofs[..len].iter().flatten() {
                    let slot = pattern.binary_search(&(*row, *col));
                    slots.push(slot.expect("a block's entry lies in the pattern"));
                }
            }
        }
        slots
    }

    /// w_q ∂R/∂q + w_v ∂R/∂q' + w_a ∂R/∂q'' (`weights` = [w_q, w_v, w_a]) at (state, qdd) into
    /// `values`, in the order of [`SecondOrderForm::iteration_pattern`]: central differences of
    /// the kernel in q and q' (steps as `ColouredDifferences`', positions within the block's
    /// smooth reach), one forward difference in q'' (R is linear in it).
    pub(super) fn block_matrix(
        &mut self,
        state: &[f64],
        qdd: &[f64],
        weights: [f64; 3],
        values: &mut [f64],
    ) {
        if self.block_slots.is_empty() {
            self.block_slots = self.block_slots();
        }
        self.free_block_matrices(state, qdd, weights);
        values.fill(0.0);
        let mut slots = self.block_slots.iter();
        for block in self.blocks() {
            let (dofs, len) = self.block_dofs(block);
            let matrix = match block {
                Block::Free { cable, e } => {
                    self.block_lanes.matrices[cable * self.elements + e - 1]
                }
                _ => {
                    let local = self.gather(block, &dofs, state, qdd);
                    self.local_matrix(block, &dofs[..len], &local, weights)
                }
            };
            for row in (0..len).filter(|&r| dofs[r].is_some()) {
                for col in (0..len).filter(|&c| dofs[c].is_some()) {
                    let slot = slots.next().expect("one slot per entry");
                    values[*slot] += matrix[row][col];
                }
            }
        }
    }

    /// The block's weighted derivative matrix local[row][col].
    pub(super) fn local_matrix(
        &self,
        block: Block,
        dofs: &[Option<usize>],
        local: &Local,
        weights: [f64; 3],
    ) -> [[f64; LOCAL]; LOCAL] {
        let base = self.block_residual(block, local);
        let limit = self.block_step_limit(block, local);
        let mut matrix = [[0.0; LOCAL]; LOCAL];
        for (col, dof) in dofs.iter().enumerate() {
            if dof.is_none() {
                continue;
            }
            for (which, weight) in weights.into_iter().enumerate() {
                if weight == 0.0 {
                    continue;
                }
                let x = local[which][col];
                let (plus, minus, width) = if which == 2 {
                    let mut up = *local;
                    up[which][col] = x + x.abs().max(1.0);
                    (self.block_residual(block, &up), base, up[which][col] - x)
                } else {
                    let step = central_step(x, if which == 0 { limit } else { f64::INFINITY });
                    let (mut up, mut down) = (*local, *local);
                    up[which][col] = x + step;
                    down[which][col] = x - step;
                    (
                        self.block_residual(block, &up),
                        self.block_residual(block, &down),
                        up[which][col] - down[which][col],
                    )
                };
                for row in 0..dofs.len() {
                    matrix[row][col] += weight * (plus[row] - minus[row]) / width;
                }
            }
        }
        matrix
    }
}

/// Where Du's form rewrites the element blocks' matrix ([`FeSpatial::driven_block_matrix`]),
/// found in the pattern once: the l_i columns of the node and effector rows in the order the
/// rewrite visits them, and in the (l_i, ρ_i) rows the l and ρ diagonals and every other entry;
/// and the accelerations' scratch.
#[derive(Debug, Clone, PartialEq, Default)]
pub(super) struct DrivenSlots {
    l_columns: Vec<usize>,
    l_diagonal: Vec<usize>,
    rho_diagonal: Vec<usize>,
    off_diagonal: Vec<usize>,
    commanded: Vec<f64>,
}

impl FeSpatial {
    /// [`DrivenSlots`] of this model's pattern.
    fn driven_slots(&self) -> DrivenSlots {
        let pattern = self.iteration_pattern();
        let slot = |row: usize, col: usize| {
            pattern
                .binary_search(&(row, col))
                .expect("an l column's entry lies in the pattern")
        };
        let mut slots = DrivenSlots::default();
        for cable in 0..self.robot.cables() {
            let l = self.l_index(cable);
            for k in 1..self.elements {
                slots
                    .l_columns
                    .extend((0..3).map(|axis| slot(self.node_index(cable, k, axis), l)));
            }
            slots
                .l_columns
                .extend((0..3).map(|axis| slot(self.effector_index(axis), l)));
        }
        // The (l_i, ρ_i) pairs are the last coordinates.
        let first = self.l_index(0);
        for (e, &(row, col)) in pattern.iter().enumerate().filter(|(_, rc)| rc.0 >= first) {
            match (col == row, (row - first).is_multiple_of(2)) {
                (false, _) => slots.off_diagonal.push(e),
                (true, true) => slots.l_diagonal.push(e),
                (true, false) => slots.rho_diagonal.push(e),
            }
        }
        slots
    }

    /// S of Du's form (reels driven by length, MODELS.md FE.5.6) from the element blocks. Its
    /// node and effector rows are the tension form's with l_i'' = a_i(l_i', t) = l̈0_i +
    /// (l̇0_i − l_i')/τ put in: ∂/∂q and ∂/∂q' are the blocks' at q''_l = a_i (M(q)'s l
    /// columns times a_i included), plus c_v ∂R/∂l_i'' ∂a_i/∂l_i' = −(c_v/τ) M_{k,l}; ∂/∂q''
    /// drops its l columns M_{k,l}. The l_i rows read l_i'' − a_i (S_ll = 1 + c_v/τ), the ρ_i
    /// rows ρ_i'' = 0 (the stored cable is on the reel).
    pub(super) fn driven_block_matrix(
        &mut self,
        state: &[f64],
        qdd: &[f64],
        tensions: &[f64],
        (c_v, c_q): (f64, f64),
        values: &mut [f64],
    ) {
        if self.driven_slots.l_columns.is_empty() {
            self.driven_slots = self.driven_slots();
        }
        let mut slots = std::mem::take(&mut self.driven_slots);
        slots.commanded.clear();
        slots.commanded.extend_from_slice(qdd);
        for cable in 0..self.robot.cables() {
            slots.commanded[self.l_index(cable)] = self.commanded_l_acceleration(state, cable);
        }
        self.block_matrix(state, &slots.commanded, [c_q, c_v, 1.0], values);
        let mut sys = std::mem::take(&mut self.system);
        self.assemble_into(&mut sys, state, tensions, false);
        let held = 1.0 + c_v / cdpr_core::robot::reels::REEL_TIME_CONSTANT;
        let nn = self.elements - 1;
        // M's l columns, in the order of `l_columns`: each cable's nodes, then the effector.
        let mut slot = slots.l_columns.iter();
        for cable in 0..self.robot.cables() {
            let effector = std::iter::once(&sys.effector_l[cable]);
            for coupling in sys.l_column[cable * nn..(cable + 1) * nn]
                .iter()
                .chain(effector)
            {
                for axis in 0..3 {
                    values[*slot.next().expect("a slot per coupling")] -= held * coupling[axis];
                }
            }
        }
        for (list, value) in [
            (&slots.l_diagonal, held),
            (&slots.rho_diagonal, 1.0),
            (&slots.off_diagonal, 0.0),
        ] {
            for &e in list {
                values[e] = value;
            }
        }
        self.system = sys;
        self.driven_slots = slots;
    }
}
