//! The lumped model's second-order form for the implicit integrator (MODELS.md §6):
//! R = diag(m) q'' − F(q, q', T), with F the spring, gravity and reel forces of [`Lumped::forces`]
//! (a stored node's vertical force is the constraint's business: its row reads m z'' = 0, so it
//! stays on z = 0 exactly). The iteration matrix is diag(m) plus, for undamped springs (the
//! paper's run), the springs' analytic tangent stiffness (~2 µs against ~7 µs for the 18
//! residual evaluations of coloured central differences, which remain for damped springs and as
//! the test's reference). Its pattern is the chain's: every node couples only to its two
//! neighbours along its cable (the straddling spring included: its ends are neighbours too), the
//! effector to the last node of each cable.
//! The pattern does not depend on which nodes are stored, so pulley events never change it.

use crate::Lumped;
use crate::damped::{AtPulley, SpringBlocks, damped_blocks, undamped_blocks};
use cdpr_core::second_order::{MatrixCost, SecondOrderForm, spring_round_off};
use cdpr_numerics::differences::ColouredDifferences;

/// Buffers of the second-order form (allocated once per model).
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct ImplicitScratch {
    forces: Vec<f64>,
    differences: Option<ColouredDifferences>,
}

/// The refresh rule's price of an analytic lumped matrix, in Newton iterations beyond one per
/// step ([`MatrixCost::refresh_price`]). A refresh (matrix ~2 µs, factorisation ~7 µs) costs
/// about 9 iterations (~1.05 µs each with the paired solve), but buys few: the lumped matrix
/// ages within a step (see the refresh rule in `generalized_alpha.rs`), so iterations per step
/// stay near 2 however often it is refreshed. Paper run (N = 40, one sample per step), price
/// → refreshes, iterations, time: 4 → 9 191, 103 269, 0.372 s; 16 → 4 533, 109 066, 0.318 s;
/// 32 → 3 285, 111 295, 0.302 s; 48 → 2 843, 113 284, 0.299 s; 64 → 2 596, 114 636, 0.297 s;
/// 128 → 2 254, 120 387, 0.302 s; never (slow contraction only) → 1 915, 137 237, 0.324 s.
/// Between 16 and 48 a refresh saved 2.5 iterations, between 64 and 128 it saved 17: the
/// break-even (~8) lies between, and the time is flat (±1 %) from 32 to 128. At N = 100 and 300
/// (5 s runs) prices 16 … 64 differ by less than this host's noise (±5 %).
const TANGENT_REFRESH_PRICE: u64 = 48;

impl Lumped {
    /// Coordinates (x, z indices) of node j of `cable` (the effector at j = N).
    fn coordinates(&self, cable: usize, j: usize) -> [usize; 2] {
        [self.x_index(cable, j), self.z_index(cable, j)]
    }

    /// Index into [`SecondOrderForm::iteration_pattern`] of entry (row `r`, column `c`; 0 = x,
    /// 1 = z) of the block coupling node `row` to node `col` of `cable` (adjacent or equal; the
    /// effector is node N). The pattern lists, per spring j (nodes j, j + 1), 12 entries: for
    /// each coordinate of node j, its two entries with node j, then (j, j + 1) and (j + 1, j)
    /// pairs; after both cables, the effector's own 2 × 2 block.
    fn pattern_index(&self, cable: usize, row: usize, col: usize, r: usize, c: usize) -> usize {
        let n = self.elements;
        let slot = |j: usize| 12 * (cable * n + j);
        if row == col {
            if row == n {
                24 * n + 2 * r + c
            } else {
                slot(row) + 6 * r + c
            }
        } else if col == row + 1 {
            slot(row) + 6 * r + 2 + 2 * c
        } else {
            debug_assert_eq!(row, col + 1);
            slot(col) + 6 * c + 3 + 2 * r
        }
    }

    /// diag(m) in the order of [`SecondOrderForm::iteration_pattern`] (every other entry 0).
    pub(crate) fn mass_matrix_into(&self, values: &mut [f64]) {
        let n = self.elements;
        values.fill(0.0);
        for cable in 0..2 {
            for j in 0..n {
                for r in 0..2 {
                    values[self.pattern_index(cable, j, j, r, r)] = self.node_mass;
                }
            }
        }
        for r in 0..2 {
            values[self.pattern_index(0, n, n, r, r)] = self.effector_mass;
        }
    }

