//! The closed loop of the paper's Fig. 4: `step5` reference → PID → tension distribution → cable
//! model, as one ODE, and the runner that integrates it, samples it and stops with a reason.
//!
//! State layout: `[model state (n) | w | f | W | D]`: the PID integral and filter states, then two
//! audit states excluded from the error norm, the reels' work W = ∫ Σ T_i v_reel,i dt and the energy
//! dissipated inside the model D. They make the energy balance E(t) − E(0) − W(t) + D(t) − ΣΔE = 0
//! (ΔE the energy changes of model events) a channel of every run.

use crate::controller::{Pid, PidState, TensionDistribution};
use crate::integrate::{
    Dopri5, Dopri5Options, GeneralizedAlpha, GeneralizedAlphaOptions, IntegratorError, MatrixCost,
    OdeSystem, SecondOrderSystem, SolverStats, Stepper,
};
use crate::model::{CableModel, Equilibrium, ModelError, ModelEvent};
use crate::scenario::{IntegratorKind, Scenario};
use crate::series::TimeSeries;
use crate::trajectory::Step5;
use std::time::Instant;

/// Where the commanded tensions come from.
pub enum Actuation {
    /// The paper's PID and tension distribution.
    Pid,
    /// Tensions prescribed as functions of time [s] → [T1, T2] [N]; the PID states still integrate
    /// the error but do not act (energy and verification runs).
    Prescribed(Box<dyn Fn(f64) -> [f64; 2] + Send + Sync>),
}

/// What the controller commands at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Command {
    /// x_ref [m].
    pub reference: f64,
    /// e = x_ref − x [m].
    pub error: f64,
    /// PID force F [N] (pulls toward A2 when positive).
    pub force: f64,
    /// Commanded tensions [T1, T2] [N].
    pub tensions: [f64; 2],
}

/// Model + controller as one [`OdeSystem`].
pub struct ClosedLoop<M: CableModel> {
    pub model: M,
    pub trajectory: Step5,
    pub pid: Pid,
    pub distribution: TensionDistribution,
    pub actuation: Actuation,
    /// The start of the current implicit step (the trapezoidal controller and audit updates).
    step_start: StepStart,
    /// Two residuals for the tension column of the implicit iteration matrix (allocated once).
    residual_scratch: [Vec<f64>; 2],
}

/// What an implicit step needs from its start (t_n, y_n) besides the integrator's own state.
#[derive(Debug, Clone, Copy, Default)]
struct StepStart {
    h: f64,
    error: f64,
    pid: PidState,
    /// Reel power Σ T_i v_reel,i [W] and model dissipation [W] at t_n.
    power: f64,
    dissipation: f64,
    /// W and D at t_n [J].
    work: f64,
    dissipated: f64,
}

/// Number of controller and audit states after the model's.
pub const EXTRA_STATES: usize = 4;

impl<M: CableModel> ClosedLoop<M> {
    /// The paper's loop for `model` with the scenario's controller and trajectory.
    pub fn new(model: M, scenario: &Scenario) -> Self {
        Self {
            model,
            trajectory: Step5::from(&scenario.trajectory),
            pid: Pid::from(&scenario.controller),
            distribution: TensionDistribution::from(&scenario.controller),
            actuation: Actuation::Pid,
            step_start: StepStart::default(),
            residual_scratch: Default::default(),
        }
    }

    /// Length of the model's part of the state.
    pub fn model_len(&self) -> usize {
        self.model.state_len()
    }

