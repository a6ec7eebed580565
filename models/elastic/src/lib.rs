//! # cdpr-elastic: massless elastic cables (paper §2.1, MODELS.md §3)
//!
//! Each cable is a massless spring from its pulley A_i to the effector C, tensioned by an ideal
//! tension-controlled winch: the effector feels exactly the commanded tension along the cable
//! (eq. 2–3), and eq. 1 tells how much unstrained cable is paid out, l0_i = l_i / (1 + T_i/EA).
//!
//! State: (x, z, ẋ, ż) of the effector [m, m/s].

use cdpr_core::controller::split_tensions;
use cdpr_core::modal_layout::{Dof, ModalLayout};
use cdpr_core::model::{CableModel, Effector, Energy, Equilibrium, ModelError, ModelParams};
use cdpr_core::scenario::{IntegratorKind, Scenario, ScenarioError, out_of_range};
use cdpr_numerics::newton::{self, NewtonOptions, StaticProblem};
use nalgebra::Vector2;

/// The two-cable robot with massless elastic cables.
#[derive(Debug, Clone, PartialEq)]
pub struct Elastic {
    /// Pulley distance d [m]: A1 = (0, 0), A2 = (d, 0).
    pub anchor_distance: f64,
    /// Effector mass M [kg].
    pub effector_mass: f64,
    /// Gravity g [m/s²] along −z.
    pub gravity: f64,
    /// Axial stiffness EA [N] (eq. 1; it sets only the paid-out unstrained length).
    pub axial_stiffness: f64,
}

/// Indices of the state vector.
const X: usize = 0;
const Z: usize = 1;
const VX: usize = 2;
const VZ: usize = 3;

/// The elastic model has no keys of its own in the `[model]` section, and stores no cable.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct Params {}

impl ModelParams for Params {
    type Model = Elastic;
    /// The massless cables have no second-order form, so no implicit path: refused here rather
    /// than when the run starts.
    fn validate(&self, scenario: &Scenario) -> Result<(), ScenarioError> {
        if scenario.simulation.integrator == IntegratorKind::Implicit {
            return Err(out_of_range(
                "simulation.integrator",
                "\"implicit\"",
                "\"dopri5\" for the elastic model: its massless cables have no second-order form \
                 for the implicit path (nor its stiffness: DOPRI5 runs it in ~1 ms)",
            ));
        }
        Ok(())
    }
    fn build(&self, scenario: &Scenario) -> Result<Elastic, ModelError> {
        Ok(Elastic::new(scenario))
    }
}

impl Elastic {
    /// The model with the scenario's robot and cable.
    pub fn new(scenario: &Scenario) -> Self {
        Self {
            anchor_distance: scenario.robot.anchor_distance,
            effector_mass: scenario.robot.effector_mass,
            gravity: scenario.robot.gravity,
            axial_stiffness: scenario.cable.axial_stiffness(),
        }
    }

    /// Pulley points A1, A2 [m].
    pub fn pulleys(&self) -> [Vector2<f64>; 2] {
        [
            Vector2::new(0.0, 0.0),
            Vector2::new(self.anchor_distance, 0.0),
        ]
    }

    /// Cable lengths l_i = |A_i − C| [m] and unit vectors e_i = (A_i − C)/l_i (eq. 3).
    pub fn cables(&self, effector: Vector2<f64>) -> [(f64, Vector2<f64>); 2] {
        self.pulleys().map(|a| {
            let chord = a - effector;
            let l = chord.norm();
            (l, chord / l)
        })
    }

    /// Net force on the effector [N]: T1 e1 + T2 e2 + M g (eq. 2 times M; zero is eq. 14).
    pub fn net_force(&self, effector: Vector2<f64>, tensions: [f64; 2]) -> Vector2<f64> {
        let [(_, e1), (_, e2)] = self.cables(effector);
        e1 * tensions[0] + e2 * tensions[1] - Vector2::new(0.0, self.effector_mass * self.gravity)
    }

