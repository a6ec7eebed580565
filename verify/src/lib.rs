//! # cdpr-verify: the crate that knows every model
//!
//! It dispatches a scenario to its cable model, linearises the closed loop at the end position,
//! and holds the acceptance table of MODELS.md §8 (the paper's numbers, ours, the tolerance,
//! pass/fail) that both the tests and the report use. Its `tests/` hold the reference cases.

use cdpr_core::closed_loop::{ClosedLoop, Run, RunFailure, RunOptions, simulate as run_loop};
use cdpr_core::integrate::AlphaCoefficients;
use cdpr_core::metrics::Metrics;
use cdpr_core::modal::{self, Mode};
use cdpr_core::model::{CableModel, Equilibrium, ModelError};
use cdpr_core::scenario::IntegratorKind;
use cdpr_core::scenario::{ModelKind, Scenario};
use cdpr_core::trajectory::Step5;
use cdpr_elastic::{Elastic, eq15_frequency};
use cdpr_fe::Fe;
use cdpr_lumped::Lumped;

pub mod acceptance;
pub mod irvine;
pub mod modes;

/// Why a scenario could not be simulated or analysed.
#[derive(Debug, thiserror::Error)]
pub enum SimulateError {
    #[error(transparent)]
    Run(#[from] Box<RunFailure>),
    #[error(transparent)]
    Model(#[from] ModelError),
    #[error("eigenvalue computation failed: {0:?}")]
    Eigen(cdpr_core::modal::EvdError),
    #[error(transparent)]
    Modal(#[from] cdpr_core::modal::ModalError),
    #[error("no oscillatory closed-loop mode found")]
    NoMode,
}

/// A cable model, whichever the scenario names: what the closed loop runs.
pub type DynModel = Box<dyn CableModel + Send>;

/// The scenario's cable model (the one place that matches on the model kind).
pub fn model(scenario: &Scenario) -> Result<DynModel, SimulateError> {
    Ok(match scenario.model.kind {
        ModelKind::Elastic => Box::new(Elastic::new(scenario)),
        ModelKind::Lumped => Box::new(Lumped::new(scenario)?),
        ModelKind::Fe => Box::new(Fe::new(scenario)?),
    })
}

/// Simulates the scenario (MODELS.md §2 initial state, DOPRI5 run, samples every sample period).
pub fn simulate(scenario: &Scenario, progress: &mut dyn FnMut(f64)) -> Result<Run, SimulateError> {
    let mut sys = ClosedLoop::new(model(scenario)?, scenario);
    Ok(run_loop(&mut sys, &RunOptions::from(scenario), progress)?)
}

/// One model's run of a scenario, measured the way MODELS.md §8 judges it.
pub struct Assessed {
    pub kind: ModelKind,
    pub run: Run,
    pub metrics: Metrics,
    pub end: EndState,
    /// The lowest closed-loop axial mode of the lumped model as the run's integrator renders it
    /// [rad/s]: 5649 rad/s for DOPRI5, its generalised-α image (period-elongated) on the implicit
    /// path.
    pub axial_mode_seen: f64,
    /// The integrator that ran it.
    pub integrator: IntegratorKind,
}

/// How the scenario's integrator renders an undamped mode of frequency `omega` [rad/s]: unchanged
/// for DOPRI5 at its tolerance, the discrete frequency of generalised-α at the scenario's step and
/// ρ∞ on the implicit path.
pub fn mode_as_integrated(scenario: &Scenario, omega: f64) -> f64 {
    let sim = &scenario.simulation;
    match sim.integrator {
        IntegratorKind::Dopri5 => omega,
        IntegratorKind::Implicit => {
            AlphaCoefficients::new(sim.rho_inf)
                .discrete_mode(omega, sim.step)
                .0
        }
    }
}

impl Assessed {
    /// The view the acceptance table takes.
    pub fn result(&self) -> acceptance::ModelResult<'_> {
        acceptance::ModelResult {
            kind: self.kind,
            metrics: &self.metrics,
            vertical_mode: self.end.mode.omega,
            axial_mode: self.axial_mode_seen,
            integrator: self.integrator,
        }
    }
}

/// Simulates the scenario and measures it: metrics (§7) and the settled end state (mode, equilibrium).
pub fn assess(
    scenario: &Scenario,
    progress: &mut dyn FnMut(f64),
) -> Result<Assessed, SimulateError> {
    let run = simulate(scenario, progress)?;
    Ok(Assessed {
        kind: scenario.model.kind,
        metrics: metrics(scenario, &run),
        end: end_state(scenario)?,
        axial_mode_seen: mode_as_integrated(scenario, acceptance::LUMPED_AXIAL_MODE),
        integrator: scenario.simulation.integrator,
        run,
    })
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
    end_state_of(ClosedLoop::new(model(scenario)?, scenario), scenario)
}

fn end_state_of<M: CableModel>(
    mut sys: ClosedLoop<M>,
    scenario: &Scenario,
) -> Result<EndState, SimulateError> {
    let (y, eq) = sys.rest_state(scenario.trajectory.x2)?;
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