    /// Splits a closed-loop state into the model state and the PID state.
    pub fn split<'a>(&self, y: &'a [f64]) -> (&'a [f64], PidState) {
        let n = self.model_len();
        (
            &y[..n],
            PidState {
                integral: y[n],
                filter: y[n + 1],
            },
        )
    }

    /// Reference, error, force and commanded tensions at (t, y).
    #[inline]
    pub fn command(&self, t: f64, y: &[f64]) -> Command {
        let (model_state, pid_state) = self.split(y);
        let x = self.model.effector(model_state).position.x;
        self.command_at(t, x, |_| pid_state).0
    }

    /// The command at time t for effector position x [m], with the PID states `pid(e)` for the
    /// error e (the states themselves, or their implicit-step update), and those states.
    #[inline]
    fn command_at(&self, t: f64, x: f64, pid: impl FnOnce(f64) -> PidState) -> (Command, PidState) {
        let reference = self.trajectory.position(t);
        let error = reference - x;
        let pid_state = pid(error);
        let force = self.pid.force(error, pid_state);
        let tensions = match &self.actuation {
            Actuation::Pid => self.distribution.tensions(force),
            Actuation::Prescribed(f) => f(t),
        };
        let command = Command {
            reference,
            error,
            force,
            tensions,
        };
        (command, pid_state)
    }

    /// Rates of the states after the model's, (w', f', W', D'), at state `y` under `cmd`.
    fn controller_and_audit_rates(&self, y: &[f64], cmd: &Command, out: &mut [f64]) {
        let (model_state, pid_state) = self.split(y);
        let pid_rate = self.pid.state_rate(cmd.error, pid_state);
        let reel = self.model.reel_speeds(model_state);
        out[0] = pid_rate.integral;
        out[1] = pid_rate.filter;
        out[2] = cmd.tensions[0] * reel[0] + cmd.tensions[1] * reel[1];
        out[3] = self.model.dissipation(model_state);
    }

    /// Initial state by the rule of MODELS.md §2: the model's static equilibrium with the effector
    /// at x_ref(0) and F0 unknown, velocities zero, w(0) = F0/I, f(0) = e(0) = 0, audits zero.
    /// Without integral action (I = 0) no controller state holds F0; w(0) = 0 then.
    pub fn initial_state(&mut self) -> Result<(Vec<f64>, Equilibrium), ModelError> {
        self.rest_state(self.trajectory.position(0.0))
    }

    /// The closed loop at rest with the effector at x [m]: the model's static equilibrium there,
    /// the PID states holding its force F0 (w = F0/I, f = 0), audits zero (the start of a run,
    /// and the point a linearisation is taken about).
    pub fn rest_state(&mut self, x: f64) -> Result<(Vec<f64>, Equilibrium), ModelError> {
        let eq = self.model.equilibrium(x, self.distribution.tension_sum)?;
        let pid = self.pid.state_holding(eq.force).unwrap_or_default();
        let mut y = eq.state.clone();
        y.extend_from_slice(&[pid.integral, pid.filter, 0.0, 0.0]);
        Ok((y, eq))
    }
}

impl<M: CableModel> OdeSystem for ClosedLoop<M> {
    fn dimension(&self) -> usize {
        self.model_len() + EXTRA_STATES
    }

    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) {
        let n = self.model_len();
        let cmd = self.command(t, y);
        let (model_rate, tail) = dy.split_at_mut(n);
        self.model.rhs(t, &y[..n], cmd.tensions, model_rate);
        self.controller_and_audit_rates(y, &cmd, tail);
    }
}

/// The implicit path (MODELS.md FE.9.3): the model's second-order form with the PID states updated
/// by the trapezoidal rule inside the same residual, so the tensions at t_{n+1} follow the effector
/// position of the iterate, and the audit states W, D by the trapezoidal rule after convergence.
/// Only for models that offer [`CableModel::second_order`] (the runner checks first).
impl<M: CableModel> SecondOrderSystem for ClosedLoop<M> {
    fn dofs(&self) -> usize {
        self.model.second_order().map_or(0, |f| f.dofs())
    }

    fn iteration_pattern(&self) -> Vec<(usize, usize)> {
        let Some(form) = self.model.second_order() else {
            return Vec::new();
        };
        let mut pattern = form.iteration_pattern();
        let x = form.effector_x();
        pattern.extend(form.tension_rows().into_iter().map(|row| (row, x)));
        pattern
    }

    /// The model's own, and the effector's x: the controller feeds it back into the tension
    /// rows at the reel ends, which closes the cables' chains (reel, …, effector, …, reel) into
    /// a loop.
    fn coupled_unknowns(&self) -> Vec<usize> {
        let Some(form) = self.model.second_order() else {
            return Vec::new();
        };
        let mut coupled = form.coupled_unknowns();
        if !form.tension_rows().is_empty() {
            coupled.push(form.effector_x());
        }
        coupled
    }

