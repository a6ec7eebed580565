//! `length`: the reels follow unstrained lengths, as stepper-driven printer firmware does
//! (Hangprinter on RepRapFirmware, Klipper's winch kinematics): no tension feedback, no
//! dynamics, each reel paid out to
//!
//! ```text
//! l0_i(t) = l_i(p_ref(t)) / (1 + T_i(t)/EA)
//! ```
//!
//! with T(t) the scenario's distribution of the static load M g at p_ref(t) (`flex_compensation
//! = "static"`, the firmware's), or of M (a_ref − g⃗) (`"dynamic"`); or, with `"none"`, the
//! lengths at the start pose shifted by the geometric length change, l0_i(t) = l0_i(0) +
//! l_i(p_ref(t)) − l_i(p_ref(0)). The cables then pull with what their strain gives: on the
//! massless elastic cables T_i = max(0, EA (l_i(p) − l0_i)/l0_i + C (l̇_i − l̇0_i)/l0_i) (eq. 1
//! solved for T, with the Kelvin–Voigt damping C of `[cable] axial_damping`; a slack cable
//! pulls with nothing, and the run goes on), so this
//! "controller" maps the measured pose to the cables' tensions the way the reels' lengths make
//! them; nothing keeps them in the tension box, and the loop does not clamp them.

use super::distribution::TensionSolver;
use super::{Controller, Measures, Output, Reference, Rest, StepStart};
use crate::robot::{Effector, PerCable, Robot, Tensions, Vector};
use crate::scenario::{self, ControllerKind, FlexCompensation};

/// Reels driven by length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LengthControl<const D: usize> {
    pub robot: Robot<D>,
    /// EA [N].
    pub axial_stiffness: f64,
    pub flex: FlexCompensation,
    /// The distribution whose tensions the flex compensation assumes.
    pub solver: TensionSolver,
    /// The reference's start pose [m] (the `"none"` compensation's calibration pose): the
    /// scenario's, then where the loop starts ([`Controller::start_at`]).
    pub start: Vector<D>,
    /// Kelvin–Voigt damping C of the cables [N s] (`[cable] axial_damping`).
    pub axial_damping: f64,
}

impl<const D: usize> LengthControl<D> {
    pub fn new(scenario: &scenario::Scenario, robot: Robot<D>) -> Self {
        let start = scenario
            .trajectory
            .start
            .as_ref()
            .map_or_else(Vector::zeros, |s| Vector::from_iterator(s.iter().copied()));
        Self {
            robot,
            axial_stiffness: scenario.cable.axial_stiffness(),
            flex: scenario.controller.flex_compensation,
            solver: TensionSolver::from(&scenario.controller),
            start,
            axial_damping: scenario.cable.axial_damping,
        }
    }

    /// The rates l̇0_i at which the reels pay out [m/s]: the chord's rate along the reference,
    /// −u_i · ṗ_ref (u_i towards the anchor), scaled by 1/(1 + T_i/EA) under flex compensation (the change of T_i along the
    /// path neglected: it moves l̇0 by T/EA ≲ 1e-3 of itself, the damping force by less).
    fn reel_rates(&self, reference: &Reference<D>, l0: &PerCable) -> PerCable {
        let r = &self.robot;
        let p = reference.position;
        PerCable::from_fn(r.cables(), |i| {
            let c = r.chord(i, &p);
            let geometric = -c.direction.dot(&reference.velocity);
            match self.flex {
                FlexCompensation::None => geometric,
                _ => geometric * l0[i] / c.length,
            }
        })
    }

    /// The unstrained lengths l0_i the reels pay out for `reference` [m].
    pub fn reel_lengths(&self, reference: &Reference<D>) -> PerCable {
        let r = &self.robot;
        let p = reference.position;
        let stretched = |p: &Vector<D>, load: &Vector<D>| {
            let t = self.solver.for_acceleration(r, p, load);
            PerCable::from_fn(r.cables(), |i| {
                r.chord(i, p).length / (1.0 + t[i] / self.axial_stiffness)
            })
        };
        match self.flex {
            FlexCompensation::Static => stretched(&p, &Vector::zeros()),
            FlexCompensation::Dynamic => stretched(&p, &reference.acceleration),
            FlexCompensation::None => {
                let calibrated = stretched(&self.start, &Vector::zeros());
                PerCable::from_fn(r.cables(), |i| {
                    calibrated[i] + r.chord(i, &p).length - r.chord(i, &self.start).length
                })
            }
        }
    }
}

impl<const D: usize> Controller<D> for LengthControl<D> {
    fn kind(&self) -> ControllerKind {
        ControllerKind::Length
    }
    fn state_len(&self) -> usize {
        0
    }
    fn uses_reference_derivatives(&self) -> bool {
        self.flex == FlexCompensation::Dynamic || self.axial_damping > 0.0
    }
    fn measures(&self) -> Measures {
        Measures {
            all_axes: true,
            velocity: self.axial_damping > 0.0,
        }
    }
    fn start_at(&mut self, pose: &Vector<D>) {
        self.start = *pose;
    }
    fn reel_lengths_for(&self, reference: &Reference<D>) -> Option<PerCable> {
        Some(self.reel_lengths(reference))
    }
    /// The cables' tensions from their strain (and strain rate) at the measured pose; the
    /// wrench is their pull.
    fn output(&self, reference: &Reference<D>, effector: &Effector<D>, _: &[f64]) -> Output<D> {
        let l0 = self.reel_lengths(reference);
        let r = &self.robot;
        let damped = self.axial_damping > 0.0;
        let l0_rate = if damped {
            self.reel_rates(reference, &l0)
        } else {
            PerCable::zeros(r.cables())
        };
        let tensions = Tensions::from_fn(r.cables(), |i| {
            let c = r.chord(i, &effector.position);
            let mut t = self.axial_stiffness * (c.length - l0[i]) / l0[i];
            if damped {
                let rate = -c.direction.dot(&effector.velocity);
                t += self.axial_damping * (rate - l0_rate[i]) / l0[i];
            }
            // A cable shorter than its unstrained length is slack: it cannot push.
            t.max(0.0)
        });
        Output {
            wrench: r.structure_matrix(&effector.position).force(&tensions),
            tensions,
        }
    }
    fn state_rate(&self, _: &Reference<D>, _: &Effector<D>, _: &[f64], _: bool, _: &mut [f64]) {}
    fn trapezoidal_step(
        &self,
        _: f64,
        _: &StepStart<D>,
        _: &Reference<D>,
        _: &Effector<D>,
        _: &mut [f64],
    ) {
    }
    fn rest_states(&self, _: &Reference<D>, _: &Effector<D>, _: &Rest, _: &mut [f64]) {}
}
