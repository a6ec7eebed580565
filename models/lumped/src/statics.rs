//! Static equilibrium of the lumped model (MODELS.md §2, §4): effector x held at x_ref(0), the PID
//! force F0 an unknown, by the core's Newton service.
//!
//! Unknowns: x of each stored node, (x, z) of each free node, the effector's z, and F0. The split
//! r_i between stored and free nodes is guessed from the chord (unstrained free length ≈
//! chord/(1 + T/EA), N − r = ⌊that/l0⌋), then checked against the side rule at the solution and
//! shifted by one node until it holds, so any start position inside the workspace finds its own
//! straddling spring.

use crate::{E_OUT, Lumped};
use cdpr_core::model::{CableModel, Equilibrium, ModelError};
use cdpr_core::statics::{self, NewtonOptions, StaticProblem};
use nalgebra::Vector2;

/// The unknowns ↔ state map and the force residual for a fixed split r.
struct Problem<'a> {
    model: &'a Lumped,
    effector_x: f64,
    tension_sum: f64,
    /// State vector being assembled (velocities stay zero).
    y: Vec<f64>,
    forces: Vec<f64>,
    /// State indices of the length unknowns, in order (F0 is the last unknown).
    map: Vec<usize>,
}

impl<'a> Problem<'a> {
    fn new(model: &'a Lumped, effector_x: f64, tension_sum: f64) -> Self {
        let mut map = Vec::new();
        for cable in 0..2 {
            for j in 0..model.elements {
                let i = model.index(cable, j);
                map.push(i);
                if j >= model.stored()[cable] {
                    map.push(i + 1);
                }
            }
        }
        map.push(4 * model.elements + 1);
        Self {
            model,
            effector_x,
            tension_sum,
            y: vec![0.0; model.state_len()],
            forces: vec![0.0; model.positions_len()],
            map,
        }
    }

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
        self.y[4 * self.model.elements] = self.effector_x;
    }
}

impl StaticProblem for Problem<'_> {
    fn dimension(&self) -> usize {
        self.map.len() + 1
    }
    fn length_unknowns(&self) -> usize {
        self.map.len()
    }
    fn residual(&mut self, u: &[f64], r: &mut [f64]) {
        self.load(u);
        let tensions = self.tensions(u[self.map.len()]);
        self.model
            .accumulate_forces(&self.y, tensions, &mut self.forces);
        for (k, &i) in self.map.iter().enumerate() {
            r[k] = self.forces[i];
        }
        // The effector's horizontal balance closes the system for F0.
        r[self.map.len()] = self.forces[4 * self.model.elements];
    }
    fn scale(&self, _i: usize) -> f64 {
        0.1
    }
}

/// Straight-chord guess: the number of free springs of each cable, and nodes at uniform strain
/// along the chord A_i → P and along the reel line.
fn guess(model: &mut Lumped, effector: Vector2<f64>, tension: f64, ea: f64) -> Vec<f64> {
    let n = model.elements;
    let stretch = 1.0 + tension / ea;
    let mut stored = [0; 2];
    let mut y = vec![0.0; model.state_len()];
    for cable in 0..2 {
        let a = model.pulley(cable);
        let chord = effector - a;
        let free = chord.norm() / stretch;
        let free_springs = ((free / model.segment).floor() as usize).min(n - 1);
        let r = n - free_springs;
        stored[cable] = r;
        let u = chord / chord.norm();
        for j in 0..n {
            // Unstrained distance of node j from the pulley along the cable path (negative: stored).
            let s = free - (n - j) as f64 * model.segment;
            let i = model.index(cable, j);
            let p = if s >= 0.0 {
                a + u * (s * stretch)
            } else {
                a + Vector2::new(E_OUT[cable], 0.0) * (-s * stretch)
            };
            y[i] = p.x;
            y[i + 1] = if s >= 0.0 { p.y } else { 0.0 };
        }
    }
    y[4 * n] = effector.x;
    y[4 * n + 1] = effector.y;
    model.set_stored(stored);
    y
}

/// Equilibrium with the split found by the side rule (MODELS.md §2, §4).
pub(crate) fn equilibrium(
    model: &mut Lumped,
    effector_x: f64,
    tension_sum: f64,
) -> Result<Equilibrium, ModelError> {
    let d = model.anchor_distance;
    if !(effector_x > 0.0 && effector_x < d) {
        return Err(ModelError::Parameter {
            name: "effector x",
            value: effector_x,
            allowed: format!("(0, {d}) m between the pulleys"),
        });
    }
    // Massless-cable sag as the effector's starting depth; the cable weight adds ~1 %.
    let weight = model.effector_mass * model.gravity;
    let sag = -weight * effector_x * (d - effector_x) / (0.5 * tension_sum * d);
    let ea = model.stiffness * model.segment;
    let mut y = guess(model, Vector2::new(effector_x, sag), 0.5 * tension_sum, ea);
    let n = model.elements;
    for _attempt in 0..4 {
        let problem_model = model.clone();
        let mut problem = Problem::new(&problem_model, effector_x, tension_sum);
        let mut u: Vec<f64> = problem.map.iter().map(|&i| y[i]).collect();
        u.push(0.0);
        let report = statics::solve(&mut problem, &mut u, NewtonOptions::default())?;
        problem.load(&u);
        y.copy_from_slice(&problem.y);
        let force = u[problem.map.len()];
        // Side rule at the solution: shift the split where the last stored node is not beyond the
        // pulley or the first free node is.
        let mut stored = model.stored();
        let mut consistent = true;
        for cable in 0..2 {
            let r = stored[cable];
            let side = |j: usize| (y[model.index(cable, j)] - model.pulley(cable).x) * E_OUT[cable];
            if r > 0 && side(r - 1) <= 0.0 {
                stored[cable] = r - 1;
                consistent = false;
            } else if r < n && side(r) > 0.0 {
                stored[cable] = r + 1;
                consistent = false;
            }
        }
        if consistent {
            return Ok(Equilibrium {
                state: y,
                force,
                iterations: report.iterations,
                residual: report.residual,
            });
        }
        for cable in 0..2 {
            // A node changing sides starts on the line z = 0 (stored) or just off it (free).
            for j in 0..n {
                let i = model.index(cable, j);
                if j < stored[cable] {
                    y[i + 1] = 0.0;
                }
            }
        }
        model.set_stored(stored);
    }
    Err(ModelError::State {
        t: 0.0,
        why: format!(
            "no consistent stored/free split found for the effector at x = {effector_x} m"
        ),
    })
}
