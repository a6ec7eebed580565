//! The FE model's second-order form for the implicit integrator (MODELS.md FE.9.3):
//! R = M(q) q'' − F(q, q', T) summed element by element (the span elements in lanes,
//! [`crate::lanes`]), and the
//! iteration matrix S = ∂R/∂q'' + c_v ∂R/∂q' + c_q ∂R/∂q element by element.
//!
//! Why element by element: the rows l_i are dense (every node of a span feeds its length's
//! equation), so colouring the columns of the global matrix would need one residual per column,
//! O(N²) per matrix. Each element's contribution, though, depends only on its own unknowns
//! (r_a, r_b, l for a free element; ρ, l for the stored one), so differentiating the element kernel
//! ([`element::residual_at_chord`], the one R sums, the axial damping of FE.5.7 included) in its
//! 5 local unknowns and adding the 5 × 5 blocks gives the exact
//! global pattern of FE.5.5 (block-tridiagonal with the border rows and columns) at O(N) cost.
//! Central differences with δ = ε^(1/3)·max(|u|, 1e-2) are accurate to ~1e-10 relative (as in
//! [`cdpr_numerics::differences::ColouredDifferences`]), the position steps kept within a quarter
//! of the element's stretch ([`cdpr_numerics::differences::central_step`]); the derivative in q''
//! is linear and exact. The quotients are kept, so that a new step size re-weighs them
//! ([`cdpr_numerics::MatrixParts`]) instead of differencing again.

use crate::element::{self, Chord, ElementState};
use crate::{Fe, TOWARD_REEL};
use cdpr_core::second_order::{MatrixCost, SecondOrderForm, spring_round_off};
use cdpr_numerics::differences::central_step;
use cdpr_numerics::matrix_parts::{MatrixParts, weighted_entry};
use nalgebra::Vector2;

/// One additive block of R: an element, the rigid stored cable or the effector.
#[derive(Debug, Clone, Copy)]
enum Block {
    /// Free element e (1…N) of a cable: local (x_a, z_a, x_b, z_b, l).
    Free { cable: usize, e: usize },
    /// The elastic stored element: local (ρ, l).
    Stored { cable: usize },
    /// The rigid stored cable: local (l).
    Rigid { cable: usize },
    /// The effector's own mass and weight: local (x_P, z_P).
    Effector,
}

/// Local unknowns of a block (at most 5) and their global indices (None: a fixed pulley node).
type LocalDofs = [Option<usize>; 5];

impl Fe {
    fn blocks(&self) -> Vec<Block> {
        let mut blocks = Vec::with_capacity(2 * self.elements + 3);
        for cable in 0..2 {
            blocks.extend((1..=self.elements).map(|e| Block::Free { cable, e }));
            blocks.push(match self.rho_index(cable) {
                Some(_) => Block::Stored { cable },
                None => Block::Rigid { cable },
            });
        }
        blocks.push(Block::Effector);
        blocks
    }

    fn block_dofs(&self, block: Block) -> (LocalDofs, usize) {
        let nn = self.chain_nodes();
        match block {
            Block::Free { cable, e } => {
                let ja = self.chain_index(cable, e - 1);
                let jb = self.chain_index(cable, e);
                (
                    [
                        ja,
                        ja.map(|j| nn + j),
                        jb,
                        jb.map(|j| nn + j),
                        Some(self.l_index(cable)),
                    ],
                    5,
                )
            }
            Block::Stored { cable } => (
                [
                    self.rho_index(cable),
                    Some(self.l_index(cable)),
                    None,
                    None,
                    None,
                ],
                2,
            ),
            Block::Rigid { cable } => ([Some(self.l_index(cable)), None, None, None, None], 1),
            Block::Effector => {
                let p = self.effector_index();
                ([Some(p), Some(nn + p), None, None, None], 2)
            }
        }
    }