    fn begin_step(&mut self, t: f64, y: &[f64], h: f64) {
        let n = self.model_len();
        let cmd = self.command(t, y);
        let (model_state, pid) = self.split(y);
        let reel = self.model.reel_speeds(model_state);
        self.step_start = StepStart {
            h,
            error: cmd.error,
            pid,
            power: cmd.tensions[0] * reel[0] + cmd.tensions[1] * reel[1],
            dissipation: self.model.dissipation(model_state),
            work: y[n + 2],
            dissipated: y[n + 3],
        };
    }

    fn residual(&mut self, t: f64, y: &[f64], qdd: &[f64], r: &mut [f64]) {
        let n = self.model_len();
        let tensions = self.step_end_command(t, &y[..n]).0.tensions;
        if let Some(form) = self.model.second_order_mut() {
            form.residual(&y[..n], qdd, tensions, r);
        }
    }

    fn iteration_matrix(
        &mut self,
        t: f64,
        y: &[f64],
        qdd: &[f64],
        c_v: f64,
        c_q: f64,
        values: &mut [f64],
    ) -> MatrixCost {
        let n = self.model_len();
        // dT/dx of the effector through the trapezoidal PID: T is affine in x (unless saturated),
        // so a unit difference is exact.
        let x = self.model.effector(&y[..n]).position.x;
        let tensions = self.step_end_command_at(t, x).0.tensions;
        let moved = self.step_end_command_at(t, x + 1.0).0.tensions;
        let slope = [moved[0] - tensions[0], moved[1] - tensions[1]];
        let [base, probe] = &mut self.residual_scratch;
        let Some(form) = self.model.second_order_mut() else {
            return MatrixCost::default();
        };
        // The pattern is the model's, then one entry (row, x) per tension row.
        let rows = form.tension_rows();
        let (model_values, tension_values) = values.split_at_mut(values.len() - rows.len());
        let mut cost = form.iteration_matrix(&y[..n], qdd, tensions, c_v, c_q, model_values);
        if slope != [0.0, 0.0] && !rows.is_empty() {
            // Column x of ∂R/∂T · dT/dx, by two more residuals (R is linear in T).
            base.resize(form.dofs(), 0.0);
            probe.resize(form.dofs(), 0.0);
            form.residual(&y[..n], qdd, tensions, base);
            let pulled = [tensions[0] + slope[0], tensions[1] + slope[1]];
            form.residual(&y[..n], qdd, pulled, probe);
            cost = cost.plus_residuals(2);
            for (value, &row) in tension_values.iter_mut().zip(&rows) {
                *value = c_q * (probe[row] - base[row]);
            }
        } else {
            tension_values.fill(0.0);
        }
        cost
    }

    fn tail_rate(&mut self, t: f64, y: &[f64], out: &mut [f64]) {
        let cmd = self.command(t, y);
        self.controller_and_audit_rates(y, &cmd, out);
    }

    fn residual_round_off(&self, y: &[f64]) -> f64 {
        let n = self.model_len();
        self.model
            .second_order()
            .map_or(0.0, |f| f.residual_round_off(&y[..n]))
    }

    fn end_step(&mut self, t: f64, y: &mut [f64]) {
        let n = self.model_len();
        let s = self.step_start;
        let (cmd, pid) = self.step_end_command(t, &y[..n]);
        y[n] = pid.integral;
        y[n + 1] = pid.filter;
        let reel = self.model.reel_speeds(&y[..n]);
        let power = cmd.tensions[0] * reel[0] + cmd.tensions[1] * reel[1];
        let dissipation = self.model.dissipation(&y[..n]);
        y[n + 2] = s.work + 0.5 * s.h * (s.power + power);
        y[n + 3] = s.dissipated + 0.5 * s.h * (s.dissipation + dissipation);
    }
}

impl<M: CableModel> ClosedLoop<M> {
    /// The command at the end t of the current implicit step for the model state `model_state`:
    /// the PID states advanced by the trapezoidal rule from the step's start.
    fn step_end_command(&self, t: f64, model_state: &[f64]) -> (Command, PidState) {
        self.step_end_command_at(t, self.model.effector(model_state).position.x)
    }

