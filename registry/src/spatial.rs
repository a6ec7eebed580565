//! A spatial robot's run (MODELS.md §11): the massless elastic cables in space under the
//! scenario's controller and tension distribution. Before any work the whole reference is checked
//! for wrench feasibility — at rest and with its acceleration, by the exact QP — so that a move
//! leaving the feasible workspace is refused with the time, the pose and the cable that cannot
//! hold, never run into saturation silently.

use crate::config::ModelConfig;
use crate::kind::ModelKind;
use crate::study::Error;
use cdpr_analysis::spatial::{SpatialContext, SpatialMetrics};
use cdpr_core::closed_loop::ClosedLoop;
use cdpr_core::model::{CableModel, ModelParams};
use cdpr_core::robot::distribution::{
    BOX_TOLERANCE, Bound, DistributionMethod, TensionBox, distribute,
};
use cdpr_core::robot::{Robot, Vector, along_vertical};
use cdpr_core::runner::{Observer, Run, RunOptions, simulate_observed_reusing};
use cdpr_core::scenario::{Scenario, out_of_range};
use cdpr_core::series::SeriesBuffer;
use cdpr_core::shaper::Impulses;
use cdpr_core::trajectory::Segment;
use cdpr_elastic::Elastic;
use cdpr_fe::spatial::FeSpatial;
use cdpr_lumped::spatial::LumpedSpatial;

/// Instants of the reference checked for feasibility over the move (plus its start and end).
pub const FEASIBILITY_SAMPLES: usize = 2000;

/// A reference the cables cannot follow inside their box.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "the reference leaves the wrench-feasible workspace at t = {t} s, pose {pose:?} m ({load}): \
     no tensions in the box [{t_min}, {t_max}] N supply the wrench {wrench:?} N; cable {cable} \
     would need to go {bound:?}"
)]
pub struct InfeasibleReference {
    pub t: f64,
    pub pose: [f64; 3],
    /// "at rest" or "with its acceleration".
    pub load: &'static str,
    pub wrench: [f64; 3],
    /// The cable (from 1) farthest outside the box in the minimum-norm solution.
    pub cable: usize,
    pub bound: Bound,
    pub t_min: f64,
    pub t_max: f64,
}

/// A spatial run and its metrics.
pub struct SpatialRun {
    pub run: Run,
    pub metrics: SpatialMetrics,
}

/// The spatial robot's move, shaper and tension box, checked: the robot and its model
/// ([`spatial_robot`]), the move given for three or more cables, the reference feasible.
pub fn prepare_spatial(scenario: &Scenario) -> Result<Robot<3>, Error> {
    let (robot, _) = run_robot(scenario)?;
    if robot.cables() >= 3 {
        let path = segment(scenario)?;
        let shaper = scenario.trajectory.impulses()?;
        check_reference(scenario, &robot, &path, shaper.as_ref())?;
    }
    Ok(robot)
}

/// The scenario's spatial robot with its model checked — what the modes study needs, without the
/// move (it runs the massless elastic cables, and the lumped lines' locked modes when the
/// scenario has them).
pub fn spatial_robot(scenario: &Scenario) -> Result<Robot<3>, Error> {
    Ok(run_robot(scenario)?.0)
}

/// The scenario's spatial robot and the cable model its move runs, checked: the massless elastic
/// cables, or the lumped ones (MODELS.md §4 in space) — reels driven by length on the lumped
/// cables on DOPRI5 only, refused by name on the implicit path.
pub(crate) fn run_robot(scenario: &Scenario) -> Result<(Robot<3>, ModelKind), Error> {
    let robot = scenario.spatial_robot().ok_or_else(|| {
        out_of_range(
            "robot.anchors",
            "absent",
            "[[x, y, z], …] for a spatial run (the planar robot runs `simulate`)",
        )
    })?;
    let config = ModelConfig::from_scenario(scenario)?;
    match config.kind {
        ModelKind::Elastic => cdpr_elastic::Params {}.validate(scenario)?,
        ModelKind::Lumped | ModelKind::Fe => check_massive(&robot, config.kind)?,
    }
    match config.kind {
        ModelKind::Lumped => {
            lumped_model(scenario, &config)?;
        }
        ModelKind::Fe => {
            fe_model(scenario, &config)?;
        }
        ModelKind::Elastic => {}
    }
    Ok((robot, config.kind))
}

