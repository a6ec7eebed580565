//! The spatial FE robot's second-order form R = M(q) q'' − F(q, q', T) for the implicit path
//! (MODELS.md FE.9.3): R summed from the element rows in lanes ([`super::lanes`]; the tests'
//! reference: R vanishing at the star solve's q'' = M⁻¹F), the iteration matrix element by
//! element ([`super::blocks`], [`super::block_lanes`]; the tests' reference: coloured central
//! differences of R over the star's pattern, [`ColouredDifferences`]), each position
//! step kept within a quarter of the stretch of the elements it moves so that no
//! probe reaches the tension-only kink.

use super::FeSpatial;
use crate::element::{self, ElementState};
use cdpr_core::second_order::{MatrixCost, SecondOrderForm, spring_round_off};
use cdpr_numerics::differences::ColouredDifferences;

impl FeSpatial {
    /// How far an element's ends may move with its forces smooth: a quarter of its |stretch|
    /// ||Δ| − h| (the tension-only kink), and with axial damping, while it stretches or
    /// shortens, of h |EA ε + C ε'|/EA (the damping's clip at N = 0; at rest that is the
    /// stretch itself, so rests are unchanged). A change δ of l moves h by δ/N (δ for the
    /// stored element), so the same reach is safe for l.
    pub(super) fn element_reach(&self, s: &ElementState<3>) -> f64 {
        let stretch = (s.rb - s.ra).norm() - s.h;
        let mut reach = 0.25 * stretch.abs();
        if self.axial_damping != 0.0 && stretch > 0.0 {
            let rate = element::strain_rate(s);
            if rate != 0.0 {
                let ea = self.material.ea;
                let pull = ea * stretch / s.h + self.axial_damping * rate;
                reach = reach.min(0.25 * s.h * (pull / ea).abs());
            }
        }
        reach
    }

    /// Every coordinate element e of `cable` moves: its end nodes' (those that are free or
    /// the effector) and l_i.
    fn element_dofs(&self, cable: usize, e: usize) -> Vec<usize> {
        let mut dofs = Vec::with_capacity(7);
        for k in [e - 1, e] {
            if k == self.elements {
                dofs.extend((0..3).map(|a| self.effector_index(a)));
            } else if k > 0 {
                dofs.extend((0..3).map(|a| self.node_index(cable, k, a)));
            }
        }
        dofs.push(self.l_index(cable));
        dofs
    }
}

impl SecondOrderForm for FeSpatial {
    fn dofs(&self) -> usize {
        self.positions_len()
    }

    fn effector_coordinate(&self, k: usize) -> usize {
        self.effector_index(k)
    }

    /// The ρ_i rows, where the reels pull.
    fn tension_rows(&self) -> Vec<usize> {
        (0..self.robot.cables())
            .map(|c| self.l_index(c) + 1)
            .collect()
    }

    /// Per element every pair of its coordinates; per stored element (l_i, ρ_i).
    fn iteration_pattern(&self) -> Vec<(usize, usize)> {
        let mut pattern = Vec::new();
        for cable in 0..self.robot.cables() {
            for e in 1..=self.elements {
                let dofs = self.element_dofs(cable, e);
                for &r in &dofs {
                    pattern.extend(dofs.iter().map(|&c| (r, c)));
                }
            }
            let (l, rho) = (self.l_index(cable), self.l_index(cable) + 1);
            pattern.extend([(l, l), (l, rho), (rho, l), (rho, rho)]);
        }
        pattern.sort_unstable();
        pattern.dedup();
        pattern
    }

    /// The l_i (every node of their span depends on them) and the effector (every span ends
    /// there): the star's hub, as the explicit solve's globals.
    fn coupled_unknowns(&self) -> Vec<usize> {
        let mut hub: Vec<usize> = (0..3).map(|a| self.effector_index(a)).collect();
        hub.extend((0..self.robot.cables()).map(|c| self.l_index(c)));
        hub
    }

    /// The stiffest element, EA/h with h = min l_i / N.
    fn residual_round_off(&self, state: &[f64]) -> f64 {
        let shortest = (0..self.robot.cables())
            .map(|c| state[self.l_index(c)] / self.elements as f64)
            .fold(f64::INFINITY, f64::min);
        spring_round_off(self.material.ea / shortest, &state[..self.positions_len()])
    }

