//! Running a scenario with its model: the simulation, its metrics (MODELS.md §7), the settled end
//! state with its closed-loop vertical mode, and the modal analyses, for whichever model the
//! scenario names.

use crate::build::{BuildError, ModelVisitor, build, with_model};
use crate::config::ModelConfig;
use crate::kind::ModelKind;
use cdpr_analysis::AnalysisError;
use cdpr_analysis::control_metrics::ControlContext;
use cdpr_analysis::damping::{self, Sweep};
use cdpr_analysis::linearise::{self, EndState, Linearised};
use cdpr_analysis::metrics::Metrics;
use cdpr_analysis::modes::{Analysis, ClassifiedMode, Loop, ModeKind};
use cdpr_core::closed_loop::ClosedLoop;
use cdpr_core::closed_loop::LoopError;
use cdpr_core::controller::TensionLimits;
use cdpr_core::model::{CableModel, ModelError};
use cdpr_core::runner::{
    Observer, Run, RunError, RunFailure, RunOptions, simulate_observed_reusing as simulate_run,
};
use cdpr_core::scenario::{Designed, IntegratorKind, ModesChoice, Scenario, ScenarioError};
use cdpr_core::series::SeriesBuffer;
use cdpr_core::shaper::ShaperKind;
use cdpr_core::trajectory::Step5;
use cdpr_elastic::eq15_frequency;
use cdpr_numerics::AlphaCoefficients;

