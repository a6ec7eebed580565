//! The lumped model's second-order form for the implicit integrator (MODELS.md §6):
//! R = diag(m) q'' − F(q, q', T), with F the spring, gravity and reel forces of [`Lumped::forces`]
//! (a stored node's vertical force is the constraint's business: its row reads m z'' = 0, so it
//! stays on z = 0 exactly). The iteration matrix is diag(m), written exactly, plus coloured
//! finite differences of F over the chain's pattern: every node couples only to its two
//! neighbours along its cable (the straddling spring included: its ends are neighbours too), the
//! effector to the last node of each cable.
//! The pattern does not depend on which nodes are stored, so pulley events never change it.

use crate::Lumped;
use cdpr_core::second_order::{
    CBRT_EPSILON, ColouredDifferences, MatrixCost, SecondOrderForm, spring_round_off,
};

/// Buffers of the second-order form (allocated once per model).
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct ImplicitScratch {
    forces: Vec<f64>,
    differences: Option<ColouredDifferences>,
}

impl Lumped {
    /// Coordinates (x, z indices) of node j of `cable` (the effector at j = N).
    fn coordinates(&self, cable: usize, j: usize) -> [usize; 2] {
        [self.xi(cable, j), self.zi(cable, j)]
    }

    fn residual_into(&mut self, state: &[f64], qdd: &[f64], tensions: [f64; 2], r: &mut [f64]) {
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

impl SecondOrderForm for Lumped {
    fn dofs(&self) -> usize {
        self.positions_len()
    }

    fn effector_x(&self) -> usize {
        self.xi(0, self.elements)
    }

    /// The commanded tension pulls the reel end P_0 along e_out (horizontal).
    fn tension_rows(&self) -> Vec<usize> {
        vec![self.xi(0, 0), self.xi(1, 0)]
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

    fn residual(&mut self, state: &[f64], qdd: &[f64], tensions: [f64; 2], r: &mut [f64]) {
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
                let length = self.spring_length(state, cable, j);
                let mut limit = 0.25 * (length - self.segment).abs();
                if j + 1 == r {
                    let pulley = self.pulley(cable);
                    for node in [j, j + 1] {
                        let d = (self.node(state, cable, node) - pulley).norm();
                        limit = limit.min(CBRT_EPSILON * d);
                    }
                }
                for node in [j, j + 1] {
                    for i in self.coordinates(cable, node) {
                        out[i] = out[i].min(limit);
                    }
                }
            }
        }
    }

    fn iteration_matrix(
        &mut self,
        state: &[f64],
        qdd: &[f64],
        tensions: [f64; 2],
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
