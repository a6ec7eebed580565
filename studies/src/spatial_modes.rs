//! A spatial robot's modes at a pose (`cargo xtask modes --scenario FILE --at X,Y,Z`), each with
//! its direction: the effector on its cables with the reels holding their tensions (the
//! geometric stiffness Σ (T_i/l_i)(I − u_i u_iᵀ), MODELS.md §11), with the reels locked
//! (K = Σ (EA/l_i) u_i u_iᵀ + (T_i/l_i) I), and in the scenario's closed loop (the elastic
//! model and its controller, linearised by central differences at rest at the pose); for a
//! scenario on lumped or FE lines also every mode of the lines and the effector with the reels
//! locked, each named (effector x, y, vertical; each cable's string in and across its vertical
//! plane; axial). The tensions at rest are the scenario's distribution of the weight there.

use crate::repeated_modes::{self, Complex};
use crate::{Result, StudyError};
use cdpr_bench::analysis::linearise::closed_loop_jacobian;
use cdpr_bench::analysis::modes::ModeKind;
use cdpr_bench::core::closed_loop::ClosedLoop;
use cdpr_bench::core::controller::TensionSolver;
use cdpr_bench::core::robot::{Matrix, Robot, Vector};
use cdpr_bench::core::scenario::Scenario;
use cdpr_bench::elastic::Elastic;
use cdpr_bench::numerics::eigen::mode_shapes;

/// Which linearisation a mode is of.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SpatialLoop {
    /// Open loop, reels holding their tensions (ideal tension control).
    TensionReels,
    /// Open loop, reels locked (lengths held).
    LockedReels,
    /// The scenario's controller closing the loop.
    Closed,
    /// The scenario's lumped lines at rest, reels locked (the firmware's robot between moves):
    /// every mode of the lines and the effector, named.
    LumpedLockedReels,
    /// The same on the scenario's FE cables (consistent masses, l_i and ρ_i held).
    FeLockedReels,
}

/// The massive lines whose locked modes are named, and their elements per line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Lines {
    Lumped(usize),
    Fe(usize),
}

/// One mode.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SpatialMode {
    pub linearisation: SpatialLoop,
    /// ω [rad/s] and growth σ [1/s] of λ = σ + iω.
    pub omega_rad_s: f64,
    pub growth: f64,
    /// The effector's motion in the mode, unit length (zero for a mode of the controller's
    /// states alone).
    pub direction: [f64; 3],
    /// "vertical (z)", "horizontal (x)", "horizontal (y)", "out-of-plane (y)" (two cables in
    /// the plane y = const), or "controller".
    pub name: String,
    /// The lumped lines' modes: what moves (effector, a cable's string, axial); absent for the
    /// effector on elastic cables.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub kind: Option<ModeKind>,
    /// The lumped lines' modes: the effector's share of the mode's kinetic energy, M_e |φ_e|²
    /// of the mass-normalised shape (1 for the effector on massless cables; over all modes the
    /// shares sum to 3, one per axis).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub effector_share: Option<f64>,
}

/// `modes.json`.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SpatialModes {
    pub pose: [f64; 3],
    /// The tensions at rest [N].
    pub tensions: Vec<f64>,
    pub modes: Vec<SpatialMode>,
}