    /// S = diag(m) − c_q ∂F/∂q for undamped springs, analytically, into `values` (pattern
    /// order). A taut chord spring (u = (b − a)/λ, T = k (λ − l0)) pulls a with T u, whose
    /// derivative in b is K = k u uᵀ + (T/λ)(I − u uᵀ) (in a: −K; b's force the opposite). The
    /// straddling spring (λ = |P − a| + |P − b|, eq. 4) pulls each end towards the pulley,
    /// F_a = T u_a: ∂F_a/∂a = −k u_a u_aᵀ − (T/|P − a|)(I − u_a u_aᵀ), ∂F_a/∂b = −k u_a u_bᵀ. A
    /// slack spring adds nothing; a stored node's z row is its mass alone (MODELS.md §4: the
    /// constraint holds it on z = 0). False (values unusable) where a straddling end sits exactly
    /// at its pulley (no direction there).
    ///
    /// With `damping` c = C/l0 ≠ 0 (the implicit path's damped springs; the statics pass 0 and
    /// keep the undamped blocks to the bit), T = k s + c λ̇ and the blocks gain the rate's
    /// position dependence and c_v ∂F/∂q' ([`crate::damped`]).
    pub(crate) fn tangent_matrix(
        &self,
        state: &[f64],
        (c_v, c_q): (f64, f64),
        damping: f64,
        values: &mut [f64],
    ) -> bool {
        let n = self.elements;
        self.mass_matrix_into(values);
        let (k, l0) = (self.stiffness, self.segment);
        for cable in 0..2 {
            let stored = self.stored[cable];
            for j in 0..n {
                let pulley = (j + 1 == stored).then(|| self.pulley(cable));
                let blocks = if damping != 0.0 {
                    let ends = [j, j + 1].map(|k| {
                        (
                            self.node(state, cable, k),
                            self.node_velocity(state, cable, k),
                        )
                    });
                    damped_blocks(ends, pulley, (k, l0, damping))
                } else {
                    let ends = (self.node(state, cable, j), self.node(state, cable, j + 1));
                    undamped_blocks(ends, pulley, (k, l0))
                };
                match blocks {
                    Ok(Some(blocks)) => self.add_blocks(cable, j, &blocks, (c_v, c_q), values),
                    Ok(None) => {}
                    Err(AtPulley) => return false,
                }
            }
        }
        true
    }

    /// Subtracts c_q times the position blocks and c_v times the rate blocks (a damped
    /// spring's) of spring j of `cable` from S, a stored node's z row left to its mass.
    fn add_blocks(
        &self,
        cable: usize,
        j: usize,
        blocks: &SpringBlocks<2>,
        (c_v, c_q): (f64, f64),
        values: &mut [f64],
    ) {
        let stored = self.stored[cable];
        for (k, (row, col)) in [(j, j), (j, j + 1), (j + 1, j), (j + 1, j + 1)]
            .into_iter()
            .enumerate()
        {
            for r in 0..2 {
                if r == 1 && row < stored {
                    continue;
                }
                for c in 0..2 {
                    let entry = &mut values[self.pattern_index(cable, row, col, r, c)];
                    let position = blocks.position[k][(r, c)];
                    match &blocks.rate {
                        None => *entry -= c_q * position,
                        Some(rate) => *entry -= c_q * position + c_v * rate[k][(r, c)],
                    }
                }
            }
        }
    }

    fn residual_into(&mut self, state: &[f64], qdd: &[f64], tensions: &[f64], r: &mut [f64]) {
        let n = self.elements;
        let mut f = std::mem::take(&mut self.implicit.forces);
        f.resize(self.positions_len(), 0.0);
        self.forces(state, tensions, &mut f);
        let m = self.node_mass;
        for i in 0..4 * n {
            r[i] = m * qdd[i] - f[i];
        }
        for i in 4 * n..4 * n + 2 {
            r[i] = self.effector_mass * qdd[i] - f[i];
        }
        self.implicit.forces = f;
    }
}

impl Lumped {
    /// Index of the effector's x among q.
    pub fn effector_x(&self) -> usize {
        self.x_index(0, self.elements)
    }

    /// Index of the effector's z among q.
    pub fn effector_z(&self) -> usize {
        self.z_index(0, self.elements)
    }
}

impl SecondOrderForm for Lumped {
    fn dofs(&self) -> usize {
        self.positions_len()
    }

