//! The closed loop of the paper's Fig. 4: reference → controller → tension limits → cable
//! model, as one ODE ([`ClosedLoop`]), in first-order form for DOPRI5 and in second-order form
//! for generalised-α ([`implicit`]). The runner that integrates it is [`crate::runner`].
//!
//! State layout: `[model state (n) | controller states (c) | W | D]`: the controller's own states
//! (the paper's PID: integral w and filter f), then two audit states excluded from the error
//! norm, the reels' work W = ∫ Σ T_i v_reel,i dt (or the work of a model's reels driven by
//! length, [`CableModel::reel_power`]) and the energy dissipated inside the model D.
//! They make the energy balance E(t) − E(0) − W(t) + D(t) − ΣΔE = 0 (ΔE the energy changes of
//! model events) a channel of every run.

mod implicit;
mod rest;
mod spatial;

pub use rest::LoopError;
pub use spatial::Path;

use crate::controller::{self, AnyController, Controller, Reference, TensionLimits};
use crate::model::CableModel;
use crate::robot::distribution::BOX_TOLERANCE;
use crate::robot::{Effector, PerCable, Robot, Tensions, Vector};
use crate::scenario::{ControllerKind, Scenario};
use crate::shaper::Impulses;
use crate::trajectory::Step5;
use cdpr_numerics::OdeSystem;

/// Where the commanded tensions come from.
pub enum Actuation {
    /// The scenario's controller, clamped to the tension limits.
    Controller,
    /// Tensions prescribed as functions of time [s] → T_1 … T_m [N]; the controller states
    /// still integrate the error but do not act (energy and verification runs).
    Prescribed(Box<dyn Fn(f64) -> Tensions + Send + Sync>),
}

/// What the controller commands at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Command {
    /// x_ref [m].
    pub reference: f64,
    /// e = x_ref − x [m].
    pub error: f64,
    /// The controller's horizontal force F [N] (the x component of its wrench; pulls toward A2
    /// when positive).
    pub force: f64,
    /// Commanded tensions T_1 … T_m [N], inside the limits.
    pub tensions: Tensions,
    /// Whether the limits clamped the controller's tensions.
    pub saturated: bool,
}

/// Number of audit states (W, D) after the controller's.
pub const AUDIT_STATES: usize = 2;

/// Most controller states a loop holds (stack buffers of the implicit step): the integral and
/// filter states of the controllers acting on every axis of a spatial robot take 9.
pub const MAX_CONTROLLER_STATES: usize = 12;

/// Model + controller as one [`OdeSystem`].
pub struct ClosedLoop<M: CableModel<D>, const D: usize> {
    pub model: M,
    pub trajectory: Step5,
    /// The input shaper the move is convolved with (one unit impulse: unshaped); None while
    /// the scenario's shaper design is still "auto" (the runner refuses to run then).
    pub shaper: Option<Impulses>,
    pub controller: AnyController<D>,
    /// A spatial robot's move (`trajectory.start` → `end`) or a print; None: the plane's
    /// x1 → x2 with the other coordinates held.
    pub path: Option<Path<D>>,
    pub limits: TensionLimits,
    pub actuation: Actuation,
    /// ΣT of the start equilibrium (MODELS.md §2) [N].
    pub tension_sum: f64,
    /// The held start position once the start equilibrium is known (the reference's
    /// coordinates but x).
    hold: Option<Vector<D>>,
    /// Whether the controller reads the reference's velocity and acceleration.
    feedforward: bool,
    /// The tensions of the last rest state ([`ClosedLoop::rest_state`]) [N].
    rest_tensions: Tensions,
    /// The start of the current implicit step.
    step_start: implicit::StepStart<D>,
    /// Two residuals for the tension columns of the implicit iteration matrix (allocated once).
    residual_scratch: [Vec<f64>; 2],
    /// Whether the reels follow the controller's unstrained lengths in the model itself (the
    /// `length` controller on massive cables): see [`ClosedLoop::drives_reels_by_length`].
    length_drive: bool,
    /// The last right-hand side's time and commanded tensions.
    last_rhs: LastRhs,
}