/// The modes of `scenario`'s robot at rest at `pose` [m] (two cables: at rest at x = pose[0],
/// the other coordinates found by the statics).
pub fn at_pose(scenario: &Scenario, pose: [f64; 3]) -> Result<SpatialModes> {
    let robot = cdpr_bench::spatial_robot(scenario)?;
    // The loop held at rest at the pose: a move of zero length (two cables: the paper's rule
    // at x, the height and y its statics').
    let mut closed_scenario = scenario.clone();
    if robot.cables() > 2 {
        closed_scenario.trajectory.start = Some(pose.to_vec());
        closed_scenario.trajectory.end = Some(pose.to_vec());
    } else {
        closed_scenario.trajectory.x1 = pose[0];
        closed_scenario.trajectory.x2 = pose[0];
    }
    closed_scenario.validate()?;
    let ea = scenario.cable.axial_stiffness();
    let mut sys = ClosedLoop::new(Elastic::new(robot, ea), &closed_scenario)
        .map_err(cdpr_bench::Error::from)?;
    let (y, eq) = sys.initial_state().map_err(cdpr_bench::Error::from)?;
    let p = Vector::<3>::from_column_slice(&eq.state[..3]);
    let pose = [p[0], p[1], p[2]];
    let tensions = if robot.cables() > 2 {
        TensionSolver::from(&scenario.controller).for_acceleration(&robot, &p, &Vector::zeros())
    } else {
        eq.tensions
    };
    let mut modes = open_loop_modes(&robot, &p, &tensions, ea);
    modes.extend(closed_loop_modes(&mut sys, &y, &robot, pose)?);
    let config = cdpr_bench::ModelConfig::from_scenario(scenario)?;
    let lines = match config.kind {
        cdpr_bench::ModelKind::Lumped => Some(Lines::Lumped(
            config.lumped().map_err(cdpr_bench::Error::from)?.elements,
        )),
        cdpr_bench::ModelKind::Fe => Some(Lines::Fe(
            config.fe().map_err(cdpr_bench::Error::from)?.elements,
        )),
        _ => None,
    };
    if let Some(lines) = lines.filter(|_| robot.cables() > 2) {
        let locked = modes
            .iter()
            .filter(|m| m.linearisation == SpatialLoop::LockedReels)
            .map(|m| m.omega_rad_s);
        let (low, high) = locked.fold((f64::INFINITY, 0.0f64), |(l, h), w| (l.min(w), h.max(w)));
        let centre = (low * high).sqrt();
        modes.extend(locked_line_modes(scenario, lines, &p, &tensions, centre)?);
    }
    Ok(SpatialModes {
        pose,
        tensions: tensions.to_vec(),
        modes,
    })
}

/// The effector's modes on its cables with the reels holding `tensions` (the geometric
/// stiffness) and with the reels locked, from the closed-form stiffness matrices.
fn open_loop_modes(robot: &Robot<3>, p: &Vector<3>, tensions: &[f64], ea: f64) -> Vec<SpatialMode> {
    let mut geometric = Matrix::<3>::zeros();
    let mut locked = Matrix::<3>::zeros();
    for (i, t) in tensions.iter().enumerate() {
        let c = robot.chord(i, p);
        let uu = c.direction * c.direction.transpose();
        geometric += (Matrix::<3>::identity() - uu) * (t / c.length);
        locked += uu * (ea / c.length) + Matrix::<3>::identity() * (t / c.length);
    }
    let mut modes = Vec::new();
    for (linearisation, k) in [
        (SpatialLoop::TensionReels, geometric),
        (SpatialLoop::LockedReels, locked),
    ] {
        let eigen = (k / robot.effector_mass).symmetric_eigen();
        let mut pairs: Vec<(f64, Vector<3>)> = (0..3)
            .map(|j| {
                (
                    eigen.eigenvalues[j],
                    eigen.eigenvectors.column(j).into_owned(),
                )
            })
            .collect();
        pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
        let first = modes.len();
        let motions: Vec<[Complex; 3]> = pairs
            .iter()
            .map(|(_, v)| [0, 1, 2].map(|k| (v[k], 0.0)))
            .collect();
        for (lambda, v) in pairs {
            let direction = [v[0], v[1], v[2]];
            modes.push(SpatialMode {
                linearisation,
                omega_rad_s: lambda.max(0.0).sqrt(),
                growth: (-lambda).max(0.0).sqrt(),
                name: name(robot, direction),
                direction,
                kind: None,
                effector_share: None,
            });
        }
        // A real eigenspace's axis basis is real: its directions keep their signs.
        from_eigenspaces(robot, &mut modes[first..], &motions, |c| c.map(|z| z.0));
    }
    modes
}

