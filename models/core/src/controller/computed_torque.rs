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
//! ∫e_x, ∫e_z, then the filter's four). Anti-windup: the integrals hold while the command is
//! clamped.

use super::velocity_filter::{self, VelocityFilter};
use super::{
    Controller, Measures, Output, Plant, Reference, Rest, StepStart, integrate_trapezoidal,
};
use crate::Vector2;
use crate::model::Effector;
use crate::scenario::{self, ControllerKind};

/// Feedback linearisation with PID error dynamics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ComputedTorque {
    /// K_p [1/s²].
    pub kp: f64,
    /// K_d [1/s].
    pub kd: f64,
    /// K_i [1/s³].
    pub ki: f64,
    /// The low-pass on the velocity error.
    pub filter: VelocityFilter,
    pub plant: Plant,
}

impl ComputedTorque {
    pub fn new(c: &scenario::Controller, plant: Plant) -> Self {
        Self {
            kp: c.kp,
            kd: c.kd,
            ki: c.ki,
            filter: VelocityFilter {
                omega: c.velocity_filter,
            },
            plant,
        }
    }

    /// The commanded acceleration a_ref + K_d ė + K_p e + K_i σ [m/s²].
    pub fn acceleration(
        &self,
        reference: &Reference,
        effector: &Effector,
        states: &[f64],
    ) -> Vector2<f64> {
        let e = reference.position - effector.position;
        let raw = reference.velocity - effector.velocity;
        let de = Vector2::new(
            self.filter.output(&states[2..], 0, raw.x),
            self.filter.output(&states[2..], 1, raw.y),
        );
        let sigma = Vector2::new(states[0], states[1]);
        reference.acceleration + self.kd * de + self.kp * e + self.ki * sigma
    }
}

impl Controller for ComputedTorque {
    fn kind(&self) -> ControllerKind {
        ControllerKind::ComputedTorque
    }
    fn state_len(&self) -> usize {
        2 + velocity_filter::STATES
    }
    fn uses_reference_derivatives(&self) -> bool {
        true
    }
    fn measures(&self) -> Measures {
        Measures {
            z: true,
            velocity: true,
        }
    }
    fn output(&self, reference: &Reference, effector: &Effector, states: &[f64]) -> Output {
        let a = self.acceleration(reference, effector, states);
        Output {
            force: self.plant.effector_mass * a.x,
            tensions: self.plant.tensions_for_acceleration(effector.position, a),
        }
    }
    fn state_rate(
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
    fn trapezoidal_step(
        &self,
        h: f64,
        start: &StepStart,
        reference: &Reference,
        effector: &Effector,
        out: &mut [f64],
    ) {
        let e0 = start.reference.position - start.effector.position;
        let e1 = reference.position - effector.position;
        integrate_trapezoidal(
            start.states,
            [e0.x, e0.y],
            [e1.x, e1.y],
            h,
            start.saturated,
            out,
        );
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
    fn rest_states(&self, _: &Reference, effector: &Effector, rest: &Rest, out: &mut [f64]) {
        // At rest the integral supplies what the rigid-cable statics miss (the cables' weight).
        let a = self.plant.acceleration(effector.position, rest.tensions);
        for k in 0..2 {
            out[k] = if self.ki > 0.0 { a[k] / self.ki } else { 0.0 };
        }
        out[2..2 + velocity_filter::STATES].fill(0.0);
    }
}
