//! The scenario's checks: every key against its physical range, one function per section, the
//! first violation returned naming the key, its value and the allowed range.

use super::*;

impl Scenario {
    /// Checks every value against its physical range; the first violation is returned.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        if let Some(printer) = &self.printer {
            printer.validate(if self.robot.anchors.is_some() { 3 } else { 2 })?;
        }
        if self.robot.anchors.is_some() {
            return self.validate_spatial();
        }
        if let Some(start) = self
            .trajectory
            .start
            .as_ref()
            .or(self.trajectory.end.as_ref())
        {
            return Err(out_of_range(
                "trajectory.start, trajectory.end",
                format!("{start:?}"),
                "absent for the planar robot (its move is x1 → x2); a spatial robot gives \
                 [robot] anchors",
            ));
        }
        if let Some(reels) = &self.robot.reel_directions {
            return Err(out_of_range(
                "robot.reel_directions",
                format!("{reels:?}"),
                "absent for the planar robot (its reels lie along ∓x, MODELS.md §4); a spatial \
                 robot gives [robot] anchors",
            ));
        }
        self.validate_robot_and_cable()?;
        if self.controller.kind == ControllerKind::Length {
            return Err(out_of_range(
                "controller.kind",
                "\"length\"",
                "a tension controller for the planar robot; `length` drives a spatial robot's \
                 reels ([robot] anchors)",
            ));
        }
        self.controller.validate(&self.robot)?;
        self.validate_trajectory()?;
        self.validate_simulation()
    }

    fn validate_robot_and_cable(&self) -> Result<(), ScenarioError> {
        let r = &self.robot;
        positive("robot.anchor_distance", r.anchor_distance)?;
        positive("robot.effector_mass", r.effector_mass)?;
        // The effector hangs below the pulleys on taut cables: without gravity it has no rest
        // below them (the run left the workspace at t = 0).
        positive("robot.gravity", r.gravity)?;
        self.validate_cable()
    }

    pub(super) fn validate_cable(&self) -> Result<(), ScenarioError> {
        let c = &self.cable;
        positive("cable.youngs_modulus", c.youngs_modulus)?;
        positive("cable.area", c.area)?;
        positive("cable.density", c.density)?;
        positive("cable.modelled_length", c.modelled_length)?;
        non_negative("cable.axial_damping", c.axial_damping)
    }

    /// The move inside the workspace, z_ref consistent with the controller, the shaper's design.
    fn validate_trajectory(&self) -> Result<(), ScenarioError> {
        let t = &self.trajectory;
        let d = self.robot.anchor_distance;
        for (key, x) in [("trajectory.x1", t.x1), ("trajectory.x2", t.x2)] {
            finite(key, x)?;
            if !(x > 0.0 && x < d) {
                return Err(out_of_range(
                    key,
                    x,
                    format!("(0, anchor_distance = {d}) m: the workspace between the pulleys"),
                ));
            }
        }
        self.validate_times()?;

        let kind = self.controller.kind;
        match (kind.acts_on_z(), t.z_ref) {
            (false, Some(ZRef::Hold)) => {
                return Err(out_of_range(
                    "trajectory.z_ref",
                    "\"hold\"",
                    format!(
                        "\"free\" with controller.kind = \"{}\": it does not act on z",
                        kind.name()
                    ),
                ));
            }
            (true, Some(ZRef::Free)) => {
                return Err(out_of_range(
                    "trajectory.z_ref",
                    "\"free\"",
                    format!(
                        "\"hold\" with controller.kind = \"{}\": it regulates z",
                        kind.name()
                    ),
                ));
            }
            _ => {}
        }

        // The shaper's design values, where given (the zeros of "auto" only to check the others).
        if t.shaper != ShaperKind::None {
            Impulses::design(
                t.shaper,
                t.shaper_frequency.value().unwrap_or(1.0),
                t.shaper_damping.value().unwrap_or(0.0),
                t.shaper_vtol,
            )?;
        }

        Ok(())
    }

    pub(super) fn validate_simulation(&self) -> Result<(), ScenarioError> {
        let s = &self.simulation;
        positive("simulation.t_final", s.t_final)?;
        finite("simulation.rtol", s.rtol)?;
        if !(s.rtol >= 1e-14 && s.rtol <= 0.1) {
            return Err(out_of_range("simulation.rtol", s.rtol, "[1e-14, 0.1]"));
        }
        positive("simulation.atol", s.atol)?;
        positive("simulation.sample_period", s.sample_period)?;
        if s.sample_period > s.t_final {
            return Err(out_of_range(
                "simulation.sample_period",
                s.sample_period,
                format!("(0, t_final = {}] s", s.t_final),
            ));
        }
        if s.t_final / s.sample_period > MAX_SAMPLES {
            return Err(out_of_range(
                "simulation.sample_period",
                s.sample_period,
                format!(
                    "≥ t_final / {MAX_SAMPLES:e} = {} s",
                    s.t_final / MAX_SAMPLES
                ),
            ));
        }
        finite("simulation.dopri_beta", s.dopri_beta)?;
        if !(0.0..=0.2).contains(&s.dopri_beta) {
            return Err(out_of_range(
                "simulation.dopri_beta",
                s.dopri_beta,
                "[0, 0.2]",
            ));
        }
        positive("simulation.step", s.step)?;
        if s.integrator == IntegratorKind::Implicit {
            let the_move = format!(
                "resolve the move (at least {STEPS_PER_MOVE} steps over t2 − t1 = {} s)",
                self.trajectory.t2 - self.trajectory.t1
            );
            // An adaptive run's `step` is only its first: the error control measures the
            // controller's states, so the filter bounds the fixed step alone.
            let (largest, rule) = if s.adaptive {
                (
                    self.largest_adaptive_step(),
                    format!("an adaptive run's first step must {the_move}"),
                )
            } else {
                (
                    self.largest_implicit_step(),
                    format!(
                        "the fixed step must {the_move} and the PID's derivative filter \
                         (h ≤ 1/filter = {:e} s)",
                        1.0 / self.controller.filter
                    ),
                )
            };
            if s.step > largest {
                return Err(out_of_range(
                    "simulation.step",
                    s.step,
                    format!("≤ {largest:e} s for this scenario: {rule}"),
                ));
            }
        }
        if s.adaptive && s.integrator != IntegratorKind::Implicit {
            return Err(out_of_range(
                "simulation.adaptive",
                s.adaptive,
                "false with integrator = \"dopri5\" (DOPRI5 always controls its error; \
                 `adaptive` switches the implicit integrator's error control on)",
            ));
        }
        if s.error_norm != ErrorNorm::All && !s.adaptive {
            return Err(out_of_range(
                "simulation.error_norm",
                s.error_norm.name(),
                "\"all\" unless adaptive = true (the norm of the implicit integrator's error \
                 control)",
            ));
        }
        finite("simulation.rho_inf", s.rho_inf)?;
        if !(0.0..=1.0).contains(&s.rho_inf) {
            return Err(out_of_range("simulation.rho_inf", s.rho_inf, "[0, 1]"));
        }

        Ok(())
    }
}
