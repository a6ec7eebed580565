//! Controllers: from the reference, the measured effector state (position and velocity) and the
//! controller's own states, the wrench asked of the cables and the commanded tensions T_1 … T_m.
//! They know nothing of cable models; the closed loop ([`crate::closed_loop`]) integrates their
//! states with the model's, clamps their tensions to the limits and tells them when it did
//! (anti-windup). The robot's space is the type parameter D.
//!
//! # Examples
//!
//! A controller of one's own: a proportional pull on x with ΣT fixed, split as the paper's PID
//! splits it (no states of its own).
//!
//! ```
//! use cdpr_core::controller::{Controller, Measures, Output, Reference, Rest, StepStart, split_tensions};
//! use cdpr_core::robot::{Effector, Tensions, Vector};
//! use cdpr_core::scenario::ControllerKind;
//!
//! #[derive(Debug)]
//! struct Spring { gain: f64, tension_sum: f64 }
//!
//! impl Controller<2> for Spring {
//!     fn kind(&self) -> ControllerKind { ControllerKind::Pid }
//!     fn state_len(&self) -> usize { 0 }
//!     fn measures(&self) -> Measures { Measures { all_axes: false, velocity: false } }
//!     fn output(&self, reference: &Reference<2>, effector: &Effector<2>, _: &[f64]) -> Output<2> {
//!         let force = self.gain * (reference.position.x - effector.position.x);
//!         Output {
//!             wrench: Vector::<2>::new(force, 0.0),
//!             tensions: Tensions::pair(split_tensions(self.tension_sum, force)),
//!         }
//!     }
//!     fn state_rate(&self, _: &Reference<2>, _: &Effector<2>, _: &[f64], _: bool, _: &mut [f64]) {}
//!     fn trapezoidal_step(&self, _: f64, _: &StepStart<2>, _: &Reference<2>, _: &Effector<2>, _: &mut [f64]) {}
//!     fn rest_states(&self, _: &Reference<2>, _: &Effector<2>, _: &Rest, _: &mut [f64]) {}
//! }
//!
//! let c = Spring { gain: 1000.0, tension_sum: 200.0 };
//! let reference = Reference { position: Vector::<2>::new(0.6, -0.02), ..Reference::default() };
//! let effector = Effector { position: Vector::<2>::new(0.5, -0.02), velocity: Vector::zeros() };
//! let out = c.output(&reference, &effector, &[]);
//! assert!((out.tensions[1] - out.tensions[0] - 100.0).abs() < 1e-12, "F = 100 N toward A2");
//! ```
//!
//! | kind | file | acts on | states |
//! |---|---|---|---|
//! | `pid` (the paper's, default) | [`pid`] | x, ΣT fixed | w, f |
//! | `pid-xz` | [`pid_xz`] | x and z through W | w_x, f_x, w_z, f_z |
//! | `computed-torque` | [`computed_torque`] | x and z, feedback-linearised | ∫e_x, ∫e_z, velocity filter (4) |
//! | `lqr` | [`lqr`] | x and z, state feedback | ∫e_x, ∫e_z, velocity filter (4) |
//! | `length` (spatial robots) | [`length`] | the reels' unstrained lengths, no feedback | none |
//!
//! On a spatial robot every kind acts on x, y and z (three filters more), and a redundant robot's
//! wrench becomes tensions by the scenario's distribution ([`TensionSolver`]).

pub mod computed_torque;
pub mod distribution;
pub mod error_states;
pub mod length;
pub mod lqr;
pub mod pid;
pub mod pid_xz;
pub mod velocity_filter;

pub use distribution::{TensionDistribution, TensionLimits, TensionSolver, split_tensions};
pub use pid::{PaperPid, Pid, PidState};

use crate::robot::{Effector, Robot, Tensions, Vector, along_vertical};
use crate::scenario::{ControllerKind, Scenario};

/// The reference at one instant: position, velocity and acceleration [m, m/s, m/s²] of the
/// effector (x from `step5`; the other coordinates the held start, or the start where they are
/// free).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reference<const D: usize> {
    pub position: Vector<D>,
    pub velocity: Vector<D>,
    pub acceleration: Vector<D>,
}

impl<const D: usize> Default for Reference<D> {
    fn default() -> Self {
        Self {
            position: Vector::zeros(),
            velocity: Vector::zeros(),
            acceleration: Vector::zeros(),
        }
    }
}

/// What a controller asks for at one instant, before the tension limits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Output<const D: usize> {
    /// The force the controller asks of the cables on the effector [N]. The paper's PID asks
    /// for the horizontal F only (its split fixes ΣT instead of a vertical force): the other
    /// components are 0 for it.
    pub wrench: Vector<D>,
    /// Commanded tensions T_1 … T_m [N], unclamped.
    pub tensions: Tensions,
}

