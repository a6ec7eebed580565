//! The interface through which a cable model plugs into the closed loop.
//!
//! A model owns its physical state layout (effector and cable coordinates and velocities), computes
//! its right-hand side for given commanded tensions, and reports the effector, its energy and the
//! extra output channels it has. It knows nothing of the controller, the trajectory or the
//! integrator; the closed loop ([`crate::closed_loop`]) knows nothing of cables. The robot's
//! space is the type parameter D ([`crate::robot::space`]).
//!
//! # Examples
//!
//! A model of one's own: the effector on two rigid-length springs that carry the commanded
//! tensions unchanged (the elastic model without its unstrained lengths). It states its state
//! layout, its right-hand side, its statics under the closed loop's rest rule, and its energy.
//!
//! ```
//! use cdpr_core::model::{CableModel, Energy, Equilibrium, ModelError, RestRule};
//! use cdpr_core::modal_layout::{Dof, ModalLayout};
//! use cdpr_core::robot::{Effector, PerCable, Robot, Tensions, Vector, height};
//!
//! #[derive(Clone)]
//! struct Strings { robot: Robot<2> }
//!
//! impl CableModel<2> for Strings {
//!     fn name(&self) -> &'static str { "strings" }
//!     fn robot(&self) -> &Robot<2> { &self.robot }
//!     fn state_len(&self) -> usize { 4 } // x, z, ẋ, ż
//!     fn rhs(&mut self, _t: f64, y: &[f64], tensions: &[f64], rate: &mut [f64]) {
//!         let p = Vector::<2>::new(y[0], y[1]);
//!         let force = self.robot.structure_matrix(&p).force(tensions) + self.robot.weight();
//!         rate[..2].copy_from_slice(&y[2..]);
//!         rate[2] = force.x / self.robot.effector_mass;
//!         rate[3] = force.y / self.robot.effector_mass;
//!     }
//!     fn effector(&self, y: &[f64]) -> Effector<2> {
//!         Effector { position: Vector::<2>::new(y[0], y[1]), velocity: Vector::<2>::new(y[2], y[3]) }
//!     }
//!     fn reel_speeds(&self, y: &[f64]) -> PerCable {
//!         let e = self.effector(y);
//!         let w = self.robot.structure_matrix(&e.position);
//!         PerCable::from_fn(2, |i| w.column(i).dot(&e.velocity))
//!     }
//!     fn energy(&self, y: &[f64]) -> Energy {
//!         let m = self.robot.effector_mass;
//!         Energy {
//!             kinetic: 0.5 * m * (y[2] * y[2] + y[3] * y[3]),
//!             elastic: 0.0,
//!             gravity: m * self.robot.gravity * y[1],
//!         }
//!     }
//!     /// The rule pins x; z and the rule's parameter follow from the force balance, solved
//!     /// here by a few Newton steps of the 2 × 2 balance (a real model uses `cdpr_numerics::newton`).
//!     fn equilibrium(&mut self, rule: &dyn RestRule<2>) -> Result<Equilibrium, ModelError> {
//!         let x = rule.pinned()[0].1;
//!         let (mut z, mut lambda) = (-0.1, 0.0);
//!         let balance = |z: f64, lambda: f64| {
//!             let p = Vector::<2>::new(x, z);
//!             self.robot.structure_matrix(&p).force(&rule.tensions(&[lambda])) + self.robot.weight()
//!         };
//!         for _ in 0..50 {
//!             let f = balance(z, lambda);
//!             let (h, k) = (1e-7, 1e-4);
//!             let fz = (balance(z + h, lambda) - f) / h;
//!             let fl = (balance(z, lambda + k) - f) / k;
//!             let det = fz.x * fl.y - fl.x * fz.y;
//!             z -= (fl.y * f.x - fl.x * f.y) / det;
//!             lambda -= (fz.x * f.y - fz.y * f.x) / det;
//!         }
//!         Ok(Equilibrium {
//!             state: vec![x, z, 0.0, 0.0],
//!             tensions: rule.tensions(&[lambda]),
//!             parameters: vec![lambda],
//!             iterations: 50,
//!             residual: balance(z, lambda).norm(),
//!         })
//!     }
//!     fn channel_names(&self) -> Vec<String> { Vec::new() }
//!     fn channels(&self, _: &[f64], _: &[f64], _: &mut [f64]) {}
//!     fn modal_layout(&self, _: &[f64]) -> ModalLayout {
//!         ModalLayout {
//!             dofs: vec![Dof::Effector { coordinates: vec![0, 1], mass: self.robot.effector_mass }],
//!             frozen: Vec::new(),
//!         }
//!     }
//! }
//!
//! // At rest under the paper's rule (x pinned, ΣT = 200 N split by the unknown force F0).
//! let robot = Robot::new(&[Vector::<2>::new(0.0, 0.0), Vector::<2>::new(1.0, 0.0)], 1.0, 9.81)?;
//! let mut model = Strings { robot };
//! let eq = model.equilibrium(&cdpr_core::model::SplitRule::new(0.5, 200.0))?;
//! assert!((eq.state[1] + 0.0245546).abs() < 1e-6, "the paper's sag (MODELS.md §2)");
//! assert!(eq.parameters[0].abs() < 1e-9, "no horizontal force at mid-span");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::modal_layout::ModalLayout;
use crate::robot::{Effector, PerCable, Robot, Tensions};
use crate::scenario::{Scenario, ScenarioError};
use crate::second_order::SecondOrderForm;

