//! # cdpr-elastic: massless elastic cables (paper §2.1, MODELS.md §3)
//!
//! Each cable is a massless spring from its anchor A_i to the effector C, tensioned by an ideal
//! tension-controlled winch: the effector feels exactly the commanded tension along the cable
//! (eq. 2–3), and eq. 1 tells how much unstrained cable is paid out, l0_i = l_i / (1 + T_i/EA).
//! The robot's space is the type parameter D (the paper's plane: D = 2) and its cables any
//! number m of the robot's.
//!
//! State: the effector's position and velocity, (p, ṗ) [m, m/s] (the plane: (x, z, ẋ, ż)).

use cdpr_core::modal_layout::{Dof, ModalLayout};
use cdpr_core::model::{
    CableModel, Energy, Equilibrium, ModelError, ModelParams, RestRule, check_effector_x,
};
use cdpr_core::robot::{Effector, PerCable, Robot, Vector, along_vertical};
use cdpr_core::scenario::{IntegratorKind, Scenario, ScenarioError, out_of_range};
use cdpr_numerics::newton::{self, NewtonOptions, StaticProblem};

/// A robot with massless elastic cables.
#[derive(Debug, Clone, PartialEq)]
pub struct Elastic<const D: usize> {
    pub robot: Robot<D>,
    /// Axial stiffness EA [N] (eq. 1; it sets only the paid-out unstrained length).
    pub axial_stiffness: f64,
}

/// The elastic model has no keys of its own in the `[model]` section, and stores no cable.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct Params {}

impl ModelParams for Params {
    type Model = Elastic<2>;
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
    fn build(&self, scenario: &Scenario) -> Result<Elastic<2>, ModelError> {
        Ok(Elastic::from_scenario(scenario))
    }
}

impl<const D: usize> Elastic<D> {
    /// The model of `robot` with cables of axial stiffness EA [N].
    pub fn new(robot: Robot<D>, axial_stiffness: f64) -> Self {
        Self {
            robot,
            axial_stiffness,
        }
    }

    /// Net force on the effector [N]: Σ T_i e_i + M g⃗ (eq. 2 times M; zero is eq. 14).
    pub fn net_force(&self, effector: &Vector<D>, tensions: &[f64]) -> Vector<D> {
        let r = &self.robot;
        r.structure_matrix(effector).force(tensions)
            - along_vertical::<D>(r.effector_mass * r.gravity)
    }

    /// Unstrained paid-out length of each cable, eq. 1 inverted: l0 = l/(1 + T/EA) [m].
    pub fn unstrained_lengths(&self, effector: &Vector<D>, tensions: &[f64]) -> PerCable {
        PerCable::from_fn(self.robot.cables(), |i| {
            self.robot.chord(i, effector).length / (1.0 + tensions[i] / self.axial_stiffness)
        })
    }

    /// Linearised vertical frequency at a static state with the tensions held fixed (geometric
    /// stiffness, MODELS.md §3): ω² = Σ T_i |u_i,horizontal|² / (M l_i) [rad/s].
    pub fn vertical_frequency(&self, effector: &Vector<D>, tensions: &[f64]) -> f64 {
        let stiffness: f64 = (0..self.robot.cables())
            .map(|i| {
                let c = self.robot.chord(i, effector);
                (0..D - 1)
                    .map(|k| tensions[i] * c.direction[k] * c.direction[k] / c.length)
                    .sum::<f64>()
            })
            .sum();
        (stiffness / self.robot.effector_mass).sqrt()
    }
}