/// When the last right-hand side was evaluated and what it commanded then.
#[derive(Default)]
struct LastRhs {
    t: f64,
    tensions: Tensions,
}

/// Central-difference half-step in time [s] for the commanded lengths' rate and acceleration:
/// the rate's truncation h² l0‴/6 stays below 2e-7 m/s for length jerks ≲ 1e2 m/s³ (3e-8 m
/// over a 0.2 s move), the acceleration's round-off 1e-16 m / h² = 1e-8 m/s², and the reel's
/// velocity loop corrects what remains. Three evaluations of the lengths per right-hand side
/// (each a distribution at the reference) are the drive's cost.
const LENGTH_DIFFERENCE_STEP: f64 = 1e-4;

impl<M: CableModel<D>, const D: usize> ClosedLoop<M, D> {
    /// The loop for `model` with the scenario's controller, limits and trajectory; refused when
    /// the controller has more states than the loop's buffers hold.
    pub fn new(model: M, scenario: &Scenario) -> Result<Self, LoopError> {
        let controller = controller::build(scenario, *model.robot());
        let c = controller.state_len();
        if c > MAX_CONTROLLER_STATES {
            return Err(LoopError::ControllerStates {
                controller: scenario.controller.kind.name(),
                states: c,
            });
        }
        let feedforward = controller.uses_reference_derivatives();
        let m = model.cables();
        let path = spatial::path(scenario, m);
        let length_drive =
            scenario.controller.kind == ControllerKind::Length && model.reels_follow_lengths();
        Ok(Self {
            model,
            trajectory: Step5::from(&scenario.trajectory),
            shaper: scenario.trajectory.impulses().ok().flatten(),
            controller,
            path,
            // Reels driven by length: the cables pull with what their strain gives.
            limits: if scenario.controller.kind == ControllerKind::Length {
                TensionLimits {
                    t_min: f64::NEG_INFINITY,
                    t_max: f64::INFINITY,
                }
            } else {
                TensionLimits::from(&scenario.controller)
            },
            actuation: Actuation::Controller,
            tension_sum: scenario.controller.tension_sum,
            hold: None,
            feedforward,
            rest_tensions: Tensions::zeros(m),
            step_start: implicit::StepStart::default(),
            residual_scratch: Default::default(),
            length_drive,
            last_rhs: LastRhs::default(),
        })
    }

    /// Whether the reels are driven by length inside the model (the `length` controller on a
    /// model whose reels follow lengths, [`CableModel::reels_follow_lengths`]): the commanded
    /// tensions are then the elastic law's estimate, reported but not applied.
    pub fn drives_reels_by_length(&self) -> bool {
        self.length_drive && matches!(self.actuation, Actuation::Controller)
    }

    /// Hands the model the commanded lengths' rate l̇0_i and acceleration l̈0_i at t [s], by
    /// central differences of [`ClosedLoop::commanded_lengths`] (the flex compensation's
    /// distribution makes them awkward in closed form) with the half-step
    /// [`LENGTH_DIFFERENCE_STEP`].
    fn drive_reels(&mut self, t: f64) {
        let at = |t: f64| self.commanded_lengths(t).unwrap_or_default();
        let h = LENGTH_DIFFERENCE_STEP;
        let (ahead, now, behind) = (at(t + h), at(t), at(t - h));
        let m = self.model.cables();
        let rates = PerCable::from_fn(m, |i| (ahead[i] - behind[i]) / (2.0 * h));
        let accelerations =
            PerCable::from_fn(m, |i| (ahead[i] - 2.0 * now[i] + behind[i]) / (h * h));
        self.model.drive_reels(&rates, &accelerations);
        self.step_start.driven_at = Some(t);
    }

    /// The robot.
    pub fn robot(&self) -> &Robot<D> {
        self.model.robot()
    }

    /// Length of the model's part of the state.
    pub fn model_len(&self) -> usize {
        self.model.state_len()
    }