/// Why a model refused a state or could not find its equilibrium.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// A parameter outside the model's domain (e.g. a modelled length too short for the trajectory).
    #[error("model parameter `{name}` = {value} is out of range: allowed {allowed}")]
    Parameter {
        name: &'static str,
        value: f64,
        allowed: String,
    },
    /// The static equilibrium of MODELS.md §2 was not found.
    #[error("static equilibrium not found: {0}")]
    Equilibrium(#[from] cdpr_numerics::newton::NewtonError),
    /// The state left the model's domain (e.g. a node ordering the pulley rule forbids).
    #[error("invalid model state at t = {t} s: {why}")]
    State { t: f64, why: String },
}

/// MODELS.md §2 holds the effector's x fixed for the static equilibrium: it must lie in the
/// robot's workspace (the plane: strictly between the pulleys A1 = (0, 0) and A2 = (d, 0)).
pub fn check_effector_x(effector_x: f64, anchor_distance: f64) -> Result<(), ModelError> {
    if effector_x > 0.0 && effector_x < anchor_distance {
        Ok(())
    } else {
        Err(ModelError::Parameter {
            name: "effector x",
            value: effector_x,
            allowed: format!("(0, {anchor_distance}) m between the pulleys"),
        })
    }
}

/// What the planar massive models' statics take from a rest rule: the pinned effector x (the
/// rule must pin x alone, as the paper's does; checked to lie between the pulleys) and the
/// rule's pretension ΣT (its tensions at a zero parameter) [m, N].
pub fn planar_rest(
    rule: &dyn RestRule<2>,
    anchor_distance: f64,
    model: &str,
) -> Result<(f64, f64), ModelError> {
    let effector_x = match rule.pinned() {
        &[(0, x)] => x,
        pinned => {
            return Err(ModelError::Parameter {
                name: "rest rule",
                value: pinned.len() as f64,
                allowed: format!(
                    "the effector's x pinned and one parameter: the planar {model} statics"
                ),
            });
        }
    };
    check_effector_x(effector_x, anchor_distance)?;
    Ok((effector_x, rule.tensions(&[0.0]).iter().sum()))
}

/// How the robot and its controller hold the effector at rest (MODELS.md §2), which a model's
/// statics solves with: effector coordinates pinned at values, and the commanded tensions as a
/// function of as many unknown parameters, affine in them. The paper's PID: x pinned, F0 free,
/// T = ((ΣT − F0)/2, (ΣT + F0)/2) ([`SplitRule`]). The model finds its coordinates but the
/// pinned ones and the parameters from its force balance.
pub trait RestRule<const D: usize> {
    /// The pinned effector coordinates: (axis, value [m]).
    fn pinned(&self) -> &[(usize, f64)];
    /// The commanded tensions for the `parameters` (one per pinned coordinate) [N].
    fn tensions(&self, parameters: &[f64]) -> Tensions;
    /// dT/dλ_j, the same for every λ (the rule is affine).
    fn slope(&self, j: usize) -> Tensions;
    /// A typical size of parameter j, the Newton scale of its unknown [N].
    fn scale(&self, j: usize) -> f64;
}

/// The paper's rest rule (MODELS.md §2): the effector's x pinned at `x` [m], ΣT = `tension_sum`
/// [N] split by the unknown horizontal force F0 into T1 = (ΣT − F0)/2, T2 = (ΣT + F0)/2.
#[derive(Debug, Clone, PartialEq)]
pub struct SplitRule {
    pinned: [(usize, f64); 1],
    pub tension_sum: f64,
}