impl<const D: usize> Elastic<D> {
    /// A rule that pins every coordinate (a spatial robot at rest at a pose, tensions given):
    /// nothing to solve, the balance is checked — to 1e-9 of the weight plus the tensions, the
    /// tension distribution's W T = w holding to 1e-12 of the wrench.
    fn balance_at_pose(&self, rule: &dyn RestRule<D>) -> Result<Equilibrium, ModelError> {
        let mut p = Vector::<D>::zeros();
        for &(axis, value) in rule.pinned() {
            p[axis] = value;
        }
        let tensions = rule.tensions(&[]);
        let residual = self.net_force(&p, &tensions).amax();
        let r = &self.robot;
        let scale = r.effector_mass * r.gravity + tensions.iter().map(|t| t.abs()).sum::<f64>();
        if residual.is_nan() || residual > 1e-9 * scale {
            return Err(ModelError::Parameter {
                name: "rest tensions",
                value: residual,
                allowed: format!(
                    "a net force ≤ {:e} N at {:?} m: the tensions {:?} N do not hold the \
                     effector there (no distribution in the box holds its weight)",
                    1e-9 * scale,
                    p.as_slice(),
                    tensions
                ),
            });
        }
        let mut state = vec![0.0; 2 * D];
        state[..D].copy_from_slice(p.as_slice());
        Ok(Equilibrium {
            state,
            tensions,
            parameters: Vec::new(),
            iterations: 0,
            residual,
        })
    }
}

impl Elastic<2> {
    /// The planar robot of `scenario` (its `[robot]` and `[cable]` sections).
    pub fn from_scenario(scenario: &Scenario) -> Self {
        Self::new(scenario.robot(), scenario.cable.axial_stiffness())
    }

    /// Symmetric closed form of eq. 14 for the effector at mid-span with ΣT/2 in each cable:
    /// z0 = −(d/2)·tan(asin(M g/ΣT)) [m] (MODELS.md §2: −0.0245546 m for the paper).
    pub fn midspan_sag(&self, tension_sum: f64) -> f64 {
        let r = &self.robot;
        -0.5 * self.anchor_distance() * (r.effector_mass * r.gravity / tension_sum).asin().tan()
    }

    /// The distance d between the plane's two pulleys [m].
    pub fn anchor_distance(&self) -> f64 {
        self.robot.anchor(1)[0] - self.robot.anchor(0)[0]
    }
}

/// Vertical resonance of a mass between two strings, paper eq. 15:
/// ω = √(T/M · (1/x + 1/(d − x))) [rad/s] (20.41 rad/s at x = 0.6 for the paper).
pub fn eq15_frequency(tension: f64, effector_mass: f64, x: f64, anchor_distance: f64) -> f64 {
    (tension / effector_mass * (1.0 / x + 1.0 / (anchor_distance - x))).sqrt()
}

/// Eq. 14 under a rest rule: unknowns the effector's coordinates the rule leaves free (in axis
/// order) [m] and the rule's parameters, residual the net force on the effector.
struct Eq14<'a, const D: usize> {
    model: &'a Elastic<D>,
    rule: &'a dyn RestRule<D>,
    /// The axes the rule leaves free.
    free: Vec<usize>,
}

impl<const D: usize> Eq14<'_, D> {
    fn position(&self, u: &[f64]) -> Vector<D> {
        let mut p = Vector::zeros();
        for &(axis, value) in self.rule.pinned() {
            p[axis] = value;
        }
        for (k, &axis) in self.free.iter().enumerate() {
            p[axis] = u[k];
        }
        p
    }
}

impl<const D: usize> StaticProblem for Eq14<'_, D> {
    fn dimension(&self) -> usize {
        D
    }
    fn length_unknowns(&self) -> usize {
        self.free.len()
    }
    fn residual(&mut self, u: &[f64], r: &mut [f64]) {
        let tensions = self.rule.tensions(&u[self.free.len()..]);
        let f = self.model.net_force(&self.position(u), &tensions);
        r.copy_from_slice(f.as_slice());
    }
    fn scale(&self, i: usize) -> f64 {
        match i.checked_sub(self.free.len()) {
            None => 1e-2,
            // The paper's rule: F0, of order 1 N (a share of ΣT that vanishes at mid-span).
            Some(_) => 1.0,
        }
    }
}

