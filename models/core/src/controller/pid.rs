//! The paper's controller (§3.2, MODELS.md §2): a parallel PID with a first-order derivative filter
//! computing the horizontal force F on the effector, and the closed-form tension distribution of two
//! opposed cables (Pott's method, [`split_tensions`]) turning F into the commanded tensions T1, T2
//! with ΣT fixed. It measures x only; z is left to the statics.
//!
//! The controller is part of the ODE: its integral state w and filter state f are integrated with the
//! model, so its transfer function C(s) = P + I/s + D N_f s/(s + N_f) holds exactly.

use super::{Controller, Measures, Output, Reference, Rest, StepStart, split_tensions};
use crate::robot::{Effector, Tensions, Vector};
use crate::scenario::{self, ControllerKind};

/// PID with derivative filter, Simulink parallel form: C(s) = P + I/s + D·N_f·s/(s + N_f).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pid {
    /// Proportional gain P [N/m].
    pub p: f64,
    /// Integral gain I [N/(m s)].
    pub i: f64,
    /// Derivative gain D [N s/m].
    pub d: f64,
    /// Derivative filter coefficient N_f [1/s].
    pub filter: f64,
}

impl From<&scenario::Controller> for Pid {
    fn from(c: &scenario::Controller) -> Self {
        Self {
            p: c.p,
            i: c.i,
            d: c.d,
            filter: c.filter,
        }
    }
}

/// The PID's two states: w = ∫e dt and the filter state f (f' = N_f (e − f)).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PidState {
    pub integral: f64,
    pub filter: f64,
}

impl PidState {
    /// The states (w, f) at the start of `states`, a controller's state slice.
    #[inline]
    pub fn of(states: &[f64]) -> Self {
        Self {
            integral: states[0],
            filter: states[1],
        }
    }
}

impl Pid {
    /// Force F = P e + I w + D N_f (e − f) [N] for the tracking error e = x_ref − x [m].
    #[inline]
    pub fn force(&self, error: f64, state: PidState) -> f64 {
        self.p * error + self.i * state.integral + self.d * self.filter * (error - state.filter)
    }

    /// State derivatives (w', f') = (e, N_f (e − f)).
    pub fn state_rate(&self, error: f64, state: PidState) -> PidState {
        PidState {
            integral: error,
            filter: self.filter * (error - state.filter),
        }
    }

    /// The states at the end of a step of size h [s] by the trapezoidal rule (MODELS.md FE.9.3),
    /// from the states and error e_n at its start and the error e_{n+1} at its end:
    /// w_{n+1} = w_n + h (e_n + e_{n+1})/2,
    /// f_{n+1} = [f_n (1 − h N_f/2) + h N_f (e_n + e_{n+1})/2] / (1 + h N_f/2).
    /// A-stable for the filter pole −N_f at any step, second order like the generalised-α step.
    pub fn trapezoidal_step(&self, start: PidState, e_start: f64, e_end: f64, h: f64) -> PidState {
        let mean = 0.5 * (e_start + e_end);
        let k = 0.5 * h * self.filter;
        PidState {
            integral: start.integral + h * mean,
            filter: (start.filter * (1.0 - k) + 2.0 * k * mean) / (1.0 + k),
        }
    }

    /// State that makes the controller output `force` at zero error and rest: w = F0/I, f = e = 0.
    /// Without integral action (I = 0) no state can hold a force at zero error: `None`.
    pub fn state_holding(&self, force: f64) -> Option<PidState> {
        if force == 0.0 {
            return Some(PidState::default());
        }
        (self.i > 0.0).then(|| PidState {
            integral: force / self.i,
            filter: 0.0,
        })
    }
}

/// The paper's controller: [`Pid`] on e = x_ref − x and the split of ΣT (eq. of §3.2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PaperPid {
    pub pid: Pid,
    /// Pretension sum ΣT [N].
    pub tension_sum: f64,
}

impl From<&scenario::Controller> for PaperPid {
    fn from(c: &scenario::Controller) -> Self {
        Self {
            pid: Pid::from(c),
            tension_sum: c.tension_sum,
        }
    }
}

impl<const D: usize> Controller<D> for PaperPid {
    fn kind(&self) -> ControllerKind {
        ControllerKind::Pid
    }
    fn state_len(&self) -> usize {
        2
    }
    fn measures(&self) -> Measures {
        Measures {
            all_axes: false,
            velocity: false,
        }
    }
    #[inline]
    fn output(
        &self,
        reference: &Reference<D>,
        effector: &Effector<D>,
        states: &[f64],
    ) -> Output<D> {
        let error = reference.position[0] - effector.position[0];
        let force = self.pid.force(error, PidState::of(states));
        let mut wrench = Vector::zeros();
        wrench[0] = force;
        Output {
            wrench,
            tensions: Tensions::pair(split_tensions(self.tension_sum, force)),
        }
    }
    /// The paper's PID has no anti-windup: `saturated` is ignored.
    fn state_rate(
        &self,
        reference: &Reference<D>,
        effector: &Effector<D>,
        states: &[f64],
        _saturated: bool,
        rate: &mut [f64],
    ) {
        let error = reference.position[0] - effector.position[0];
        let r = self.pid.state_rate(error, PidState::of(states));
        rate[0] = r.integral;
        rate[1] = r.filter;
    }
    fn trapezoidal_step(
        &self,
        h: f64,
        start: &StepStart<D>,
        reference: &Reference<D>,
        effector: &Effector<D>,
        out: &mut [f64],
    ) {
        let e_start = start.reference.position[0] - start.effector.position[0];
        let e_end = reference.position[0] - effector.position[0];
        let s = self
            .pid
            .trapezoidal_step(PidState::of(start.states), e_start, e_end, h);
        out[0] = s.integral;
        out[1] = s.filter;
    }
    fn rest_states(&self, _: &Reference<D>, _: &Effector<D>, rest: &Rest, out: &mut [f64]) {
        let s = self.pid.state_holding(rest.force).unwrap_or_default();
        out[0] = s.integral;
        out[1] = s.filter;
    }
    /// F is affine in x: a unit step gives dT/dx exactly.
    fn difference_step(&self) -> f64 {
        1.0
    }
}