impl SplitRule {
    pub fn new(x: f64, tension_sum: f64) -> Self {
        Self {
            pinned: [(0, x)],
            tension_sum,
        }
    }

    /// The pinned x [m].
    pub fn x(&self) -> f64 {
        self.pinned[0].1
    }
}

impl<const D: usize> RestRule<D> for SplitRule {
    fn pinned(&self) -> &[(usize, f64)] {
        &self.pinned
    }
    fn tensions(&self, parameters: &[f64]) -> Tensions {
        Tensions::pair(crate::controller::split_tensions(
            self.tension_sum,
            parameters[0],
        ))
    }
    fn slope(&self, _: usize) -> Tensions {
        Tensions::pair([-0.5, 0.5])
    }
    /// ΣT: F0 is a share of it.
    fn scale(&self, _: usize) -> f64 {
        self.tension_sum
    }
}

/// A spatial robot at rest at a given pose (MODELS.md §11): every coordinate pinned, the
/// tensions the controller's distribution commands there fixed (no parameter). A model's statics
/// then only checks the balance (the massless cables) or finds its cables' shape.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseRule<const D: usize> {
    pinned: [(usize, f64); D],
    pub tensions: Tensions,
}

impl<const D: usize> PoseRule<D> {
    /// At rest at `pose` [m] under `tensions` [N].
    pub fn new(pose: &crate::robot::Vector<D>, tensions: Tensions) -> Self {
        Self {
            pinned: std::array::from_fn(|k| (k, pose[k])),
            tensions,
        }
    }
}

impl<const D: usize> RestRule<D> for PoseRule<D> {
    fn pinned(&self) -> &[(usize, f64)] {
        &self.pinned
    }
    fn tensions(&self, _: &[f64]) -> Tensions {
        self.tensions
    }
    /// No parameter: never asked.
    fn slope(&self, _: usize) -> Tensions {
        Tensions::zeros(self.tensions.len())
    }
    fn scale(&self, _: usize) -> f64 {
        1.0
    }
}

/// Energy terms of a state [J]; gravity's zero is at z = 0 (the pulleys' height).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Energy {
    /// Kinetic energy of effector and cable.
    pub kinetic: f64,
    /// Elastic (strain) energy of the cable.
    pub elastic: f64,
    /// Gravitational potential energy.
    pub gravity: f64,
}

impl Energy {
    /// Mechanical energy: kinetic + elastic + gravity.
    pub fn total(&self) -> f64 {
        self.kinetic + self.elastic + self.gravity
    }
}

/// Static equilibrium under a [`RestRule`] (MODELS.md §2: the effector's x held at x_ref(0), the
/// PID's force F0 an unknown).
#[derive(Debug, Clone, PartialEq)]
pub struct Equilibrium {
    /// The model's state at rest.
    pub state: Vec<f64>,
    /// The rule's parameters found (the paper's rule: F0 [N]).
    pub parameters: Vec<f64>,
    /// The commanded tensions they give [N].
    pub tensions: Tensions,
    /// Newton iterations used.
    pub iterations: usize,
    /// Largest force residual at the solution [N].
    pub residual: f64,
}

impl Equilibrium {
    /// The paper's rule's force F0 [N] (its first parameter; NaN under a rule without one).
    pub fn force(&self) -> f64 {
        self.parameters.first().copied().unwrap_or(f64::NAN)
    }
}

/// A discrete change of a model's state at a located time (e.g. a lumped node passing a pulley).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ModelEvent {
    /// Time of the event [s] (located to 1e-12 s on the dense output).
    pub t: f64,
    /// Cable concerned (1 … m).
    pub cable: usize,
    /// What happened, in the model's words (e.g. "node 19 leaves the reel").
    pub what: String,
    /// Change of the mechanical energy (kinetic + elastic + gravity) caused by the event [J].
    pub energy_change: f64,
}

/// A cable model of a robot in D dimensions: state, right-hand side, energy and tensions.
///
/// The commanded tensions T_1 … T_m act at the reels; how they reach the effector is the model's
/// physics. Implementations must not allocate in [`CableModel::rhs`].
pub trait CableModel<const D: usize> {
    /// Short name used in files and tables ("elastic", "lumped", "fe").
    fn name(&self) -> &'static str;

    /// The robot the cables belong to (its anchors, effector mass, gravity).
    fn robot(&self) -> &Robot<D>;

    /// Number of cables m.
    fn cables(&self) -> usize {
        self.robot().cables()
    }

    /// Number of components of the model's state vector.
    fn state_len(&self) -> usize;