    /// As [`Self::step_end_command`], for effector position x [m].
    fn step_end_command_at(&self, t: f64, x: f64) -> (Command, PidState) {
        let s = self.step_start;
        self.command_at(t, x, |error| {
            self.pid.trapezoidal_step(s.pid, s.error, error, s.h)
        })
    }
}

/// Why a run stopped early.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RunError {
    #[error(transparent)]
    Model(#[from] ModelError),
    #[error("integrator failed at t = {t} s: {source}")]
    Integrator {
        t: f64,
        #[source]
        source: IntegratorError,
    },
    /// A commanded tension ≤ 0 (MODELS.md §2): a cable cannot push.
    #[error("cable {cable} went slack at t = {t} s: commanded tension {tension} N ≤ 0")]
    SlackCable { t: f64, cable: usize, tension: f64 },
    /// The scenario asks for an integrator the model does not support.
    #[error(
        "simulation.integrator = \"{integrator}\" is not available for the {model} model: {why}"
    )]
    Unsupported {
        integrator: &'static str,
        model: &'static str,
        why: &'static str,
    },
}

/// Output of a run: sampled channels, counters, the initial equilibrium, the state at the end.
#[derive(Clone)]
pub struct Run {
    pub model: &'static str,
    pub series: TimeSeries,
    pub stats: SolverStats,
    pub equilibrium: Equilibrium,
    /// Closed-loop state at the last accepted step (model | w | f | W | D).
    pub final_state: Vec<f64>,
    /// Time reached [s] (t_final unless the run failed).
    pub t_reached: f64,
    /// Model events (e.g. lumped nodes passing a pulley), in time order.
    pub events: Vec<ModelEvent>,
    /// Wall-clock time of the integration [s] (the only non-reproducible number of a run).
    pub wall_s: f64,
}

/// A summary, not the samples (a failed `unwrap` would otherwise print megabytes).
impl std::fmt::Debug for Run {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Run")
            .field("model", &self.model)
            .field("samples", &self.series.len())
            .field("channels", &self.series.names())
            .field("t_reached", &self.t_reached)
            .field("stats", &self.stats)
            .field("events", &self.events.len())
            .field("wall_s", &self.wall_s)
            .finish_non_exhaustive()
    }
}

/// A failed run: the reason and everything sampled before it.
#[derive(Debug, Clone)]
pub struct RunFailure {
    pub error: RunError,
    pub partial: Option<Run>,
}

impl std::fmt::Display for RunFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.error)?;
        if let Some(run) = &self.partial {
            write!(
                f,
                " (output kept up to t = {} s, {} samples)",
                run.t_reached,
                run.series.len()
            )?;
        }
        Ok(())
    }
}

impl std::error::Error for RunFailure {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        Some(&self.error)
    }
}

/// How to integrate and sample a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunOptions {
    pub t_final: f64,
    pub sample_period: f64,
    pub integrator: IntegratorKind,
    pub dopri: Dopri5Options,
    pub implicit: GeneralizedAlphaOptions,
}

impl RunOptions {
    /// A DOPRI5 run to `t_final` [s], sampled every `sample_period` [s] (tests and studies that
    /// set the tolerances themselves).
    pub fn dopri5(t_final: f64, sample_period: f64, dopri: Dopri5Options) -> Self {
        Self {
            t_final,
            sample_period,
            integrator: IntegratorKind::Dopri5,
            dopri,
            implicit: GeneralizedAlphaOptions::default(),
        }
    }
}

impl From<&Scenario> for RunOptions {
    fn from(s: &Scenario) -> Self {
        let sim = &s.simulation;
        Self {
            t_final: sim.t_final,
            sample_period: sim.sample_period,
            integrator: sim.integrator,
            dopri: Dopri5Options {
                rtol: sim.rtol,
                atol: sim.atol,
                beta: sim.dopri_beta,
                ..Dopri5Options::default()
            },
            implicit: GeneralizedAlphaOptions {
                step: sim.step,
                rho_inf: sim.rho_inf,
                ..GeneralizedAlphaOptions::default()
            },
        }
    }
}

