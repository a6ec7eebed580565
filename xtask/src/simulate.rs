//! `cargo xtask simulate`: one scenario → `timeseries.csv` and `metrics.json`.
//!
//! The run is guarded before it starts (the scenario checked whole, then with its model: an
//! "auto" shaper designed, the start equilibrium found and the controller designed there; `--out`
//! locked against a second run and writable; the samples' memory against the machine's),
//! streams its samples to `timeseries.partial.csv` while it goes (so a killed run leaves what it
//! sampled; a failed write stops it at once), stops at the next step on SIGINT or SIGTERM, and
//! always ends with a `metrics.json` that says whether it completed, failed or was interrupted,
//! and where it came from.

pub(crate) use crate::csv_stream::CsvStream;
use crate::output::{Progress, write_json};
use anyhow::{Context, Result, bail};
use cdpr_bench::analysis::metrics::{Metrics, UNITS};
use cdpr_bench::core::channel::heading;
use cdpr_bench::core::runner::{Observer, RunError, channel_names, channel_units};
use cdpr_bench::core::scenario::Scenario;
use cdpr_bench::memory::{MEMORY_SHARE, available_memory, run_memory, samples};
use cdpr_bench::{Assessed, EndAnalysis, Error, ModelConfig, ModelKind, Provenance};
use cdpr_sweep::DirLock;
use std::collections::BTreeMap;
use std::fs::File;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

/// Set by SIGINT/SIGTERM, or by a failed write of the samples: the run stops after its current
/// step.
pub(crate) static STOP: AtomicBool = AtomicBool::new(false);

/// The outputs of a run in `--out`; any of them left by an earlier run is removed first, so a
/// failed run never sits beside another run's files.
pub(crate) const TIMESERIES: &str = "timeseries.csv";
pub(crate) const PARTIAL: &str = "timeseries.partial.csv";
pub(crate) const METRICS: &str = "metrics.json";

/// `metrics.json`: the run's status and provenance, the §7 metrics at the top level (absent when
/// the run failed before its first sample), the units of every metric, and the modal analysis at
/// the end of the move.
#[derive(serde::Serialize)]
pub struct MetricsFile<'a> {
    /// "complete", "failed" or "interrupted".
    pub status: &'static str,
    /// Why it did not complete.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// Time reached [s] (t_final when complete).
    pub t_reached: f64,
    pub provenance: &'a Provenance,
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub metrics: Option<&'a Metrics>,
    /// Closed-loop vertical eigenfrequency at the x2 equilibrium [rad/s] (null: not computed).
    pub vertical_mode_rad_s: Option<f64>,
    /// Its growth rate [1/s] (negative: damped; null: not computed).
    pub vertical_mode_growth: Option<f64>,
    /// "done", "skipped" or "failed", and why.
    pub modal_analysis: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub modal_analysis_note: Option<&'a str>,
    /// Paper eq. 15 at x2 [rad/s].
    pub eq15_rad_s: f64,
    /// What a reader of these numbers must know (closed-loop modes that grow).
    pub warnings: &'a [String],
    /// Unit of every key above that has one.
    pub units: BTreeMap<&'static str, &'static str>,
}

/// The units of `metrics.json`'s keys.
fn units() -> BTreeMap<&'static str, &'static str> {
    let mut units: BTreeMap<_, _> = UNITS.iter().copied().collect();
    units.extend([
        ("t_reached", "s"),
        ("vertical_mode_rad_s", "rad/s"),
        ("vertical_mode_growth", "1/s"),
        ("eq15_rad_s", "rad/s"),
    ]);
    units
}

/// Loads the scenario file (or the paper's) and applies a `--model` override; the whole scenario
/// is checked before any work starts.
pub fn load_scenario(path: Option<&Path>, model: Option<ModelKind>) -> Result<Scenario> {
    let scenario = match path {
        Some(p) => cdpr_bench::scenario_from_file(p)?,
        None => Scenario::paper(),
    };
    Ok(match model {
        Some(kind) => cdpr_bench::with_model_kind(&scenario, kind)?,
        None => scenario,
    })
}

/// The scenario's model kind (its `[model]` section was checked when it was loaded).
pub fn model_kind(scenario: &Scenario) -> Result<ModelKind> {
    Ok(ModelConfig::from_scenario(scenario)?.kind)
}

