//! The runner: integrates a [`ClosedLoop`] from its MODELS.md §2 initial state with the
//! scenario's integrator, samples it on the dense output, locates and applies the model's events,
//! and stops with a reason ([`RunError`]) while keeping what it sampled ([`RunFailure`]).

use crate::channel::Channel;
use crate::closed_loop::{ClosedLoop, LoopError};
use crate::controller::{ControlError, Controller};
use crate::model::{CableModel, Equilibrium, ModelError, ModelEvent};
use crate::robot::{CableId, Tensions};
use crate::scenario::{ImplicitMethod, IntegratorKind, Scenario};
use crate::series::{SeriesBuffer, TimeSeries};
use cdpr_numerics::{
    Dopri5, Dopri5Options, GeneralizedAlpha, GeneralizedAlphaOptions, IntegratorError, SolverStats,
    Stepper,
};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Why a run stopped early.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RunError {
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The controller could not be designed at the run's start.
    #[error(transparent)]
    Control(#[from] ControlError),
    /// The loop could not be assembled (e.g. a controller with more states than it holds).
    #[error("{0}")]
    Loop(String),
    /// The integrator's error is part of the message (not a `source`, which a chain would print
    /// twice).
    #[error("integrator failed at t = {t} s: {error}")]
    Integrator { t: f64, error: IntegratorError },
    /// The effector left the workspace (below the highest anchor and, seen from above, inside
    /// the anchors' hull; the plane: 0 < x < d, z < 0): a run gone unstable, its numbers past
    /// here describe no robot.
    #[error(
        "the effector left the workspace at t = {t} s: {}, allowed below the highest anchor and between the anchors",
        coordinates(position)
    )]
    Workspace {
        t: f64,
        /// The effector's coordinates [m], per axis, the vertical last.
        position: Vec<f64>,
    },
    /// The shaper's design is still "auto": the modal analysis must resolve it first.
    #[error(
        "trajectory.shaper_frequency / shaper_damping = \"auto\" are not resolved: the registry's \
         simulate designs the shaper from the modal analysis before a run"
    )]
    UnresolvedShaper,
    /// A commanded tension ≤ 0 (MODELS.md §2): a cable cannot push.
    #[error("cable {cable} went slack at t = {t} s: commanded tension {tension} N ≤ 0")]
    SlackCable {
        t: f64,
        cable: CableId,
        tension: f64,
    },
    /// Stopped from outside (an interrupt) after the step that reached `t`.
    #[error("interrupted at t = {t} s")]
    Interrupted { t: f64 },
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

/// "x = …, z = … m" (or x, y, z in space) for a message.
fn coordinates(position: &[f64]) -> String {
    let names: &[&str] = if position.len() == 3 {
        &["x", "y", "z"]
    } else {
        &["x", "z"]
    };
    let parts: Vec<String> = position
        .iter()
        .zip(names)
        .map(|(value, name)| format!("{name} = {value}"))
        .collect();
    format!("{} m", parts.join(", "))
}

impl From<LoopError> for RunError {
    fn from(e: LoopError) -> Self {
        match e {
            LoopError::Model(e) => RunError::Model(e),
            LoopError::Control(e) => RunError::Control(e),
            e @ LoopError::ControllerStates { .. } => RunError::Loop(e.to_string()),
        }
    }
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
    /// The gains the controller designed for this run (the LQR's K at the start's height), by
    /// name, row-major.
    pub controller_gains: Vec<(&'static str, Vec<f64>)>,
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
            implicit: match sim.implicit_method {
                ImplicitMethod::GeneralizedAlpha => GeneralizedAlphaOptions {
                    step: sim.step,
                    rho_inf: sim.rho_inf,
                    ..GeneralizedAlphaOptions::default()
                },
            },
        }
    }
}

/// The names of a run's channels with `model`, in order: [`Channel::common`], the model's own,
/// [`Channel::ENERGY`].
pub fn channel_names<const D: usize, M: CableModel<D> + ?Sized>(model: &M) -> Vec<String> {
    let mut names: Vec<String> = Channel::common::<D>(model.cables())
        .into_iter()
        .map(Channel::name)
        .collect();
    names.extend(model.channel_names());
    names.extend(Channel::ENERGY.map(Channel::name));
    names
}

/// The units of [`channel_names`], in order.
pub fn channel_units<const D: usize, M: CableModel<D> + ?Sized>(model: &M) -> Vec<&'static str> {
    let mut units: Vec<&'static str> = Channel::common::<D>(model.cables())
        .into_iter()
        .map(Channel::unit)
        .collect();
    units.extend(model.channel_units());
    units.extend(Channel::ENERGY.map(Channel::unit));
    units
}

/// Receives one sample row (the run's channels, in order).
pub type SampleSink<'a> = dyn FnMut(&[f64]) + 'a;

