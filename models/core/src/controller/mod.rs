//! Controllers: from the reference, the measured effector state (x, z, ẋ, ż) and the
//! controller's own states, the commanded tensions [T1, T2]. They know nothing of cable models;
//! the closed loop ([`crate::closed_loop`]) integrates their states with the model's, clamps their
//! tensions to the limits and tells them when it did (anti-windup).
//!
//! | kind | file | acts on | states |
//! |---|---|---|---|
//! | `pid` (the paper's, default) | [`pid`] | x, ΣT fixed | w, f |
//! | `pid-xz` | [`pid_xz`] | x and z through W | w_x, f_x, w_z, f_z |
//! | `computed-torque` | [`computed_torque`] | x and z, feedback-linearised | ∫e_x, ∫e_z, velocity filter (4) |
//! | `lqr` | [`lqr`] | x and z, state feedback | ∫e_x, ∫e_z, velocity filter (4) |

pub mod computed_torque;
pub mod distribution;
pub mod error_states;
pub mod lqr;
pub mod pid;
pub mod pid_xz;
pub mod velocity_filter;

pub use distribution::{
    TensionDistribution, TensionLimits, geometric_stiffness, split_tensions, structure_matrix,
    tensions_for_force,
};
pub use pid::{PaperPid, Pid, PidState};

use crate::Vector2;
use crate::model::Effector;
use crate::scenario::{ControllerKind, Scenario};

/// The reference at one instant: position, velocity and acceleration [m, m/s, m/s²] of the
/// effector (x from `step5`; z the held start height, or z0 where z is free).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Reference {
    pub position: Vector2<f64>,
    pub velocity: Vector2<f64>,
    pub acceleration: Vector2<f64>,
}

/// What a controller asks for at one instant, before the tension limits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Output {
    /// The horizontal force the controller asks of the cables [N] (the paper's F; for the
    /// controllers acting through W, the x component of the desired force).
    pub force: f64,
    /// Commanded tensions [T1, T2] [N], unclamped.
    pub tensions: [f64; 2],
}

/// The rest the controller must hold at a run's start or a linearisation point: the model's
/// static equilibrium's tensions and the paper PID's force F0 (T2 − T1 in exact arithmetic).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rest {
    pub tensions: [f64; 2],
    pub force: f64,
}

/// The start of an implicit step as a controller sees it.
#[derive(Debug, Clone, Copy)]
pub struct StepStart<'a> {
    pub reference: Reference,
    pub effector: Effector,
    pub states: &'a [f64],
    /// Whether the command was clamped at the step's start (anti-windup holds the integrals).
    pub saturated: bool,
}

/// A controller of the two-cable robot. Implementations are pure functions of their inputs.
pub trait Controller: Send + Sync + std::fmt::Debug {
    /// Which controller this is.
    fn kind(&self) -> ControllerKind;

    /// Number of the controller's own states.
    fn state_len(&self) -> usize;

    /// Whether the tensions depend on the effector's z, and on its velocity (the implicit
    /// iteration matrix then has those columns).
    fn measures(&self) -> Measures;

    /// The force and tensions for `reference`, the measured `effector` and the `states`.
    fn output(&self, reference: &Reference, effector: &Effector, states: &[f64]) -> Output;

    /// d/dt of the states (`rate`, [`Controller::state_len`] long); `saturated`: the command is
    /// clamped (anti-windup).
    fn state_rate(
        &self,
        reference: &Reference,
        effector: &Effector,
        states: &[f64],
        saturated: bool,
        rate: &mut [f64],
    );

    /// The states at the end of an implicit step of size h [s] from `start`, for the reference
    /// and effector at its end, by an A-stable second-order rule (the trapezoidal rule, MODELS.md
    /// FE.9.3), into `out`.
    fn trapezoidal_step(
        &self,
        h: f64,
        start: &StepStart,
        reference: &Reference,
        effector: &Effector,
        out: &mut [f64],
    );

    /// States that command the `rest` tensions at zero error and rest (zero where the controller
    /// has no integral action to hold them).
    fn rest_states(&self, reference: &Reference, effector: &Effector, rest: &Rest, out: &mut [f64]);

    /// Whether the controller reads the reference's velocity and acceleration (feedforward);
    /// the loop skips computing them otherwise (the elastic RHS is ~15 ns: it shows).
    fn uses_reference_derivatives(&self) -> bool {
        false
    }

    /// Step [m, m/s] of the differences that give the implicit iteration matrix dT/dq: a unit
    /// step is exact for controllers affine in the measurement (the paper's PID).
    fn difference_step(&self) -> f64 {
        1e-6
    }

    /// Re-targets a controller designed at a height (the LQR's linearisation point) once the
    /// held start height z0 [m] is known.
    fn hold_height(&mut self, _z0: f64) -> Result<(), ControlError> {
        Ok(())
    }

    /// Named gains for the run's metrics (e.g. the LQR's K), row-major.
    fn gains(&self) -> Vec<(&'static str, Vec<f64>)> {
        Vec::new()
    }
}