/// Creates `out` and checks that it takes files (before any work, so that a study does not
/// fail after its runs).
pub fn writable_out(out: &Path) -> Result<()> {
    std::fs::create_dir_all(out).with_context(|| format!("creating --out {}", out.display()))?;
    let probe = out.join(format!(".write-probe-{}", std::process::id()));
    File::create(&probe)
        .and_then(|_| std::fs::remove_file(&probe))
        .with_context(|| format!("--out {} is not writable", out.display()))
}

/// Creates `out`, checks that it takes files, and removes the outputs of an earlier run (the
/// caller holds `out`'s lock).
pub fn prepare_out(out: &Path) -> Result<()> {
    writable_out(out)?;
    // An earlier run's outputs, and the temporary files of atomic writes a kill interrupted
    // (`.metrics.json.tmp-PID`), which would otherwise accumulate.
    let stale = |name: &str| {
        [TIMESERIES, PARTIAL, METRICS].contains(&name)
            || [TIMESERIES, METRICS]
                .iter()
                .any(|o| name.starts_with(&format!(".{o}.tmp-")))
    };
    let entries =
        std::fs::read_dir(out).with_context(|| format!("reading --out {}", out.display()))?;
    for entry in entries {
        let entry = entry?;
        if stale(&entry.file_name().to_string_lossy()) {
            std::fs::remove_file(entry.path())
                .with_context(|| format!("removing {}", entry.path().display()))?;
        }
    }
    Ok(())
}

/// Refuses a run whose samples and their metrics would take more than [`MEMORY_SHARE`] of the
/// available memory, naming the estimate and the keys that set it.
pub(crate) fn check_memory(scenario: &Scenario) -> Result<()> {
    let sim = &scenario.simulation;
    let bytes = run_memory(scenario)?;
    if let Some(available) = available_memory()
        && bytes > MEMORY_SHARE * available
    {
        bail!(
            "the run and its metrics need about {:.1} GB ({:e} samples and their spectra), more \
             than half of the {:.1} GB available: raise simulation.sample_period (now {} s) or \
             shorten simulation.t_final (now {} s)",
            bytes / 1e9,
            samples(scenario),
            available / 1e9,
            sim.sample_period,
            sim.t_final
        );
    }
    Ok(())
}

/// `run` watched by a progress bar labelled `label`, each sample written to `stream`, stopped
/// by SIGINT/SIGTERM or a failed write ([`STOP`]).
pub(crate) fn streamed<T>(
    stream: &mut CsvStream,
    label: &str,
    run: impl FnOnce(&mut Observer) -> T,
) -> T {
    let mut progress = Progress::new(label);
    let result = {
        let mut on_sample = |row: &[f64]| stream.push(row);
        let mut report = |f: f64| progress.set(f);
        let mut observer = Observer {
            progress: &mut report,
            on_sample: Some(&mut on_sample),
            stop: Some(&STOP),
            frames: None,
        };
        run(&mut observer)
    };
    progress.finish();
    result
}

/// How a run ended.
struct Ending {
    status: &'static str,
    error: Option<String>,
}

pub fn run(
    scenario: Option<&Path>,
    model: Option<ModelKind>,
    out: &Path,
    every: usize,
) -> Result<()> {
    let scenario = load_scenario(scenario, model)?;
    if scenario.robot.anchors.is_some() {
        return crate::simulate_spatial::run(&scenario, out, every);
    }
    // What can be known before the run: refused here, before anything is written.
    let scenario = cdpr_bench::prepare(&scenario)?;
    let provenance = Provenance::of(&scenario)?;
    writable_out(out)?;
    let _lock = DirLock::acquire(out, "simulate")?;
    prepare_out(out)?;
    let model = cdpr_bench::build(&scenario)?;
    let headings: Vec<String> = channel_names(&*model)
        .iter()
        .zip(channel_units(&*model))
        .map(|(name, unit)| heading(name, unit))
        .collect();
    drop(model);
    check_memory(&scenario)?;
    ctrlc::set_handler(|| STOP.store(true, Ordering::Relaxed))
        .context("installing the SIGINT/SIGTERM handler")?;
    let kind = model_kind(&scenario)?;

    let mut stream = CsvStream::create(out.join(PARTIAL), &headings, every)?;
    let result = streamed(&mut stream, kind.name(), |observer| {
        cdpr_bench::assess_observed(&scenario, observer)
    });
    let (assessed, ending) = ending(&scenario, kind, result, stream.failure());
    let written = match &assessed {
        Some(a) => stream.finish(&a.run.series, &out.join(TIMESERIES)),
        None => stream.finish(
            &cdpr_bench::core::series::TimeSeries::new(Vec::new()),
            &out.join(TIMESERIES),
        ),
    };
    write_metrics(out, &scenario, &provenance, assessed.as_ref(), &ending)?;
    written?;
    if let Some(a) = &assessed {
        report(a, out);
    }
    match ending.error {
        None => Ok(()),
        Some(e) => bail!(
            "{e}; {} run kept up to t = {} s in {} and {}",
            ending.status,
            assessed.as_ref().map_or(0.0, |a| a.run.t_reached),
            out.join(TIMESERIES).display(),
            out.join(METRICS).display()
        ),
    }
}

