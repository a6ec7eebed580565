//! # The lumped cable in space (MODELS.md §4 along each cable's own path, §11)
//!
//! Every cable i of a spatial robot is the planar model's chain: N point masses P_0 … P_{N−1}
//! (m = μ l0 each, l0 = L0/N) joined by N tension-only springs of stiffness k0 = EA/l0, spring j
//! from P_j to P_{j+1}, P_N the effector shared by all m cables. The pulley is the anchor A_i;
//! behind it the stored nodes slide on the reel line A_i + s r_i (r_i the cable's unit reel
//! direction, pointing away from the workspace), the 3-D form of eq. 6: their acceleration is
//! the component along r_i of their net force (gravity included), the guide reacting the rest.
//! Free nodes move in space under gravity (eq. 7). The straddling spring runs over the pulley
//! (eq. 4): λ = |P_{r−1} A_i| + |A_i P_r|. The commanded tension pulls P_0 along r_i. Nodes pass
//! the pulley as located events ([`pulley`]), each keeping its mass: the cable mass is
//! conserved exactly.
//!
//! With two cables whose anchors and reel lines lie in the x–z plane this is the planar model
//! [`crate::Lumped`] in a third coordinate that stays zero; the tests check the two against each
//! other.
//!
//! State: per cable the x, y and z of nodes 0 … N−1 (each axis contiguous, so that the spring
//! sweep vectorises), then the effector's (x, y, z): 3mN + 3 positions, then the velocities in
//! the same order. The stored-node counts r_i are the model's discrete mode.
//!
//! [`springs`]: the springs and the forces; [`reel`]: the reels, pulled by tension, locked or
//! driven by length; [`pulley`]: the passages; [`statics`]: the rest (and with locked reels);
//! [`implicit`]: the second-order form; [`modal`]: the coordinates for a modal analysis.

mod implicit;
mod modal;
mod pulley;
mod reel;
mod springs;
mod statics;
mod tangent;

use crate::spring_tension;
use cdpr_core::modal_layout::ModalLayout;
use cdpr_core::model::{CableModel, Energy, Equilibrium, ModelError, ModelEvent, RestRule};
use cdpr_core::robot::{Effector, MAX_CABLES, PerCable, Robot};
use cdpr_core::scenario::Scenario;
use nalgebra::Vector3;

pub use reel::REEL_TIME_CONSTANT;
pub use statics::{Hang, hang, hang_with_length, rest_with_lengths};

/// The scenario's cable as the spatial lumped model needs it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CableProperties {
    /// Springs per cable N.
    pub elements: usize,
    /// Modelled unstrained length per cable L0 [m].
    pub modelled_length: f64,
    /// Mass per unstrained length μ [kg/m].
    pub mass_per_length: f64,
    /// Axial stiffness EA [N].
    pub axial_stiffness: f64,
    /// Kelvin–Voigt coefficient C [N s] (0: undamped).
    pub axial_damping: f64,
}

/// The spatial robot with lumped mass-spring cables.
#[derive(Debug, Clone, PartialEq)]
pub struct LumpedSpatial {
    robot: Robot<3>,
    /// Springs per cable N.
    pub elements: usize,
    /// Unstrained spring length l0 = L0/N [m].
    pub segment: f64,
    /// Node mass m = μ l0 [kg].
    pub node_mass: f64,
    /// Spring stiffness k0 = EA/l0 [N/m].
    pub stiffness: f64,
    /// Kelvin–Voigt coefficient per unit length rate, C/l0 [N s/m].
    pub damping: f64,
    /// Unit reel direction r_i of each cable.
    reels: [Vector3<f64>; MAX_CABLES],
    /// Stored nodes r_i of each cable (nodes 0 … r_i − 1 lie on the reel line).
    stored: [usize; MAX_CABLES],
    /// What moves the reel ends P_0: the commanded tensions, a lock, or the length drive.
    drive: reel::ReelDrive,
    /// Per cable, the forces of its springs on their two end nodes (allocated once).
    scratch: Vec<springs::SpringForces>,
    /// Buffers of the second-order form ([`implicit`]).
    implicit: implicit::ImplicitScratch,
}

pub use cdpr_core::robot::reels::default_reel_directions;