/// What the spatial massive cables (`kind`: lumped or FE) run: three or more cables, on reels
/// pulled by tension or driven by length (lumped: the passage rate of nodes; FE: Du's prescribed
/// free lengths), on either integrator.
fn check_massive(robot: &Robot<3>, kind: ModelKind) -> Result<(), Error> {
    if robot.cables() >= 3 {
        return Ok(());
    }
    let label = match kind {
        ModelKind::Fe => "FE",
        _ => kind.name(),
    };
    Err(out_of_range(
        "robot.anchors",
        format!("{} anchors with model.kind = \"{kind}\"", robot.cables()),
        format!("3 to 8 anchors for the spatial {label} cables (two cables in space run elastic)"),
    )
    .into())
}

/// The spatial FE model of `scenario` (its `[model]` keys), its modelled length checked against
/// the move: 1.05 (1 + t_max/EA) times the longest chord from a pulley to the move's start or
/// end (the chord to a straight segment is longest at one of its ends), as the lumped lines'.
pub(crate) fn fe_model(scenario: &Scenario, config: &ModelConfig) -> Result<FeSpatial, Error> {
    let model = FeSpatial::from_scenario(scenario, config.fe()?)?;
    if let Ok((start, end)) = scenario.trajectory.spatial_move() {
        let t_max = scenario.controller.t_max.unwrap_or(0.0);
        let chord = [start, end]
            .iter()
            .flat_map(|p| {
                let p = Vector::from(*p);
                model.robot().anchors().iter().map(move |a| (a - p).norm())
            })
            .fold(0.0, f64::max);
        let needed = 1.05 * (1.0 + t_max / model.material.ea) * chord;
        if model.modelled_length < needed {
            return Err(out_of_range(
                "cable.modelled_length",
                model.modelled_length.to_string(),
                format!(
                    "≥ {needed:.6} m for this move (1.05 × (1 + t_max/EA) × longest chord \
                     {chord:.6} m)"
                ),
            )
            .into());
        }
    }
    Ok(model)
}

/// The spatial lumped model of `scenario` (its `[model] elements`).
pub(crate) fn lumped_model(
    scenario: &Scenario,
    config: &ModelConfig,
) -> Result<LumpedSpatial, Error> {
    Ok(LumpedSpatial::from_scenario(
        scenario,
        config.lumped()?.elements,
    )?)
}

/// The scenario's move as a segment.
fn segment(scenario: &Scenario) -> Result<Segment<3>, Error> {
    let (start, end) = scenario.trajectory.spatial_move()?;
    Ok(Segment {
        start: Vector::from(start),
        end: Vector::from(end),
        t1: scenario.trajectory.t1,
        t2: scenario.trajectory.t2,
    })
}

/// The wrench-feasibility check of the whole reference: at [`FEASIBILITY_SAMPLES`] instants
/// of the (shaped) move and its start and end, the exact QP must find tensions in the box for
/// the weight alone (the robot may stop anywhere) and for M (a_ref − g⃗).
pub fn check_reference(
    scenario: &Scenario,
    robot: &Robot<3>,
    path: &Segment<3>,
    shaper: Option<&Impulses>,
) -> Result<(), Error> {
    let end = path.t2 + shaper.map_or(0.0, Impulses::duration);
    let n = FEASIBILITY_SAMPLES;
    let times = (0..=n + 1).map(|k| {
        if k == 0 {
            0.0
        } else {
            path.t1 + (end - path.t1) * (k - 1) as f64 / n as f64
        }
    });
    check_feasible(scenario, robot, times, |t| {
        let [p, _, a] = path.shaped(shaper, t, true);
        (p, a)
    })
}

