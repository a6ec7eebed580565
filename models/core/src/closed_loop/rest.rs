//! The closed loop at rest (MODELS.md §2): the start of every run and the point a linearisation is
//! taken about. The model's static equilibrium under the paper's rest rule with the effector at
//! x ([`SplitRule`]); for a controller that acts on every axis, at the held height z0 (the
//! pretension found by a secant iteration on ΣT, since the rule fixes x and ΣT); the controller's
//! states holding the equilibrium's tensions.

use super::ClosedLoop;
use crate::controller::{ControlError, Controller, Reference, Rest};
use crate::model::{CableModel, Equilibrium, ModelError, SplitRule};
use crate::robot::{Tensions, height, vertical};

/// Tolerance of the held height in the secant iteration [m] (a few ulps of a 0.1 m height).
const HEIGHT_TOLERANCE: f64 = 1e-14;
/// Most secant iterations on ΣT (the height is smooth and monotone in ΣT: 4–6 suffice).
const MAX_SECANT_ITERATIONS: usize = 40;

/// Why the loop could not be assembled or brought to rest.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LoopError {
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The controller could not be designed for the loop's rest point.
    #[error(transparent)]
    Control(#[from] ControlError),
    /// More controller states than the loop holds.
    #[error(
        "controller.kind = \"{controller}\" has {states} states, more than the {} a closed loop holds",
        super::MAX_CONTROLLER_STATES
    )]
    ControllerStates {
        controller: &'static str,
        states: usize,
    },
}

impl<M: CableModel<D>, const D: usize> ClosedLoop<M, D> {
    /// Initial state by the rule of MODELS.md §2: the model's static equilibrium with the effector
    /// at x_ref(0), ΣT the scenario's and F0 unknown, velocities zero, the controller's states
    /// holding the equilibrium's tensions (the paper's PID: w(0) = F0/I, f(0) = e(0) = 0), audits
    /// zero. The equilibrium's position becomes the held start of the reference.
    pub fn initial_state(&mut self) -> Result<(Vec<f64>, Equilibrium), LoopError> {
        self.forget_reference();
        if let Some(path) = self.path.clone() {
            return self.start_of_path(&path);
        }
        let x = self.trajectory.position(0.0);
        let eq = self
            .model
            .equilibrium(&SplitRule::new(x, self.tension_sum))?;
        let start = self.model.effector(&eq.state).position;
        self.hold = Some(start);
        self.controller.hold_height(height(&start))?;
        Ok((self.assemble(x, &eq), eq))
    }

    /// Sets the held height z0 [m] of the reference (and re-designs a controller designed there).
    pub fn set_hold_height(&mut self, z0: f64) -> Result<(), LoopError> {
        let mut hold = self.hold.unwrap_or_else(crate::robot::Vector::zeros);
        hold[vertical::<D>()] = z0;
        self.hold = Some(hold);
        self.forget_reference();
        self.controller.hold_height(z0)?;
        Ok(())
    }

    /// The closed loop at rest with the effector at x [m]: for the paper's PID (z free) the
    /// model's equilibrium at ΣT; for controllers acting on every axis, the equilibrium at
    /// (x, z0), z0 the held height (found from the start equilibrium first if not yet known).
    pub fn rest_state(&mut self, x: f64) -> Result<(Vec<f64>, Equilibrium), LoopError> {
        if !self.controller.kind().acts_on_z() {
            let eq = self
                .model
                .equilibrium(&SplitRule::new(x, self.tension_sum))?;
            return Ok((self.assemble(x, &eq), eq));
        }
        if self.hold.is_none() {
            self.initial_state()?;
        }
        let z0 = self.hold_height().unwrap_or_default();
        let eq = self.equilibrium_at_height(x, z0)?;
        Ok((self.assemble(x, &eq), eq))
    }

    /// The tensions T_1 … T_m [N] of the last rest state.
    pub fn rest_tensions(&self) -> Tensions {
        self.rest_tensions
    }

    /// The model's equilibrium with the effector at (x, z0): the secant iteration on ΣT of
    /// z(ΣT) = z0.
    fn equilibrium_at_height(&mut self, x: f64, z0: f64) -> Result<Equilibrium, ModelError> {
        let height_at = |loop_: &mut Self, sum: f64| -> Result<(Equilibrium, f64), ModelError> {
            let eq = loop_.model.equilibrium(&SplitRule::new(x, sum))?;
            let z = height(&loop_.model.effector(&eq.state).position);
            Ok((eq, z - z0))
        };
        let mut s0 = self.tension_sum;
        let (mut eq, mut f0) = height_at(self, s0)?;
        let mut s1 = 1.01 * s0;
        for _ in 0..MAX_SECANT_ITERATIONS {
            if f0.abs() <= HEIGHT_TOLERANCE {
                return Ok(eq);
            }
            let (eq1, f1) = height_at(self, s1)?;
            if f1 == f0 {
                break;
            }
            let s2 = s1 - f1 * (s1 - s0) / (f1 - f0);
            (s0, f0, eq) = (s1, f1, eq1);
            s1 = s2;
            if (s1 - s0).abs() <= 1e-15 * s0.abs() {
                return Ok(eq);
            }
        }
        if f0.abs() <= 1e-9 {
            return Ok(eq);
        }
        Err(ModelError::Parameter {
            name: "held height z0",
            value: z0,
            allowed: format!(
                "a height the cables can hold at x = {x} m (secant on ΣT stopped {f0:e} m away)"
            ),
        })
    }

    /// `[equilibrium state | controller states holding its tensions | 0 | 0]`.
    fn assemble(&mut self, x: f64, eq: &Equilibrium) -> Vec<f64> {
        let effector = self.model.effector(&eq.state);
        let mut position = self.hold.unwrap_or(effector.position);
        position[0] = x;
        let reference = Reference {
            position,
            ..Reference::default()
        };
        self.assemble_at(&reference, eq)
    }

    /// As [`ClosedLoop::assemble`], the controller at rest on `reference`.
    pub(super) fn assemble_at(&mut self, reference: &Reference<D>, eq: &Equilibrium) -> Vec<f64> {
        let effector = self.model.effector(&eq.state);
        self.rest_tensions = eq.tensions;
        let reference = *reference;
        let rest = Rest {
            tensions: eq.tensions,
            force: eq.parameters.first().copied().unwrap_or(0.0),
        };
        let c = self.controller_len();
        let mut y = eq.state.clone();
        y.resize(eq.state.len() + c + super::AUDIT_STATES, 0.0);
        let n = eq.state.len();
        self.controller
            .rest_states(&reference, &effector, &rest, &mut y[n..n + c]);
        y
    }
}