    /// Per coordinate, the smallest smooth reach ([`FeSpatial::element_reach`]) of the elements
    /// it moves (ρ_i: the stored element's).
    fn smooth_reach(&self, state: &[f64], out: &mut [f64]) {
        out.fill(f64::INFINITY);
        for cable in 0..self.robot.cables() {
            for e in 1..=self.elements {
                let limit = self.element_reach(&self.free_element(state, cable, e));
                for d in self.element_dofs(cable, e) {
                    out[d] = out[d].min(limit);
                }
            }
            let limit = self.element_reach(&self.stored_element(state, cable));
            let (l, rho) = (self.l_index(cable), self.l_index(cable) + 1);
            out[l] = out[l].min(limit);
            out[rho] = out[rho].min(limit);
        }
    }

    /// Driven by length, the residual's l_i rows read l_i'' = the command (Du's form).
    fn follows_driven_reels(&self) -> bool {
        true
    }

    fn residual(&mut self, state: &[f64], qdd: &[f64], tensions: &[f64], r: &mut [f64]) {
        self.element_residual(state, qdd, tensions, r);
    }

    /// Element by element ([`super::blocks`]), under tension reels or, rewritten for Du's
    /// form, with the reels prescribing the lengths.
    fn iteration_matrix(
        &mut self,
        state: &[f64],
        qdd: &[f64],
        tensions: &[f64],
        c_v: f64,
        c_q: f64,
        values: &mut [f64],
    ) -> MatrixCost {
        if self.length_driven {
            self.driven_block_matrix(state, qdd, tensions, (c_v, c_q), values);
        } else {
            self.block_matrix(state, qdd, [c_q, c_v, 1.0], values);
        }
        // No full residual: per block one base and 7 × (1 + 2 + 2) kernel probes, the kernels
        // of about 36 residual sweeps.
        MatrixCost::without_residuals(REFRESH_PRICE).with_slow_contraction(KEPT_CONTRACTION)
    }
}

/// The refresh rule's price of an element-by-element matrix, in Newton iterations beyond one
/// per step: four times its cost of ~36 residual sweeps, because a refresh buys back less than
/// it costs. The matrix ages within a step or two wherever the lines move (see
/// [`KEPT_CONTRACTION`]), so the iterations it saves stop soon after it. Measured (criterion,
/// one sitting) at 36, 144 and 576: the cube layer 11 339, 6 226 and 5 680 matrices for 1.364,
/// 1.382 and 1.386 M residuals, 2.43, 2.35 and 2.36 s; the Hangprinter move 1 201, 313 and 81
/// factorisations for 152 838, 151 310 and 151 675 residuals.
const REFRESH_PRICE: u64 = 144;

/// How slowly Newton may contract on a kept element matrix before it is re-evaluated. The
/// matrix ages within one step wherever the lines' string motion turns the elements (the
/// axial stiffness EA/l along a direction that has moved): on the printed cube layer a matrix
/// one step old already needs 1.9 iterations per step against 1.02 fresh, and older ones 2.0,
/// with contractions of 0.01–0.1 per iteration. At the integrator's 0.05 half of all
/// refreshes only bought back the one step they were taken at. Measured (criterion, one
/// sitting): the cube layer on FE N = 10 took 2.96 s at 0.05, 2.66 s at 0.1, 2.55 s at 0.2,
/// 2.54 s at 0.5 (23 054, 14 519, 11 339, 10 824 matrices); the Hangprinter move 243, 234,
/// 232 ms (0.05, 0.2, 0.5); the move's first 0.5 s at N = 100 166.6, 164.1, 164.8 ms.
const KEPT_CONTRACTION: f64 = 0.2;

impl FeSpatial {
    /// S by coloured central differences of the whole residual (the element-by-element
    /// matrix's reference in the tests).
    pub fn differenced_matrix(
        &mut self,
        state: &[f64],
        qdd: &[f64],
        tensions: &[f64],
        c_v: f64,
        c_q: f64,
        values: &mut [f64],
    ) -> MatrixCost {
        let mut differences = match self.differences.take() {
            Some(d) => d,
            None => ColouredDifferences::new(self.positions_len(), &self.iteration_pattern()),
        };
        self.smooth_reach(state, differences.step_limits_mut());
        let evals = differences.fill(
            &mut |s, a, r| SecondOrderForm::residual(self, s, a, tensions, r),
            state,
            qdd,
            c_v,
            c_q,
            values,
        );
        self.differences = Some(differences);
        MatrixCost::differences(evals)
    }
}