impl<const D: usize> CableModel<D> for Elastic<D> {
    fn name(&self) -> &'static str {
        "elastic"
    }

    fn robot(&self) -> &Robot<D> {
        &self.robot
    }

    /// One group: the effector, which is all the model's coordinates.
    fn modal_layout(&self, _state: &[f64]) -> ModalLayout {
        ModalLayout {
            dofs: vec![Dof::Effector {
                coordinates: (0..D).collect(),
                mass: self.robot.effector_mass,
            }],
            frozen: Vec::new(),
        }
    }

    fn state_len(&self) -> usize {
        2 * D
    }

    fn equilibrium(&mut self, rule: &dyn RestRule<D>) -> Result<Equilibrium, ModelError> {
        let pinned = rule.pinned();
        if pinned.len() == D {
            return self.balance_at_pose(rule);
        }
        let free: Vec<usize> = (0..D)
            .filter(|k| pinned.iter().all(|(axis, _)| axis != k))
            .collect();
        if free.len() + pinned.len() != D {
            return Err(ModelError::Parameter {
                name: "rest rule",
                value: pinned.len() as f64,
                allowed: format!("as many parameters as pinned coordinates, of {D}"),
            });
        }
        let r = &self.robot;
        let weight = r.effector_mass * r.gravity;
        let mut unknowns = vec![0.0; D];
        if D == 2 && pinned.len() == 1 && pinned[0].0 == 0 {
            // The plane's rule: x pinned, (z, F0) unknown. Small-sag start (a string with ΣT/2
            // deflected by M g at x): within a few percent of the solution in the workspace.
            let x = pinned[0].1;
            let tension_sum = rule.tensions(&[0.0]).iter().sum::<f64>();
            let (a, d) = (r.anchor(0)[0], r.anchor(1)[0] - r.anchor(0)[0]);
            check_effector_x(x - a, d)?;
            if weight >= tension_sum {
                return Err(ModelError::Parameter {
                    name: "tension_sum",
                    value: tension_sum,
                    allowed: format!("> M g = {weight} N"),
                });
            }
            unknowns[0] = -weight * (x - a) * (d - (x - a)) / (0.5 * tension_sum * d);
        } else {
            // Elsewhere: the anchors' centroid, one chord length below the lowest.
            let centroid = r.anchors().iter().sum::<Vector<D>>() / r.cables() as f64;
            for (k, &axis) in free.iter().enumerate() {
                unknowns[k] = centroid[axis];
            }
        }
        let mut problem = Eq14 {
            model: self,
            rule,
            free,
        };
        let report = newton::solve(&mut problem, &mut unknowns, NewtonOptions::default())?;
        let p = problem.position(&unknowns);
        let parameters = unknowns[problem.free.len()..].to_vec();
        let mut state = vec![0.0; 2 * D];
        state[..D].copy_from_slice(p.as_slice());
        Ok(Equilibrium {
            state,
            tensions: rule.tensions(&parameters),
            parameters,
            iterations: report.iterations,
            residual: report.residual,
        })
    }

    fn rhs(&mut self, _t: f64, y: &[f64], tensions: &[f64], rate: &mut [f64]) {
        let p = Vector::<D>::from_column_slice(&y[..D]);
        let acc = self.net_force(&p, tensions) / self.robot.effector_mass;
        rate[..D].copy_from_slice(&y[D..]);
        rate[D..].copy_from_slice(acc.as_slice());
    }

    fn effector(&self, y: &[f64]) -> Effector<D> {
        Effector {
            position: Vector::from_column_slice(&y[..D]),
            velocity: Vector::from_column_slice(&y[D..2 * D]),
        }
    }

    /// Eq. 2 and the reels' speeds with the structure matrix W formed once (the same
    /// arithmetic as [`CableModel::rhs`] and [`CableModel::reel_speeds`], so the same bits).
    fn rhs_and_reel_speeds(
        &mut self,
        _t: f64,
        y: &[f64],
        tensions: &[f64],
        rate: &mut [f64],
    ) -> PerCable {
        let r = &self.robot;
        let e = self.effector(y);
        let w = r.structure_matrix(&e.position);
        let force = w.force(tensions) - along_vertical::<D>(r.effector_mass * r.gravity);
        let acc = force / r.effector_mass;
        rate[..D].copy_from_slice(&y[D..]);
        rate[D..].copy_from_slice(acc.as_slice());
        PerCable::from_fn(r.cables(), |i| w.column(i).dot(&e.velocity))
    }

    /// Reeling-in rate = −dl_i/dt = e_i·v: the reel takes in what the effector's approach frees.
    fn reel_speeds(&self, y: &[f64]) -> PerCable {
        let e = self.effector(y);
        let w = self.robot.structure_matrix(&e.position);
        PerCable::from_fn(self.robot.cables(), |i| w.column(i).dot(&e.velocity))
    }

    /// Kinetic and gravity energy of the effector; massless cables carry no kinetic energy and,
    /// between ideal tension-controlled winches, their strain energy is not part of the effector's
    /// balance: d/dt(½M|v|² + M g z) = Σ T_i e_i·v, the reels' power (MODELS.md §3).
    fn energy(&self, y: &[f64]) -> Energy {
        let r = &self.robot;
        let v = &y[D..2 * D];
        let mut speed2 = v[0] * v[0];
        for vk in &v[1..] {
            speed2 += vk * vk;
        }
        Energy {
            kinetic: 0.5 * r.effector_mass * speed2,
            elastic: 0.0,
            gravity: r.effector_mass * r.gravity * y[D - 1],
        }
    }

    /// Strained lengths l_i and unstrained lengths l0_i (eq. 1) [m]. A massless cable carries the
    /// commanded tension to the effector unchanged, so no separate effector-end tension is stored.
    fn channel_names(&self) -> Vec<String> {
        let m = self.robot.cables();
        (1..=m)
            .map(|i| format!("l{i}"))
            .chain((1..=m).map(|i| format!("l0_{i}")))
            .collect()
    }

    fn channel_units(&self) -> Vec<&'static str> {
        vec!["m"; 2 * self.robot.cables()]
    }

    fn channels(&self, y: &[f64], tensions: &[f64], out: &mut [f64]) {
        let p = Vector::<D>::from_column_slice(&y[..D]);
        let (m, ea) = (self.robot.cables(), self.axial_stiffness);
        for i in 0..m {
            let l = self.robot.chord(i, &p).length;
            out[i] = l;
            out[m + i] = l / (1.0 + tensions[i] / ea);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cdpr_core::model::SplitRule;

    fn paper() -> Elastic<2> {
        let s = Scenario::paper();
        Elastic::new(s.robot(), s.cable.axial_stiffness())
    }

    #[test]
    fn paper_equilibrium_matches_the_closed_form() {
        let mut m = paper();
        let eq = m.equilibrium(&SplitRule::new(0.5, 200.0)).unwrap();
        // Symmetric start: F0 = 0 and z0 the closed form (MODELS.md §2: −0.0245546 m).
        assert!((eq.state[1] - m.midspan_sag(200.0)).abs() < 1e-12);
        assert!((eq.state[1] + 0.0245546).abs() < 1e-7);
        assert!(eq.parameters[0].abs() < 1e-9);
    }

    #[test]
    fn frequencies_at_the_end_position() {
        // MODELS.md §3 at x = 0.6: eq. 15 = 20.4124, geometric 20.3721 rad/s; MODELS.md FE.8.3:
        // massless z_P = −0.023573508 m, F0 = 0.096236 N.
        let mut m = paper();
        let eq = m.equilibrium(&SplitRule::new(0.6, 200.0)).unwrap();
        assert!((eq.state[1] + 0.023573508).abs() < 1e-9, "{}", eq.state[1]);
        assert!(
            (eq.parameters[0] - 0.096236).abs() < 1e-6,
            "{}",
            eq.parameters[0]
        );
        let f0 = eq.parameters[0];
        let t = [0.5 * (200.0 - f0), 0.5 * (200.0 + f0)];
        let w = m.vertical_frequency(&nalgebra::Vector2::new(0.6, eq.state[1]), &t);
        assert!((w - 20.3721).abs() < 1e-4, "{w}");
        assert!((eq15_frequency(100.0, 1.0, 0.6, 1.0) - 20.4124).abs() < 1e-4);
    }
}
