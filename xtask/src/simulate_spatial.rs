//! `cargo xtask simulate` of a spatial robot (`[robot] anchors`): the same guarantees as the
//! planar run — checked before work (here also the whole reference's wrench feasibility), `--out`
//! locked, samples streamed to `timeseries.partial.csv`, SIGINT/SIGTERM honoured, always a
//! `metrics.json` saying how the run ended — with the spatial metrics (3-D path error, tensions
//! and reel speeds per cable) and two figures: the path in three projections, the tensions.

use crate::output::write_json;
use crate::simulate::{
    CsvStream, METRICS, PARTIAL, STOP, TIMESERIES, check_memory, prepare_out, streamed,
    writable_out,
};
use anyhow::{Context, Result, bail};
use cdpr_bench::analysis::spatial::SpatialMetrics;
use cdpr_bench::core::channel::heading;
use cdpr_bench::core::runner::RunError;
use cdpr_bench::core::scenario::Scenario;
use cdpr_bench::{Error, Provenance, SpatialRun};
use cdpr_sweep::DirLock;
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::atomic::Ordering;

/// `metrics.json` of a spatial run.
#[derive(serde::Serialize)]
struct SpatialMetricsFile<'a> {
    status: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    error: Option<String>,
    t_reached: f64,
    provenance: &'a Provenance,
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    metrics: Option<&'a SpatialMetrics>,
    /// The run's cost.
    #[serde(flatten)]
    cost: crate::cost::RunCost,
    units: BTreeMap<&'static str, &'static str>,
}

/// Runs the spatial `scenario` into `out`, every `every`-th sample written.
pub fn run(scenario: &Scenario, out: &Path, every: usize) -> Result<()> {
    // What can be known before the run (the reference's feasibility, the start, the
    // controller's design): refused here, before anything is written.
    cdpr_bench::prepare(scenario)?;
    let (names, units) = cdpr_bench::spatial_channel_headings(scenario)?;
    let provenance = Provenance::of(scenario)?;
    writable_out(out)?;
    let _lock = DirLock::acquire(out, "simulate")?;
    prepare_out(out)?;
    let headings: Vec<String> = names
        .iter()
        .zip(units)
        .map(|(name, unit)| heading(name, unit))
        .collect();
    check_memory(scenario)?;
    ctrlc::set_handler(|| STOP.store(true, Ordering::Relaxed))
        .context("installing the SIGINT/SIGTERM handler")?;
    let mut stream = CsvStream::create(out.join(PARTIAL), &headings, every)?;
    let label = format!(
        "{} (space)",
        cdpr_bench::ModelConfig::from_scenario(scenario)?.kind
    );
    let result = streamed(&mut stream, &label, |observer| {
        cdpr_bench::simulate_spatial(scenario, observer)
    });
    let Ending {
        done,
        status,
        error,
    } = ending(scenario, result, stream.failure());
    let empty = cdpr_bench::core::series::TimeSeries::new(Vec::new());
    let written = stream.finish(
        done.as_ref().map_or(&empty, |d| &d.run.series),
        &out.join(TIMESERIES),
    );
    write_metrics(out, &provenance, done.as_ref(), status, error.clone())?;
    written?;
    if let Some(d) = &done {
        crate::spatial_figures::write(scenario, &d.run, out)?;
        summary(d, out);
    }
    match error {
        None => Ok(()),
        Some(e) => bail!(
            "{e}; {status} run kept up to t = {} s in {} and {}",
            done.as_ref().map_or(0.0, |d| d.run.t_reached),
            out.join(TIMESERIES).display(),
            out.join(METRICS).display()
        ),
    }
}

/// How a spatial run ended: what it computed (complete, or the part a failed run sampled),
/// "complete" | "failed" | "interrupted", and why it did not complete.
struct Ending {
    done: Option<SpatialRun>,
    status: &'static str,
    error: Option<String>,
}

/// The ending of `result`; a failed write of the samples fails the run whatever it did.
fn ending(
    scenario: &Scenario,
    result: Result<SpatialRun, Error>,
    write_failure: Option<String>,
) -> Ending {
    let failed = |done, error| Ending {
        done,
        status: "failed",
        error: Some(error),
    };
    match result {
        Ok(done) => match write_failure {
            None => Ending {
                done: Some(done),
                status: "complete",
                error: None,
            },
            Some(e) => failed(Some(done), e),
        },
        Err(Error::Run(failure)) => {
            let status = match (&write_failure, &failure.error) {
                (None, RunError::Interrupted { .. }) => "interrupted",
                _ => "failed",
            };
            let error = write_failure.unwrap_or_else(|| failure.error.to_string());
            let done = failure.partial.and_then(|run| {
                let metrics = cdpr_bench::spatial_metrics_of(scenario, &run).ok()?;
                Some(SpatialRun { run, metrics })
            });
            Ending {
                done,
                status,
                error: Some(error),
            }
        }
        Err(e) => failed(None, e.to_string()),
    }
}

/// `metrics.json` for the run's ending.
fn write_metrics(
    out: &Path,
    provenance: &Provenance,
    done: Option<&SpatialRun>,
    status: &'static str,
    error: Option<String>,
) -> Result<()> {
    let units = SpatialMetrics::UNITS
        .into_iter()
        .chain([("t_reached", "s"), ("move_end_s", "s")]);
    write_json(
        &out.join(METRICS),
        &SpatialMetricsFile {
            status,
            error,
            t_reached: done.map_or(0.0, |d| d.run.t_reached),
            provenance,
            metrics: done.map(|d| &d.metrics),
            cost: done.map(|d| (&d.run.stats).into()).unwrap_or_default(),
            units: units.collect(),
        },
    )
}

/// The run's summary on stdout.
fn summary(d: &SpatialRun, out: &Path) {
    println!(
        "{} in space, {} cables: {} samples, {} RHS evaluations, {} accepted steps, {} pulley events; path error during the move {:.3e} m, 1 s after {:.3e} m → {}",
        d.run.model,
        d.metrics.cables,
        d.run.series.len(),
        d.run.stats.rhs_evals,
        d.run.stats.steps_accepted,
        d.run.events.len(),
        d.metrics.path_err_max_move,
        d.metrics.path_err_max_after_1s,
        out.display()
    );
}