/// The rest the controller must hold at a run's start or a linearisation point: the model's
/// static equilibrium's tensions and the paper PID's force F0 (T2 − T1 in exact arithmetic).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rest {
    pub tensions: Tensions,
    pub force: f64,
}

/// The start of an implicit step as a controller sees it.
#[derive(Debug, Clone, Copy)]
pub struct StepStart<'a, const D: usize> {
    pub reference: Reference<D>,
    pub effector: Effector<D>,
    pub states: &'a [f64],
    /// Whether the command was clamped at the step's start (anti-windup holds the integrals).
    pub saturated: bool,
}

/// A controller of a robot in D dimensions. Implementations are pure functions of their inputs.
pub trait Controller<const D: usize>: Send + Sync + std::fmt::Debug {
    /// Which controller this is.
    fn kind(&self) -> ControllerKind;

    /// Number of the controller's own states.
    fn state_len(&self) -> usize;

    /// Which of the effector's coordinates the tensions depend on besides x, and whether on its
    /// velocity (the implicit iteration matrix then has those columns).
    fn measures(&self) -> Measures;

    /// The wrench and tensions for `reference`, the measured `effector` and the `states`.
    fn output(&self, reference: &Reference<D>, effector: &Effector<D>, states: &[f64])
    -> Output<D>;

    /// d/dt of the states (`rate`, [`Controller::state_len`] long); `saturated`: the command is
    /// clamped (anti-windup).
    fn state_rate(
        &self,
        reference: &Reference<D>,
        effector: &Effector<D>,
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
        start: &StepStart<D>,
        reference: &Reference<D>,
        effector: &Effector<D>,
        out: &mut [f64],
    );

    /// States that command the `rest` tensions at zero error and rest (zero where the controller
    /// has no integral action to hold them).
    fn rest_states(
        &self,
        reference: &Reference<D>,
        effector: &Effector<D>,
        rest: &Rest,
        out: &mut [f64],
    );

    /// Each state's factor to metres in an error norm
    /// (`cdpr_numerics::SecondOrderSystem::tail_weights`): a state in other units (a filtered
    /// velocity) enters as the position error that commands as much. Default: 1 (states in
    /// metres, and integrals in m s as they are).
    fn state_weights(&self, out: &mut [f64]) {
        out.fill(1.0);
    }

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

    /// Calibrates a controller to the pose [m] the loop starts at rest at (the length
    /// controller's flex-none calibration: a print starts where its first layer begins).
    fn start_at(&mut self, _pose: &Vector<D>) {}

    /// The unstrained lengths l0_i [m] the reels pay out for `reference`, for a controller
    /// that drives its reels by length (None: the reels pull with commanded tensions, and the
    /// model derives l0 from them).
    fn reel_lengths_for(&self, _reference: &Reference<D>) -> Option<crate::robot::PerCable> {
        None
    }

    /// Named gains for the run's metrics (e.g. the LQR's K), row-major.
    fn gains(&self) -> Vec<(&'static str, Vec<f64>)> {
        Vec::new()
    }
}

/// What a controller's tensions depend on besides the effector's x.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Measures {
    /// Every coordinate of the effector (the vertical, and y in space), not only x.
    pub all_axes: bool,
    pub velocity: bool,
}

/// Why a controller could not be designed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ControlError {
    #[error("LQR design at {point:?} m failed: {why}")]
    Design { point: Vec<f64>, why: String },
}

/// Tensions that give the effector at `p` the acceleration `a` [m/s²] on rigid massless
/// cables: M a = W T + M g⃗ ⇒ T = W⁻¹ M (a − g⃗) (robots with as many cables as axes; NaN
/// tensions otherwise, which the runner refuses).
pub fn tensions_for_acceleration<const D: usize>(
    robot: &Robot<D>,
    p: &Vector<D>,
    a: &Vector<D>,
) -> Tensions {
    let v = crate::robot::vertical::<D>();
    let mut lift = *a;
    lift[v] = a[v] + robot.gravity;
    let force = lift * robot.effector_mass;
    robot
        .tensions_for_force(p, &force)
        .unwrap_or_else(|| Tensions::from_fn(robot.cables(), |_| f64::NAN))
}

/// The acceleration [m/s²] the tensions give the effector at `p` on rigid massless cables.
pub fn acceleration<const D: usize>(
    robot: &Robot<D>,
    p: &Vector<D>,
    tensions: &[f64],
) -> Vector<D> {
    robot.structure_matrix(p).force(tensions) / robot.effector_mass - along_vertical(robot.gravity)
}

