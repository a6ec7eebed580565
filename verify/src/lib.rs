//! # cdpr-verify: the crate that knows every model
//!
//! It dispatches a scenario to its cable model, linearises the closed loop at the end position,
//! and holds the acceptance table of MODELS.md §8 (the paper's numbers, ours, the tolerance,
//! pass/fail) that both the tests and the report use. Its `tests/` hold the reference cases.

use cdpr_core::closed_loop::{ClosedLoop, Run, RunFailure, RunOptions, simulate as run_loop};
use cdpr_core::integrate::OdeSystem;
use cdpr_core::metrics::Metrics;
use cdpr_core::modal::{self, Mode};
use cdpr_core::model::{CableModel, Equilibrium, ModelError};
use cdpr_core::scenario::{ModelKind, Scenario};
use cdpr_core::trajectory::Step5;
use cdpr_elastic::{Elastic, eq15_frequency};
use cdpr_fe::Fe;
use cdpr_lumped::Lumped;

pub mod acceptance;
pub mod irvine;

/// Why a scenario could not be simulated or analysed.
#[derive(Debug, thiserror::Error)]
pub enum SimulateError {
    #[error("model `{0}` is not implemented yet (available: elastic, lumped, fe)")]
    ModelUnavailable(ModelKind),
    #[error(transparent)]
    Run(#[from] Box<RunFailure>),
    #[error(transparent)]
    Model(#[from] ModelError),
    #[error("eigenvalue computation failed: {0:?}")]
    Eigen(cdpr_core::modal::EvdError),
    #[error("no oscillatory closed-loop mode found")]
    NoMode,
}

/// A scenario's model, ready for the closed loop (the one place that matches on the model kind).
pub enum AnyModel {
    Elastic(Elastic),
    Lumped(Box<Lumped>),
    Fe(Box<Fe>),
}

impl AnyModel {
    /// The model the scenario asks for, or why it cannot be had.
    pub fn new(scenario: &Scenario) -> Result<Self, SimulateError> {
        match scenario.model.kind {
            ModelKind::Elastic => Ok(AnyModel::Elastic(Elastic::new(scenario))),
            ModelKind::Lumped => Ok(AnyModel::Lumped(Box::new(Lumped::new(scenario)?))),
            ModelKind::Fe => Ok(AnyModel::Fe(Box::new(Fe::new(scenario)?))),
        }
    }
}

/// Simulates the scenario (MODELS.md §2 initial state, DOPRI5 run, samples every sample period).
pub fn simulate(scenario: &Scenario, progress: &mut dyn FnMut(f64)) -> Result<Run, SimulateError> {
    let opts = RunOptions::from(scenario);
    match AnyModel::new(scenario)? {
        AnyModel::Elastic(m) => Ok(run_loop(
            &mut ClosedLoop::new(m, scenario),
            &opts,
            progress,
        )?),
        AnyModel::Lumped(m) => Ok(run_loop(
            &mut ClosedLoop::new(*m, scenario),
            &opts,
            progress,
        )?),
        AnyModel::Fe(m) => Ok(run_loop(
            &mut ClosedLoop::new(*m, scenario),
            &opts,
            progress,
        )?),
    }
}

/// Metrics of a run of `scenario` (MODELS.md §7).
pub fn metrics(scenario: &Scenario, run: &Run) -> Metrics {
    Metrics::from_run(
        run,
        &Step5::from(&scenario.trajectory),
        scenario.simulation.sample_period,
    )
}

/// The closed-loop mode nearest eq. 15 at the static equilibrium at x2 (the effector's vertical
/// mode), from the finite-difference Jacobian of model + PID + tension distribution.
pub fn vertical_mode_at_end(scenario: &Scenario) -> Result<Mode, SimulateError> {
    Ok(end_state(scenario)?.mode)
}

/// The settled end of the paper's move: the static equilibrium at x2 and the closed-loop
/// vertical mode there.
#[derive(Debug, Clone)]
pub struct EndState {
    /// Closed-loop mode nearest eq. 15.
    pub mode: Mode,
    /// Static equilibrium at x2 (MODELS.md §2 rule).
    pub equilibrium: Equilibrium,
    /// Effector position there [m].
    pub effector: cdpr_core::Vector2<f64>,
}

/// [`EndState`] of the scenario's model.
pub fn end_state(scenario: &Scenario) -> Result<EndState, SimulateError> {
    match AnyModel::new(scenario)? {
        AnyModel::Elastic(m) => end_state_of(ClosedLoop::new(m, scenario), scenario),
        AnyModel::Lumped(m) => end_state_of(ClosedLoop::new(*m, scenario), scenario),
        AnyModel::Fe(m) => end_state_of(ClosedLoop::new(*m, scenario), scenario),
    }
}

fn end_state_of<M: CableModel>(
    mut sys: ClosedLoop<M>,
    scenario: &Scenario,
) -> Result<EndState, SimulateError> {
    let x2 = scenario.trajectory.x2;
    let eq = sys.model.equilibrium(x2, scenario.controller.tension_sum)?;
    let pid = sys.pid.state_holding(eq.force).unwrap_or_default();
    let mut y = eq.state.clone();
    y.extend_from_slice(&[pid.integral, pid.filter, 0.0, 0.0]);
    debug_assert_eq!(y.len(), sys.dimension());
    // After t2 the reference is constant: the loop is autonomous there.
    let t = scenario.trajectory.t2 + 1.0;
    let jac = modal::closed_loop_jacobian(&mut sys, t, &y);
    let modes = modal::modes(&jac).map_err(SimulateError::Eigen)?;
    let mode = modal::nearest_mode(&modes, eq15_at_end(scenario)).ok_or(SimulateError::NoMode)?;
    let effector = sys.model.effector(&eq.state).position;
    Ok(EndState {
        mode,
        equilibrium: eq,
        effector,
    })
}

/// Eq. 15 at x2 with T = ΣT/2 [rad/s] (paper: 20.41 rad/s).
pub fn eq15_at_end(scenario: &Scenario) -> f64 {
    eq15_frequency(
        0.5 * scenario.controller.tension_sum,
        scenario.robot.effector_mass,
        scenario.trajectory.x2,
        scenario.robot.anchor_distance,
    )
}