    fn effector_coordinate(&self, k: usize) -> usize {
        if k == 0 {
            self.effector_x()
        } else {
            self.effector_z()
        }
    }
    /// The commanded tension pulls the reel end P_0 along e_out (horizontal).
    fn tension_rows(&self) -> Vec<usize> {
        vec![self.x_index(0, 0), self.x_index(1, 0)]
    }

    fn iteration_pattern(&self) -> Vec<(usize, usize)> {
        let n = self.elements;
        let mut pattern = Vec::with_capacity(2 * n * 12 + 4);
        for cable in 0..2 {
            for j in 0..n {
                // Node j with itself and with node j + 1 (the effector after the last), both ways.
                let a = self.coordinates(cable, j);
                let b = self.coordinates(cable, j + 1);
                for &ra in &a {
                    for &ca in &a {
                        pattern.push((ra, ca));
                    }
                    for &cb in &b {
                        pattern.push((ra, cb));
                        pattern.push((cb, ra));
                    }
                }
            }
        }
        let p = self.coordinates(0, n);
        for &rp in &p {
            for &cp in &p {
                pattern.push((rp, cp));
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

    /// Per position coordinate, the largest finite-difference step over which its forces are
    /// smooth (see [`ColouredDifferences`]): a quarter of the smallest |λ − l0| of the springs at
    /// its node (no probe reaches the tension-only kink; a probe moves a spring's length by at
    /// most the step) and, at the straddling spring's two ends, ε^(1/3) of the node's distance d
    /// to the pulley (the path's direction turns on the scale d: truncation (δ/d)² ≈ 4e-11).
    fn smooth_reach(&self, state: &[f64], out: &mut [f64]) {
        let n = self.elements;
        out.fill(f64::INFINITY);
        for cable in 0..2 {
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
                    for i in self.coordinates(cable, node) {
                        out[i] = out[i].min(limit);
                    }
                }
            }
        }
    }

    /// Analytic ([`Lumped::tangent_matrix`], damped springs' rate terms included); coloured
    /// central differences of the residual where a straddling spring's end sits exactly at its
    /// pulley.
    fn iteration_matrix(
        &mut self,
        state: &[f64],
        qdd: &[f64],
        tensions: &[f64],
        c_v: f64,
        c_q: f64,
        values: &mut [f64],
    ) -> MatrixCost {
        if self.tangent_matrix(state, (c_v, c_q), self.damping, values) {
            return MatrixCost::without_residuals(TANGENT_REFRESH_PRICE);
        }
        self.differenced_matrix(state, qdd, tensions, c_v, c_q, values)
    }
}

impl Lumped {
    /// S by coloured central differences of the residual (any damping).
    fn differenced_matrix(
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
                let mut mass = vec![self.node_mass; self.dofs()];
                mass[4 * self.elements..].fill(self.effector_mass);
                ColouredDifferences::new(self.dofs(), &self.iteration_pattern())
                    .with_diagonal_mass(&mass)
            }
        };
        self.smooth_reach(state, differences.step_limits_mut());
        // Undamped springs (the paper's run) pull with forces of the positions alone: ∂R/∂q' = 0,
        // and differencing it would cost two residuals per column group for zeros.
        let c_v = if self.damping == 0.0 { 0.0 } else { c_v };
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Params;
    use cdpr_core::model::{CableModel, SplitRule};
    use cdpr_core::scenario::Scenario;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(24))]

        /// The analytic matrix against the model's own coloured central differences, at static
        /// equilibria whose free nodes are shaken by up to 3e-5 m (twice the springs' stretch
        /// of ~1.4e-5 m, so some go slack; the differences' steps stay within a quarter of each
        /// stretch and never cross the kink), over the weights c_q of h = 1e-5 … 1e-3 s. The
        /// differences' truncation is (δ/λ)² ≈ 6e-8 of an entry (δ ≤ 6e-6 m, λ ≈ l0 = 2.5e-2
        /// m). Compared on the stiffness part c_q ∂F/∂q alone (the masses, up to the effector's
        /// 1 kg, would swamp it at small c_q): a missing geometric term T/λ ≈ 4e3 N/m is ~6e-4
        /// of the axial k = 7.2e6 N/m there, so 1e-6 of that part separates it from truncation.
        #[test]
        fn tangent_matrix_matches_coloured_differences(
            x in 0.42f64..0.62,
            shake in 0.0f64..3e-5,
            seed in 0u32..1000,
            h in 1e-5f64..1e-3,
        ) {
            let s = Scenario::paper();
            let mut model = Lumped::new(&s, Params::default()).unwrap();
            let eq = model.equilibrium(&SplitRule::new(x, s.controller.tension_sum)).unwrap();
            let mut state = eq.state.clone();
            let n = model.elements;
            for cable in 0..2 {
                for j in 0..n {
                    let phase = f64::from(seed) + (cable * n + j) as f64;
                    state[model.x_index(cable, j)] += shake * (1.7 * phase).sin();
                    if j >= model.stored[cable] {
                        state[model.z_index(cable, j)] += shake * (2.3 * phase).cos();
                    }
                }
            }
            let c_q = 0.3 * h * h;
            let dofs = model.dofs();
            let qdd = vec![0.0; dofs];
            let len = model.iteration_pattern().len();
            let (mut analytic, mut differenced) = (vec![0.0; len], vec![0.0; len]);
            prop_assert!(model.tangent_matrix(&state, (0.0, c_q), 0.0, &mut analytic));
            model.differenced_matrix(&state, &qdd, &[100.0, 100.0], 0.0, c_q, &mut differenced);
            let mut masses = vec![0.0; len];
            prop_assert!(model.tangent_matrix(&state, (0.0, 0.0), 0.0, &mut masses));
            let scale = differenced
                .iter()
                .zip(&masses)
                .fold(0.0f64, |m, (v, mass)| m.max((v - mass).abs()));
            for (i, (a, d)) in analytic.iter().zip(&differenced).enumerate() {
                prop_assert!((a - d).abs() <= 1e-6 * scale, "entry {}: {:e} vs {:e} (scale {:e})", i, a, d, scale);
            }
        }

        /// The damped springs' analytic matrix (the printer example's C = 8.5 N s on the
        /// paper's line) against the coloured differences of the same damped model, at
        /// equilibria shaken as above with every node moving at up to `speed` (stored nodes
        /// along the reel line only), with c_v = γh and c_q = βh²: S − diag(m) to 1e-6 of its
        /// largest entry. The differences' steps keep off the damping's clip, T/k away.
        #[test]
        fn damped_tangent_matrix_matches_coloured_differences(
            x in 0.42f64..0.62,
            shake in 0.0f64..3e-5,
            speed in 0.0f64..0.05,
            seed in 0u32..1000,
            h in 1e-5f64..1e-3,
        ) {
            let mut s = Scenario::paper();
            s.cable.axial_damping = 8.5;
            let mut model = Lumped::new(&s, Params::default()).unwrap();
            let eq = model.equilibrium(&SplitRule::new(x, s.controller.tension_sum)).unwrap();
            let mut state = eq.state.clone();
            let (n, np) = (model.elements, model.positions_len());
            for cable in 0..2 {
                for j in 0..n {
                    let phase = f64::from(seed) + (cable * n + j) as f64;
                    let (ix, iz) = (model.x_index(cable, j), model.z_index(cable, j));
                    state[ix] += shake * (1.7 * phase).sin();
                    state[np + ix] = speed * (2.9 * phase).sin();
                    if j >= model.stored[cable] {
                        state[iz] += shake * (2.3 * phase).cos();
                        state[np + iz] = speed * (3.1 * phase).cos();
                    }
                }
            }
            let (c_v, c_q) = (0.6 * h, 0.3 * h * h);
            let qdd = vec![0.0; model.dofs()];
            let len = model.iteration_pattern().len();
            let (mut analytic, mut differenced, mut masses) = (vec![0.0; len], vec![0.0; len], vec![0.0; len]);
            let damping = model.damping;
            prop_assert!(model.tangent_matrix(&state, (c_v, c_q), damping, &mut analytic));
            model.differenced_matrix(&state, &qdd, &[100.0, 100.0], c_v, c_q, &mut differenced);
            prop_assert!(model.tangent_matrix(&state, (0.0, 0.0), damping, &mut masses));
            let scale = differenced
                .iter()
                .zip(&masses)
                .fold(0.0f64, |m, (v, mass)| m.max((v - mass).abs()));
            prop_assert!(scale > 0.0);
            for (i, (a, d)) in analytic.iter().zip(&differenced).enumerate() {
                prop_assert!((a - d).abs() <= 1e-6 * scale, "entry {}: {:e} vs {:e} (scale {:e})", i, a, d, scale);
            }
        }
    }
}
