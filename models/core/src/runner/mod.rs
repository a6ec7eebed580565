//! The runner: integrates a [`ClosedLoop`] from its MODELS.md §2 initial state with the
//! scenario's integrator, samples it on the dense output, locates and applies the model's events,
//! and stops with a reason ([`RunError`]) while keeping what it sampled ([`RunFailure`]).

mod error;
mod events;
mod frames;
mod sampler;
mod stops;

pub use error::{RunError, RunFailure};
pub use events::EVENT_TIME_TOL;
use events::{EventMonitor, check_slack};
use frames::FrameClock;
pub use frames::{FrameSink, Frames};
use sampler::Sampler;
use stops::{Stops, restart_after_event};

use crate::channel::Channel;
use crate::closed_loop::ClosedLoop;
use crate::controller::Controller;
use crate::model::{CableModel, Equilibrium, ModelEvent};
use crate::scenario::{ErrorNorm, ImplicitMethod, IntegratorKind, Scenario};
use crate::series::{SeriesBuffer, TimeSeries};
use cdpr_numerics::{
    Dopri5, Dopri5Options, ErrorControl, ErrorPositions, GeneralizedAlpha, GeneralizedAlphaOptions,
    SolverStats, Stepper,
};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

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
    /// Whether the run stops at the reference's jumps and restarts past them ([`stops`]): every
    /// integrator that controls its error, since a step across a jump has an error that shrinks
    /// only as h, which the error test chases down to round-off (the implicit path) or through
    /// rejected steps (DOPRI5). The fixed step keeps its grid and its bits.
    pub fn stops_at_reference_jumps(&self) -> bool {
        match self.integrator {
            IntegratorKind::Dopri5 => true,
            IntegratorKind::Implicit => self.implicit.error_control.is_some(),
        }
    }

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
                    error_control: sim.adaptive.then(|| ErrorControl {
                        rtol: sim.rtol,
                        atol: sim.atol,
                        max_step: s.largest_adaptive_step(),
                        positions: match sim.error_norm {
                            ErrorNorm::All => ErrorPositions::All,
                            ErrorNorm::Effector => ErrorPositions::Principal,
                        },
                    }),
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
    /// When set, receives the cables' lines every `period` (drawings, animations).
    pub frames: Option<Frames<'a>>,
}

impl<'a> Observer<'a> {
    /// An observer of the progress only.
    pub fn progress(progress: &'a mut dyn FnMut(f64)) -> Self {
        Self {
            progress,
            on_sample: None,
            stop: None,
            frames: None,
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
    sys.forget_reference();
    let mut sampler = Sampler::new(sys, &y0, opts, buffer);
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
    let outcome = match unsupported(sys, opts) {
        Some(error) => Err(error),
        None => integrate(
            sys,
            &y0,
            (opts.t_final, opts.stops_at_reference_jumps()),
            stepper,
            &mut sampler,
            &mut events,
            observer,
        ),
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

/// Why the loop cannot be run with `opts` at all: a shaper still to be resolved, or the
/// implicit integrator on a model without a second-order form.
fn unsupported<M: CableModel<D>, const D: usize>(
    sys: &ClosedLoop<M, D>,
    opts: &RunOptions,
) -> Option<RunError> {
    if sys.shaper.is_none() {
        Some(RunError::UnresolvedShaper)
    } else if opts.integrator == IntegratorKind::Implicit && sys.model.second_order().is_none() {
        Some(RunError::Unsupported {
            integrator: IntegratorKind::Implicit.name(),
            model: sys.model.name(),
            why: "the model offers no second-order form",
        })
    } else if opts.integrator == IntegratorKind::Implicit
        && sys.drives_reels_by_length()
        && !sys
            .model
            .second_order()
            .is_some_and(|f| f.follows_driven_reels())
    {
        Some(RunError::Unsupported {
            integrator: IntegratorKind::Implicit.name(),
            model: sys.model.name(),
            why: "reels driven by length on this model run on DOPRI5 (the reel's velocity \
                  loop is not in its second-order form)",
        })
    } else {
        None
    }
}

/// The integration loop: accepted steps, located model events, samples, slack checks.
fn integrate<M: CableModel<D>, const D: usize>(
    sys: &mut ClosedLoop<M, D>,
    y0: &[f64],
    (t_end, stop_at_jumps): (f64, bool),
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
    let mut clock = FrameClock::default();
    sampler.sample_through(sys, stepper, 0.0)?;
    observer.emit(&sampler.series, 0, &mut row);
    clock.take_through(sys, stepper, 0.0, &mut observer.frames);
    let jumps = stop_at_jumps.then(|| sys.reference_breakpoints());
    let mut stops = Stops::new(jumps.unwrap_or_default(), t_end);
    // The state a restart starts from (at a stop, or changed by an event).
    let mut restart_state = vec![0.0; y0.len()];
    while stepper.time() < t_end {
        if observer.stopped() {
            return Err(RunError::Interrupted { t: stepper.time() });
        }
        let window = stops.after(stepper.time());
        let target = window.map_or(t_end, |w| w.stop);
        stepper
            .step(sys, target)
            .map_err(integrator(stepper.time()))?;
        let taken = sampler.series.len();
        let Some((index, t_event)) = monitor.earliest_crossing(sys, stepper) else {
            let t = stepper.time();
            sampler.sample_through(sys, stepper, t)?;
            observer.emit(&sampler.series, taken, &mut row);
            clock.take_through(sys, stepper, t, &mut observer.frames);
            check_slack(
                t,
                &sys.tensions_at_step_end(t, stepper.state(), stepper.last_rhs_at_state()),
                sys.slack_allowed(),
            )?;
            monitor.accept(sys, stepper.state());
            (observer.progress)(t / t_end);
            if let Some(w) = window.filter(|_| t == target) {
                // Across the jumps from the same state ([`stops`]).
                restart_state.copy_from_slice(stepper.state());
                stepper.restart(sys, w.resume, &restart_state);
            }
            continue;
        };
        // Samples up to the event come from the step as integrated; the event changes the state
        // there and the integrator restarts from it, abandoning the rest of the step.
        sampler.sample_through(sys, stepper, t_event)?;
        observer.emit(&sampler.series, taken, &mut row);
        clock.take_through(sys, stepper, t_event, &mut observer.frames);
        let y = &mut restart_state[..];
        stepper.dense_output(t_event, y);
        let n = sys.model_len();
        let event = sys.model.apply_event(index, t_event, &mut y[..n])?;
        sampler.event_energy += event.energy_change;
        events.push(event);
        // An event by a stop restarts past its jumps, not a sliver before them ([`stops`]).
        stepper.restart(sys, restart_after_event(t_event, window), y);
        check_slack(
            t_event,
            &sys.command(t_event, y).tensions,
            sys.slack_allowed(),
        )?;
        monitor.accept(sys, y);
    }
    Ok(())
}
