//! Static equilibrium of the FE model (MODELS.md FE.8.1): F(q, 0) = 0 with the effector's x held at
//! x_ref(0) and the PID force F0 an unknown, by the core's Newton service from the straight-chord
//! guess (nodes on the chords A_i → P, l_i = chord/(1 + T_i/EA), ρ_i = (L0 − l_i)(1 + T_i/EA)).
//!
//! Unknowns: every coordinate of q except the effector's x, then F0; equations: every row of F.
//! At rest the l-row says N_s(1 + ε_s/2) = Σ_e h'[N_e(1 + ε_e/2) − μ g z̄_e]: the pulley tension is
//! continuous, so the solution is the discrete version of the continuum CDPR of FE.8.3.

use crate::Fe;
use cdpr_core::model::{CableModel, Equilibrium, ModelError, RestRule};
use cdpr_core::second_order::SecondOrderForm;
use cdpr_core::statics;
use cdpr_numerics::newton::{self, NewtonOptions, StaticProblem};
use nalgebra::Vector2;

struct Problem<'a> {
    model: &'a mut Fe,
    effector_x: f64,
    rule: &'a dyn RestRule<2>,
    /// State being assembled (velocities stay zero).
    y: Vec<f64>,
    /// Indices in q of the length unknowns, in order (F0 is the last unknown).
    map: Vec<usize>,
    /// The Jacobian's pattern, from the model's second-order pattern over q, and per entry of
    /// that, its ∂R/∂q (Jacobian scratch).
    pattern: statics::StaticPattern,
    stiffness: Vec<f64>,
    /// Scratch of the Jacobian: q'' = 0 (at rest), the unknowns with F0 moved, and the residuals
    /// for F0's column.
    at_rest: Vec<f64>,
    moved: Vec<f64>,
    base: Vec<f64>,
    pulled: Vec<f64>,
}

impl Problem<'_> {
    fn tensions(&self, force: f64) -> [f64; 2] {
        let t = self.rule.tensions(&[force]);
        [t[0], t[1]]
    }

    fn load(&mut self, u: &[f64]) {
        for (k, &i) in self.map.iter().enumerate() {
            self.y[i] = u[k];
        }
        let p = self.model.effector_index();
        self.y[p] = self.effector_x;
    }
}

impl StaticProblem for Problem<'_> {
    fn dimension(&self) -> usize {
        self.map.len() + 1
    }
    fn length_unknowns(&self) -> usize {
        self.map.len()
    }
    /// The n rows of F(q, 0, T(F0)) [N].
    fn residual(&mut self, u: &[f64], r: &mut [f64]) {
        self.load(u);
        let tensions = self.tensions(u[self.map.len()]);
        self.model.assemble(&self.y, tensions);
        let s = &self.model.system;
        let nn = s.nodes;
        for j in 0..nn {
            r[j] = s.rhs[j][0];
            r[nn + j] = s.rhs[j][1];
        }
        r[2 * nn..2 * nn + s.border].copy_from_slice(&s.f_border[..s.border]);
    }
    /// The assembly's pattern (`SecondOrderForm::iteration_pattern`: node blocks and the l
    /// border) over the unknowns (every q but the effector's x, whose row is F0's equation).
    fn pattern(&self) -> Option<Vec<(usize, usize)>> {
        Some(self.pattern.entries.clone())
    }
    fn residual_round_off(&self) -> f64 {
        self.model.residual_round_off(&self.y)
    }
    /// Element by element ([`Fe::block_matrix`] with weights [1, 0, 0] at rest: ∂R/∂q of
    /// R = M q'' − F, and the residual here is F, so the entries change sign), in the order of
    /// [`Self::pattern`]: the model's entries it keeps ([`statics::StaticPattern::kept`]: all
    /// but the effector's x column), then F0's column, exact by one unit difference (F is affine in
    /// F0 through T_i = (ΣT ∓ F0)/2).
    fn jacobian(&mut self, u: &[f64], values: &mut [f64]) -> bool {
        self.load(u);
        self.model
            .block_matrix(&self.y, &self.at_rest, [1.0, 0.0, 0.0], &mut self.stiffness);
        let (stiffness, force_column) = values.split_at_mut(self.pattern.kept.len());
        for (value, &p) in stiffness.iter_mut().zip(&self.pattern.kept) {
            *value = -self.stiffness[p];
        }
        let force = self.map.len();
        let (mut base, mut pulled, mut moved) = (
            std::mem::take(&mut self.base),
            std::mem::take(&mut self.pulled),
            std::mem::take(&mut self.moved),
        );
        self.residual(u, &mut base);
        moved.copy_from_slice(u);
        moved[force] += 1.0;
        self.residual(&moved, &mut pulled);
        self.load(u);
        let rows = self.model.tension_rows();
        debug_assert_eq!(force_column.len(), rows.len());
        for (value, row) in force_column.iter_mut().zip(rows) {
            *value = pulled[row] - base[row];
        }
        (self.base, self.pulled, self.moved) = (base, pulled, moved);
        true
    }
    /// 1e-4 m for lengths: a 6e-10 m step, far inside an element's stretch (ε h = 2.8e-5 m at
    /// 100 N, h = 0.05 m; a step beyond it would slacken the element and corrupt the Jacobian)
    /// and moving the forces by EA/h·6e-10 ≈ 2e-3 N against a round-off of EA/h·ulp ≈ 4e-10 N.
    /// ΣT for F0, on which the residual is linear.
    fn scale(&self, i: usize) -> f64 {
        if i == self.map.len() {
            self.rule.scale(0)
        } else {
            1e-4
        }
    }
}