    /// Unstrained paid-out length of each cable, eq. 1 inverted: l0 = l/(1 + T/EA) [m].
    pub fn unstrained_lengths(&self, effector: Vector2<f64>, tensions: [f64; 2]) -> [f64; 2] {
        let [(l1, _), (l2, _)] = self.cables(effector);
        [
            l1 / (1.0 + tensions[0] / self.axial_stiffness),
            l2 / (1.0 + tensions[1] / self.axial_stiffness),
        ]
    }

    /// Symmetric closed form of eq. 14 for the effector at mid-span with ΣT/2 in each cable:
    /// z0 = −(d/2)·tan(asin(M g/ΣT)) [m] (MODELS.md §2: −0.0245546 m for the paper).
    pub fn midspan_sag(&self, tension_sum: f64) -> f64 {
        -0.5 * self.anchor_distance
            * (self.effector_mass * self.gravity / tension_sum)
                .asin()
                .tan()
    }

    /// Linearised vertical frequency at a static state with the tensions held fixed (geometric
    /// stiffness, MODELS.md §3): ω² = Σ T_i cos²θ_i / (M l_i) [rad/s].
    pub fn vertical_frequency(&self, effector: Vector2<f64>, tensions: [f64; 2]) -> f64 {
        let stiffness: f64 = self
            .cables(effector)
            .iter()
            .zip(tensions)
            .map(|(&(l, e), t)| t * e.x * e.x / l)
            .sum();
        (stiffness / self.effector_mass).sqrt()
    }
}

/// Vertical resonance of a mass between two strings, paper eq. 15:
/// ω = √(T/M · (1/x + 1/(d − x))) [rad/s] (20.41 rad/s at x = 0.6 for the paper).
pub fn eq15_frequency(tension: f64, effector_mass: f64, x: f64, anchor_distance: f64) -> f64 {
    (tension / effector_mass * (1.0 / x + 1.0 / (anchor_distance - x))).sqrt()
}

/// Eq. 14 with x fixed: unknowns (z [m], F0 [N]), residual the net force on the effector.
struct Eq14<'a> {
    model: &'a Elastic,
    x: f64,
    tension_sum: f64,
}

impl StaticProblem for Eq14<'_> {
    fn dimension(&self) -> usize {
        2
    }
    fn length_unknowns(&self) -> usize {
        1
    }
    fn residual(&mut self, u: &[f64], r: &mut [f64]) {
        let tensions = split_tensions(self.tension_sum, u[1]);
        let f = self.model.net_force(Vector2::new(self.x, u[0]), tensions);
        r[0] = f.x;
        r[1] = f.y;
    }
    fn scale(&self, i: usize) -> f64 {
        [1e-2, 1.0][i]
    }
}