/// Names of the channels every run has, in order, before the model's own.
pub const COMMON_CHANNELS: [&str; 8] = ["t", "x_ref", "x", "z", "error", "F", "T1", "T2"];
/// Energy channels every run has, after the model's own [J].
pub const ENERGY_CHANNELS: [&str; 6] = [
    "e_kinetic",
    "e_elastic",
    "e_gravity",
    "w_reel",
    "e_dissipated",
    "e_residual",
];

/// Integrates the loop from its MODELS.md §2 initial state to `t_final`, sampling every
/// `sample_period` on the dense output. `progress` receives the fraction of time done after each
/// accepted step.
pub fn simulate<M: CableModel>(
    sys: &mut ClosedLoop<M>,
    opts: &RunOptions,
    progress: &mut dyn FnMut(f64),
) -> Result<Run, Box<RunFailure>> {
    simulate_reusing(sys, opts, Vec::new(), progress)
}

/// As [`simulate`], writing the samples into `buffer`'s memory (from [`TimeSeries::into_buffer`]
/// of an earlier run): sweeps and benches then allocate their output once.
pub fn simulate_reusing<M: CableModel>(
    sys: &mut ClosedLoop<M>,
    opts: &RunOptions,
    buffer: Vec<f64>,
    progress: &mut dyn FnMut(f64),
) -> Result<Run, Box<RunFailure>> {
    let (y0, equilibrium) = sys.initial_state().map_err(|e| {
        Box::new(RunFailure {
            error: e.into(),
            partial: None,
        })
    })?;
    integrate_and_sample(sys, y0, equilibrium, opts, buffer, progress)
}

/// As [`simulate`], from a given closed-loop state `y0` at t = 0 (`equilibrium` is reported as the
/// run's starting point).
pub fn simulate_from<M: CableModel>(
    sys: &mut ClosedLoop<M>,
    y0: Vec<f64>,
    equilibrium: Equilibrium,
    opts: &RunOptions,
    progress: &mut dyn FnMut(f64),
) -> Result<Run, Box<RunFailure>> {
    integrate_and_sample(sys, y0, equilibrium, opts, Vec::new(), progress)
}

fn integrate_and_sample<M: CableModel>(
    sys: &mut ClosedLoop<M>,
    y0: Vec<f64>,
    equilibrium: Equilibrium,
    opts: &RunOptions,
    buffer: Vec<f64>,
    progress: &mut dyn FnMut(f64),
) -> Result<Run, Box<RunFailure>> {
    let start = Instant::now();
    let n = sys.model_len();
    let mut names: Vec<String> = COMMON_CHANNELS.iter().map(|s| s.to_string()).collect();
    names.extend(sys.model.channel_names());
    names.extend(ENERGY_CHANNELS.iter().map(|s| s.to_string()));
    let samples = (opts.t_final / opts.sample_period).round() as usize + 1;
    let mut sampler = Sampler {
        series: TimeSeries::with_buffer(names, samples, buffer),
        y: vec![0.0; y0.len()],
        model_channels: sys.model.channel_names().len(),
        energy0: sys.model.energy(&y0[..n]).total(),
        event_energy: 0.0,
        next: 0,
        samples,
        period: opts.sample_period,
        t_final: opts.t_final,
    };
    let mut events = Vec::new();
    let mut dopri;
    let mut alpha;
    let stepper: &mut dyn Stepper<ClosedLoop<M>> = match opts.integrator {
        IntegratorKind::Dopri5 => {
            dopri = Dopri5::new(
                y0.len(),
                Dopri5Options {
                    norm_components: Some(n + 2),
                    ..opts.dopri
                },
            );
            &mut dopri
        }
        IntegratorKind::Implicit => {
            alpha = GeneralizedAlpha::new(opts.implicit);
            &mut alpha
        }
    };
    let outcome =
        if opts.integrator == IntegratorKind::Implicit && sys.model.second_order().is_none() {
            Err(RunError::Unsupported {
                integrator: IntegratorKind::Implicit.name(),
                model: sys.model.name(),
                why: "the model offers no second-order form",
            })
        } else {
            integrate(
                sys,
                &y0,
                opts.t_final,
                stepper,
                &mut sampler,
                &mut events,
                progress,
            )
        };
    let t_reached = if stepper.stats().rhs_evals == 0 {
        0.0
    } else {
        stepper.time()
    };
    let run = Run {
        model: sys.model.name(),
        series: sampler.series,
        stats: stepper.stats(),
        equilibrium,
        final_state: if t_reached > 0.0 {
            stepper.state().to_vec()
        } else {
            y0
        },
        t_reached,
        events,
        wall_s: start.elapsed().as_secs_f64(),
    };
    match outcome {
        Ok(()) => Ok(run),
        Err(error) => Err(Box::new(RunFailure {
            error,
            partial: Some(run),
        })),
    }
}