    /// Largest finite-difference step over which the block's forces are smooth in its positions
    /// (see [`cdpr_numerics::differences::ColouredDifferences`]): a quarter of the element's
    /// |stretch| = ||Δ| − h|, so no probe reaches the tension-only kink (at N = 1000 the stretch
    /// is 2.8–4.5e-7 m, below the 6e-6 m a step scaled by the coordinate would take). A change δ of l
    /// moves h by δ/N (δ for the stored element), so the same limit is safe for l.
    fn block_step_limit(&self, block: Block, q: &[f64; 5]) -> f64 {
        match block {
            Block::Free { .. } => {
                let h = q[4] / self.elements as f64;
                0.25 * ((q[2] - q[0]).hypot(q[3] - q[1]) - h).abs()
            }
            Block::Stored { .. } => 0.25 * (q[0] - (self.modelled_length - q[1])).abs(),
            Block::Rigid { .. } | Block::Effector => f64::INFINITY,
        }
    }

    /// The block's part of R (tension terms left out: they do not depend on the unknowns) for
    /// local positions `q`, velocities `v`, accelerations `a`.
    fn block_residual(&self, block: Block, q: &[f64; 5], v: &[f64; 5], a: &[f64; 5]) -> [f64; 5] {
        let mat = &self.material;
        let mut r = [0.0; 5];
        match block {
            Block::Free { cable: _, e } => {
                let n = self.elements as f64;
                let s = ElementState::new(
                    (Vector2::new(q[0], q[1]), Vector2::new(v[0], v[1])),
                    (Vector2::new(q[2], q[3]), Vector2::new(v[2], v[3])),
                    v[4],
                    q[4] / n,
                    1.0 / n,
                );
                let (ra, rb, rl) = element::residual_at_chord(
                    mat,
                    &self.coefficients[e - 1],
                    &s,
                    self.axial_damping,
                    Chord::of(&s),
                    Vector2::new(a[0], a[1]),
                    Vector2::new(a[2], a[3]),
                    a[4],
                );
                r.copy_from_slice(&[ra.x, ra.y, rb.x, rb.y, rl]);
            }
            Block::Stored { cable } => {
                let e_out = Vector2::new(TOWARD_REEL[cable], 0.0);
                let pulley = self.pulley(cable);
                let s = ElementState::new(
                    (pulley + e_out * q[0], e_out * v[0]),
                    (pulley, Vector2::zeros()),
                    v[1],
                    self.modelled_length - q[1],
                    -1.0,
                );
                [r[0], r[1]] = self.stored_rows(cable, &s, a[0], a[1]);
            }
            Block::Rigid { .. } => r[0] = self.rigid_stored_row(q[0], v[0], a[0]),
            Block::Effector => [r[0], r[1]] = self.effector_rows(a[0], a[1]),
        }
        r
    }

    /// Row l of R from the rigid stored cable, T_s = ½ μ (L0 − l) l'² (tension left out), at l,
    /// l', l'' [N].
    #[inline(always)]
    fn rigid_stored_row(&self, l: f64, l_rate: f64, l_acceleration: f64) -> f64 {
        let mu = self.material.mu;
        mu * (self.modelled_length - l) * l_acceleration - 0.5 * mu * l_rate * l_rate
    }

    /// Rows (x_P, z_P) of R from the effector's own mass and weight at P'' = (a_x, a_z) [N].
    #[inline(always)]
    fn effector_rows(&self, a_x: f64, a_z: f64) -> [f64; 2] {
        [
            self.effector_mass * a_x,
            self.effector_mass * (a_z + self.material.gravity),
        ]
    }

    /// Rows (ρ, l) of R from the elastic stored element `s` of `cable` (R = A + ρ e_out), at
    /// ρ'' = `a_rho`, l'' = `a_l`: the kernel's R-node terms projected on e_out (tension left out).
    #[inline(always)]
    fn stored_rows(&self, cable: usize, s: &ElementState, a_rho: f64, a_l: f64) -> [f64; 2] {
        let e_out = Vector2::new(TOWARD_REEL[cable], 0.0);
        let (r_reel, _, r_l) = element::residual_at_chord(
            &self.material,
            &self.stored_coefficients,
            s,
            self.axial_damping,
            Chord::of(s),
            e_out * a_rho,
            Vector2::zeros(),
            a_l,
        );
        [r_reel.dot(&e_out), r_l]
    }

