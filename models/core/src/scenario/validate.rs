//! The scenario's checks: every key against its physical range, one function per section, the
//! first violation returned naming the key, its value and the allowed range.

use super::*;

impl Scenario {
    /// Checks every value against its physical range; the first violation is returned.
    pub fn validate(&self) -> Result<(), ScenarioError> {
        if self.robot.anchors.is_some() {
            return self.validate_spatial();
        }
        self.validate_robot_and_cable()?;
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

    fn validate_cable(&self) -> Result<(), ScenarioError> {
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
        finite("trajectory.t1", t.t1)?;
        if t.t1 < 0.0 {
            return Err(out_of_range("trajectory.t1", t.t1, "≥ 0 s"));
        }
        finite("trajectory.t2", t.t2)?;
        if t.t2 <= t.t1 {
            return Err(out_of_range(
                "trajectory.t2",
                t.t2,
                format!("> t1 = {} s", t.t1),
            ));
        }

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

    fn validate_simulation(&self) -> Result<(), ScenarioError> {
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
            let largest = self.largest_implicit_step();
            if s.step > largest {
                return Err(out_of_range(
                    "simulation.step",
                    s.step,
                    format!(
                        "≤ {largest:e} s for this scenario: the fixed step must resolve the move \
                         (at least {STEPS_PER_MOVE} steps over t2 − t1 = {} s) and the PID's \
                         derivative filter (h ≤ 1/filter = {:e} s)",
                        self.trajectory.t2 - self.trajectory.t1,
                        1.0 / self.controller.filter
                    ),
                ));
            }
        }
        finite("simulation.rho_inf", s.rho_inf)?;
        if !(0.0..=1.0).contains(&s.rho_inf) {
            return Err(out_of_range("simulation.rho_inf", s.rho_inf, "[0, 1]"));
        }

        Ok(())
    }

    /// A spatial robot (`[robot] anchors`): its anchors, mass, cable and the tension box its
    /// distribution needs. The planar sections (trajectory, PID) do not apply to it yet.
    fn validate_spatial(&self) -> Result<(), ScenarioError> {
        let r = &self.robot;
        let anchors = r.anchors.as_deref().unwrap_or_default();
        let m = anchors.len();
        if !(2..=crate::robot::MAX_CABLES).contains(&m) {
            return Err(out_of_range(
                "robot.anchors",
                format!("{m} anchors"),
                format!("2 to {} anchors", crate::robot::MAX_CABLES),
            ));
        }
        for (i, a) in anchors.iter().enumerate() {
            if a.len() != 3 || !a.iter().all(|v| v.is_finite()) {
                return Err(out_of_range(
                    "robot.anchors",
                    format!("anchor {} = {a:?}", i + 1),
                    "three finite coordinates [x, y, z] m",
                ));
            }
        }
        let point = |i: usize| crate::robot::Vector::<3>::from_column_slice(&anchors[i]);
        for (i, a) in anchors.iter().enumerate() {
            for j in i + 1..m {
                if (point(i) - point(j)).norm() < 1e-9 {
                    return Err(out_of_range(
                        "robot.anchors",
                        format!("anchors {} and {} both at {a:?}", i + 1, j + 1),
                        "distinct points (> 1 nm apart)",
                    ));
                }
            }
        }
        let spread = (1..m).fold(crate::robot::Vector::<3>::zeros(), |n, k| {
            let c = (point(k) - point(0)).cross(&(point(1) - point(0)));
            if c.norm() > n.norm() { c } else { n }
        });
        if m > 2 && spread.norm() < 1e-9 {
            return Err(out_of_range(
                "robot.anchors",
                format!("{m} anchors on one line"),
                "anchors not all collinear: the cables must pull in three directions",
            ));
        }
        positive("robot.effector_mass", r.effector_mass)?;
        positive("robot.gravity", r.gravity)?;
        self.validate_cable()?;
        let (Some(t_min), Some(t_max)) = (self.controller.t_min, self.controller.t_max) else {
            return Err(out_of_range(
                "controller.t_min, controller.t_max",
                "absent",
                "both given for a spatial robot: the tension distribution's box [N]",
            ));
        };
        non_negative("controller.t_min", t_min)?;
        finite("controller.t_max", t_max)?;
        if t_max <= t_min {
            return Err(out_of_range(
                "controller.t_max",
                t_max,
                format!("> t_min = {t_min} N"),
            ));
        }
        Ok(())
    }
}
