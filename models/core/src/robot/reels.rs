//! Where each massive cable's stored line lies behind its pulley (MODELS.md §11): the reel
//! direction r_i, given per cable by the scenario or by default horizontal and away from the
//! anchors' centroid, and checked not to point into the workspace. Shared by every massive
//! cable model in space, which lay their stored line along it.

use super::Robot;
use crate::model::ModelError;
use nalgebra::Vector3;

/// Time constant τ of a length-driven reel's velocity loop [s]: the massive models' reels follow
/// the commanded l̇0 with the loop's correction (v_cmd − v)/τ added to the command's own
/// derivative — far faster than the effector's modes, far slower than the lines' axial ones.
pub const REEL_TIME_CONSTANT: f64 = 1e-4;

/// The anchors' centroid [m], the workspace's middle for the reel directions.
pub fn centroid(anchors: &[Vector3<f64>]) -> Vector3<f64> {
    anchors.iter().sum::<Vector3<f64>>() / anchors.len() as f64
}

/// The default reel direction of each anchor (MODELS.md §11): horizontal, away from the anchors'
/// centroid — but for an anchor whose horizontal offset from the centroid is smaller than its
/// vertical one (a ceiling anchor such as Hangprinter's D), vertical, away from the centroid: a
/// horizontal reel line there would put the anchor's own plumb line on the boundary of the
/// pulley's side rule.
pub fn default_reel_directions(anchors: &[Vector3<f64>]) -> Vec<Vector3<f64>> {
    let centroid = centroid(anchors);
    anchors
        .iter()
        .map(|a| {
            let away = a - centroid;
            let horizontal = Vector3::new(away.x, away.y, 0.0);
            if horizontal.norm() >= away.z.abs() {
                horizontal.normalize()
            } else {
                Vector3::z() * away.z.signum()
            }
        })
        .collect()
}

/// `reels`, one per cable, as unit vectors, each checked not to point into the workspace
/// ((A_i − centroid)·r_i ≥ 0, so that a top anchor may reel horizontally).
pub fn unit_reel_directions(
    robot: &Robot<3>,
    reels: &[Vector3<f64>],
) -> Result<Vec<Vector3<f64>>, ModelError> {
    let m = robot.cables();
    if reels.len() != m {
        return Err(ModelError::Parameter {
            name: "robot.reel_directions",
            value: reels.len() as f64,
            allowed: format!("one direction per anchor ({m})"),
        });
    }
    let centroid = centroid(robot.anchors());
    reels
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let norm = r.norm();
            let away = robot.anchor(i) - centroid;
            let outward = away.dot(r);
            let tolerance = -1e-9 * away.norm();
            if norm.is_finite() && norm > 0.0 && outward >= tolerance {
                Ok(r / norm)
            } else {
                Err(ModelError::Parameter {
                    name: "robot.reel_directions",
                    value: outward,
                    allowed: format!(
                        "cable {}: a nonzero direction [{}, {}, {}] not pointing into the \
                         workspace (its dot product with A_i − the anchors' centroid ≥ 0): the \
                         reel line must leave the workspace",
                        i + 1,
                        r.x,
                        r.y,
                        r.z
                    ),
                })
            }
        })
        .collect()
}

/// The scenario's reel directions (`robot.reel_directions`, or the defaults) as checked units.
pub fn scenario_reel_directions(
    scenario: &crate::scenario::Scenario,
    robot: &Robot<3>,
) -> Result<Vec<Vector3<f64>>, ModelError> {
    let reels: Vec<Vector3<f64>> = match &scenario.robot.reel_directions {
        Some(given) => given
            .iter()
            .map(|r| Vector3::from_iterator(r.iter().copied()))
            .collect(),
        None => default_reel_directions(robot.anchors()),
    };
    unit_reel_directions(robot, &reels)
}