    /// The block's local unknowns from the global state; a fixed pulley node sits at A_i at rest.
    fn gather(&self, block: Block, dofs: &LocalDofs, state: &[f64], qdd: &[f64]) -> [[f64; 5]; 3] {
        let np = self.positions_len();
        let mut local = [[0.0; 5]; 3];
        for (k, dof) in dofs.iter().enumerate() {
            match dof {
                Some(g) => {
                    local[0][k] = state[*g];
                    local[1][k] = state[np + g];
                    local[2][k] = qdd[*g];
                }
                None => {
                    if let (Block::Free { cable, .. }, 0 | 1) = (block, k) {
                        local[0][k] = self.pulley(cable)[k];
                    }
                }
            }
        }
        local
    }

    /// The difference quotients of `block` at (state, qdd): `numerators[k][row][col]` over
    /// `widths[k][col]` is ∂R_row/∂u_col for u = q, q', q'' (k = 0, 1, 2), taken where `needed[k]`.
    fn block_differences(
        &self,
        block: Block,
        (dofs, len): (&LocalDofs, usize),
        (state, qdd): (&[f64], &[f64]),
        needed: [bool; 3],
    ) -> BlockDifferences {
        let [q, v, a] = self.gather(block, dofs, state, qdd);
        let base = self.block_residual(block, &q, &v, &a);
        let limit = self.block_step_limit(block, &q);
        let mut d = BlockDifferences {
            numerators: [[[0.0; 5]; 5]; 3],
            widths: [[1.0; 5]; 3],
        };
        for col in 0..len {
            if dofs[col].is_none() {
                continue;
            }
            for which in (0..3).filter(|&k| needed[k]) {
                // q'': linear, one forward difference is exact; q', q: central.
                let x = [q, v, a][which][col];
                let (plus, minus, width) = if which == 2 {
                    let mut u = [q, v, a];
                    u[which][col] = x + x.abs().max(1.0);
                    let width = u[which][col] - x;
                    (self.block_residual(block, &u[0], &u[1], &u[2]), base, width)
                } else {
                    let step = central_step(x, if which == 0 { limit } else { f64::INFINITY });
                    let (mut up, mut down) = ([q, v, a], [q, v, a]);
                    up[which][col] = x + step;
                    down[which][col] = x - step;
                    (
                        self.block_residual(block, &up[0], &up[1], &up[2]),
                        self.block_residual(block, &down[0], &down[1], &down[2]),
                        up[which][col] - down[which][col],
                    )
                };
                for row in 0..len {
                    d.numerators[which][row][col] = plus[row] - minus[row];
                }
                d.widths[which][col] = width;
            }
        }
        d
    }

    /// Visits every block's quotients ([`Self::block_differences`]) with the index, in the order
    /// of [`SecondOrderForm::iteration_pattern`], of each entry it contributes.
    fn for_each_entry(
        &self,
        (state, qdd): (&[f64], &[f64]),
        needed: [bool; 3],
        mut entry: impl FnMut(usize, [f64; 3], [f64; 3]),
    ) {
        let mut at = 0;
        for block in self.blocks() {
            let (dofs, len) = self.block_dofs(block);
            let d = self.block_differences(block, (&dofs, len), (state, qdd), needed);
            for row in (0..len).filter(|&row| dofs[row].is_some()) {
                for col in (0..len).filter(|&col| dofs[col].is_some()) {
                    let numerators = [0, 1, 2].map(|k| d.numerators[k][row][col]);
                    let widths = [0, 1, 2].map(|k| d.widths[k][col]);
                    entry(at, numerators, widths);
                    at += 1;
                }
            }
        }
    }

