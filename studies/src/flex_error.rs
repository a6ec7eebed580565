//! What the lines' mass does to a printer at rest (`cargo xtask flex-error`): printer firmware
//! drives its reels by length and corrects for the lines' stretch with straight elastic lines
//! (MODELS.md §11, `flex_compensation = "static"`: l0_i = l_i / (1 + T_i/EA), T the
//! distribution of the weight at the target). Real lines sag; with the reels locked at those
//! lengths the effector rests elsewhere. Over a grid of targets this study finds that rest on
//! the lumped lines (their statics with locked reels) and reports the position error.

use crate::{Result, StudyError};
use cdpr_bench::core::model::CableModel;
use cdpr_bench::core::robot::Vector;
use cdpr_bench::core::robot::distribution::{TensionBox, distribute};
use cdpr_bench::core::scenario::Scenario;
use cdpr_bench::lumped::spatial::{LumpedSpatial, rest_with_lengths};

/// One target of the grid.
#[derive(Debug, Clone, serde::Serialize)]
pub struct FlexPoint {
    /// The pose the firmware aims at [m].
    pub target: [f64; 3],
    /// Where the effector rests on the sagging lines [m].
    pub rest: [f64; 3],
    /// |rest − target| [m].
    pub error: f64,
    /// The tensions the firmware's compensation assumed [N] and those the locked reels hold [N].
    pub assumed_tensions: Vec<f64>,
    pub held_tensions: Vec<f64>,
}

/// The study over a grid.
#[derive(Debug, Clone, serde::Serialize)]
pub struct FlexError {
    /// Springs per line of the lumped statics.
    pub elements: usize,
    /// Targets whose weight no distribution in the box holds (skipped).
    pub infeasible: usize,
    pub points: Vec<FlexPoint>,
    /// Largest and root-mean-square error over the grid [m].
    pub max: f64,
    pub rms: f64,
}

/// The error at every target of the `per_axis`³ grid spanning the box `low`–`high` [m], on the
/// scenario's robot and line lumped into `elements` springs.
pub fn over_box(
    scenario: &Scenario,
    low: [f64; 3],
    high: [f64; 3],
    per_axis: usize,
    elements: usize,
) -> Result<FlexError> {
    let model = LumpedSpatial::from_scenario(scenario, elements)
        .map_err(|e| StudyError::Failed(format!("the lumped lines: {e}")))?;
    let targets = grid(low, high, per_axis);
    let rows = crate::pool::map(&targets, |p| -> Result<Option<FlexPoint>> {
        let robot = model.robot();
        let Some(tensions) = rest_tensions(scenario, robot, p) else {
            return Ok(None);
        };
        let ea = scenario.cable.axial_stiffness();
        let lengths: Vec<f64> = (0..robot.cables())
            .map(|i| (robot.anchor(i) - p).norm() / (1.0 + tensions[i] / ea))
            .collect();
        let (rest, hangs) = rest_with_lengths(&model, p, &lengths).map_err(|e| {
            StudyError::Failed(format!(
                "locked reels at the target {:?} m: {e}",
                p.as_slice()
            ))
        })?;
        Ok(Some(FlexPoint {
            target: [p.x, p.y, p.z],
            rest: [rest.x, rest.y, rest.z],
            error: (rest - p).norm(),
            assumed_tensions: tensions,
            held_tensions: hangs.iter().map(|h| h.straddle_tension).collect(),
        }))
    })?;
    let (points, infeasible) = feasible(rows)?;
    let max = points.iter().map(|p| p.error).fold(0.0, f64::max);
    let rms =
        (points.iter().map(|p| p.error * p.error).sum::<f64>() / points.len().max(1) as f64).sqrt();
    Ok(FlexError {
        elements,
        infeasible,
        points,
        max,
        rms,
    })
}

/// A grid study's rows split into the targets' results and the count of targets outside the
/// wrench-feasible workspace (None), or its first error.
pub fn feasible<T>(rows: Vec<Result<Option<T>>>) -> Result<(Vec<T>, usize)> {
    let mut points = Vec::new();
    let mut infeasible = 0;
    for row in rows {
        match row? {
            Some(point) => points.push(point),
            None => infeasible += 1,
        }
    }
    Ok((points, infeasible))
}

/// The `per_axis`³ targets spanning the box `low`–`high` [m], x fastest, then y, then z (one
/// point per axis: the box's centre).
pub fn grid(low: [f64; 3], high: [f64; 3], per_axis: usize) -> Vec<Vector<3>> {
    let at = |k: usize, axis: usize| {
        let s = if per_axis > 1 {
            k as f64 / (per_axis - 1) as f64
        } else {
            0.5
        };
        low[axis] + s * (high[axis] - low[axis])
    };
    (0..per_axis.pow(3))
        .map(|k| {
            let (i, j, l) = (k % per_axis, (k / per_axis) % per_axis, k / per_axis.pow(2));
            Vector::<3>::new(at(i, 0), at(j, 1), at(l, 2))
        })
        .collect()
}

/// The scenario's distribution of the effector's weight at `p` [m] within its tension box
/// [N], or None where no tensions in the box hold it (outside the wrench-feasible workspace).
pub fn rest_tensions(
    scenario: &Scenario,
    robot: &cdpr_bench::core::robot::Robot<3>,
    p: &Vector<3>,
) -> Option<Vec<f64>> {
    let limits = TensionBox {
        t_min: scenario.controller.t_min.unwrap_or(0.0),
        t_max: scenario.controller.t_max.unwrap_or(f64::INFINITY),
    };
    let w = robot.structure_matrix(p);
    let lift = Vector::<3>::new(0.0, 0.0, robot.effector_mass * robot.gravity);
    let d = distribute(scenario.controller.distribution, &w, &lift, limits).ok()?;
    d.feasible.then(|| d.tensions.iter().copied().collect())
}

/// The study in Markdown: per height, the largest and the mean error over the targets there.
pub fn markdown(study: &FlexError) -> String {
    let mut heights: Vec<f64> = study.points.iter().map(|p| p.target[2]).collect();
    heights.sort_by(f64::total_cmp);
    heights.dedup();
    let mut out = format!(
        "Static flex compensation on sagging lines ({} springs per line): largest error {:.3e} m, \
         rms {:.3e} m over {} targets ({} outside the wrench-feasible workspace).\n\n\
         | z [m] | largest error [m] | mean error [m] | worst target [m] |\n|---|---|---|---|\n",
        study.elements,
        study.max,
        study.rms,
        study.points.len(),
        study.infeasible
    );
    for z in heights {
        let here: Vec<&FlexPoint> = study.points.iter().filter(|p| p.target[2] == z).collect();
        let worst = here
            .iter()
            .max_by(|a, b| a.error.total_cmp(&b.error))
            .map_or([f64::NAN; 3], |p| p.target);
        let mean = here.iter().map(|p| p.error).sum::<f64>() / here.len() as f64;
        out += &format!(
            "| {z:.3} | {:.3e} | {mean:.3e} | [{:.3}, {:.3}, {:.3}] |\n",
            here.iter().map(|p| p.error).fold(0.0, f64::max),
            worst[0],
            worst[1],
            worst[2]
        );
    }
    out
}