/// The directions (and names) of modes that share an eigenvalue, replaced by their eigenspace's
/// axis basis ([`repeated_modes`]), `direction_of` turning a unit complex motion into the
/// reported direction; `motions` are the modes' effector parts. A simple mode keeps its own.
fn from_eigenspaces(
    robot: &Robot<3>,
    modes: &mut [SpatialMode],
    motions: &[[Complex; 3]],
    direction_of: impl Fn(&[Complex; 3]) -> [f64; 3],
) {
    let eigenvalues: Vec<(f64, f64)> = modes.iter().map(|m| (m.growth, m.omega_rad_s)).collect();
    for group in repeated_modes::groups(&eigenvalues) {
        if group.len() < 2 {
            continue;
        }
        let own: Vec<[Complex; 3]> = group.iter().map(|&i| motions[i]).collect();
        let basis = repeated_modes::axis_basis(&own);
        for (n, &i) in group.iter().enumerate() {
            let direction = basis.get(n).map_or([0.0; 3], &direction_of);
            modes[i].direction = direction;
            modes[i].name = name(robot, direction);
        }
    }
}

/// Every mode of the scenario's massive `lines` at rest at `p` [m] under `tensions` [N], reels
/// then locked, each named (`cdpr_analysis::rest_modes`); beyond the dense solve's size, the
/// lumped lines' [`SPARSE_MODES`] nearest `centre` [rad/s] (the elastic lines' locked effector
/// modes), by shift-invert.
pub fn locked_line_modes(
    scenario: &Scenario,
    lines: Lines,
    p: &Vector<3>,
    tensions: &[f64],
    centre: f64,
) -> Result<Vec<SpatialMode>> {
    use cdpr_bench::core::model::{CableModel, PoseRule};
    let fail =
        |e: String| StudyError::Failed(format!("{lines:?} modes at {:?} m: {e}", p.as_slice()));
    let hold = cdpr_bench::core::robot::Tensions::from_slice(tensions);
    let rule = PoseRule::new(p, hold);
    match lines {
        Lines::Lumped(elements) => {
            let mut model =
                cdpr_bench::lumped::spatial::LumpedSpatial::from_scenario(scenario, elements)
                    .map_err(|e| fail(e.to_string()))?;
            let rest = model.equilibrium(&rule).map_err(|e| fail(e.to_string()))?;
            model.lock_reels(true);
            named_modes(
                &mut model,
                &rest.state,
                centre,
                SpatialLoop::LumpedLockedReels,
            )
        }
        Lines::Fe(elements) => {
            let mut params = cdpr_bench::ModelConfig::from_scenario(scenario)?
                .fe()
                .map_err(cdpr_bench::Error::from)?;
            params.elements = elements;
            let mut model = cdpr_bench::fe::spatial::FeSpatial::from_scenario(scenario, params)
                .map_err(|e| fail(e.to_string()))?;
            let rest = model.equilibrium(&rule).map_err(|e| fail(e.to_string()))?;
            model.lock_reels(true);
            named_modes(&mut model, &rest.state, centre, SpatialLoop::FeLockedReels)
        }
    }
    .map_err(|e| fail(e.to_string()))
}

/// The named modes of a locked `model` at rest in `rest` (the dense solve, or beyond its size
/// the sparse one near `centre` [rad/s]), each with its effector direction and share.
fn named_modes<M: cdpr_bench::core::model::CableModel<3>>(
    model: &mut M,
    rest: &[f64],
    centre: f64,
    linearisation: SpatialLoop,
) -> std::result::Result<Vec<SpatialMode>, cdpr_bench::analysis::AnalysisError> {
    use cdpr_bench::analysis::AnalysisError;
    use cdpr_bench::analysis::rest_modes::{rest_modes, rest_modes_near};
    let none = vec![0.0; model.robot().cables()];
    let named = match rest_modes(model, rest, &none) {
        Err(AnalysisError::TooLarge { .. }) => {
            rest_modes_near(model, rest, &none, (centre, SPARSE_MODES, 80)).map(|(named, _)| named)
        }
        other => other,
    }?;
    let effector_mass = model.robot().effector_mass;
    Ok(named
        .modes
        .iter()
        .zip(&named.effector_motion)
        .map(|(m, motion)| {
            let norm = motion.iter().map(|v| v * v).sum::<f64>().sqrt();
            let direction =
                std::array::from_fn(|k| if norm > 0.0 { motion[k] / norm } else { 0.0 });
            SpatialMode {
                linearisation,
                omega_rad_s: m.mode.omega,
                growth: m.mode.growth,
                direction,
                name: format!("{} #{}", m.kind, m.order),
                kind: Some(m.kind),
                effector_share: Some(effector_mass * norm * norm),
            }
        })
        .collect())
}