    /// w_q ∂R/∂q + w_v ∂R/∂q' + w_a ∂R/∂q'' (weights `[w_q, w_v, w_a]`) at (state, qdd), block by
    /// block in the order of [`SecondOrderForm::iteration_pattern`] (duplicates summed by the
    /// caller): the iteration matrix S, and with weights [1, 0, 0] the static stiffness.
    pub(crate) fn block_matrix(
        &self,
        state: &[f64],
        qdd: &[f64],
        weights: [f64; 3],
        values: &mut [f64],
    ) {
        let needed = weights.map(|w| w != 0.0);
        self.for_each_entry((state, qdd), needed, |at, numerators, widths| {
            values[at] = weighted_entry(weights, numerators, widths);
        });
    }

    /// Every entry's three quotients into `parts` (see [`MatrixParts`]), `entries` of them (the
    /// pattern's length).
    fn block_parts(&self, state: &[f64], qdd: &[f64], entries: usize, parts: &mut MatrixParts) {
        parts.start(entries);
        self.for_each_entry((state, qdd), [true; 3], |at, numerators, widths| {
            parts.set(at, numerators, widths);
        });
        parts.finish();
    }
}

/// One block's difference quotients ([`Fe::block_differences`]).
struct BlockDifferences {
    numerators: [[[f64; 5]; 5]; 3],
    widths: [[f64; 5]; 3],
}

impl SecondOrderForm for Fe {
    fn dofs(&self) -> usize {
        self.positions_len()
    }

    fn effector_coordinate(&self, k: usize) -> usize {
        self.effector_index() + k * self.chain_nodes()
    }

    /// T_i pulls the reel end (row ρ_i), or the rigid stored cable through l_i.
    fn tension_rows(&self) -> Vec<usize> {
        (0..2)
            .map(|c| self.rho_index(c).unwrap_or(self.l_index(c)))
            .collect()
    }

    fn iteration_pattern(&self) -> Vec<(usize, usize)> {
        let mut pattern = Vec::new();
        for block in self.blocks() {
            let (dofs, len) = self.block_dofs(block);
            for row in dofs[..len].iter().flatten() {
                for col in dofs[..len].iter().flatten() {
                    pattern.push((*row, *col));
                }
            }
        }
        pattern
    }

    /// The stiffest element, EA/h with h = min l_i / N, sets the round-off of the forces (the
    /// stored element, EA/(L0 − l), would be stiffer only if L0 − l < l/N, outside the paper's
    /// workspace).
    fn residual_round_off(&self, state: &[f64]) -> f64 {
        let shortest = (0..2)
            .map(|cable| state[self.l_index(cable)] / self.elements as f64)
            .fold(f64::INFINITY, f64::min);
        spring_round_off(self.material.ea / shortest, &state[..self.positions_len()])
    }

    /// The l_i: every node of their span depends on them (at N = 10 their 20-odd entries stay
    /// below the sparse LU's density limit for a border of its own).
    fn coupled_unknowns(&self) -> Vec<usize> {
        vec![self.l_index(0), self.l_index(1)]
    }

    /// Per coordinate, the smallest [`Fe::block_step_limit`] of the blocks it belongs to (a node:
    /// its two elements; l_i: every element of its span; ρ_i: the stored element).
    fn smooth_reach(&self, state: &[f64], out: &mut [f64]) {
        out.fill(f64::INFINITY);
        for block in self.blocks() {
            let (dofs, len) = self.block_dofs(block);
            // Only the positions are used: `state` stands in for q'' (no buffer to allocate).
            let [q, _, _] = self.gather(block, &dofs, state, state);
            let limit = self.block_step_limit(block, &q);
            for dof in dofs[..len].iter().flatten() {
                out[*dof] = out[*dof].min(limit);
            }
        }
    }