    /// Static equilibrium under `rule`, all velocities zero (MODELS.md §2).
    fn equilibrium(&mut self, rule: &dyn RestRule<D>) -> Result<Equilibrium, ModelError>;

    /// State derivative for the commanded tensions T_1 … T_m [N] at time `t` [s].
    fn rhs(&mut self, t: f64, state: &[f64], tensions: &[f64], rate: &mut [f64]);

    /// The effector's position and velocity in `state`.
    fn effector(&self, state: &[f64]) -> Effector<D>;

    /// Rate at which each reel takes in cable [m/s] (positive: reeling in). The reels' power is
    /// Σ T_i v_reel,i, so that d/dt (kinetic + elastic + gravity) = Σ T_i v_reel,i − dissipation.
    fn reel_speeds(&self, state: &[f64]) -> PerCable;

    /// [`CableModel::rhs`] and [`CableModel::reel_speeds`] of one state in one call, as the
    /// closed loop needs them: a model whose two share work (the massless cables' structure
    /// matrix) computes it once. The default calls both.
    fn rhs_and_reel_speeds(
        &mut self,
        t: f64,
        state: &[f64],
        tensions: &[f64],
        rate: &mut [f64],
    ) -> PerCable {
        self.rhs(t, state, tensions, rate);
        self.reel_speeds(state)
    }

    /// Whether the model's reels can follow commanded unstrained lengths by moving its reel
    /// ends ([`CableModel::drive_reels`]): massive cables can. Massless cables cannot: their
    /// `length` controller acts through eq. 1's tensions.
    fn reels_follow_lengths(&self) -> bool {
        false
    }

    /// From the next right-hand side on, drives every reel so that its free unstrained length
    /// changes at `rates` l̇0_i [m/s] and `accelerations` l̈0_i [m/s²] (positive: paying out);
    /// the commanded tensions are then not applied. Only called when
    /// [`CableModel::reels_follow_lengths`].
    fn drive_reels(&mut self, _rates: &PerCable, _accelerations: &PerCable) {}

    /// The reels' power into the cables at `state` [W], for the commanded `tensions` and the
    /// `reel_speeds` of the same state: Σ T_i v_reel,i, unless the reels are driven by length
    /// (then the model's reel-end forces do the work).
    fn reel_power(&self, _state: &[f64], tensions: &Tensions, reel_speeds: &PerCable) -> f64 {
        tensions.dot(reel_speeds)
    }

    /// Energy terms of `state`.
    fn energy(&self, state: &[f64]) -> Energy;

    /// Power dissipated inside the model [W] (damping); 0 for conservative models.
    fn dissipation(&self, _state: &[f64]) -> f64 {
        0.0
    }

    /// Number of event functions (0 for models without discrete events).
    fn event_count(&self) -> usize {
        0
    }

    /// Event functions g_k(state): positive while nothing happens; event k occurs when g_k falls
    /// from > 0 to ≤ 0 between two accepted steps. They depend on the model's discrete mode and
    /// are continuous in the state within a mode.
    fn event_functions(&self, _state: &[f64], _out: &mut [f64]) {}

    /// Applies event `index` at time `t` to `state` (in place) and the model's discrete mode, and
    /// says what happened. Called at the located crossing, where g_index ≤ 0.
    fn apply_event(
        &mut self,
        index: usize,
        t: f64,
        _state: &mut [f64],
    ) -> Result<ModelEvent, ModelError> {
        Err(ModelError::State {
            t,
            why: format!("model {} has no event {index}", self.name()),
        })
    }

    /// Each cable's line from its pulley to the effector in `state`, as points [m] (for
    /// drawings: a massive model's free nodes show the sag and the string motion). By default
    /// the straight chord from the anchor.
    fn cable_paths(&self, state: &[f64]) -> Vec<Vec<crate::robot::Vector<D>>> {
        let effector = self.effector(state).position;
        (0..self.cables())
            .map(|i| vec![self.robot().anchor(i), effector])
            .collect()
    }

    /// Names of the model's own output channels, after the common ones.
    fn channel_names(&self) -> Vec<String>;

    /// Values of [`CableModel::channel_names`] for `state` under the tensions `tensions`.
    fn channels(&self, state: &[f64], tensions: &[f64], out: &mut [f64]);