/// What a caller watches and steers while a run goes: its progress, each sample as it is taken,
/// and a flag that stops it.
pub struct Observer<'a> {
    /// Receives the fraction of time done after each accepted step.
    pub progress: &'a mut dyn FnMut(f64),
    /// Receives each sample row (the run's channels, in order) as soon as it is taken, e.g. to
    /// stream it to disk so that a killed run leaves what it sampled.
    pub on_sample: Option<&'a mut SampleSink<'a>>,
    /// When set (e.g. by a signal handler), the run stops after the current step with
    /// [`RunError::Interrupted`], keeping what it sampled.
    pub stop: Option<&'a AtomicBool>,
}

impl<'a> Observer<'a> {
    /// An observer of the progress only.
    pub fn progress(progress: &'a mut dyn FnMut(f64)) -> Self {
        Self {
            progress,
            on_sample: None,
            stop: None,
        }
    }

    /// Whether the stop flag is set.
    pub fn stopped(&self) -> bool {
        self.stop.is_some_and(|s| s.load(Ordering::Relaxed))
    }

    /// Hands the rows of `series` from `from` on to `on_sample`, through `row`.
    fn emit(&mut self, series: &TimeSeries, from: usize, row: &mut Vec<f64>) {
        if let Some(sink) = self.on_sample.as_mut() {
            row.resize(series.width(), 0.0);
            for i in from..series.len() {
                series.copy_row(i, row);
                sink(row);
            }
        }
    }
}

/// Integrates the loop from its MODELS.md §2 initial state to `t_final`, sampling every
/// `sample_period` on the dense output. `progress` receives the fraction of time done after each
/// accepted step.
pub fn simulate<M: CableModel<D>, const D: usize>(
    sys: &mut ClosedLoop<M, D>,
    opts: &RunOptions,
    progress: &mut dyn FnMut(f64),
) -> Result<Run, Box<RunFailure>> {
    simulate_reusing(sys, opts, SeriesBuffer::default(), progress)
}

/// The loop's MODELS.md §2 initial state, or the failure of a run that could not start.
fn initial_state<M: CableModel<D>, const D: usize>(
    sys: &mut ClosedLoop<M, D>,
) -> Result<(Vec<f64>, Equilibrium), Box<RunFailure>> {
    sys.initial_state().map_err(|e| {
        Box::new(RunFailure {
            error: e.into(),
            partial: None,
        })
    })
}

/// As [`simulate`], watched and steered by `observer`.
pub fn simulate_observed<M: CableModel<D>, const D: usize>(
    sys: &mut ClosedLoop<M, D>,
    opts: &RunOptions,
    observer: &mut Observer,
) -> Result<Run, Box<RunFailure>> {
    simulate_observed_reusing(sys, opts, SeriesBuffer::default(), observer)
}

/// As [`simulate_observed`], writing the samples into `buffer`'s memory.
pub fn simulate_observed_reusing<M: CableModel<D>, const D: usize>(
    sys: &mut ClosedLoop<M, D>,
    opts: &RunOptions,
    buffer: SeriesBuffer,
    observer: &mut Observer,
) -> Result<Run, Box<RunFailure>> {
    let (y0, equilibrium) = initial_state(sys)?;
    integrate_and_sample(sys, y0, equilibrium, opts, buffer, observer)
}

/// As [`simulate`], writing the samples into `buffer`'s memory (from [`TimeSeries::into_buffer`]
/// of an earlier run): sweeps and benches then allocate their output once.
pub fn simulate_reusing<M: CableModel<D>, const D: usize>(
    sys: &mut ClosedLoop<M, D>,
    opts: &RunOptions,
    buffer: SeriesBuffer,
    progress: &mut dyn FnMut(f64),
) -> Result<Run, Box<RunFailure>> {
    let (y0, equilibrium) = initial_state(sys)?;
    integrate_and_sample(
        sys,
        y0,
        equilibrium,
        opts,
        buffer,
        &mut Observer::progress(progress),
    )
}

/// As [`simulate`], from a given closed-loop state `y0` at t = 0 (`equilibrium` is reported as the
/// run's starting point).
pub fn simulate_from<M: CableModel<D>, const D: usize>(
    sys: &mut ClosedLoop<M, D>,
    y0: Vec<f64>,
    equilibrium: Equilibrium,
    opts: &RunOptions,
    progress: &mut dyn FnMut(f64),
) -> Result<Run, Box<RunFailure>> {
    integrate_and_sample(
        sys,
        y0,
        equilibrium,
        opts,
        SeriesBuffer::default(),
        &mut Observer::progress(progress),
    )
}