/// Why a scenario could not be simulated or analysed.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    #[error(transparent)]
    Model(#[from] ModelError),
    #[error(transparent)]
    Loop(#[from] LoopError),
    #[error(transparent)]
    Run(#[from] Box<RunFailure>),
    #[error(transparent)]
    Analysis(#[from] AnalysisError),
    /// A spatial reference that no tensions in the box can follow.
    #[error(transparent)]
    Reference(#[from] crate::spatial::InfeasibleReference),
    /// A G-code file the reader refuses.
    #[error(transparent)]
    Gcode(#[from] cdpr_printing::gcode::GcodeError),
    /// A program the planner refuses.
    #[error(transparent)]
    Plan(#[from] cdpr_printing::planner::PlanError),
}

impl From<BuildError> for Error {
    fn from(e: BuildError) -> Self {
        match e {
            BuildError::Scenario(e) => Error::Scenario(e),
            BuildError::Model(e) => Error::Model(e),
        }
    }
}

/// As [`simulate`], watched and steered by `observer` (progress, each sample, a stop flag).
pub fn simulate_observed(scenario: &Scenario, observer: &mut Observer) -> Result<Run, Error> {
    simulate_observed_into(scenario, observer, SeriesBuffer::default())
}

/// As [`simulate_observed`], writing the samples into `buffer`'s memory (from
/// [`TimeSeries::into_buffer`](cdpr_core::series::TimeSeries::into_buffer) of an earlier run):
/// a sweep's worker then allocates its samples once.
pub fn simulate_observed_into(
    scenario: &Scenario,
    observer: &mut Observer,
    buffer: SeriesBuffer,
) -> Result<Run, Error> {
    let scenario = &resolve_shaper(scenario)?;
    let mut sys = ClosedLoop::new(build(scenario)?, scenario)?;
    Ok(simulate_run(
        &mut sys,
        &RunOptions::from(scenario),
        buffer,
        observer,
    )?)
}

/// Simulates the scenario: the MODELS.md §2 initial state, then the scenario's integrator,
/// sampled every sample period. `progress` receives the fraction of time done.
pub fn simulate(scenario: &Scenario, progress: &mut dyn FnMut(f64)) -> Result<Run, Error> {
    simulate_observed(scenario, &mut Observer::progress(progress))
}

/// One model's run of a scenario, measured.
pub struct Assessed {
    pub kind: ModelKind,
    pub run: Run,
    pub metrics: Metrics,
    /// The static equilibrium at x2 and the closed-loop vertical mode there, as far as that
    /// analysis went.
    pub end: EndAnalysis,
    /// The integrator that ran it.
    pub integrator: IntegratorKind,
    /// What a reader of the metrics must know: closed-loop modes at the end of the move that
    /// grow (beyond the cables' axial modes, which the massive models' PID loops are known to
    /// leave growing slowly; see docs/control.md).
    pub warnings: Vec<String>,
}

/// The modal analysis at the end of the move, which never costs a run its results: done,
/// skipped (by choice or by size) or failed, with the reason.
#[derive(Debug, Clone)]
pub enum EndAnalysis {
    Done(EndState),
    /// Not attempted: `[analysis] modes = "off"`, or the loop is larger than the dense
    /// eigen-analysis's limit.
    Skipped {
        reason: String,
    },
    /// Attempted and failed (e.g. no equilibrium at x2).
    Failed {
        reason: String,
    },
}

impl EndAnalysis {
    /// The end state, where the analysis was done.
    pub fn state(&self) -> Option<&EndState> {
        match self {
            EndAnalysis::Done(end) => Some(end),
            _ => None,
        }
    }

    /// "done", "skipped" or "failed".
    pub fn status(&self) -> &'static str {
        match self {
            EndAnalysis::Done(_) => "done",
            EndAnalysis::Skipped { .. } => "skipped",
            EndAnalysis::Failed { .. } => "failed",
        }
    }

    /// Why it was skipped or failed.
    pub fn reason(&self) -> Option<&str> {
        match self {
            EndAnalysis::Done(_) => None,
            EndAnalysis::Skipped { reason } | EndAnalysis::Failed { reason } => Some(reason),
        }
    }
}

/// Simulates the scenario and measures it: metrics (§7) and, as `[analysis] modes` chooses, the
/// settled end state, whose failure is reported, never fatal.
pub fn assess(scenario: &Scenario, progress: &mut dyn FnMut(f64)) -> Result<Assessed, Error> {
    assess_observed(scenario, &mut Observer::progress(progress))
}

/// As [`assess`], watched and steered by `observer`.
pub fn assess_observed(scenario: &Scenario, observer: &mut Observer) -> Result<Assessed, Error> {
    assess_observed_into(scenario, observer, SeriesBuffer::default())
}

/// As [`assess_observed`], the samples written into `buffer`'s memory.
pub fn assess_observed_into(
    scenario: &Scenario,
    observer: &mut Observer,
    buffer: SeriesBuffer,
) -> Result<Assessed, Error> {
    let scenario = &resolve_shaper(scenario)?;
    let kind = ModelConfig::from_scenario(scenario)?.kind;
    let run = simulate_observed_into(scenario, observer, buffer)?;
    let interrupted = |run: Run| {
        let t = run.t_reached;
        Error::Run(Box::new(RunFailure {
            error: RunError::Interrupted { t },
            partial: Some(run),
        }))
    };
    if observer.stopped() {
        return Err(interrupted(run));
    }
    let (end, modes) = end_analysis_and_modes(scenario);
    if observer.stopped() {
        return Err(interrupted(run));
    }
    let mut metrics = metrics(scenario, &run);
    let least_stable = modes
        .iter()
        .max_by(|p, q| p.mode.growth.total_cmp(&q.mode.growth));
    if let Some(mode) = least_stable {
        metrics.control.least_stable_growth = mode.mode.growth;
        metrics.control.least_stable_omega_rad_s = mode.mode.omega;
        metrics.control.least_stable_kind = mode.kind.to_string();
    }
    Ok(Assessed {
        kind,
        metrics,
        end,
        integrator: scenario.simulation.integrator,
        warnings: growth_warnings(scenario, &modes),
        run,
    })
}

/// Growth rate above which a closed-loop mode is reported as growing [1/s]: it doubles within
/// ~700 s, far above the linearisation's resolution (~1e-6 1/s, `growth_resolution`).
pub const GROWTH_WARNING: f64 = 1e-3;

/// A warning for each closed-loop mode at x2 that grows faster than [`GROWTH_WARNING`], the
/// cables' axial modes aside.
fn growth_warnings(scenario: &Scenario, modes: &[ClassifiedMode]) -> Vec<String> {
    modes
        .iter()
        .filter(|m| m.mode.growth > GROWTH_WARNING && !matches!(m.kind, ModeKind::Axial(_)))
        .map(|m| {
            format!(
                "the closed loop at x2 = {} m has a growing {} mode: growth {:.4e} 1/s at {:.4} rad/s \
                 (the controller's gains do not stabilise it; the run's numbers describe a loop \
                 that diverges)",
                scenario.trajectory.x2, m.kind, m.mode.growth, m.mode.omega
            )
        })
        .collect()
}

impl Assessed {
    /// What can be measured of a run that stopped early: its metrics over the samples taken; the
    /// end's modal analysis is skipped.
    pub fn partial(scenario: &Scenario, kind: ModelKind, run: Run) -> Self {
        // The run used the resolved shaper; resolving again repeats the same modal analysis.
        let resolved = resolve_shaper(scenario).unwrap_or_else(|_| scenario.clone());
        Self {
            kind,
            metrics: metrics(&resolved, &run),
            end: EndAnalysis::Skipped {
                reason: format!("the run stopped at t = {} s", run.t_reached),
            },
            integrator: scenario.simulation.integrator,
            warnings: Vec::new(),
            run,
        }
    }
}

/// The end state as `[analysis] modes` chooses, its size limit and failure turned into notes.
pub fn end_analysis(scenario: &Scenario) -> EndAnalysis {
    end_analysis_and_modes(scenario).0
}

/// [`end_analysis`] and the closed loop's modes at x2, from the modal analysis that drops the
/// frozen coordinates ([`analyse`]; none where it was not done or failed). A loop without an
/// oscillatory mode near eq. 15 (a z loop that over-damps it) fails the end state but still has
/// its modes.
pub fn end_analysis_and_modes(scenario: &Scenario) -> (EndAnalysis, Vec<ClassifiedMode>) {
    if scenario.analysis.modes == ModesChoice::Off {
        let reason = "[analysis] modes = \"off\"".into();
        return (EndAnalysis::Skipped { reason }, Vec::new());
    }
    let end = match end_state(scenario) {
        Ok(end) => EndAnalysis::Done(end),
        Err(Error::Analysis(e @ AnalysisError::TooLarge { .. })) => {
            let reason = e.to_string();
            return (EndAnalysis::Skipped { reason }, Vec::new());
        }
        Err(e) => EndAnalysis::Failed {
            reason: e.to_string(),
        },
    };
    let modes = analyse(scenario, scenario.trajectory.x2, Loop::Closed)
        .map(|a| a.modes)
        .unwrap_or_default();
    (end, modes)
}

/// Metrics of a run of `scenario` (MODELS.md §7 and the vibration-control metrics); the
/// scenario's shaper as resolved for the run ([`resolve_shaper`]).
pub fn metrics(scenario: &Scenario, run: &Run) -> Metrics {
    let step5 = Step5::from(&scenario.trajectory);
    let t = &scenario.trajectory;
    let impulses = t.impulses().ok().flatten();
    let shaped = t.shaper != ShaperKind::None;
    let design = |d: Designed| {
        if shaped {
            d.value().unwrap_or(f64::NAN)
        } else {
            f64::NAN
        }
    };
    let context = ControlContext {
        controller: scenario.controller.kind.name(),
        move_start: step5.t1,
        move_end: step5.t2 + impulses.map_or(0.0, |i| i.duration()),
        limits: TensionLimits::from(&scenario.controller),
        sample_period: scenario.simulation.sample_period,
        resolution: scenario.simulation.atol,
        shaper: t.shaper.name(),
        shaper_frequency: design(t.shaper_frequency),
        shaper_damping: design(t.shaper_damping),
    };
    let mut metrics = Metrics::from_run(run, &step5, scenario.simulation.sample_period, &context);
    metrics.control.controller_gains = run
        .controller_gains
        .iter()
        .map(|(name, values)| ((*name).to_owned(), values.clone()))
        .collect();
    metrics
}

/// The least-damped oscillatory vertical mode of the scenario's closed loop at effector position
/// x [m]: its natural frequency |λ| [rad/s] and damping ratio −σ/|λ| (a growing mode's taken as
/// 0), what a shaper is designed for.
pub fn least_damped_vertical_mode(scenario: &Scenario, x: f64) -> Result<(f64, f64), Error> {
    let analysis = analyse(scenario, x, Loop::Closed)?;
    let mode = analysis
        .modes
        .iter()
        .filter(|m| m.kind == ModeKind::Vertical && m.mode.omega > 0.0)
        .min_by(|a, b| {
            let zeta = |m: &ClassifiedMode| m.mode.damping_ratio().abs();
            zeta(a).total_cmp(&zeta(b))
        })
        .ok_or(AnalysisError::NoMode)?;
    Ok((
        mode.mode.growth.hypot(mode.mode.omega),
        mode.mode.damping_ratio().max(0.0),
    ))
}

/// The scenario with its shaper's "auto" design values replaced by the least-damped vertical
/// mode of the model's closed loop at x2 ([`least_damped_vertical_mode`]), from the modal
/// analysis of the unshaped loop; unchanged when nothing is "auto".
pub fn resolve_shaper(scenario: &Scenario) -> Result<Scenario, Error> {
    let t = &scenario.trajectory;
    let auto = t.shaper_frequency.value().is_none() || t.shaper_damping.value().is_none();
    if t.shaper == ShaperKind::None || !auto {
        return Ok(scenario.clone());
    }
    let mut unshaped = scenario.clone();
    unshaped.trajectory.shaper = ShaperKind::None;
    let (omega, zeta) = least_damped_vertical_mode(&unshaped, t.x2).map_err(|e| {
        let key = if t.shaper_frequency.value().is_none() {
            "trajectory.shaper_frequency = \"auto\""
        } else {
            "trajectory.shaper_damping = \"auto\""
        };
        let why = match e {
            Error::Analysis(AnalysisError::NoMode) => format!(
                "the {} controller's closed loop at x2 = {} m has no lightly damped vertical mode \
                 to design the shaper for (its z loop damps it): give the value",
                scenario.controller.kind.name(),
                t.x2
            ),
            e => format!("the modal analysis that designs the shaper failed: {e}; give the value"),
        };
        ScenarioError::Infeasible {
            keys: key.into(),
            why,
        }
    })?;
    let mut resolved = scenario.clone();
    let r = &mut resolved.trajectory;
    if r.shaper_frequency.value().is_none() {
        r.shaper_frequency = Designed::Value(omega);
    }
    if r.shaper_damping.value().is_none() {
        r.shaper_damping = Designed::Value(zeta);
    }
    resolved.validate()?;
    Ok(resolved)
}

/// Everything about a scenario that can be known before its run, checked with its model: an
/// "auto" shaper designed from the modal analysis, the start equilibrium (MODELS.md §2) found
/// and the controller designed there. Each failure is a [`ScenarioError`] naming the keys that
/// set it, so a run that cannot start is refused before it writes anything. Returns the
/// scenario with its shaper resolved (what the run then uses).
pub fn prepare(scenario: &Scenario) -> Result<Scenario, Error> {
    if scenario.robot.anchors.is_some() {
        crate::spatial::prepare_spatial_start(scenario)?;
        return Ok(scenario.clone());
    }
    let resolved = resolve_shaper(scenario)?;
    let config = ModelConfig::from_scenario(&resolved)?;
    let start = |e| start_error(&resolved, &config, e);
    let mut sys = ClosedLoop::new(build(&resolved)?, &resolved).map_err(start)?;
    sys.initial_state().map_err(start)?;
    Ok(resolved)
}

/// The keys that set a start that failed, and why.
fn start_error(scenario: &Scenario, config: &ModelConfig, error: LoopError) -> ScenarioError {
    let c = &scenario.controller;
    let keys = match &error {
        LoopError::Control(_) | LoopError::ControllerStates { .. } => format!(
            "controller.kind = \"{}\", q_position = {}, q_velocity = {}, q_integral = {}, r = {}",
            c.kind.name(),
            c.q_position,
            c.q_velocity,
            c.q_integral,
            c.r
        ),
        _ => {
            let elements = config
                .elements
                .map_or(String::new(), |n| format!(", model.elements = {n}"));
            format!(
                "controller.tension_sum = {}, trajectory.x1 = {}, model.kind = \"{}\"{elements}",
                c.tension_sum,
                scenario.trajectory.x1,
                config.kind.name()
            )
        }
    };
    let why = match error {
        LoopError::Control(e) => format!("the controller cannot be designed at the start: {e}"),
        e => format!("the run cannot start: {e}"),
    };
    ScenarioError::Infeasible { keys, why }
}

/// The static equilibrium at x2 and the closed-loop mode nearest eq. 15 there (the effector's
/// vertical mode), from the finite-difference Jacobian of model + PID + tension distribution.
pub fn end_state(scenario: &Scenario) -> Result<EndState, Error> {
    let sys = ClosedLoop::new(build(scenario)?, scenario)?;
    Ok(linearise::end_state(sys, eq15_at_end(scenario))?)
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

/// How the scenario's integrator renders an undamped mode of frequency `omega` [rad/s]: unchanged
/// for DOPRI5 at its tolerance, the discrete frequency of generalised-α at the scenario's fixed
/// step and ρ∞ on the implicit path (an error-controlled step has no single image: there the
/// mode itself).
pub fn mode_as_integrated(scenario: &Scenario, omega: f64) -> f64 {
    let sim = &scenario.simulation;
    match sim.integrator {
        IntegratorKind::Dopri5 => omega,
        IntegratorKind::Implicit if sim.adaptive => omega,
        IntegratorKind::Implicit => {
            AlphaCoefficients::new(sim.rho_inf)
                .discrete_mode(omega, sim.step)
                .0
        }
    }
}

/// Modal analysis of the scenario's model at effector position `x` [m] (the static equilibrium
/// of MODELS.md §2 there, with the reference held at x).
pub fn analyse(scenario: &Scenario, x: f64, feedback: Loop) -> Result<Analysis, Error> {
    Ok(linearise(scenario, x, feedback)?.analysis)
}

/// As [`analyse`], keeping the equilibrium state and the eigenvectors.
pub fn linearise(scenario: &Scenario, x: f64, feedback: Loop) -> Result<Linearised, Error> {
    struct Linearise<'a>(&'a Scenario, f64, Loop);
    impl ModelVisitor for Linearise<'_> {
        type Output = Result<Linearised, AnalysisError>;
        fn visit<M: CableModel<2> + Clone + Send + 'static>(self, model: M) -> Self::Output {
            linearise::linearise(model, self.0, self.1, self.2)
        }
    }
    Ok(with_model(scenario, Linearise(scenario, x, feedback))??)
}

/// The linearisation's resolution in growth rate at x [1/s]
/// ([`cdpr_analysis::damping::growth_resolution`]).
pub fn growth_resolution(scenario: &Scenario, x: f64) -> Result<f64, Error> {
    damping::growth_resolution(scenario, x, &mut analyse)
}

/// The smallest axial damping in `range` [N s] that makes every closed-loop mode at x grow no
/// faster than `threshold` [1/s] ([`cdpr_analysis::damping::damping_sweep`]).
pub fn damping_sweep(
    scenario: &Scenario,
    x: f64,
    range: (f64, f64),
    scan: usize,
    threshold: f64,
) -> Result<Sweep, Error> {
    damping::damping_sweep(scenario, x, range, scan, threshold, &mut analyse)
}