    /// The unit of each of [`CableModel::channel_names`] ("" for a count or a ratio); by
    /// default [`crate::channel::Channel::unit`] of the channels named alike, "" for others.
    fn channel_units(&self) -> Vec<&'static str> {
        self.channel_names()
            .iter()
            .map(|n| crate::channel::Channel::named(n).map_or("", |c| c.unit()))
            .collect()
    }

    /// The model's second-order form for the implicit integrator, if it offers one (its state is
    /// then `[q | q']`).
    fn second_order(&self) -> Option<&dyn SecondOrderForm> {
        None
    }

    /// Mutable access to [`CableModel::second_order`] (its residual reuses the model's buffers).
    fn second_order_mut(&mut self) -> Option<&mut dyn SecondOrderForm> {
        None
    }

    /// The coordinate groups and constrained coordinates at `state`, for the modal analysis.
    fn modal_layout(&self, state: &[f64]) -> ModalLayout;
}

/// A model's own parameters (its keys of the scenario's `[model]` section): what checks a
/// scenario against the model's needs and builds the model from it.
pub trait ModelParams: serde::Serialize {
    type Model: CableModel<2> + Clone + Send + 'static;
    /// The model's own checks of the scenario (e.g. enough modelled cable for the trajectory),
    /// before any work starts.
    fn validate(&self, scenario: &Scenario) -> Result<(), ScenarioError>;
    /// The model for the scenario's robot and cable.
    fn build(&self, scenario: &Scenario) -> Result<Self::Model, ModelError>;
}

/// A boxed model is a model: one dispatcher can hand any model to the closed loop
/// (`ClosedLoop<Box<dyn CableModel<D> + Send>, D>`); the model's own arithmetic stays statically
/// dispatched, and one virtual call per right-hand side is negligible next to it.
impl<const D: usize, M: CableModel<D> + ?Sized> CableModel<D> for Box<M> {
    fn name(&self) -> &'static str {
        (**self).name()
    }
    fn robot(&self) -> &Robot<D> {
        (**self).robot()
    }
    fn cables(&self) -> usize {
        (**self).cables()
    }
    fn state_len(&self) -> usize {
        (**self).state_len()
    }
    fn equilibrium(&mut self, rule: &dyn RestRule<D>) -> Result<Equilibrium, ModelError> {
        (**self).equilibrium(rule)
    }
    fn rhs(&mut self, t: f64, state: &[f64], tensions: &[f64], rate: &mut [f64]) {
        (**self).rhs(t, state, tensions, rate)
    }
    fn effector(&self, state: &[f64]) -> Effector<D> {
        (**self).effector(state)
    }
    fn reel_speeds(&self, state: &[f64]) -> PerCable {
        (**self).reel_speeds(state)
    }
    fn rhs_and_reel_speeds(
        &mut self,
        t: f64,
        state: &[f64],
        tensions: &[f64],
        rate: &mut [f64],
    ) -> PerCable {
        (**self).rhs_and_reel_speeds(t, state, tensions, rate)
    }
    fn reels_follow_lengths(&self) -> bool {
        (**self).reels_follow_lengths()
    }
    fn drive_reels(&mut self, rates: &PerCable, accelerations: &PerCable) {
        (**self).drive_reels(rates, accelerations)
    }
    fn reel_power(&self, state: &[f64], tensions: &Tensions, reel_speeds: &PerCable) -> f64 {
        (**self).reel_power(state, tensions, reel_speeds)
    }
    fn energy(&self, state: &[f64]) -> Energy {
        (**self).energy(state)
    }
    fn dissipation(&self, state: &[f64]) -> f64 {
        (**self).dissipation(state)
    }
    fn event_count(&self) -> usize {
        (**self).event_count()
    }
    fn event_functions(&self, state: &[f64], out: &mut [f64]) {
        (**self).event_functions(state, out)
    }
    fn apply_event(
        &mut self,
        index: usize,
        t: f64,
        state: &mut [f64],
    ) -> Result<ModelEvent, ModelError> {
        (**self).apply_event(index, t, state)
    }
    fn channel_names(&self) -> Vec<String> {
        (**self).channel_names()
    }
    fn channels(&self, state: &[f64], tensions: &[f64], out: &mut [f64]) {
        (**self).channels(state, tensions, out)
    }
    fn channel_units(&self) -> Vec<&'static str> {
        (**self).channel_units()
    }
    fn second_order(&self) -> Option<&dyn SecondOrderForm> {
        (**self).second_order()
    }
    fn second_order_mut(&mut self) -> Option<&mut dyn SecondOrderForm> {
        (**self).second_order_mut()
    }
    fn modal_layout(&self, state: &[f64]) -> ModalLayout {
        (**self).modal_layout(state)
    }
}