    /// R = M q'' − F summed element by element: the span elements' rows
    /// ([`element::residual_at_chord`]) computed in lanes ([`crate::lanes::ChainRows`]) and
    /// summed here in span order, then the stored cables, the effector and the commanded
    /// tensions. Why not M q'' from the assembled system: scattering M into the block form,
    /// clearing it and multiplying it out again is a second pass over every node that the
    /// residual does not need (FE implicit paper run 0.1436 → 0.1420 s). The rows collected
    /// before they are summed and the lanes took it from 0.124 to 0.097 s (docs/performance.md).
    fn residual(&mut self, state: &[f64], qdd: &[f64], tensions: &[f64], r: &mut [f64]) {
        let tensions = [tensions[0], tensions[1]];
        let (n, nn, np) = (self.elements, self.chain_nodes(), self.positions_len());
        r.fill(0.0);
        let spans = [self.span_of(state, 0), self.span_of(state, 1)];
        let l_accelerations = [0, 1].map(|cable| qdd[self.l_index(cable)]);
        // The chain's x and z coordinates of a vector in q's layout (FE.5.1).
        fn halves(v: &[f64], nn: usize) -> [&[f64]; 2] {
            [&v[..nn], &v[nn..2 * nn]]
        }
        self.chain_rows.evaluate(
            &self.material,
            self.axial_damping,
            [&spans[0], &spans[1]],
            l_accelerations,
            [self.pulley(0), self.pulley(1)],
            halves(state, nn),
            halves(&state[np..], nn),
            halves(qdd, nn),
        );
        let rows = &self.chain_rows;
        let p = self.effector_index();
        for (cable, tension) in tensions.into_iter().enumerate() {
            let li = self.l_index(cable);
            // Elements 1 … N in span order. Node k's rows are element k's r_b plus element
            // k + 1's r_a: r_b waits in a register for its partner instead of a store and a
            // reload, so each row is written once. Element 1's r_a is the fixed pulley's.
            let (mut pending, mut l_row) = (Vector2::zeros(), 0.0);
            for e in 1..=n {
                let i = rows.element(cable, e);
                if let Some(ja) = self.chain_index(cable, e - 1) {
                    let row = pending + Vector2::new(rows.a_x[i], rows.a_z[i]);
                    r[ja] = row.x;
                    r[nn + ja] = row.y;
                }
                pending = Vector2::new(rows.b_x[i], rows.b_z[i]);
                l_row += rows.l[i];
            }
            // Element N's r_b: the effector's rows, which both spans and the effector add to.
            r[p] += pending.x;
            r[nn + p] += pending.y;
            r[li] += l_row;
            // The stored cable; T_i pulls the reel end (F_ρ = +T_i) or, rigid, does the virtual
            // work −T_i δl_i.
            match (self.rho_index(cable), self.stored_element(state, cable)) {
                (Some(rho), Some(s)) => {
                    let rows = self.stored_rows(cable, &s, qdd[rho], qdd[li]);
                    r[rho] += rows[0] - tension;
                    r[li] += rows[1];
                }
                (None, None) => {
                    r[li] += self.rigid_stored_row(state[li], state[np + li], qdd[li]) + tension;
                }
                _ => unreachable!("ρ_i and the stored element exist together"),
            }
        }
        let [r_x, r_z] = self.effector_rows(qdd[p], qdd[nn + p]);
        r[p] += r_x;
        r[nn + p] += r_z;
    }

    fn iteration_matrix(
        &mut self,
        state: &[f64],
        qdd: &[f64],
        _tensions: &[f64],
        c_v: f64,
        c_q: f64,
        values: &mut [f64],
    ) -> MatrixCost {
        // The quotients kept for a later step size ([`Self::reweighted_matrix`]); weighed as
        // `block_matrix` weighs them as it takes them, so S is the same to the bit.
        let mut parts = std::mem::take(&mut self.matrix_parts);
        self.block_parts(state, qdd, values.len(), &mut parts);
        parts.weigh([c_q, c_v, 1.0], values);
        self.matrix_parts = parts;
        // Element-local differences, no full residual: one base and 5 × (1 + 2 + 2) probes per
        // block, the cost of about 26 residual sweeps, which is the refresh rule's price.
        MatrixCost::without_residuals(26)
    }

    fn reweighted_matrix(&self, c_v: f64, c_q: f64, values: &mut [f64]) -> bool {
        self.matrix_parts.weigh([c_q, c_v, 1.0], values)
    }
}