    /// Number of the controller's states (after the model's).
    pub fn controller_len(&self) -> usize {
        self.controller.state_len()
    }

    /// Model and controller states: the part of the state the error norm and the
    /// linearisation see (the audits excluded).
    pub fn dynamic_len(&self) -> usize {
        self.model_len() + self.controller_len()
    }

    /// The reference at time t [s]: x, ẋ, ẍ from `step5`; the other coordinates the held start
    /// (0 before the start equilibrium is known), at rest. ẋ and ẍ are 0 for controllers that do
    /// not read them.
    #[inline]
    pub fn reference(&self, t: f64) -> Reference<D> {
        if let Some(path) = &self.path {
            return self.path_reference(path, t);
        }
        let step = &self.trajectory;
        let (x, v, a) = match &self.shaper {
            Some(shaper) if !shaper.is_none() => {
                // step5 convolved with the impulses: Σ A_i step5(t − t_i).
                let x = shaper.convolve(t, |t| step.position(t));
                if self.feedforward {
                    let v = shaper.convolve(t, |t| step.velocity(t));
                    (x, v, shaper.convolve(t, |t| step.acceleration(t)))
                } else {
                    (x, 0.0, 0.0)
                }
            }
            _ if self.feedforward => (step.position(t), step.velocity(t), step.acceleration(t)),
            _ => (step.position(t), 0.0, 0.0),
        };
        let mut position = self.hold.unwrap_or_else(Vector::zeros);
        position[0] = x;
        let mut velocity = Vector::zeros();
        velocity[0] = v;
        let mut acceleration = Vector::zeros();
        acceleration[0] = a;
        Reference {
            position,
            velocity,
            acceleration,
        }
    }

    /// The times [s] where the reference may jump in velocity or acceleration: a print's
    /// ([`crate::print_path::PrintPath::breakpoints`]); none for eq. 13, whose position,
    /// velocity and acceleration are continuous (shaped or not: a sum of delayed copies).
    pub fn reference_breakpoints(&self) -> Vec<f64> {
        match &self.path {
            Some(Path::Print(print)) => print.breakpoints(),
            _ => Vec::new(),
        }
    }

    /// When the (shaped) reference reaches x2 [s]: t2 plus the shaper's duration (a print:
    /// when its shaped reference comes to rest).
    pub fn move_end(&self) -> f64 {
        if let Some(Path::Print(print)) = &self.path {
            return print.duration();
        }
        self.trajectory.t2 + self.shaper.as_ref().map_or(0.0, Impulses::duration)
    }

    /// The unstrained lengths [m] the reels pay out at t [s] when the controller drives them
    /// by length (the model's l0 channels then report these, not l/(1 + T/EA): a slack cable's
    /// reel has paid out more than its chord, and a damped line's tension is not its strain's).
    pub fn commanded_lengths(&self, t: f64) -> Option<crate::robot::PerCable> {
        match self.actuation {
            Actuation::Controller => self.controller.reel_lengths_for(&self.reference(t)),
            Actuation::Prescribed(_) => None,
        }
    }

    /// The held start height z0 [m], once [`ClosedLoop::initial_state`] has found it.
    pub fn hold_height(&self) -> Option<f64> {
        self.hold.map(|h| crate::robot::height(&h))
    }

    /// Reference, error, force and commanded tensions at (t, y).
    #[inline]
    pub fn command(&self, t: f64, y: &[f64]) -> Command {
        let n = self.model_len();
        let effector = self.model.effector(&y[..n]);
        let states = &y[n..n + self.controller_len()];
        self.command_with(t, &self.reference(t), &effector, states)
    }

