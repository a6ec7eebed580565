//! The interface through which a cable model plugs into the closed loop.
//!
//! A model owns its physical state layout (effector and cable coordinates and velocities), computes
//! its right-hand side for given commanded tensions, and reports the effector, its energy and the
//! extra output channels it has. It knows nothing of the controller, the trajectory or the
//! integrator; the closed loop ([`crate::closed_loop`]) knows nothing of cables.

use crate::modal_layout::ModalLayout;
use crate::scenario::{Scenario, ScenarioError};
use crate::second_order::SecondOrderForm;
use nalgebra::Vector2;

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
    /// The controller could not be designed for the loop's rest point.
    #[error(transparent)]
    Control(#[from] crate::controller::ControlError),
    /// The state left the model's domain (e.g. a node ordering the pulley rule forbids).
    #[error("invalid model state at t = {t} s: {why}")]
    State { t: f64, why: String },
}

/// MODELS.md §2 holds the effector's x fixed for the static equilibrium: it must lie strictly
/// between the pulleys A1 = (0, 0) and A2 = (d, 0).
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

/// Position and velocity of the effector (the point mass C of the paper) [m, m/s].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Effector {
    pub position: Vector2<f64>,
    pub velocity: Vector2<f64>,
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

/// Static equilibrium of MODELS.md §2: effector x held at x_ref(0), the PID's force F0 an unknown.
#[derive(Debug, Clone, PartialEq)]
pub struct Equilibrium {
    /// The model's state at rest.
    pub state: Vec<f64>,
    /// Horizontal force F0 [N] the tension distribution must supply: T1 = (ΣT − F0)/2, T2 = (ΣT + F0)/2.
    pub force: f64,
    /// Newton iterations used.
    pub iterations: usize,
    /// Largest force residual at the solution [N].
    pub residual: f64,
}

/// A discrete change of a model's state at a located time (e.g. a lumped node passing a pulley).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ModelEvent {
    /// Time of the event [s] (located to 1e-12 s on the dense output).
    pub t: f64,
    /// Cable concerned (1 or 2).
    pub cable: usize,
    /// What happened, in the model's words (e.g. "node 19 leaves the reel").
    pub what: String,
    /// Change of the mechanical energy (kinetic + elastic + gravity) caused by the event [J].
    pub energy_change: f64,
}

/// A cable model of the two-cable planar CDPR: state, right-hand side, energy and tensions.
///
/// The commanded tensions `[T1, T2]` act at the reels; how they reach the effector is the model's
/// physics. Implementations must not allocate in [`CableModel::rhs`].
pub trait CableModel {
    /// Short name used in files and tables ("elastic", "lumped", "fe").
    fn name(&self) -> &'static str;

    /// Number of components of the model's state vector.
    fn state_len(&self) -> usize;

    /// Static equilibrium with the effector's x fixed at `effector_x` [m] and commanded tensions
    /// T1 = (ΣT − F0)/2, T2 = (ΣT + F0)/2, F0 an unknown; all velocities zero (MODELS.md §2).
    fn equilibrium(&mut self, effector_x: f64, tension_sum: f64)
    -> Result<Equilibrium, ModelError>;

    /// State derivative for the commanded tensions `[T1, T2]` [N] at time `t` [s].
    fn rhs(&mut self, t: f64, state: &[f64], tensions: [f64; 2], rate: &mut [f64]);

    /// The effector's position and velocity in `state`.
    fn effector(&self, state: &[f64]) -> Effector;

    /// Rate at which each reel takes in cable [m/s] (positive: reeling in). The reels' power is
    /// Σ T_i v_reel,i, so that d/dt (kinetic + elastic + gravity) = Σ T_i v_reel,i − dissipation.
    fn reel_speeds(&self, state: &[f64]) -> [f64; 2];

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

    /// Names of the model's own output channels (with units), after the common ones.
    fn channel_names(&self) -> Vec<String>;

    /// Values of [`CableModel::channel_names`] for `state` under the tensions `[T1, T2]`.
    fn channels(&self, state: &[f64], tensions: [f64; 2], out: &mut [f64]);

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
    type Model: CableModel + Clone + Send + 'static;
    /// The model's own checks of the scenario (e.g. enough modelled cable for the trajectory),
    /// before any work starts.
    fn validate(&self, scenario: &Scenario) -> Result<(), ScenarioError>;
    /// The model for the scenario's robot and cable.
    fn build(&self, scenario: &Scenario) -> Result<Self::Model, ModelError>;
}

/// A boxed model is a model: one dispatcher can hand any model to the closed loop
/// (`ClosedLoop<Box<dyn CableModel + Send>>`); the model's own arithmetic stays statically
/// dispatched, and one virtual call per right-hand side is negligible next to it.
impl<M: CableModel + ?Sized> CableModel for Box<M> {
    fn name(&self) -> &'static str {
        (**self).name()
    }
    fn state_len(&self) -> usize {
        (**self).state_len()
    }
    fn equilibrium(
        &mut self,
        effector_x: f64,
        tension_sum: f64,
    ) -> Result<Equilibrium, ModelError> {
        (**self).equilibrium(effector_x, tension_sum)
    }
    fn rhs(&mut self, t: f64, state: &[f64], tensions: [f64; 2], rate: &mut [f64]) {
        (**self).rhs(t, state, tensions, rate)
    }
    fn effector(&self, state: &[f64]) -> Effector {
        (**self).effector(state)
    }
    fn reel_speeds(&self, state: &[f64]) -> [f64; 2] {
        (**self).reel_speeds(state)
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
    fn channels(&self, state: &[f64], tensions: [f64; 2], out: &mut [f64]) {
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
