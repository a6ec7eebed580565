//! The states computed-torque and the LQR share: the integral of the position error σ = ∫e dt
//! (held while the command is clamped: conditional integration) and the low-passed velocity
//! error ([`VelocityFilter`]). Layout: [σ_x, σ_z, then the filter's four].

use super::velocity_filter::{self, VelocityFilter};
use super::{Reference, StepStart};
use crate::Vector2;
use crate::model::Effector;

/// Number of states: two integrals and the filter's.
pub const STATES: usize = 2 + velocity_filter::STATES;

/// The integral and filtered-velocity error states.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorStates {
    pub filter: VelocityFilter,
}

impl ErrorStates {
    /// σ = ∫e dt [m s].
    pub fn integral(states: &[f64]) -> Vector2<f64> {
        Vector2::new(states[0], states[1])
    }

    /// The velocity error ė [m/s] the controller acts on: filtered, or raw when the filter is off.
    pub fn velocity_error(
        &self,
        reference: &Reference,
        effector: &Effector,
        states: &[f64],
    ) -> Vector2<f64> {
        let raw = reference.velocity - effector.velocity;
        Vector2::new(
            self.filter.output(&states[2..], 0, raw.x),
            self.filter.output(&states[2..], 1, raw.y),
        )
    }

    /// d/dt of the states; the integrals hold while `saturated`.
    pub fn rate(
        &self,
        reference: &Reference,
        effector: &Effector,
        states: &[f64],
        saturated: bool,
        rate: &mut [f64],
    ) {
        let e = reference.position - effector.position;
        let de = reference.velocity - effector.velocity;
        let gate = if saturated { 0.0 } else { 1.0 };
        rate[0] = gate * e.x;
        rate[1] = gate * e.y;
        self.filter.rate(&states[2..], [de.x, de.y], &mut rate[2..]);
    }

    /// The trapezoidal step of size h [s] from `start` to the reference and effector at its end;
    /// the integrals hold if the command was clamped at the start.
    pub fn trapezoidal_step(
        &self,
        h: f64,
        start: &StepStart,
        reference: &Reference,
        effector: &Effector,
        out: &mut [f64],
    ) {
        let e0 = start.reference.position - start.effector.position;
        let e1 = reference.position - effector.position;
        for k in 0..2 {
            out[k] = if start.saturated {
                start.states[k]
            } else {
                start.states[k] + 0.5 * h * (e0[k] + e1[k])
            };
        }
        let de0 = start.reference.velocity - start.effector.velocity;
        let de1 = reference.velocity - effector.velocity;
        self.filter.trapezoidal_step(
            &start.states[2..],
            [de0.x, de0.y],
            [de1.x, de1.y],
            h,
            &mut out[2..],
        );
    }

    /// The rest: integrals `sigma`, filter at zero.
    pub fn rest(sigma: Vector2<f64>, out: &mut [f64]) {
        out[0] = sigma.x;
        out[1] = sigma.y;
        out[2..STATES].fill(0.0);
    }
}
