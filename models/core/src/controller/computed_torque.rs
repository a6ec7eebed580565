//! `computed-torque`: feedback linearisation of the effector on rigid massless cables. With
//! M a = W T + M g, the tensions
//!
//! ```text
//! T = W(x, z)⁻¹ M (a_ref + K_d ė + K_p e + K_i ∫e dt − g),   e = p_ref − p,  g = (0, −g)
//! ```
//!
//! make every error component obey ë + K_d ė + K_p e + K_i ∫e = 0 exactly on the elastic model
//! (whose cables are massless and whose effector feels the commanded tension) when ė is measured
//! unfiltered; on the massive cable models the cables' own dynamics are what is left over. It
//! measures position and velocity, the velocity error through [`VelocityFilter`] (states:
//! ∫e per axis, then the filter's two per axis). Anti-windup: the integrals hold while the
//! command is clamped.

use super::distribution::TensionSolver;
use super::error_states::{self, ErrorStates};
use super::velocity_filter::VelocityFilter;
use super::{Controller, Measures, Output, Reference, Rest, StepStart};
use crate::robot::{Effector, Robot, Vector};
use crate::scenario::{self, ControllerKind};

/// Feedback linearisation with PID error dynamics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ComputedTorque<const D: usize> {
    /// K_p [1/s²].
    pub kp: f64,
    /// K_d [1/s].
    pub kd: f64,
    /// K_i [1/s³].
    pub ki: f64,
    /// The integral and filtered-velocity error states.
    pub errors: ErrorStates,
    pub robot: Robot<D>,
    /// W T = f: directly, or by the distribution of a redundant robot.
    pub solver: TensionSolver,
}

impl<const D: usize> ComputedTorque<D> {
    pub fn new(c: &scenario::Controller, robot: Robot<D>) -> Self {
        Self {
            kp: c.kp,
            kd: c.kd,
            ki: c.ki,
            errors: ErrorStates {
                filter: VelocityFilter {
                    omega: c.velocity_filter,
                },
            },
            robot,
            solver: TensionSolver::from(c),
        }
    }

    /// The commanded acceleration a_ref + K_d ė + K_p e + K_i σ [m/s²].
    pub fn acceleration(
        &self,
        reference: &Reference<D>,
        effector: &Effector<D>,
        states: &[f64],
    ) -> Vector<D> {
        let e = reference.position - effector.position;
        let de = self.errors.velocity_error(reference, effector, states);
        let sigma = ErrorStates::integral::<D>(states);
        reference.acceleration + self.kd * de + self.kp * e + self.ki * sigma
    }
}

impl<const D: usize> Controller<D> for ComputedTorque<D> {
    fn kind(&self) -> ControllerKind {
        ControllerKind::ComputedTorque
    }
    fn state_len(&self) -> usize {
        error_states::states::<D>()
    }
    fn state_weights(&self, out: &mut [f64]) {
        self.errors
            .weights::<D>(Vector::repeat(self.kd / self.kp), out);
    }
    fn uses_reference_derivatives(&self) -> bool {
        true
    }
    fn measures(&self) -> Measures {
        Measures {
            all_axes: true,
            velocity: true,
        }
    }
    fn output(
        &self,
        reference: &Reference<D>,
        effector: &Effector<D>,
        states: &[f64],
    ) -> Output<D> {
        let a = self.acceleration(reference, effector, states);
        Output {
            wrench: self.robot.effector_mass * a,
            tensions: self
                .solver
                .for_acceleration(&self.robot, &effector.position, &a),
        }
    }
    fn state_rate(
        &self,
        reference: &Reference<D>,
        effector: &Effector<D>,
        states: &[f64],
        saturated: bool,
        rate: &mut [f64],
    ) {
        self.errors
            .rate(reference, effector, states, saturated, rate);
    }
    fn trapezoidal_step(
        &self,
        h: f64,
        start: &StepStart<D>,
        reference: &Reference<D>,
        effector: &Effector<D>,
        out: &mut [f64],
    ) {
        self.errors
            .trapezoidal_step(h, start, reference, effector, out);
    }
    fn rest_states(&self, _: &Reference<D>, effector: &Effector<D>, rest: &Rest, out: &mut [f64]) {
        // At rest the integral supplies what the rigid-cable statics miss (the cables' weight).
        let a = super::acceleration(&self.robot, &effector.position, &rest.tensions);
        let sigma = if self.ki > 0.0 {
            a / self.ki
        } else {
            Vector::zeros()
        };
        ErrorStates::rest(sigma, out);
    }
}