/// The integration loop: accepted steps, located model events, samples, slack checks.
fn integrate<M: CableModel>(
    sys: &mut ClosedLoop<M>,
    y0: &[f64],
    t_end: f64,
    stepper: &mut dyn Stepper<ClosedLoop<M>>,
    sampler: &mut Sampler,
    events: &mut Vec<ModelEvent>,
    progress: &mut dyn FnMut(f64),
) -> Result<(), RunError> {
    let integrator = |t: f64| move |source| RunError::Integrator { t, source };
    stepper
        .start(sys, 0.0, y0, t_end)
        .map_err(integrator(0.0))?;
    let mut monitor = EventMonitor::new(sys, y0);
    sampler.sample_through(sys, stepper, 0.0)?;
    while stepper.time() < t_end {
        stepper
            .step(sys, t_end)
            .map_err(integrator(stepper.time()))?;
        let Some((index, t_event)) = monitor.earliest_crossing(sys, stepper) else {
            let t = stepper.time();
            sampler.sample_through(sys, stepper, t)?;
            check_slack(t, sys.command(t, stepper.state()).tensions)?;
            monitor.accept(sys, stepper.state());
            progress(t / t_end);
            continue;
        };
        // Samples up to the event come from the step as integrated; the event changes the state
        // there and the integrator restarts from it, abandoning the rest of the step.
        sampler.sample_through(sys, stepper, t_event)?;
        let mut y = vec![0.0; y0.len()];
        stepper.dense_output(t_event, &mut y);
        let n = sys.model_len();
        let event = sys.model.apply_event(index, t_event, &mut y[..n])?;
        sampler.event_energy += event.energy_change;
        events.push(event);
        stepper.restart(sys, t_event, &y);
        check_slack(t_event, sys.command(t_event, &y).tensions)?;
        monitor.accept(sys, &y);
    }
    Ok(())
}

/// Watches the model's event functions between accepted steps and locates sign changes on the
/// dense output by bisection to [`EVENT_TIME_TOL`] (MODELS.md §4).
struct EventMonitor {
    /// g at the start of the current step.
    before: Vec<f64>,
    after: Vec<f64>,
    probe: Vec<f64>,
    y: Vec<f64>,
}

/// Width of the bracket a located event time lies in [s].
pub const EVENT_TIME_TOL: f64 = 1e-12;

impl EventMonitor {
    fn new<M: CableModel>(sys: &ClosedLoop<M>, y: &[f64]) -> Self {
        let k = sys.model.event_count();
        let mut monitor = Self {
            before: vec![0.0; k],
            after: vec![0.0; k],
            probe: vec![0.0; k],
            y: vec![0.0; if k > 0 { y.len() } else { 0 }],
        };
        monitor.accept(sys, y);
        monitor
    }

    /// Takes `y` as the start of the next step.
    fn accept<M: CableModel>(&mut self, sys: &ClosedLoop<M>, y: &[f64]) {
        if !self.before.is_empty() {
            sys.model
                .event_functions(&y[..sys.model_len()], &mut self.before);
        }
    }