impl LumpedSpatial {
    /// The robot's cables lumped, reeled along `reels` (checked not to point into the workspace,
    /// (A_i − centroid)·r_i ≥ 0, so that a top anchor may reel horizontally); r_i are set by the
    /// statics.
    pub fn new(
        robot: Robot<3>,
        cable: CableProperties,
        reels: &[Vector3<f64>],
    ) -> Result<Self, ModelError> {
        let n = cable.elements;
        if n < crate::params::MIN_ELEMENTS {
            return Err(ModelError::Parameter {
                name: "model.elements",
                value: n as f64,
                allowed: "≥ 3 for the lumped model (a reel end, a straddling spring, a free node)"
                    .into(),
            });
        }
        let m = robot.cables();
        let mut units = [Vector3::x(); MAX_CABLES];
        for (unit, r) in units
            .iter_mut()
            .zip(cdpr_core::robot::reels::unit_reel_directions(
                &robot, reels,
            )?)
        {
            *unit = r;
        }
        let segment = cable.modelled_length / n as f64;
        Ok(Self {
            robot,
            elements: n,
            segment,
            node_mass: cable.mass_per_length * segment,
            stiffness: cable.axial_stiffness / segment,
            damping: cable.axial_damping / segment,
            reels: units,
            stored: [n / 2; MAX_CABLES],
            drive: reel::ReelDrive::Tension,
            implicit: Default::default(),
            scratch: vec![
                springs::SpringForces {
                    a: std::array::from_fn(|_| vec![0.0; n]),
                    b: std::array::from_fn(|_| vec![0.0; n]),
                };
                m
            ],
        })
    }

    /// The scenario's spatial robot (`[robot] anchors`, `reel_directions`) with its cable lumped
    /// into `elements` springs, the modelled length checked against the move: it must cover
    /// 1.05 (1 + t_max/EA) times the longest chord from a pulley to the move's start or end, plus
    /// two spare stored elements (MODELS.md §9's rule in space; the chord to a straight segment
    /// is longest at one of its ends).
    pub fn from_scenario(scenario: &Scenario, elements: usize) -> Result<Self, ModelError> {
        let robot = scenario.spatial_robot().ok_or(ModelError::Parameter {
            name: "robot.anchors",
            value: f64::NAN,
            allowed: "the anchors of a spatial robot".into(),
        })?;
        let reels = cdpr_core::robot::reels::scenario_reel_directions(scenario, &robot)?;
        let c = &scenario.cable;
        let cable = CableProperties {
            elements,
            modelled_length: c.modelled_length,
            mass_per_length: c.mass_per_length(),
            axial_stiffness: c.axial_stiffness(),
            axial_damping: c.axial_damping,
        };
        let model = Self::new(robot, cable, &reels)?;
        if let Ok((start, end)) = scenario.trajectory.spatial_move() {
            let t_max = scenario.controller.t_max.unwrap_or(0.0);
            model.check_poses(&[Vector3::from(start), Vector3::from(end)], t_max)?;
        }
        Ok(model)
    }

    /// The lines fit every one of `poses` [m] (a move's ends, or a print's sampled path): each
    /// pose on every pulley's free side ([`Self::check_free_side`]), and the modelled length at
    /// least 1.05 (1 + t_max/EA) times the longest chord plus two spare stored elements.
    pub fn check_poses(&self, poses: &[Vector3<f64>], t_max: f64) -> Result<(), ModelError> {
        self.check_free_side(poses)?;
        let chord = poses
            .iter()
            .flat_map(|p| self.robot.anchors().iter().map(move |a| (a - p).norm()))
            .fold(0.0, f64::max);
        let ea = self.stiffness * self.segment;
        let length = self.segment * self.elements as f64;
        let needed = 1.05 * (1.0 + t_max / ea) * chord + 2.0 * self.segment;
        if length < needed {
            return Err(ModelError::Parameter {
                name: "cable.modelled_length",
                value: length,
                allowed: format!(
                    "≥ {needed:.6} m for this path (1.05 × (1 + t_max/EA) × longest chord \
                     {chord:.6} m, plus two spare stored elements)"
                ),
            });
        }
        Ok(())
    }

    /// Each of `poses` [m] on the free side of every cable's pulley ((p − A_i)·r_i < 0 by more
    /// than a segment): an effector on a reel line's side has no free cable.
    pub fn check_free_side(&self, poses: &[Vector3<f64>]) -> Result<(), ModelError> {
        for p in poses {
            for i in 0..self.robot.cables() {
                let beyond = (p - self.pulley(i)).dot(&self.reels[i]);
                if beyond > -self.segment {
                    return Err(ModelError::Parameter {
                        name: "robot.reel_directions",
                        value: beyond,
                        allowed: format!(
                            "cable {}: the effector at {:?} m lies {beyond:.4} m along the reel \
                             direction from its pulley; it must lie more than a segment \
                             ({:.4} m) on the free side (< 0)",
                            i + 1,
                            p.as_slice(),
                            -self.segment
                        ),
                    });
                }
            }
        }
        Ok(())
    }