impl CableModel for Elastic {
    fn name(&self) -> &'static str {
        "elastic"
    }

    /// One group: the effector, which is all the model's coordinates.
    fn modal_layout(&self, _state: &[f64]) -> ModalLayout {
        ModalLayout {
            dofs: vec![Dof::Effector {
                x: X,
                z: Z,
                mass: self.effector_mass,
            }],
            frozen: Vec::new(),
        }
    }

    fn state_len(&self) -> usize {
        4
    }

    fn equilibrium(
        &mut self,
        effector_x: f64,
        tension_sum: f64,
    ) -> Result<Equilibrium, ModelError> {
        cdpr_core::model::check_effector_x(effector_x, self.anchor_distance)?;
        let d = self.anchor_distance;
        if self.effector_mass * self.gravity >= tension_sum {
            return Err(ModelError::Parameter {
                name: "tension_sum",
                value: tension_sum,
                allowed: format!("> M g = {} N", self.effector_mass * self.gravity),
            });
        }
        // Small-sag start (string with tension ΣT/2 deflected by M g at x): within a few percent of
        // the solution anywhere in the workspace, where the mid-span sag is not near the pulleys.
        let sag = -self.effector_mass * self.gravity * effector_x * (d - effector_x)
            / (0.5 * tension_sum * d);
        let mut unknowns = [sag, 0.0];
        let mut problem = Eq14 {
            model: self,
            x: effector_x,
            tension_sum,
        };
        let report = newton::solve(&mut problem, &mut unknowns, NewtonOptions::default())?;
        Ok(Equilibrium {
            state: vec![effector_x, unknowns[0], 0.0, 0.0],
            force: unknowns[1],
            iterations: report.iterations,
            residual: report.residual,
        })
    }

    fn rhs(&mut self, _t: f64, y: &[f64], tensions: [f64; 2], rate: &mut [f64]) {
        let acc = self.net_force(Vector2::new(y[X], y[Z]), tensions) / self.effector_mass;
        rate[X] = y[VX];
        rate[Z] = y[VZ];
        rate[VX] = acc.x;
        rate[VZ] = acc.y;
    }

    fn effector(&self, y: &[f64]) -> Effector {
        Effector {
            position: Vector2::new(y[X], y[Z]),
            velocity: Vector2::new(y[VX], y[VZ]),
        }
    }

    /// Reeling-in rate = −dl_i/dt = e_i·v: the reel takes in what the effector's approach frees.
    fn reel_speeds(&self, y: &[f64]) -> [f64; 2] {
        let v = Vector2::new(y[VX], y[VZ]);
        self.cables(Vector2::new(y[X], y[Z]))
            .map(|(_, e)| e.dot(&v))
    }

    /// Kinetic and gravity energy of the effector; massless cables carry no kinetic energy and,
    /// between ideal tension-controlled winches, their strain energy is not part of the effector's
    /// balance: d/dt(½M|v|² + M g z) = Σ T_i e_i·v, the reels' power (MODELS.md §3).
    fn energy(&self, y: &[f64]) -> Energy {
        Energy {
            kinetic: 0.5 * self.effector_mass * (y[VX] * y[VX] + y[VZ] * y[VZ]),
            elastic: 0.0,
            gravity: self.effector_mass * self.gravity * y[Z],
        }
    }

    /// Strained lengths l_i and unstrained lengths l0_i (eq. 1) [m]. A massless cable carries the
    /// commanded tension to the effector unchanged, so no separate effector-end tension is stored.
    fn channel_names(&self) -> Vec<String> {
        ["l1", "l2", "l0_1", "l0_2"].map(String::from).to_vec()
    }

    fn channel_units(&self) -> Vec<&'static str> {
        vec!["m"; 4]
    }

    fn channels(&self, y: &[f64], tensions: [f64; 2], out: &mut [f64]) {
        let [(l1, _), (l2, _)] = self.cables(Vector2::new(y[X], y[Z]));
        let ea = self.axial_stiffness;
        out.copy_from_slice(&[
            l1,
            l2,
            l1 / (1.0 + tensions[0] / ea),
            l2 / (1.0 + tensions[1] / ea),
        ]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_equilibrium_matches_the_closed_form() {
        let mut m = Elastic::new(&Scenario::paper());
        let eq = m.equilibrium(0.5, 200.0).unwrap();
        // Symmetric start: F0 = 0 and z0 the closed form (MODELS.md §2: −0.0245546 m).
        assert!((eq.state[1] - m.midspan_sag(200.0)).abs() < 1e-12);
        assert!((eq.state[1] + 0.0245546).abs() < 1e-7);
        assert!(eq.force.abs() < 1e-9);
    }

    #[test]
    fn frequencies_at_the_end_position() {
        // MODELS.md §3 at x = 0.6: eq. 15 = 20.4124, geometric 20.3721 rad/s; MODELS.md FE.8.3:
        // massless z_P = −0.023573508 m, F0 = 0.096236 N.
        let mut m = Elastic::new(&Scenario::paper());
        let eq = m.equilibrium(0.6, 200.0).unwrap();
        assert!((eq.state[1] + 0.023573508).abs() < 1e-9, "{}", eq.state[1]);
        assert!((eq.force - 0.096236).abs() < 1e-6, "{}", eq.force);
        let t = [0.5 * (200.0 - eq.force), 0.5 * (200.0 + eq.force)];
        let w = m.vertical_frequency(Vector2::new(0.6, eq.state[1]), t);
        assert!((w - 20.3721).abs() < 1e-4, "{w}");
        assert!((eq15_frequency(100.0, 1.0, 0.6, 1.0) - 20.4124).abs() < 1e-4);
    }
}