/// The wrench-feasibility check at the given `times` [s] of a reference giving (p_ref, p̈_ref)
/// (see [`check_reference`]).
pub fn check_feasible(
    scenario: &Scenario,
    robot: &Robot<3>,
    times: impl Iterator<Item = f64>,
    reference: impl Fn(f64) -> (Vector<3>, Vector<3>),
) -> Result<(), Error> {
    let limits = TensionBox {
        t_min: scenario.controller.t_min.unwrap_or(0.0),
        t_max: scenario.controller.t_max.unwrap_or(f64::INFINITY),
    };
    let mass = robot.effector_mass;
    let lift = along_vertical::<3>(robot.gravity);
    for t in times {
        let (p, a) = reference(t);
        let w = robot.structure_matrix(&p);
        for (load, wrench) in [
            ("at rest", lift * mass),
            ("with its acceleration", (a + lift) * mass),
        ] {
            let d = distribute(DistributionMethod::Qp, &w, &wrench, limits).map_err(|e| {
                out_of_range(
                    "trajectory",
                    format!("pose {:?} m at t = {t} s", p.as_slice()),
                    format!("a pose where the cables span every direction ({e})"),
                )
            })?;
            if !d.feasible {
                let (cable, bound) = worst_cable(&d.tensions, limits);
                return Err(InfeasibleReference {
                    t,
                    pose: [p[0], p[1], p[2]],
                    load,
                    wrench: [wrench[0], wrench[1], wrench[2]],
                    cable: cable + 1,
                    bound,
                    t_min: limits.t_min,
                    t_max: limits.t_max,
                }
                .into());
            }
        }
    }
    Ok(())
}

/// The cable farthest outside the box, and which bound it crosses.
fn worst_cable(tensions: &[f64], limits: TensionBox) -> (usize, Bound) {
    let mut worst = (0, Bound::Min, f64::NEG_INFINITY);
    for (i, &t) in tensions.iter().enumerate() {
        for (bound, excess) in [
            (Bound::Min, limits.t_min - t),
            (Bound::Max, t - limits.t_max),
        ] {
            if excess > worst.2 + BOX_TOLERANCE {
                worst = (i, bound, excess);
            }
        }
    }
    (worst.0, worst.1)
}

/// Runs a spatial scenario, watched and steered by `observer`, and measures it.
pub fn simulate_spatial(scenario: &Scenario, observer: &mut Observer) -> Result<SpatialRun, Error> {
    simulate_spatial_into(scenario, observer, SeriesBuffer::default())
}

/// Generic work on a spatial scenario's cable model, monomorphised for each (as the planar
/// [`crate::ModelVisitor`]).
pub(crate) trait SpatialVisitor {
    type Output;
    fn visit<M: CableModel<3>>(self, model: M) -> Result<Self::Output, Error>;
}

/// The scenario's spatial cable model, checked and built, handed to `visitor`: the kind is
/// matched here and nowhere else.
pub(crate) fn with_spatial_model<V: SpatialVisitor>(
    scenario: &Scenario,
    visitor: V,
) -> Result<V::Output, Error> {
    let (robot, kind) = run_robot(scenario)?;
    match kind {
        ModelKind::Lumped => visitor.visit(lumped_model(
            scenario,
            &ModelConfig::from_scenario(scenario)?,
        )?),
        ModelKind::Fe => visitor.visit(fe_model(scenario, &ModelConfig::from_scenario(scenario)?)?),
        ModelKind::Elastic => visitor.visit(Elastic::new(robot, scenario.cable.axial_stiffness())),
    }
}