    /// The earliest event function that fell from > 0 to ≤ 0 over the last accepted step, with
    /// the first time at which it is ≤ 0 (to within [`EVENT_TIME_TOL`]).
    fn earliest_crossing<M: CableModel>(
        &mut self,
        sys: &ClosedLoop<M>,
        stepper: &dyn Stepper<ClosedLoop<M>>,
    ) -> Option<(usize, f64)> {
        if self.before.is_empty() {
            return None;
        }
        let n = sys.model_len();
        sys.model
            .event_functions(&stepper.state()[..n], &mut self.after);
        let mut earliest: Option<(usize, f64)> = None;
        for k in 0..self.before.len() {
            if !(self.before[k] > 0.0 && self.after[k] <= 0.0) {
                continue;
            }
            let (mut a, mut b) = (stepper.previous_time(), stepper.time());
            while b - a > EVENT_TIME_TOL {
                let mid = 0.5 * (a + b);
                if mid <= a || mid >= b {
                    break;
                }
                stepper.dense_output(mid, &mut self.y);
                sys.model.event_functions(&self.y[..n], &mut self.probe);
                if self.probe[k] > 0.0 {
                    a = mid;
                } else {
                    b = mid;
                }
            }
            if earliest.is_none_or(|(_, t)| b < t) {
                earliest = Some((k, b));
            }
        }
        earliest
    }
}

/// A commanded tension ≤ 0 (or NaN) is a slack cable.
#[inline]
fn check_slack(t: f64, tensions: [f64; 2]) -> Result<(), RunError> {
    if tensions[0] > 0.0 && tensions[1] > 0.0 {
        return Ok(());
    }
    let cable = if tensions[0] > 0.0 { 2 } else { 1 };
    Err(RunError::SlackCable {
        t,
        cable,
        tension: tensions[cable - 1],
    })
}

/// Samples the dense output on the grid t_k = k·Δt (computed, not accumulated, so the grid is
/// exact and reproducible).
struct Sampler {
    series: TimeSeries,
    y: Vec<f64>,
    /// Number of the model's own channels.
    model_channels: usize,
    energy0: f64,
    /// Sum of the energy changes of the model events so far [J].
    event_energy: f64,
    next: usize,
    samples: usize,
    period: f64,
    /// End of the run [s]: the last sample is taken there, when the integration reaches it.
    t_final: f64,
}

impl Sampler {
    /// Appends every grid sample with t_k ≤ `t` (within the last accepted step).
    fn sample_through<M: CableModel>(
        &mut self,
        sys: &ClosedLoop<M>,
        stepper: &dyn Stepper<ClosedLoop<M>>,
        t: f64,
    ) -> Result<(), RunError> {
        let n = sys.model_len();
        while self.next < self.samples {
            let tk = self.next as f64 * self.period;
            // The last sample is the end point itself (t_final may not be a multiple of Δt by ulps),
            // taken once the integration has reached it.
            let tk = if self.next + 1 == self.samples {
                self.t_final
            } else {
                tk
            };
            if tk > t {
                break;
            }
            if tk == stepper.time() {
                self.y.copy_from_slice(stepper.state());
            } else {
                stepper.dense_output(tk, &mut self.y);
            }
            let y = &self.y;
            let cmd = sys.command(tk, y);
            check_slack(tk, cmd.tensions)?;
            let model_state = &y[..n];
            let eff = sys.model.effector(model_state);
            let energy = sys.model.energy(model_state);
            let (work, dissipated) = (y[n + 2], y[n + 3]);
            let residual = energy.total() - self.energy0 - work + dissipated - self.event_energy;
            let m = self.model_channels;
            self.series.push_row_with(|row| {
                let (common, rest) = row.split_at_mut(COMMON_CHANNELS.len());
                let (own, energies) = rest.split_at_mut(m);
                common.copy_from_slice(&[
                    tk,
                    cmd.reference,
                    eff.position.x,
                    eff.position.y,
                    cmd.error,
                    cmd.force,
                    cmd.tensions[0],
                    cmd.tensions[1],
                ]);
                sys.model.channels(model_state, cmd.tensions, own);
                energies.copy_from_slice(&[
                    energy.kinetic,
                    energy.elastic,
                    energy.gravity,
                    work,
                    dissipated,
                    residual,
                ]);
            });
            self.next += 1;
        }
        Ok(())
    }
}
