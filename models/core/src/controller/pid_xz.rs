//! `pid-xz`: the paper's PID on x plus a PID of the same form on z, their forces decoupled
//! through the structure matrix W:
//!
//! ```text
//! F_x = C_x(s) e_x,  F_z = C_z(s) e_z,  C(s) = P + I/s + D N_f s/(s + N_f)
//! T = W(x, z)⁻¹ (F_x, M g + F_z)          (so W T + M g = (F_x, F_z) on rigid cables)
//! ```
//!
//! The tension sum is no longer fixed: the z loop acts through it. Anti-windup by conditional
//! integration: while the command is clamped to [t_min, t_max], the integrals hold. In space the
//! y axis takes the x gains.

use super::distribution::TensionSolver;
use super::{Controller, Measures, Output, Pid, PidState, Reference, Rest, StepStart};
use crate::robot::{Effector, Robot, Vector, along_vertical, vertical};
use crate::scenario::{self, ControllerKind};

/// One PID per axis (x and, in space, y with the x gains; z with its own), decoupled through W.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PidXz<const D: usize> {
    pub axes: [Pid; D],
    pub robot: Robot<D>,
    /// W T = f: directly, or by the distribution of a redundant robot.
    pub solver: TensionSolver,
    /// `pid-xz`, or `pid` on a spatial robot with three or more cables (the paper's gains on
    /// every axis, gravity held by the distribution).
    kind: ControllerKind,
}

impl<const D: usize> PidXz<D> {
    pub fn new(c: &scenario::Controller, robot: Robot<D>) -> Self {
        let horizontal = Pid::from(c);
        let vertical_pid = Pid {
            p: c.p_z,
            i: c.i_z,
            d: c.d_z,
            filter: c.filter,
        };
        Self {
            axes: std::array::from_fn(|k| {
                if k == vertical::<D>() {
                    vertical_pid
                } else {
                    horizontal
                }
            }),
            robot,
            solver: TensionSolver::from(c),
            kind: ControllerKind::PidXz,
        }
    }

    /// `pid` on a spatial robot: the paper's gains (p, i, d, filter) on every axis, the weight
    /// fed forward through the tension distribution.
    pub fn paper_gains_per_axis(c: &scenario::Controller, robot: Robot<D>) -> Self {
        Self {
            axes: [Pid::from(c); D],
            kind: ControllerKind::Pid,
            ..Self::new(c, robot)
        }
    }

    fn errors(reference: &Reference<D>, effector: &Effector<D>) -> Vector<D> {
        reference.position - effector.position
    }

    /// The robot's weight M g [N].
    fn weight(&self) -> f64 {
        self.robot.effector_mass * self.robot.gravity
    }
}

fn state(states: &[f64], k: usize) -> PidState {
    PidState::of(&states[2 * k..])
}

impl<const D: usize> Controller<D> for PidXz<D> {
    fn kind(&self) -> ControllerKind {
        self.kind
    }
    fn state_len(&self) -> usize {
        2 * D
    }
    fn measures(&self) -> Measures {
        Measures {
            all_axes: true,
            velocity: false,
        }
    }
    fn output(
        &self,
        reference: &Reference<D>,
        effector: &Effector<D>,
        states: &[f64],
    ) -> Output<D> {
        let e = Self::errors(reference, effector);
        let force = Vector::<D>::from_fn(|k, _| self.axes[k].force(e[k], state(states, k)));
        let pull = force + along_vertical::<D>(self.weight());
        Output {
            wrench: force,
            tensions: self
                .solver
                .for_force(&self.robot, &effector.position, &pull),
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
        let e = Self::errors(reference, effector);
        for (k, pid) in self.axes.iter().enumerate() {
            let r = pid.state_rate(e[k], state(states, k));
            rate[2 * k] = if saturated { 0.0 } else { r.integral };
            rate[2 * k + 1] = r.filter;
        }
    }
    fn trapezoidal_step(
        &self,
        h: f64,
        start: &StepStart<D>,
        reference: &Reference<D>,
        effector: &Effector<D>,
        out: &mut [f64],
    ) {
        let e0 = Self::errors(&start.reference, &start.effector);
        let e1 = Self::errors(reference, effector);
        for (k, pid) in self.axes.iter().enumerate() {
            let s0 = state(start.states, k);
            let s = pid.trapezoidal_step(s0, e0[k], e1[k], h);
            out[2 * k] = if start.saturated {
                s0.integral
            } else {
                s.integral
            };
            out[2 * k + 1] = s.filter;
        }
    }
    fn rest_states(&self, _: &Reference<D>, effector: &Effector<D>, rest: &Rest, out: &mut [f64]) {
        let pull = self
            .robot
            .structure_matrix(&effector.position)
            .force(&rest.tensions);
        let force = pull - along_vertical::<D>(self.weight());
        for (k, pid) in self.axes.iter().enumerate() {
            let s = pid.state_holding(force[k]).unwrap_or_default();
            out[2 * k] = s.integral;
            out[2 * k + 1] = s.filter;
        }
    }
}
