//! `pid-xz`: the paper's PID on x plus a PID of the same form on z, their forces decoupled
//! through the structure matrix W:
//!
//! ```text
//! F_x = C_x(s) e_x,  F_z = C_z(s) e_z,  C(s) = P + I/s + D N_f s/(s + N_f)
//! T = W(x, z)⁻¹ (F_x, M g + F_z)          (so W T + M g = (F_x, F_z) on rigid cables)
//! ```
//!
//! The tension sum is no longer fixed: the z loop acts through it. Anti-windup by conditional
//! integration: while the command is clamped to [t_min, t_max], both integrals hold.

use super::{Controller, Measures, Output, Pid, PidState, Plant, Reference, Rest, StepStart};
use crate::Vector2;
use crate::model::Effector;
use crate::scenario::{self, ControllerKind};

/// Two PIDs (x, z) decoupled through W.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PidXz {
    pub x: Pid,
    pub z: Pid,
    pub plant: Plant,
}

impl PidXz {
    pub fn new(c: &scenario::Controller, plant: Plant) -> Self {
        Self {
            x: Pid::from(c),
            z: Pid {
                p: c.p_z,
                i: c.i_z,
                d: c.d_z,
                filter: c.filter,
            },
            plant,
        }
    }

    fn errors(reference: &Reference, effector: &Effector) -> Vector2<f64> {
        reference.position - effector.position
    }
}

/// Loop k's (x: 0, z: 1) PID states in `states`.
fn state(states: &[f64], k: usize) -> PidState {
    PidState::of(&states[2 * k..])
}

impl Controller for PidXz {
    fn kind(&self) -> ControllerKind {
        ControllerKind::PidXz
    }
    fn state_len(&self) -> usize {
        4
    }
    fn measures(&self) -> Measures {
        Measures {
            z: true,
            velocity: false,
        }
    }
    fn output(&self, reference: &Reference, effector: &Effector, states: &[f64]) -> Output {
        let e = Self::errors(reference, effector);
        let force = Vector2::new(
            self.x.force(e.x, state(states, 0)),
            self.z.force(e.y, state(states, 1)),
        );
        let p = &self.plant;
        let pull = force + Vector2::new(0.0, p.effector_mass * p.gravity);
        Output {
            force: force.x,
            tensions: super::tensions_for_force(effector.position, p.anchor_distance, pull),
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
        let e = Self::errors(reference, effector);
        for (k, (pid, e)) in [(self.x, e.x), (self.z, e.y)].into_iter().enumerate() {
            let r = pid.state_rate(e, state(states, k));
            rate[2 * k] = if saturated { 0.0 } else { r.integral };
            rate[2 * k + 1] = r.filter;
        }
    }
    fn trapezoidal_step(
        &self,
        h: f64,
        start: &StepStart,
        reference: &Reference,
        effector: &Effector,
        out: &mut [f64],
    ) {
        let e0 = Self::errors(&start.reference, &start.effector);
        let e1 = Self::errors(reference, effector);
        for (k, (pid, e0, e1)) in [(self.x, e0.x, e1.x), (self.z, e0.y, e1.y)]
            .into_iter()
            .enumerate()
        {
            let s0 = state(start.states, k);
            let s = pid.trapezoidal_step(s0, e0, e1, h);
            out[2 * k] = if start.saturated {
                s0.integral
            } else {
                s.integral
            };
            out[2 * k + 1] = s.filter;
        }
    }
    fn rest_states(&self, _: &Reference, effector: &Effector, rest: &Rest, out: &mut [f64]) {
        let p = &self.plant;
        let w = super::structure_matrix(effector.position, p.anchor_distance);
        let pull = w * Vector2::new(rest.tensions[0], rest.tensions[1]);
        let force = pull - Vector2::new(0.0, p.effector_mass * p.gravity);
        for (k, (pid, f)) in [(self.x, force.x), (self.z, force.y)]
            .into_iter()
            .enumerate()
        {
            let s = pid.state_holding(f).unwrap_or_default();
            out[2 * k] = s.integral;
            out[2 * k + 1] = s.filter;
        }
    }
}
