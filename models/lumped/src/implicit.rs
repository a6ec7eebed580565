//! The lumped model's second-order form for the implicit integrator (MODELS.md §6):
//! R = diag(m) q'' − F(q, q', T), with F the spring, gravity and reel forces of [`Lumped::forces`]
//! (a stored node's vertical force is the constraint's business: its row reads m z'' = 0, so it
//! stays on z = 0 exactly). The iteration matrix comes from coloured finite differences over the
//! chain's pattern: every node couples only to its two neighbours along its cable (the straddling
//! spring included: its ends are neighbours too), the effector to the last node of each cable.
//! The pattern does not depend on which nodes are stored, so pulley events never change it.

use crate::Lumped;
use cdpr_core::second_order::{ColouredDifferences, SecondOrderForm};

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

    fn iteration_matrix(
        &mut self,
        state: &[f64],
        qdd: &[f64],
        tensions: [f64; 2],
        c_v: f64,
        c_q: f64,
        values: &mut [f64],
    ) -> u64 {
        let mut differences = match self.implicit.differences.take() {
            Some(d) => d,
            None => ColouredDifferences::new(self.dofs(), &self.iteration_pattern()),
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
        evals
    }
}