/// The scenario's controller for `robot`. A controller designed at the held height (the LQR) is
/// designed when the closed loop knows it ([`Controller::hold_height`]).
pub fn build<const D: usize>(scenario: &Scenario, robot: Robot<D>) -> AnyController<D> {
    let c = &scenario.controller;
    match c.kind {
        // A spatial robot of three or more cables: the paper's gains on every axis.
        ControllerKind::Pid if robot.cables() > 2 => {
            AnyController::PidXz(pid_xz::PidXz::paper_gains_per_axis(c, robot))
        }
        ControllerKind::Pid => AnyController::Pid(PaperPid::from(c)),
        ControllerKind::PidXz => AnyController::PidXz(pid_xz::PidXz::new(c, robot)),
        ControllerKind::ComputedTorque => {
            AnyController::ComputedTorque(computed_torque::ComputedTorque::new(c, robot))
        }
        ControllerKind::Lqr => AnyController::Lqr(lqr::Lqr::new(scenario, robot)),
        ControllerKind::Length => {
            AnyController::Length(length::LengthControl::new(scenario, robot))
        }
    }
}

/// Every controller, dispatched by a match rather than a virtual call: the elastic model's RHS
/// is ~15 ns, and the compiler inlines the paper PID's arithmetic through the match (a boxed
/// trait object cost 7.6 ns per RHS, 12.8 → 20.4 ns).
#[derive(Debug, Clone)]
pub enum AnyController<const D: usize> {
    Pid(PaperPid),
    PidXz(pid_xz::PidXz<D>),
    ComputedTorque(computed_torque::ComputedTorque<D>),
    Lqr(lqr::Lqr<D>),
    Length(length::LengthControl<D>),
}

/// `$body` with `$c` bound to the controller inside `$self`, whichever it is.
macro_rules! dispatch {
    ($self:expr, $c:ident => $body:expr) => {
        match $self {
            AnyController::Pid($c) => $body,
            AnyController::PidXz($c) => $body,
            AnyController::ComputedTorque($c) => $body,
            AnyController::Lqr($c) => $body,
            AnyController::Length($c) => $body,
        }
    };
}

impl<const D: usize> Controller<D> for AnyController<D> {
    fn kind(&self) -> ControllerKind {
        dispatch!(self, c => Controller::<D>::kind(c))
    }
    fn state_len(&self) -> usize {
        dispatch!(self, c => Controller::<D>::state_len(c))
    }
    fn measures(&self) -> Measures {
        dispatch!(self, c => Controller::<D>::measures(c))
    }
    fn state_weights(&self, out: &mut [f64]) {
        dispatch!(self, c => Controller::<D>::state_weights(c, out))
    }
    #[inline]
    fn output(
        &self,
        reference: &Reference<D>,
        effector: &Effector<D>,
        states: &[f64],
    ) -> Output<D> {
        dispatch!(self, c => c.output(reference, effector, states))
    }
    #[inline]
    fn state_rate(
        &self,
        reference: &Reference<D>,
        effector: &Effector<D>,
        states: &[f64],
        saturated: bool,
        rate: &mut [f64],
    ) {
        dispatch!(self, c => c.state_rate(reference, effector, states, saturated, rate))
    }
    fn trapezoidal_step(
        &self,
        h: f64,
        start: &StepStart<D>,
        reference: &Reference<D>,
        effector: &Effector<D>,
        out: &mut [f64],
    ) {
        dispatch!(self, c => c.trapezoidal_step(h, start, reference, effector, out))
    }
    fn rest_states(
        &self,
        reference: &Reference<D>,
        effector: &Effector<D>,
        rest: &Rest,
        out: &mut [f64],
    ) {
        dispatch!(self, c => c.rest_states(reference, effector, rest, out))
    }
    fn uses_reference_derivatives(&self) -> bool {
        dispatch!(self, c => Controller::<D>::uses_reference_derivatives(c))
    }
    fn difference_step(&self) -> f64 {
        dispatch!(self, c => Controller::<D>::difference_step(c))
    }
    fn hold_height(&mut self, z0: f64) -> Result<(), ControlError> {
        dispatch!(self, c => Controller::<D>::hold_height(c, z0))
    }
    fn start_at(&mut self, pose: &Vector<D>) {
        dispatch!(self, c => Controller::<D>::start_at(c, pose))
    }
    fn reel_lengths_for(&self, reference: &Reference<D>) -> Option<crate::robot::PerCable> {
        dispatch!(self, c => Controller::<D>::reel_lengths_for(c, reference))
    }
    fn gains(&self) -> Vec<(&'static str, Vec<f64>)> {
        dispatch!(self, c => Controller::<D>::gains(c))
    }
}