    /// Locks every reel (or hands it back to the commanded tensions): a locked reel holds its
    /// reel end P_0 still, the length reels holding still; the robot is then a conservative
    /// system (no reel work).
    pub fn lock_reels(&mut self, locked: bool) {
        self.drive = if locked {
            reel::ReelDrive::Locked
        } else {
            reel::ReelDrive::Tension
        };
    }

    /// Stored nodes per cable, r_i.
    pub fn stored(&self) -> &[usize] {
        &self.stored[..self.robot.cables()]
    }

    /// Sets the stored-node counts (the discrete mode), e.g. for a hand-made state.
    pub fn set_stored(&mut self, stored: &[usize]) {
        self.stored[..stored.len()].copy_from_slice(stored);
    }

    /// The unit reel direction r_i of `cable`.
    pub fn reel(&self, cable: usize) -> Vector3<f64> {
        self.reels[cable]
    }

    /// Pulley point A_i [m].
    pub fn pulley(&self, cable: usize) -> Vector3<f64> {
        self.robot.anchor(cable)
    }

    /// Number of position coordinates, 3mN + 3.
    pub fn positions_len(&self) -> usize {
        3 * self.robot.cables() * self.elements + 3
    }

    /// Index of coordinate `axis` (0 x, 1 y, 2 z) of node `j` of `cable` (j = N: the effector).
    #[inline]
    pub fn index(&self, cable: usize, j: usize, axis: usize) -> usize {
        let n = self.elements;
        if j == n {
            3 * self.robot.cables() * n + axis
        } else {
            (3 * cable + axis) * n + j
        }
    }

    /// Position of node `j` of `cable` (the effector at j = N) [m].
    #[inline]
    pub fn node(&self, y: &[f64], cable: usize, j: usize) -> Vector3<f64> {
        Vector3::from_fn(|axis, _| y[self.index(cable, j, axis)])
    }

    /// Velocity of node `j` of `cable` [m/s].
    #[inline]
    pub fn node_velocity(&self, y: &[f64], cable: usize, j: usize) -> Vector3<f64> {
        let np = self.positions_len();
        Vector3::from_fn(|axis, _| y[np + self.index(cable, j, axis)])
    }

    /// Total mass of the cables [kg].
    pub fn cable_mass(&self) -> f64 {
        (self.robot.cables() * self.elements) as f64 * self.node_mass
    }

    fn gravity(&self) -> f64 {
        self.robot.gravity
    }
}