    /// The commanded tensions at the end (t, y) of an accepted step: those the last
    /// right-hand side commanded when `evaluated_there` (the stepper's
    /// [`Stepper::last_rhs_at_state`](cdpr_numerics::Stepper::last_rhs_at_state)) and it was at
    /// this t, so that the runner's slack check after each DOPRI5 step commands nothing again;
    /// else commanded anew. The same bits either way: the right-hand side commands through
    /// [`ClosedLoop::command`]'s arithmetic.
    pub fn tensions_at_step_end(&self, t: f64, y: &[f64], evaluated_there: bool) -> Tensions {
        let last = &self.last_rhs;
        if evaluated_there && last.t == t {
            last.tensions
        } else {
            self.command(t, y).tensions
        }
    }

    /// Whether a cable may carry zero tension without failing the run: reels driven by length,
    /// whose cables pull only with their strain, and any spatial robot, whose distribution may
    /// leave a cable idle at t_min = 0 (IPAnema's box is [0, 720] N). A negative tension still
    /// fails.
    pub fn slack_allowed(&self) -> bool {
        D == 3 || self.controller.kind() == ControllerKind::Length
    }

    /// The command for a given reference, effector and controller states.
    #[inline]
    fn command_with(
        &self,
        t: f64,
        reference: &Reference<D>,
        effector: &Effector<D>,
        states: &[f64],
    ) -> Command {
        let out = self.controller.output(reference, effector, states);
        let (tensions, mut saturated) = match &self.actuation {
            Actuation::Controller => self.limits.clamp(&out.tensions),
            Actuation::Prescribed(f) => (f(t), false),
        };
        if D == 3 && saturated {
            // In space a distribution's cable on a bound may lie an ulp past it: saturation
            // (and the anti-windup it triggers) is a clamp beyond the distribution's tolerance.
            saturated = self.limits.excess(&out.tensions) > BOX_TOLERANCE;
        }
        Command {
            reference: reference.position[0],
            error: reference.position[0] - effector.position[0],
            force: out.wrench[0],
            tensions,
            saturated,
        }
    }

    /// The audits' rates W' = the reels' power (Σ T_i v_reel,i, or a driven reel's) and D' =
    /// the model's dissipation [W] at `model_state` under the commanded `tensions`, the reels
    /// turning at `reel`.
    fn audit_rates(&self, model_state: &[f64], tensions: &Tensions, reel: &PerCable) -> (f64, f64) {
        (
            self.model.reel_power(model_state, tensions, reel),
            self.model.dissipation(model_state),
        )
    }

    /// Rates of the states after the model's (controller, W', D') at state `y`, with the
    /// reference and the effector of (t, y), whether the command saturates there, and the
    /// audits' rates ([`ClosedLoop::audit_rates`]).
    fn controller_and_audit_rates(
        &self,
        y: &[f64],
        (reference, effector): (&Reference<D>, &Effector<D>),
        saturated: bool,
        (power, dissipation): (f64, f64),
        out: &mut [f64],
    ) {
        let n = self.model_len();
        let c = self.controller_len();
        let (rates, audits) = out.split_at_mut(c);
        self.controller
            .state_rate(reference, effector, &y[n..n + c], saturated, rates);
        audits[0] = power;
        audits[1] = dissipation;
    }
}

impl<M: CableModel<D>, const D: usize> OdeSystem for ClosedLoop<M, D> {
    fn dimension(&self) -> usize {
        self.dynamic_len() + AUDIT_STATES
    }

    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) {
        // A state the implicit path's audits were not taken at (a restart starts here).
        self.step_start.audited_at = None;
        let n = self.model_len();
        let effector = self.model.effector(&y[..n]);
        let reference = self.reference(t);
        let states = &y[n..n + self.controller_len()];
        let cmd = self.command_with(t, &reference, &effector, states);
        if self.drives_reels_by_length() {
            self.drive_reels(t);
        }
        let (model_rate, tail) = dy.split_at_mut(n);
        let reel = self
            .model
            .rhs_and_reel_speeds(t, &y[..n], &cmd.tensions, model_rate);
        let audits = self.audit_rates(&y[..n], &cmd.tensions, &reel);
        self.controller_and_audit_rates(y, (&reference, &effector), cmd.saturated, audits, tail);
        self.last_rhs = LastRhs {
            t,
            tensions: cmd.tensions,
        };
    }
}
