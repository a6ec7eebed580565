//! The checks of a spatial robot's scenario (`[robot] anchors`, MODELS.md §11): its anchors, the
//! tension box its distribution needs, the controllers that can hold it, and its move — all
//! before any work, each error naming the key, its value and the allowed range.

use super::*;
use crate::robot::{MAX_CABLES, Robot as SpatialRobot, Vector};

impl Scenario {
    /// A spatial robot: anchors, mass, cable, box, controller, move and integration.
    pub(super) fn validate_spatial(&self) -> Result<(), ScenarioError> {
        let anchors = self.validate_anchors()?;
        self.validate_reel_directions(anchors.len())?;
        positive("robot.effector_mass", self.robot.effector_mass)?;
        positive("robot.gravity", self.robot.gravity)?;
        self.validate_cable()?;
        self.controller.validate_gains()?;
        if anchors.len() == 2 {
            // The paper's PID and its optional limits, as in the plane.
            self.validate_spatial_pair(&anchors)?;
            self.controller.validate_limits(&self.robot)?;
        } else {
            self.validate_box()?;
            self.validate_spatial_move(&anchors)?;
        }
        self.validate_simulation()
    }

    /// 2 … 8 distinct anchors of three finite coordinates, not all on one line.
    fn validate_anchors(&self) -> Result<Vec<Vector<3>>, ScenarioError> {
        let anchors = self.robot.anchors.as_deref().unwrap_or_default();
        let m = anchors.len();
        if !(2..=MAX_CABLES).contains(&m) {
            return Err(out_of_range(
                "robot.anchors",
                format!("{m} anchors"),
                format!("2 to {MAX_CABLES} anchors"),
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
        let points: Vec<Vector<3>> = anchors
            .iter()
            .map(|a| Vector::<3>::from_column_slice(a))
            .collect();
        for i in 0..m {
            for j in i + 1..m {
                if (points[i] - points[j]).norm() < 1e-9 {
                    return Err(out_of_range(
                        "robot.anchors",
                        format!("anchors {} and {} both at {:?}", i + 1, j + 1, anchors[i]),
                        "distinct points (> 1 nm apart)",
                    ));
                }
            }
        }
        let spread = (1..m).fold(Vector::<3>::zeros(), |n, k| {
            let c = (points[k] - points[0]).cross(&(points[1] - points[0]));
            if c.norm() > n.norm() { c } else { n }
        });
        if m > 2 && spread.norm() < 1e-9 {
            return Err(out_of_range(
                "robot.anchors",
                format!("{m} anchors on one line"),
                "anchors not all collinear: the cables must pull in three directions",
            ));
        }
        Ok(points)
    }

    /// One reel direction of three finite coordinates, not zero, per anchor (whether each
    /// leaves the workspace is the massive model's check, which knows the robot).
    fn validate_reel_directions(&self, m: usize) -> Result<(), ScenarioError> {
        let Some(reels) = &self.robot.reel_directions else {
            return Ok(());
        };
        if reels.len() != m {
            return Err(out_of_range(
                "robot.reel_directions",
                format!("{} directions", reels.len()),
                format!("one per anchor ({m})"),
            ));
        }
        for (i, r) in reels.iter().enumerate() {
            let finite = r.len() == 3 && r.iter().all(|v| v.is_finite());
            if !finite || r.iter().all(|v| *v == 0.0) {
                return Err(out_of_range(
                    "robot.reel_directions",
                    format!("direction {} = {r:?}", i + 1),
                    "three finite coordinates [x, y, z], not all zero",
                ));
            }
        }
        Ok(())
    }

    /// The box [t_min, t_max] every distribution keeps the tensions in.
    fn validate_box(&self) -> Result<(), ScenarioError> {
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

    /// Two anchors in space: the paper's robot in a vertical plane, run by the paper's PID with
    /// its planar move x1 → x2 (the plane's other keys keep their meaning).
    fn validate_spatial_pair(&self, anchors: &[Vector<3>]) -> Result<(), ScenarioError> {
        let kind = self.controller.kind;
        if kind != ControllerKind::Pid {
            return Err(out_of_range(
                "controller.kind",
                format!("\"{}\" with 2 anchors in space", kind.name()),
                "\"pid\" (the paper's ΣT split): two cables cannot hold the effector across \
                 their plane, so no controller can place it in y",
            ));
        }
        let (a, b) = (anchors[0], anchors[1]);
        if a[1] != b[1] || a[2] != b[2] || b[0] <= a[0] {
            return Err(out_of_range(
                "robot.anchors",
                format!("{:?}, {:?}", a.as_slice(), b.as_slice()),
                "two anchors on one horizontal line along x, the first at the smaller x (the \
                 paper's robot in the plane y = const)",
            ));
        }
        let t = &self.trajectory;
        for (key, x) in [("trajectory.x1", t.x1), ("trajectory.x2", t.x2)] {
            finite(key, x)?;
            if !(x > a[0] && x < b[0]) {
                return Err(out_of_range(
                    key,
                    x,
                    format!("({}, {}) m: between the anchors", a[0], b[0]),
                ));
            }
        }
        if t.start.is_some() || t.end.is_some() {
            return Err(out_of_range(
                "trajectory.start",
                format!("{:?}", t.start),
                "absent with 2 anchors: the paper's move is x1 → x2",
            ));
        }
        self.validate_times()?;
        let weight = self.robot.effector_mass * self.robot.gravity;
        positive("controller.tension_sum", self.controller.tension_sum)?;
        if weight >= self.controller.tension_sum {
            return Err(out_of_range(
                "controller.tension_sum",
                self.controller.tension_sum,
                format!("> effector weight M g = {weight} N"),
            ));
        }
        Ok(())
    }

    /// Three or more anchors: a move `start` → `end` (where given) inside the workspace, by a controller that
    /// acts on every axis; the shaper's design given as numbers.
    fn validate_spatial_move(&self, anchors: &[Vector<3>]) -> Result<(), ScenarioError> {
        let robot = SpatialRobot::new(anchors, self.robot.effector_mass, self.robot.gravity)
            .map_err(|e| out_of_range("robot.anchors", e.to_string(), "a valid robot"))?;
        let t = &self.trajectory;
        for (key, pose) in [("trajectory.start", &t.start), ("trajectory.end", &t.end)] {
            // Absent: a robot described for its statics only; a run asks for the move.
            let Some(pose) = pose else {
                continue;
            };
            if pose.len() != 3 || !pose.iter().all(|v| v.is_finite()) {
                return Err(out_of_range(
                    key,
                    format!("{pose:?}"),
                    "three finite coordinates [x, y, z] m",
                ));
            }
            if !robot.in_workspace(&Vector::<3>::from_column_slice(pose)) {
                return Err(out_of_range(
                    key,
                    format!("{pose:?}"),
                    "inside the workspace: below the highest anchor and, seen from above, \
                     inside the anchors' hull",
                ));
            }
        }
        if let Some(z_ref) = t.z_ref {
            return Err(out_of_range(
                "trajectory.z_ref",
                format!("{z_ref:?}"),
                "absent for a spatial robot: its move sets every coordinate",
            ));
        }
        self.validate_times()?;
        if t.shaper != ShaperKind::None {
            let (Some(omega), Some(zeta)) = (t.shaper_frequency.value(), t.shaper_damping.value())
            else {
                return Err(out_of_range(
                    "trajectory.shaper_frequency",
                    "\"auto\"",
                    "numbers (shaper_frequency [rad/s], shaper_damping) for a spatial robot",
                ));
            };
            Impulses::design(t.shaper, omega, zeta, t.shaper_vtol)?;
        }
        Ok(())
    }

    /// 0 ≤ t1 < t2.
    pub(super) fn validate_times(&self) -> Result<(), ScenarioError> {
        let t = &self.trajectory;
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
        Ok(())
    }
}

impl Trajectory {
    /// A spatial robot's move start → end [m]; the error names the missing key.
    pub fn spatial_move(&self) -> Result<([f64; 3], [f64; 3]), ScenarioError> {
        let pose = |key: &'static str, pose: &Option<Vec<f64>>| match pose.as_deref() {
            Some(&[x, y, z]) => Ok([x, y, z]),
            other => Err(out_of_range(
                key,
                format!("{other:?}"),
                "[x, y, z] m: a spatial robot's run moves from start to end",
            )),
        };
        Ok((
            pose("trajectory.start", &self.start)?,
            pose("trajectory.end", &self.end)?,
        ))
    }
}