impl CableModel<3> for LumpedSpatial {
    fn name(&self) -> &'static str {
        "lumped"
    }

    fn robot(&self) -> &Robot<3> {
        &self.robot
    }

    fn state_len(&self) -> usize {
        2 * self.positions_len()
    }

    fn equilibrium(&mut self, rule: &dyn RestRule<3>) -> Result<Equilibrium, ModelError> {
        statics::equilibrium(self, rule)
    }

    fn rhs(&mut self, _t: f64, y: &[f64], tensions: &[f64], rate: &mut [f64]) {
        let n = self.elements;
        let np = self.positions_len();
        let (dq, dv) = rate.split_at_mut(np);
        dq.copy_from_slice(&y[np..]);
        self.forces(y, tensions, dv);
        let inv_m = 1.0 / self.node_mass;
        let cables = 3 * self.robot.cables() * n;
        dv[..cables].iter_mut().for_each(|a| *a *= inv_m);
        dv[cables..]
            .iter_mut()
            .for_each(|a| *a /= self.robot.effector_mass);
        // Stored nodes move along their reel line only.
        for cable in 0..self.robot.cables() {
            let reel = self.reels[cable];
            for j in 0..self.stored[cable] {
                let v = self.node(dq, cable, j);
                let along = reel * v.dot(&reel);
                for axis in 0..3 {
                    dq[self.index(cable, j, axis)] = along[axis];
                }
            }
        }
    }

    fn effector(&self, y: &[f64]) -> Effector<3> {
        Effector {
            position: self.node(y, 0, self.elements),
            velocity: self.node_velocity(y, 0, self.elements),
        }
    }

    /// The reel end P_0 moving along r_i takes cable in.
    fn reel_speeds(&self, y: &[f64]) -> PerCable {
        PerCable::from_fn(self.robot.cables(), |c| {
            self.node_velocity(y, c, 0).dot(&self.reels[c])
        })
    }

    fn reels_follow_lengths(&self) -> bool {
        true
    }

    fn drive_reels(&mut self, rates: &PerCable, accelerations: &PerCable) {
        self.drive = reel::ReelDrive::Length {
            rates: *rates,
            accelerations: *accelerations,
        };
    }

    /// Σ T_i v_reel,i under tension; the reel-end forces' power when locked or driven.
    fn reel_power(&self, y: &[f64], tensions: &PerCable, reel_speeds: &PerCable) -> f64 {
        match self.drive {
            reel::ReelDrive::Tension => tensions.dot(reel_speeds),
            _ => self.driven_reel_power(y),
        }
    }

    fn energy(&self, y: &[f64]) -> Energy {
        let (m, g, l0, k) = (self.node_mass, self.gravity(), self.segment, self.stiffness);
        let mut e = Energy::default();
        for cable in 0..self.robot.cables() {
            for j in 0..self.elements {
                let (p, v) = (self.node(y, cable, j), self.node_velocity(y, cable, j));
                e.kinetic += 0.5 * m * v.norm_squared();
                e.gravity += m * g * p.z;
                let stretch = (self.spring_length(y, cable, j) - l0).max(0.0);
                e.elastic += 0.5 * k * stretch * stretch;
            }
        }
        let effector = self.effector(y);
        e.kinetic += 0.5 * self.robot.effector_mass * effector.velocity.norm_squared();
        e.gravity += self.robot.effector_mass * g * effector.position.z;
        e
    }

    /// Power of the damping forces: Σ (T − k0 (λ − l0)⁺) λ̇ ≥ 0.
    fn dissipation(&self, y: &[f64]) -> f64 {
        if self.damping == 0.0 {
            return 0.0;
        }
        let mut d = 0.0;
        for cable in 0..self.robot.cables() {
            for j in 0..self.elements {
                let (length, rate, _, _) = self.spring(y, cable, j);
                let elastic = self.stiffness * (length - self.segment).max(0.0);
                let t = spring_tension(self.stiffness, self.segment, self.damping, length, rate);
                d += (t - elastic) * rate;
            }
        }
        d
    }

    fn event_count(&self) -> usize {
        pulley::PER_CABLE * self.robot.cables()
    }

    fn event_functions(&self, y: &[f64], out: &mut [f64]) {
        pulley::event_functions(self, y, out);
    }

    fn apply_event(
        &mut self,
        index: usize,
        t: f64,
        y: &mut [f64],
    ) -> Result<ModelEvent, ModelError> {
        pulley::apply_event(self, index, t, y)
    }

    /// The pulley, then the free nodes r_i … N − 1 and the effector (node N).
    fn cable_paths(&self, y: &[f64]) -> Vec<Vec<Vector3<f64>>> {
        (0..self.robot.cables())
            .map(|c| {
                std::iter::once(self.pulley(c))
                    .chain((self.stored[c]..=self.elements).map(|j| self.node(y, c, j)))
                    .collect()
            })
            .collect()
    }

    fn channel_names(&self) -> Vec<String> {
        cdpr_core::channel::Channel::cable_channel_names(self.robot.cables())
    }

    fn channel_units(&self) -> Vec<&'static str> {
        cdpr_core::channel::Channel::cable_channel_units(self.robot.cables(), "nodes")
    }

    /// Per kind, cable 1 … m: the spring tension at the effector and over the pulley [N], the
    /// free unstrained length [m], the stored-node count.
    fn channels(&self, y: &[f64], _tensions: &[f64], out: &mut [f64]) {
        let m = self.robot.cables();
        let n = self.elements;
        for c in 0..m {
            let r = self.stored[c];
            out[c] = self.spring_force(y, c, n - 1);
            out[m + c] = if r == 0 {
                f64::NAN
            } else {
                self.spring_force(y, c, r - 1)
            };
            out[2 * m + c] = self.free_length(y, c);
            out[3 * m + c] = r as f64;
        }
    }

    fn second_order(&self) -> Option<&dyn cdpr_core::second_order::SecondOrderForm> {
        Some(self)
    }

    fn second_order_mut(&mut self) -> Option<&mut dyn cdpr_core::second_order::SecondOrderForm> {
        Some(self)
    }

    /// The effector, each free node with its cable's tangent, each stored node along its reel
    /// line ([`modal`]).
    fn modal_layout(&self, y: &[f64]) -> ModalLayout {
        self.modal_layout_of(y)
    }
}