/// What a controller's tensions depend on besides the effector's x.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Measures {
    pub z: bool,
    pub velocity: bool,
}

/// Why a controller could not be designed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ControlError {
    #[error("LQR design at (x, z) = ({x}, {z}) m failed: {why}")]
    Design { x: f64, z: f64, why: String },
}

/// The robot as the controllers see it: rigid massless cables from pulleys A1 = (0, 0) and
/// A2 = (d, 0) to an effector of mass M under gravity g.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plant {
    pub anchor_distance: f64,
    pub effector_mass: f64,
    pub gravity: f64,
}

impl Plant {
    pub fn new(scenario: &Scenario) -> Self {
        Self {
            anchor_distance: scenario.robot.anchor_distance,
            effector_mass: scenario.robot.effector_mass,
            gravity: scenario.robot.gravity,
        }
    }

    /// Tensions that give the effector at `p` the acceleration `a` [m/s²] on rigid massless
    /// cables: M a = W T + M g ⇒ T = W⁻¹ M (a − g), g = (0, −g).
    pub fn tensions_for_acceleration(&self, p: Vector2<f64>, a: Vector2<f64>) -> [f64; 2] {
        let force = self.effector_mass * Vector2::new(a.x, a.y + self.gravity);
        tensions_for_force(p, self.anchor_distance, force)
    }

    /// The acceleration [m/s²] the tensions give the effector at `p` on rigid massless cables.
    pub fn acceleration(&self, p: Vector2<f64>, tensions: [f64; 2]) -> Vector2<f64> {
        let w = structure_matrix(p, self.anchor_distance);
        w * Vector2::new(tensions[0], tensions[1]) / self.effector_mass
            - Vector2::new(0.0, self.gravity)
    }
}

/// The scenario's controller. A controller designed at the held height (the LQR) is designed
/// when the closed loop knows it ([`Controller::hold_height`]).
pub fn build(scenario: &Scenario) -> AnyController {
    let c = &scenario.controller;
    let plant = Plant::new(scenario);
    match c.kind {
        ControllerKind::Pid => AnyController::Pid(PaperPid::from(c)),
        ControllerKind::PidXz => AnyController::PidXz(pid_xz::PidXz::new(c, plant)),
        ControllerKind::ComputedTorque => {
            AnyController::ComputedTorque(computed_torque::ComputedTorque::new(c, plant))
        }
        ControllerKind::Lqr => AnyController::Lqr(Box::new(lqr::Lqr::new(scenario, plant))),
    }
}

/// Every controller, dispatched by a match rather than a virtual call: the elastic model's RHS
/// is ~15 ns, and the compiler inlines the paper PID's arithmetic through the match (a boxed
/// trait object cost 7.6 ns per RHS, 12.8 → 20.4 ns).
#[derive(Debug, Clone)]
pub enum AnyController {
    Pid(PaperPid),
    PidXz(pid_xz::PidXz),
    ComputedTorque(computed_torque::ComputedTorque),
    Lqr(Box<lqr::Lqr>),
}

macro_rules! each {
    ($self:expr, $c:ident => $body:expr) => {
        match $self {
            AnyController::Pid($c) => $body,
            AnyController::PidXz($c) => $body,
            AnyController::ComputedTorque($c) => $body,
            AnyController::Lqr($c) => $body,
        }
    };
}

impl Controller for AnyController {
    fn kind(&self) -> ControllerKind {
        each!(self, c => c.kind())
    }
    fn state_len(&self) -> usize {
        each!(self, c => c.state_len())
    }
    fn measures(&self) -> Measures {
        each!(self, c => c.measures())
    }
    #[inline]
    fn output(&self, reference: &Reference, effector: &Effector, states: &[f64]) -> Output {
        each!(self, c => c.output(reference, effector, states))
    }
    #[inline]
    fn state_rate(
        &self,
        reference: &Reference,
        effector: &Effector,
        states: &[f64],
        saturated: bool,
        rate: &mut [f64],
    ) {
        each!(self, c => c.state_rate(reference, effector, states, saturated, rate))
    }
    fn trapezoidal_step(
        &self,
        h: f64,
        start: &StepStart,
        reference: &Reference,
        effector: &Effector,
        out: &mut [f64],
    ) {
        each!(self, c => c.trapezoidal_step(h, start, reference, effector, out))
    }
    fn rest_states(
        &self,
        reference: &Reference,
        effector: &Effector,
        rest: &Rest,
        out: &mut [f64],
    ) {
        each!(self, c => c.rest_states(reference, effector, rest, out))
    }
    fn uses_reference_derivatives(&self) -> bool {
        each!(self, c => c.uses_reference_derivatives())
    }
    fn difference_step(&self) -> f64 {
        each!(self, c => c.difference_step())
    }
    fn hold_height(&mut self, z0: f64) -> Result<(), ControlError> {
        each!(self, c => c.hold_height(z0))
    }
    fn gains(&self) -> Vec<(&'static str, Vec<f64>)> {
        each!(self, c => c.gains())
    }
}