fn integrate_and_sample<M: CableModel<D>, const D: usize>(
    sys: &mut ClosedLoop<M, D>,
    y0: Vec<f64>,
    equilibrium: Equilibrium,
    opts: &RunOptions,
    buffer: SeriesBuffer,
    observer: &mut Observer,
) -> Result<Run, Box<RunFailure>> {
    let start = Instant::now();
    let n = sys.model_len();
    let names = channel_names(&sys.model);
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
    let stepper: &mut dyn Stepper<ClosedLoop<M, D>> = match opts.integrator {
        IntegratorKind::Dopri5 => {
            dopri = Dopri5::new(
                y0.len(),
                Dopri5Options {
                    norm_components: Some(sys.dynamic_len()),
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
    let outcome = if sys.shaper.is_none() {
        Err(RunError::UnresolvedShaper)
    } else if opts.integrator == IntegratorKind::Implicit && sys.model.second_order().is_none() {
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
            observer,
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
        controller_gains: sys.controller.gains(),
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
fn integrate<M: CableModel<D>, const D: usize>(
    sys: &mut ClosedLoop<M, D>,
    y0: &[f64],
    t_end: f64,
    stepper: &mut dyn Stepper<ClosedLoop<M, D>>,
    sampler: &mut Sampler,
    events: &mut Vec<ModelEvent>,
    observer: &mut Observer,
) -> Result<(), RunError> {
    let integrator = |t: f64| move |error| RunError::Integrator { t, error };
    stepper
        .start(sys, 0.0, y0, t_end)
        .map_err(integrator(0.0))?;
    let mut monitor = EventMonitor::new(sys, y0);
    let mut row = Vec::new();
    sampler.sample_through(sys, stepper, 0.0)?;
    observer.emit(&sampler.series, 0, &mut row);
    while stepper.time() < t_end {
        if observer.stopped() {
            return Err(RunError::Interrupted { t: stepper.time() });
        }
        stepper
            .step(sys, t_end)
            .map_err(integrator(stepper.time()))?;
        let taken = sampler.series.len();
        let Some((index, t_event)) = monitor.earliest_crossing(sys, stepper) else {
            let t = stepper.time();
            sampler.sample_through(sys, stepper, t)?;
            observer.emit(&sampler.series, taken, &mut row);
            check_slack(t, &sys.command(t, stepper.state()).tensions)?;
            monitor.accept(sys, stepper.state());
            (observer.progress)(t / t_end);
            continue;
        };
        // Samples up to the event come from the step as integrated; the event changes the state
        // there and the integrator restarts from it, abandoning the rest of the step.
        sampler.sample_through(sys, stepper, t_event)?;
        observer.emit(&sampler.series, taken, &mut row);
        let mut y = vec![0.0; y0.len()];
        stepper.dense_output(t_event, &mut y);
        let n = sys.model_len();
        let event = sys.model.apply_event(index, t_event, &mut y[..n])?;
        sampler.event_energy += event.energy_change;
        events.push(event);
        stepper.restart(sys, t_event, &y);
        check_slack(t_event, &sys.command(t_event, &y).tensions)?;
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
    fn new<M: CableModel<D>, const D: usize>(sys: &ClosedLoop<M, D>, y: &[f64]) -> Self {
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
    fn accept<M: CableModel<D>, const D: usize>(&mut self, sys: &ClosedLoop<M, D>, y: &[f64]) {
        if !self.before.is_empty() {
            sys.model
                .event_functions(&y[..sys.model_len()], &mut self.before);
        }
    }

    /// The earliest event function that fell from > 0 to ≤ 0 over the last accepted step, with
    /// the first time at which it is ≤ 0 (to within [`EVENT_TIME_TOL`]).
    fn earliest_crossing<M: CableModel<D>, const D: usize>(
        &mut self,
        sys: &ClosedLoop<M, D>,
        stepper: &dyn Stepper<ClosedLoop<M, D>>,
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

/// A commanded tension ≤ 0 (or NaN) is a slack cable (the first such cable is named).
#[inline]
fn check_slack(t: f64, tensions: &Tensions) -> Result<(), RunError> {
    match tensions.iter().position(|&t| t <= 0.0 || t.is_nan()) {
        None => Ok(()),
        Some(i) => Err(RunError::SlackCable {
            t,
            cable: CableId(i),
            tension: tensions[i],
        }),
    }
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
    fn sample_through<M: CableModel<D>, const D: usize>(
        &mut self,
        sys: &ClosedLoop<M, D>,
        stepper: &dyn Stepper<ClosedLoop<M, D>>,
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
            check_slack(tk, &cmd.tensions)?;
            let model_state = &y[..n];
            let eff = sys.model.effector(model_state);
            if !sys.robot().in_workspace(&eff.position) {
                return Err(RunError::Workspace {
                    t: tk,
                    position: eff.position.as_slice().to_vec(),
                });
            }
            let energy = sys.model.energy(model_state);
            let c = n + sys.controller_len();
            let (work, dissipated) = (y[c], y[c + 1]);
            let residual = energy.total() - self.energy0 - work + dissipated - self.event_energy;
            let m = self.model_channels;
            let cables = cmd.tensions.len();
            self.series.push_row_with(|row| {
                let (common, rest) = row.split_at_mut(4 + D + cables);
                let (own, energies) = rest.split_at_mut(m);
                common[0] = tk;
                common[1] = cmd.reference;
                common[2..2 + D].copy_from_slice(eff.position.as_slice());
                common[2 + D] = cmd.error;
                common[3 + D] = cmd.force;
                common[4 + D..].copy_from_slice(&cmd.tensions);
                sys.model.channels(model_state, &cmd.tensions, own);
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
