//! A spatial robot's statics at one pose (`cargo xtask distribution`): the cable lengths, every
//! tension distribution method of MODELS.md §11 holding the effector's weight within the
//! scenario's box, and the largest uniform margin to the box.

use crate::{Result, StudyError};
use cdpr_bench::core::robot::distribution::{
    Bound, DistributionMethod, TensionBox, distribute, margin,
};
use cdpr_bench::core::robot::{Vector, along_vertical, height};
use cdpr_bench::core::scenario::Scenario;
use std::collections::BTreeMap;

/// One method's answer.
#[derive(Debug, Clone, serde::Serialize)]
pub struct MethodEntry {
    /// In the scenario's cable order [N].
    pub tensions: Vec<f64>,
    pub feasible: bool,
    /// [cable number from 1, "min" | "max"] in clamping order.
    pub clamped: Vec<(usize, Bound)>,
}

/// `distribution.json`.
#[derive(Debug, Clone, serde::Serialize)]
pub struct DistributionReport {
    /// The effector position [m].
    pub pose: [f64; 3],
    /// Each cable's length from its anchor to the effector [m].
    pub lengths: Vec<f64>,
    /// The wrench the cables supply: the weight, (0, 0, M g) [N].
    pub wrench: [f64; 3],
    /// One entry per method name.
    pub methods: BTreeMap<&'static str, MethodEntry>,
    /// The largest s with W T = w and t_min + s ≤ T ≤ t_max − s [N]; negative: no distribution
    /// in the box holds the effector here.
    pub margin: f64,
}

/// The statics of `scenario`'s spatial robot with the effector at rest at `pose` [m].
pub fn at_pose(scenario: &Scenario, pose: [f64; 3]) -> Result<DistributionReport> {
    let robot = scenario.spatial_robot().ok_or_else(|| {
        StudyError::Failed(
            "robot.anchors: the tension distribution needs a spatial robot ([robot] anchors = \
             [[x, y, z], …])"
                .into(),
        )
    })?;
    if !pose.iter().all(|v| v.is_finite()) {
        return Err(StudyError::Failed(format!(
            "--at {pose:?}: the pose must be three finite coordinates [m]"
        )));
    }
    let p = Vector::<3>::from(pose);
    let lengths: Vec<f64> = (0..robot.cables())
        .map(|i| robot.chord(i, &p).length)
        .collect();
    if let Some(i) = lengths.iter().position(|&l| l < 1e-9) {
        return Err(StudyError::Failed(format!(
            "--at {pose:?} m coincides with anchor {}: the cable has no direction there",
            i + 1
        )));
    }
    let w = robot.structure_matrix(&p);
    let wrench = along_vertical::<3>(robot.effector_mass * robot.gravity);
    let limits = TensionBox {
        t_min: scenario.controller.t_min.unwrap_or(0.0),
        t_max: scenario.controller.t_max.unwrap_or(f64::INFINITY),
    };
    let failed = |e: cdpr_bench::core::robot::distribution::DistributionError| {
        StudyError::Failed(format!("at {pose:?} m: {e}"))
    };
    let mut methods = BTreeMap::new();
    for method in DistributionMethod::ALL {
        let d = distribute(method, &w, &wrench, limits).map_err(failed)?;
        methods.insert(
            method.name(),
            MethodEntry {
                tensions: d.tensions.iter().copied().collect(),
                feasible: d.feasible,
                clamped: d.clamped.iter().map(|&(c, b)| (c.0 + 1, b)).collect(),
            },
        );
    }
    Ok(DistributionReport {
        pose,
        lengths,
        wrench: [wrench[0], wrench[1], height(&wrench)],
        methods,
        margin: margin(&w, &wrench, limits).map_err(failed)?,
    })
}
