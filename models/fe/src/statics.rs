//! Static equilibrium of the FE model (MODELS.md FE.8.1): F(q, 0) = 0 with the effector's x held at
//! x_ref(0) and the PID force F0 an unknown, by the core's Newton service from the straight-chord
//! guess (nodes on the chords A_i → P, l_i = chord/(1 + T_i/EA), ρ_i = (L0 − l_i)(1 + T_i/EA)).
//!
//! Unknowns: every coordinate of q except the effector's x, then F0; equations: every row of F.
//! At rest the l-row says N_s(1 + ε_s/2) = Σ_e h'[N_e(1 + ε_e/2) − μ g z̄_e]: the pulley tension is
//! continuous, so the solution is the discrete version of the continuum CDPR of FE.8.3.

use crate::Fe;
use cdpr_core::model::{CableModel, Equilibrium, ModelError};
use cdpr_core::second_order::SecondOrderForm;
use cdpr_core::statics::{self, NewtonOptions, StaticProblem};
use nalgebra::Vector2;

struct Problem<'a> {
    model: &'a mut Fe,
    effector_x: f64,
    tension_sum: f64,
    /// State being assembled (velocities stay zero).
    y: Vec<f64>,
    /// Indices in q of the length unknowns, in order (F0 is the last unknown).
    map: Vec<usize>,
}

impl Problem<'_> {
    fn tensions(&self, force: f64) -> [f64; 2] {
        [
            0.5 * (self.tension_sum - force),
            0.5 * (self.tension_sum + force),
        ]
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
        let p = self.model.effector_index();
        let force = self.map.len();
        Some(statics::pattern_from_dynamics(
            &self.model.iteration_pattern(),
            Some,
            |j| (j != p).then(|| j - usize::from(j > p)),
            &self.model.tension_rows(),
            force,
        ))
    }
    fn residual_round_off(&self) -> f64 {
        self.model.residual_round_off(&self.y)
    }
    /// 1e-4 m for lengths: a 6e-10 m step, far inside an element's stretch (ε h = 2.8e-5 m at
    /// 100 N, h = 0.05 m; a step beyond it would slacken the element and corrupt the Jacobian)
    /// and moving the forces by EA/h·6e-10 ≈ 2e-3 N against a round-off of EA/h·ulp ≈ 4e-10 N.
    /// ΣT for F0, on which the residual is linear.
    fn scale(&self, i: usize) -> f64 {
        if i == self.map.len() {
            self.tension_sum
        } else {
            1e-4
        }
    }
}

/// Equilibrium of MODELS.md §2 / FE.8.1 with the effector at x = `effector_x`.
pub(crate) fn equilibrium(
    model: &mut Fe,
    effector_x: f64,
    tension_sum: f64,
) -> Result<Equilibrium, ModelError> {
    cdpr_core::model::check_effector_x(effector_x, model.anchor_distance)?;
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
    let mut problem = Problem {
        model,
        effector_x,
        tension_sum,
        y,
        map,
    };
    let report = statics::solve(&mut problem, &mut u, NewtonOptions::default())?;
    problem.load(&u);
    let force = u[problem.map.len()];
    debug_assert_eq!(problem.y.len(), problem.model.state_len());
    Ok(Equilibrium {
        state: problem.y,
        force,
        iterations: report.iterations,
        residual: report.residual,
    })
}