/// As [`simulate_spatial`], the samples written into `buffer`'s memory (a sweep's worker).
pub fn simulate_spatial_into(
    scenario: &Scenario,
    observer: &mut Observer,
    buffer: SeriesBuffer,
) -> Result<SpatialRun, Error> {
    struct Simulate<'s, 'o, 'p> {
        scenario: &'s Scenario,
        observer: &'o mut Observer<'p>,
        buffer: SeriesBuffer,
    }
    impl SpatialVisitor for Simulate<'_, '_, '_> {
        type Output = SpatialRun;
        fn visit<M: CableModel<3>>(self, model: M) -> Result<SpatialRun, Error> {
            let mut sys = ClosedLoop::new(model, self.scenario)?;
            let options = RunOptions::from(self.scenario);
            let run = simulate_observed_reusing(&mut sys, &options, self.buffer, self.observer)?;
            let metrics = spatial_metrics(self.scenario, &sys, &run);
            Ok(SpatialRun { run, metrics })
        }
    }
    prepare_spatial(scenario)?;
    with_spatial_model(
        scenario,
        Simulate {
            scenario,
            observer,
            buffer,
        },
    )
}

/// The closed loop of `robot` under `scenario`, the reference not checked again.
pub(crate) fn loop_of(
    scenario: &Scenario,
    robot: Robot<3>,
) -> Result<ClosedLoop<Elastic<3>, 3>, Error> {
    let model = Elastic::new(robot, scenario.cable.axial_stiffness());
    Ok(ClosedLoop::new(model, scenario)?)
}

/// The metrics of `run` (e.g. the part a failed run sampled) of the spatial `scenario`.
pub fn spatial_metrics_of(scenario: &Scenario, run: &Run) -> Result<SpatialMetrics, Error> {
    // The metrics read the loop's path, shaper and cable count, which the cable model does not
    // change: the elastic loop of the same robot gives them.
    Ok(spatial_metrics(
        scenario,
        &loop_of(scenario, run_robot(scenario)?.0)?,
        run,
    ))
}

/// The spatial scenario ready to run: checked as [`prepare_spatial`] does, and its loop
/// brought to rest at the start (a controller that cannot be designed, or a start the tensions
/// do not hold, is refused here).
pub fn prepare_spatial_start(scenario: &Scenario) -> Result<(), Error> {
    struct Start<'s>(&'s Scenario);
    impl SpatialVisitor for Start<'_> {
        type Output = ();
        fn visit<M: CableModel<3>>(self, model: M) -> Result<(), Error> {
            ClosedLoop::new(model, self.0)?.initial_state()?;
            Ok(())
        }
    }
    prepare_spatial(scenario)?;
    with_spatial_model(scenario, Start(scenario))
}

/// The number of channels of a spatial scenario's run.
pub fn spatial_channels(scenario: &Scenario) -> Result<usize, Error> {
    Ok(spatial_channel_headings(scenario)?.0.len())
}

/// The names and units of a spatial scenario's channels (its cable model's own after the common
/// ones).
pub fn spatial_channel_headings(
    scenario: &Scenario,
) -> Result<(Vec<String>, Vec<&'static str>), Error> {
    struct Headings;
    impl SpatialVisitor for Headings {
        type Output = (Vec<String>, Vec<&'static str>);
        fn visit<M: CableModel<3>>(self, model: M) -> Result<Self::Output, Error> {
            use cdpr_core::runner::{channel_names, channel_units};
            Ok((channel_names(&model), channel_units(&model)))
        }
    }
    with_spatial_model(scenario, Headings)
}

/// The metrics of a spatial run of `scenario` on the loop `sys`.
pub fn spatial_metrics<M: CableModel<3>>(
    scenario: &Scenario,
    sys: &ClosedLoop<M, 3>,
    run: &Run,
) -> SpatialMetrics {
    let context = SpatialContext {
        path: sys.path.as_ref().and_then(|p| p.as_move().copied()),
        shaper: sys.shaper.clone(),
        move_start: scenario.trajectory.t1,
        move_end: sys.move_end(),
        controller: scenario.controller.kind.name(),
        distribution: if sys.robot().cables() > 3 {
            scenario.controller.distribution.name()
        } else {
            "none"
        },
    };
    SpatialMetrics::from_run(run, &context)
}