/// What a run left (all of it, or what a failed or interrupted run sampled) and how it ended;
/// a failed write of the samples fails the run whatever it did.
fn ending(
    scenario: &Scenario,
    kind: ModelKind,
    result: Result<Assessed, Error>,
    write_failure: Option<String>,
) -> (Option<Assessed>, Ending) {
    let failed = |error: String| Ending {
        status: "failed",
        error: Some(error),
    };
    match result {
        Ok(assessed) => (
            Some(assessed),
            Ending {
                status: "complete",
                error: None,
            },
        ),
        Err(Error::Run(failure)) => {
            let ending = match (&write_failure, &failure.error) {
                (Some(e), _) => failed(e.clone()),
                (None, RunError::Interrupted { .. }) => Ending {
                    status: "interrupted",
                    error: Some(failure.error.to_string()),
                },
                (None, e) => failed(e.to_string()),
            };
            let assessed = failure
                .partial
                .map(|run| Assessed::partial(scenario, kind, run));
            (assessed, ending)
        }
        Err(e) => (None, failed(e.to_string())),
    }
}

/// `metrics.json` for the run's ending.
fn write_metrics(
    out: &Path,
    scenario: &Scenario,
    provenance: &Provenance,
    assessed: Option<&Assessed>,
    ending: &Ending,
) -> Result<()> {
    let end = assessed.and_then(|a| a.end.state());
    let none = EndAnalysis::Skipped {
        reason: "the run failed before its first sample".into(),
    };
    let analysis = assessed.map_or(&none, |a| &a.end);
    write_json(
        &out.join(METRICS),
        &MetricsFile {
            status: ending.status,
            error: ending.error.clone(),
            t_reached: assessed.map_or(0.0, |a| a.run.t_reached),
            provenance,
            metrics: assessed.map(|a| &a.metrics),
            vertical_mode_rad_s: end.map(|e| e.mode.omega),
            vertical_mode_growth: end.map(|e| e.mode.growth),
            modal_analysis: analysis.status(),
            modal_analysis_note: analysis.reason(),
            eq15_rad_s: cdpr_bench::eq15_at_end(scenario),
            warnings: assessed.map_or(&[], |a| &a.warnings),
            units: units(),
        },
    )
}

/// The run's summary on stdout, its notes and warnings on stderr.
fn report(assessed: &Assessed, out: &Path) {
    if let EndAnalysis::Skipped { reason } | EndAnalysis::Failed { reason } = &assessed.end {
        eprintln!("note: modal analysis {}: {reason}", assessed.end.status());
    }
    for w in &assessed.warnings {
        eprintln!("warning: {w}");
    }
    let run = &assessed.run;
    println!(
        "{}: {} samples, {} RHS evaluations, {} accepted / {} rejected steps, {} Newton iterations, {} matrix evaluations, {} factorisations ({} pivoting), {} events, {:.3} s wall → {}",
        run.model,
        run.series.len(),
        run.stats.rhs_evals,
        run.stats.steps_accepted,
        run.stats.steps_rejected,
        run.stats.newton_iterations,
        run.stats.jacobian_evals,
        run.stats.factorisations,
        run.stats.pivotings,
        run.events.len(),
        run.wall_s,
        out.display()
    );
}