/// The closed loop's modes at its rest state `y`, from its finite-difference Jacobian.
fn closed_loop_modes(
    sys: &mut ClosedLoop<Elastic<3>, 3>,
    y: &[f64],
    robot: &Robot<3>,
    pose: [f64; 3],
) -> Result<Vec<SpatialMode>> {
    let jacobian = closed_loop_jacobian(sys, 0.0, y);
    let shapes = mode_shapes(&jacobian)
        .map_err(|e| StudyError::Failed(format!("closed-loop modes at {pose:?} m: {e}")))?;
    let motions: Vec<[Complex; 3]> = shapes
        .iter()
        .map(|s| [s.vector[0], s.vector[1], s.vector[2]])
        .collect();
    let mut modes: Vec<SpatialMode> = shapes
        .into_iter()
        .map(|shape| {
            // The effector's position components of the (complex) eigenvector, by magnitude.
            let v = Vector::<3>::from_fn(|k, _| shape.vector[k].0.hypot(shape.vector[k].1));
            let norm = v.norm();
            let direction = if norm > 1e-6 {
                let u = v / norm;
                [u[0], u[1], u[2]]
            } else {
                [0.0; 3]
            };
            SpatialMode {
                linearisation: SpatialLoop::Closed,
                omega_rad_s: shape.mode.omega,
                growth: shape.mode.growth,
                name: name(robot, direction),
                direction,
                kind: None,
                effector_share: None,
            }
        })
        .collect();
    // A complex motion's direction is its components' magnitudes, as for a simple mode.
    from_eigenspaces(robot, &mut modes, &motions, |c| c.map(|z| z.0.hypot(z.1)));
    Ok(modes)
}

/// A mode's name from its direction's dominant axis.
fn name(robot: &Robot<3>, direction: [f64; 3]) -> String {
    let [x, y, z] = direction.map(f64::abs);
    if x.max(y).max(z) == 0.0 {
        return "controller".into();
    }
    if z >= x && z >= y {
        "vertical (z)".into()
    } else if x >= y {
        "horizontal (x)".into()
    } else if robot.cables() == 2 {
        "out-of-plane (y)".into()
    } else {
        "horizontal (y)".into()
    }
}

/// How many modes the sparse solve finds around the effector's when the dense one is too large.
const SPARSE_MODES: usize = 12;

/// The massive lines' lowest modes the Markdown table lists (modes.json has them all).
const LUMPED_ROWS: usize = 24;

/// The modes as a Markdown table.
pub fn markdown(report: &SpatialModes) -> String {
    let mut out = format!(
        "Modes at ({}, {}, {}) m, tensions at rest {:?} N\n\n| linearisation | mode | ω [rad/s] | growth [1/s] | direction (x, y, z) |\n|---|---|---|---|---|\n",
        report.pose[0], report.pose[1], report.pose[2], report.tensions
    );
    let mut lumped = 0;
    for m in &report.modes {
        if matches!(
            m.linearisation,
            SpatialLoop::LumpedLockedReels | SpatialLoop::FeLockedReels
        ) {
            lumped += 1;
            if lumped > LUMPED_ROWS {
                continue;
            }
        }
        out += &format!(
            "| {:?} | {} | {:.4} | {:.4e} | ({:.3}, {:.3}, {:.3}) |\n",
            m.linearisation,
            m.name,
            m.omega_rad_s,
            m.growth,
            m.direction[0],
            m.direction[1],
            m.direction[2]
        );
    }
    out += "\nDirections are the effector's part of each eigenvector, by magnitude; modes of one \
            frequency repeated (a controller with equal gains on every axis) share their span, \
            so their directions and names are any in it.\n";
    if lumped > LUMPED_ROWS {
        let fe = report
            .modes
            .iter()
            .any(|m| m.linearisation == SpatialLoop::FeLockedReels);
        let lines = if fe { "FE cables'" } else { "lumped lines'" };
        out += &format!(
            "\nThe {lines} lowest {LUMPED_ROWS} of {lumped} modes are listed; modes.json has \
             them all.\n"
        );
    }
    out
}
