//! Static equilibrium of the lumped model (MODELS.md §2, §4): effector x held at x_ref(0), the PID
//! force F0 an unknown, by the core's Newton service.
//!
//! Unknowns: x of each stored node, (x, z) of each free node, the effector's z, and F0. The split
//! r_i between stored and free nodes is guessed from the chord (unstrained free length ≈
//! chord/(1 + T/EA), N − r = ⌊that/l0⌋), then checked against the side rule at the solution and
//! shifted by one node until it holds, so any start position inside the workspace finds its own
//! straddling spring.

use crate::pulley::beyond;
use crate::{E_OUT, Lumped};
use cdpr_core::model::{CableModel, Equilibrium, ModelError};
use cdpr_core::second_order::SecondOrderForm;
use cdpr_core::statics::{self, NewtonOptions, StaticProblem};
use nalgebra::Vector2;

/// The unknowns ↔ state map and the force residual for a fixed split r.
struct Problem {
    model: Lumped,
    effector_x: f64,
    tension_sum: f64,
    /// State vector being assembled (velocities stay zero).
    y: Vec<f64>,
    forces: Vec<f64>,
    /// State indices of the length unknowns, in order (F0 is the last unknown).
    map: Vec<usize>,
}

impl Problem {
    fn new(model: Lumped, effector_x: f64, tension_sum: f64) -> Self {
        let mut map = Vec::new();
        for cable in 0..2 {
            for j in 0..model.elements {
                map.push(model.xi(cable, j));
                if j >= model.stored()[cable] {
                    map.push(model.zi(cable, j));
                }
            }
        }
        map.push(model.zi(0, model.elements));
        Self {
            y: vec![0.0; model.state_len()],
            forces: vec![0.0; model.positions_len()],
            model,
            effector_x,
            tension_sum,
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

impl StaticProblem for Problem {
    fn dimension(&self) -> usize {
        self.map.len() + 1
    }
    fn length_unknowns(&self) -> usize {
        self.map.len()
    }
    fn residual(&mut self, u: &[f64], r: &mut [f64]) {
        self.load(u);
        let tensions = self.tensions(u[self.map.len()]);
        self.model.forces(&self.y, tensions, &mut self.forces);
        for (k, &i) in self.map.iter().enumerate() {
            r[k] = self.forces[i];
        }
        // The effector's horizontal balance closes the system for F0.
        r[self.map.len()] = self.forces[4 * self.model.elements];
    }
    /// The chain's pattern (`SecondOrderForm::iteration_pattern`) over the unknowns; the
    /// effector's x row is F0's equation.
    fn pattern(&self) -> Option<Vec<(usize, usize)>> {
        let mut unknown = vec![None; self.model.positions_len()];
        for (k, &i) in self.map.iter().enumerate() {
            unknown[i] = Some(k);
        }
        let (force, effector_x) = (self.map.len(), self.model.xi(0, self.model.elements));
        Some(statics::pattern_from_dynamics(
            &self.model.iteration_pattern(),
            |i| {
                if i == effector_x {
                    Some(force)
                } else {
                    unknown[i]
                }
            },
            |j| unknown[j],
            &self.model.tension_rows(),
            force,
        ))
    }
    fn residual_round_off(&self) -> f64 {
        self.model.residual_round_off(&self.y)
    }
    /// Finite-difference scales: 1e-4 m for coordinates, a 6e-10 m step, far inside a spring's
    /// stretch (T/k0 = 8e-6 m at 60 N; a step beyond it slackens the spring and corrupts the
    /// Jacobian) and still moving forces by 4e-3 N against a 2e-9 N round-off. ΣT for F0, on
    /// which the residual depends linearly.
    fn scale(&self, i: usize) -> f64 {
        if i == self.map.len() {
            self.tension_sum
        } else {
            1e-4
        }
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
            let p = if s >= 0.0 {
                a + u * (s * stretch)
            } else {
                a + Vector2::new(E_OUT[cable], 0.0) * (-s * stretch)
            };
            y[model.xi(cable, j)] = p.x;
            y[model.zi(cable, j)] = if s >= 0.0 { p.y } else { 0.0 };
        }
    }
    y[4 * n] = effector.x;
    y[4 * n + 1] = effector.y;
    model.set_stored(stored);
    y
}

/// Splits tried before giving up (a start needs at most one or two shifts).
const MAX_SPLITS: usize = 6;

/// Switches to the split `stored`: a node changing sides starts just on its new side of the
/// pulley, on its new path (the straddling spring's length has a kink at the pulley that Newton
/// cannot cross).
fn reclassify(model: &mut Lumped, y: &mut [f64], stored: [usize; 2], effector_x: f64) {
    let n = model.elements;
    let effector = Vector2::new(effector_x, y[model.zi(0, n)]);
    for cable in 0..2 {
        let (old, new) = (model.stored()[cable], stored[cable]);
        if old == new {
            continue;
        }
        let a = model.pulley(cable);
        let j = old.min(new);
        let gap = (model.node(y, cable, j) - a)
            .norm()
            .max(1e-3 * model.segment);
        let p = if new > old {
            a + Vector2::new(E_OUT[cable] * gap, 0.0)
        } else {
            a + (effector - a).normalize() * gap
        };
        y[model.xi(cable, j)] = p.x;
        y[model.zi(cable, j)] = p.y;
    }
    model.set_stored(stored);
}

/// Equilibrium with the split found by the side rule (MODELS.md §2, §4).
pub(crate) fn equilibrium(
    model: &mut Lumped,
    effector_x: f64,
    tension_sum: f64,
) -> Result<Equilibrium, ModelError> {
    cdpr_core::model::check_effector_x(effector_x, model.anchor_distance)?;
    let d = model.anchor_distance;
    // Massless-cable sag as the effector's starting depth; the cable weight adds ~1 %.
    let weight = model.effector_mass * model.gravity;
    let sag = -weight * effector_x * (d - effector_x) / (0.5 * tension_sum * d);
    let ea = model.stiffness * model.segment;
    let mut y = guess(model, Vector2::new(effector_x, sag), 0.5 * tension_sum, ea);
    let n = model.elements;
    for _attempt in 0..MAX_SPLITS {
        let mut problem = Problem::new(model.clone(), effector_x, tension_sum);
        let mut u: Vec<f64> = problem.map.iter().map(|&i| y[i]).collect();
        u.push(0.0);
        let solved = statics::solve(&mut problem, &mut u, NewtonOptions::default());
        problem.load(&u);
        y.copy_from_slice(&problem.y);
        let mut stored = model.stored();
        let report = solved?;
        // Side rule at the solution: shift the split where the last stored node is not beyond
        // the pulley or the first free node is.
        let mut consistent = true;
        for (cable, r) in stored.iter_mut().enumerate() {
            if *r > 0 && beyond(model, &y, cable, *r - 1) <= 0.0 {
                *r -= 1;
                consistent = false;
            } else if *r < n && beyond(model, &y, cable, *r) > 0.0 {
                *r += 1;
                consistent = false;
            }
        }
        if consistent {
            return Ok(Equilibrium {
                state: y,
                force: u[problem.map.len()],
                iterations: report.iterations,
                residual: report.residual,
            });
        }
        reclassify(model, &mut y, stored, effector_x);
    }
    Err(ModelError::State {
        t: 0.0,
        why: format!(
            "no consistent stored/free split found for the effector at x = {effector_x} m"
        ),
    })
}