/// Equilibrium of MODELS.md §2 / FE.8.1 with the effector at x = `effector_x`.
pub(crate) fn equilibrium(
    model: &mut Fe,
    rule: &dyn RestRule<2>,
) -> Result<Equilibrium, ModelError> {
    let (mut problem, mut u) = problem(model, rule)?;
    let report = newton::solve(&mut problem, &mut u, NewtonOptions::default())?;
    problem.load(&u);
    let force = u[problem.map.len()];
    debug_assert_eq!(problem.y.len(), problem.model.state_len());
    Ok(Equilibrium {
        state: problem.y,
        parameters: vec![force],
        tensions: rule.tensions(&[force]),
        iterations: report.iterations,
        residual: report.residual,
    })
}

/// The static problem under `rule` (the effector's x pinned, one parameter: the paper's rule)
/// and its straight-chord guess (unknowns, F0 = 0 last).
fn problem<'a>(
    model: &'a mut Fe,
    rule: &'a dyn RestRule<2>,
) -> Result<(Problem<'a>, Vec<f64>), ModelError> {
    let (effector_x, tension_sum) =
        cdpr_core::model::planar_rest(rule, model.anchor_distance, "FE")?;
    let d = model.anchor_distance;
    let n = model.elements;
    let np = model.positions_len();
    let mat = model.material;
    // Massless-cable sag as the effector's starting depth; the cables' weight adds ~1 %.
    let weight = model.effector_mass * mat.gravity;
    let sag = -weight * effector_x * (d - effector_x) / (0.5 * tension_sum * d);
    let effector = Vector2::new(effector_x, sag);
    let stretch = 1.0 + 0.5 * tension_sum / mat.ea;
    let mut y = vec![0.0; 2 * np];
    for cable in 0..2 {
        let a = model.pulley(cable);
        for k in 1..=n {
            let j = model.chain_index(cable, k).expect("k ≥ 1");
            let p = a + (effector - a) * (k as f64 / n as f64);
            y[model.node_coordinate(j, 0)] = p.x;
            y[model.node_coordinate(j, 1)] = p.y;
        }
        let l = (effector - a).norm() / stretch;
        if l >= model.modelled_length {
            return Err(ModelError::Parameter {
                name: "cable.modelled_length",
                value: model.modelled_length,
                allowed: format!(
                    "> {l} m, the free span's unstrained length at x = {effector_x} m"
                ),
            });
        }
        y[model.l_index(cable)] = l;
        if let Some(r) = model.rho_index(cable) {
            y[r] = (model.modelled_length - l) * stretch;
        }
    }
    let p = model.effector_index();
    let map: Vec<usize> = (0..np).filter(|&i| i != p).collect();
    let mut u: Vec<f64> = map.iter().map(|&i| y[i]).collect();
    u.push(0.0);
    let dynamic = model.iteration_pattern();
    let unknowns = map.len() + 1;
    let pattern = statics::pattern_from_dynamics(
        &dynamic,
        Some,
        |j| (j != p).then(|| j - usize::from(j > p)),
        &model.tension_rows(),
        map.len(),
    );
    let problem = Problem {
        model,
        effector_x,
        rule,
        y,
        map,
        stiffness: vec![0.0; dynamic.len()],
        pattern,
        at_rest: vec![0.0; np],
        moved: vec![0.0; unknowns],
        base: vec![0.0; unknowns],
        pulled: vec![0.0; unknowns],
    };
    Ok((problem, u))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::{FeStored, Params};
    use cdpr_core::scenario::Scenario;
    use cdpr_numerics::differences::{CBRT_EPSILON, ColouredDifferences};

    /// The element-by-element static Jacobian against coloured central differences of the
    /// whole residual (the path it replaces), summed over duplicate entries, near the
    /// equilibrium of both stored-cable variants. Tolerance 1e-6 of the largest entry: the
    /// coloured steps (ε^(1/3)·1e-4 m = 6e-10 m) carry the strain's round-off, EA·ε/step ≈
    /// 0.03 N/m (measured worst difference 0.074 N/m), against entries up to 3.6e6 N/m (2e-8);
    /// a wrong sign, column or F0 entry is off by the entry itself.
    #[test]
    fn block_jacobian_matches_coloured_differences() {
        for stored in [FeStored::Elastic, FeStored::Rigid] {
            let params = Params {
                elements: 4,
                stored,
                ..Params::default()
            };
            let mut model = Fe::new(&Scenario::paper(), params).unwrap();
            let rule = cdpr_core::model::SplitRule::new(0.6, 200.0);
            let (mut problem, u) = problem(&mut model, &rule).unwrap();
            let n = u.len();
            let pattern = problem.pattern().unwrap();
            let mut by_blocks = vec![0.0; pattern.len()];
            assert!(problem.jacobian(&u, &mut by_blocks));
            let mut coloured = vec![0.0; pattern.len()];
            let steps: Vec<f64> = (0..n).map(|j| CBRT_EPSILON * problem.scale(j)).collect();
            ColouredDifferences::new(n, &pattern).jacobian(
                &mut |v, out| problem.residual(v, out),
                &u,
                &steps,
                &mut coloured,
            );
            let dense = |values: &[f64]| {
                let mut m = vec![0.0; n * n];
                for (&(r, c), v) in pattern.iter().zip(values) {
                    m[r * n + c] += v;
                }
                m
            };
            let (a, b) = (dense(&by_blocks), dense(&coloured));
            let largest = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let worst = a
                .iter()
                .zip(&b)
                .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
            assert!(
                worst < 1e-6 * largest,
                "{stored:?}: {worst:e} of {largest:e}"
            );
        }
    }
}
