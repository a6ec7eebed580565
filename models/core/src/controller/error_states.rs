//! The states computed-torque and the LQR share: the integral of the position error σ = ∫e dt
//! (held while the command is clamped: conditional integration) and the low-passed velocity
//! error ([`VelocityFilter`]). Layout: [σ per axis, then the filter's 2 per axis].

use super::velocity_filter::{self, VelocityFilter};
use super::{Reference, StepStart};
use crate::robot::{Effector, Vector};

/// Number of states of a robot in D dimensions: D integrals and the filter's 2 D.
pub const fn states<const D: usize>() -> usize {
    D + velocity_filter::STATES_PER_AXIS * D
}

/// The integral and filtered-velocity error states.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorStates {
    pub filter: VelocityFilter,
}

impl ErrorStates {
    /// σ = ∫e dt [m s].
    pub fn integral<const D: usize>(states: &[f64]) -> Vector<D> {
        Vector::from_fn(|k, _| states[k])
    }

    /// Each state's factor to metres in an error norm (`Controller::state_weights`), by the
    /// gain it reaches the command through: ė_f [m/s] by `velocity_time` = K_d/K_p [s] of its
    /// axis (the position error commanding as much), ė_f' [m/s²] by K_d/(K_p ω_f) (it reaches
    /// ė_f over the filter's time constant); σ [m s] as it is, as the PID's integral. Measured
    /// in their own units against one atol, the filter's rate ė_f' set the steps of a printed
    /// layer (atol 1e-4 in m/s² of an internal state). A ratio that is not finite and positive
    /// (a controller not yet designed) leaves the factor 1.
    pub fn weights<const D: usize>(&self, velocity_time: Vector<D>, out: &mut [f64]) {
        let filter_time = if self.filter.is_on() {
            1.0 / self.filter.omega
        } else {
            1.0
        };
        let usable = |w: f64| if w.is_finite() && w > 0.0 { w } else { 1.0 };
        for k in 0..D {
            out[k] = 1.0;
            out[D + k] = usable(velocity_time[k]);
            out[2 * D + k] = usable(velocity_time[k] * filter_time);
        }
    }

    /// The velocity error ė [m/s] the controller acts on: filtered, or raw when the filter is off.
    pub fn velocity_error<const D: usize>(
        &self,
        reference: &Reference<D>,
        effector: &Effector<D>,
        states: &[f64],
    ) -> Vector<D> {
        let raw = reference.velocity - effector.velocity;
        Vector::from_fn(|k, _| self.filter.output(&states[D..], k, raw[k]))
    }

    /// d/dt of the states; the integrals hold while `saturated`.
    pub fn rate<const D: usize>(
        &self,
        reference: &Reference<D>,
        effector: &Effector<D>,
        states: &[f64],
        saturated: bool,
        rate: &mut [f64],
    ) {
        let e = reference.position - effector.position;
        let de = reference.velocity - effector.velocity;
        let gate = if saturated { 0.0 } else { 1.0 };
        for k in 0..D {
            rate[k] = gate * e[k];
        }
        self.filter
            .rate(&states[D..], de.as_slice(), &mut rate[D..]);
    }

    /// The trapezoidal step of size h [s] from `start` to the reference and effector at its end;
    /// the integrals hold if the command was clamped at the start.
    pub fn trapezoidal_step<const D: usize>(
        &self,
        h: f64,
        start: &StepStart<D>,
        reference: &Reference<D>,
        effector: &Effector<D>,
        out: &mut [f64],
    ) {
        let e0 = start.reference.position - start.effector.position;
        let e1 = reference.position - effector.position;
        for k in 0..D {
            out[k] = if start.saturated {
                start.states[k]
            } else {
                start.states[k] + 0.5 * h * (e0[k] + e1[k])
            };
        }
        let de0 = start.reference.velocity - start.effector.velocity;
        let de1 = reference.velocity - effector.velocity;
        self.filter.trapezoidal_step(
            &start.states[D..],
            de0.as_slice(),
            de1.as_slice(),
            h,
            &mut out[D..],
        );
    }

    /// The rest: integrals `sigma`, filter at zero.
    pub fn rest<const D: usize>(sigma: Vector<D>, out: &mut [f64]) {
        out[..D].copy_from_slice(sigma.as_slice());
        out[D..states::<D>()].fill(0.0);
    }
}
