//! One point's record: its parameters, status, every metric of `metrics.json`, and for a failed
//! point its error and the simulated time it failed at. Runs are metrics-only: the samples live
//! as long as the metrics take to compute, then are dropped.

use crate::grid::{Grid, Point};
use crate::point;
use cdpr_bench::core::runner::{Observer, RunError};
use cdpr_bench::core::scenario::Scenario;
use cdpr_bench::core::series::SeriesBuffer;
use cdpr_bench::{Assessed, Error, ModelConfig};
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// A point's result, one line of `results.jsonl`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Record {
    /// The point's index in the grid.
    pub point: usize,
    /// Each axis key and the point's value.
    pub params: Map<String, Value>,
    /// "complete" or "failed".
    pub status: String,
    /// Why the point failed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// Simulated time reached [s]: t_final when complete, the time of failure otherwise.
    pub t_reached: f64,
    /// The keys of `metrics.json` but `wall_s` (null where a metric was not reached).
    pub metrics: Map<String, Value>,
    /// Wall time of the point [s] (the only field that differs between two runs of a point).
    pub wall_s: f64,
}

/// The metrics of an assessed run as `metrics.json` names them: the MODELS.md §7 metrics, the
/// control metrics, and the end's vertical mode and modal-analysis status.
pub fn metrics_map(scenario: &Scenario, assessed: &Assessed) -> Map<String, Value> {
    let mut map = match serde_json::to_value(&assessed.metrics) {
        Ok(Value::Object(m)) => m,
        _ => Map::new(),
    };
    let end = assessed.end.state();
    let number = |x: Option<f64>| x.map_or(Value::Null, Value::from);
    map.insert(
        "vertical_mode_rad_s".into(),
        number(end.map(|e| e.mode.omega)),
    );
    map.insert(
        "vertical_mode_growth".into(),
        number(end.map(|e| e.mode.growth)),
    );
    map.insert("modal_analysis".into(), assessed.end.status().into());
    map.insert(
        "eq15_rad_s".into(),
        Value::from(cdpr_bench::eq15_at_end(scenario)),
    );
    map.insert("warnings".into(), Value::from(assessed.warnings.clone()));
    map
}

/// Runs point `index` of `grid` metrics-only. None: the run was interrupted through `stop`
/// (nothing to record; a resumed sweep runs it again).
pub fn evaluate(grid: &Grid, index: usize, stop: Option<&AtomicBool>) -> Option<Record> {
    evaluate_into(grid, index, stop, &mut SeriesBuffer::default())
}

/// As [`evaluate`], the samples written into `buffer`'s memory and handed back there (a
/// worker's runs then allocate and fault in their samples once).
pub fn evaluate_into(
    grid: &Grid,
    index: usize,
    stop: Option<&AtomicBool>,
    buffer: &mut SeriesBuffer,
) -> Option<Record> {
    let point = grid.point(index);
    let start = Instant::now();
    let mut record = Record {
        point: index,
        params: params(&point),
        status: "complete".into(),
        error: None,
        t_reached: 0.0,
        metrics: Map::new(),
        wall_s: 0.0,
    };
    match run(grid, &point, stop, std::mem::take(buffer)) {
        Outcome::Done(scenario, assessed, error) => {
            record.t_reached = assessed.run.t_reached;
            record.metrics = metrics_map(&scenario, &assessed);
            // The record's own wall time replaces the run's.
            record.metrics.remove("wall_s");
            if let Some(e) = error {
                record.status = "failed".into();
                record.error = Some(e);
            }
            *buffer = assessed.run.series.into_buffer();
        }
        Outcome::Spatial(metrics, t_reached, samples, error) => {
            record.t_reached = t_reached;
            record.metrics = metrics;
            if let Some(e) = error {
                record.status = "failed".into();
                record.error = Some(e);
            }
            *buffer = samples;
        }
        Outcome::Failed(e) => {
            record.status = "failed".into();
            record.error = Some(e);
        }
        Outcome::Interrupted => return None,
    }
    record.wall_s = start.elapsed().as_secs_f64();
    Some(record)
}

enum Outcome {
    /// The run, measured; with the error that stopped it early.
    Done(Box<Scenario>, Box<Assessed>, Option<String>),
    /// A spatial robot's run: its metrics map, the time reached, the samples' memory and the
    /// error that stopped it early.
    Spatial(Map<String, Value>, f64, SeriesBuffer, Option<String>),
    /// Nothing to measure.
    Failed(String),
    Interrupted,
}

fn run(grid: &Grid, point: &Point, stop: Option<&AtomicBool>, buffer: SeriesBuffer) -> Outcome {
    // Checked with its model, as `simulate` does before a run: a point that cannot start is
    // recorded with the keys that stop it.
    let scenario = match point::scenario(grid, point).map(|s| cdpr_bench::prepare(&s)) {
        Ok(Ok(s)) => s,
        Ok(Err(e)) => return Outcome::Failed(e.to_string()),
        Err(e) => return Outcome::Failed(e.to_string()),
    };
    let mut quiet = |_: f64| {};
    let mut observer = Observer {
        progress: &mut quiet,
        on_sample: None,
        stop,
        frames: None,
    };
    if scenario.robot.anchors.is_some() {
        return run_spatial(scenario, &mut observer, buffer);
    }
    match cdpr_bench::assess_observed_into(&scenario, &mut observer, buffer) {
        Ok(assessed) => Outcome::Done(Box::new(scenario), Box::new(assessed), None),
        Err(Error::Run(failure)) => match (failure.error, failure.partial) {
            (RunError::Interrupted { .. }, _) => Outcome::Interrupted,
            (error, Some(run)) => {
                let kind = match ModelConfig::from_scenario(&scenario) {
                    Ok(c) => c.kind,
                    Err(e) => return Outcome::Failed(e.to_string()),
                };
                let assessed = Assessed::partial(&scenario, kind, run);
                Outcome::Done(
                    Box::new(scenario),
                    Box::new(assessed),
                    Some(error.to_string()),
                )
            }
            (error, None) => Outcome::Failed(error.to_string()),
        },
        Err(e) => Outcome::Failed(e.to_string()),
    }
}

/// A point's values as JSON.
pub(crate) fn params(point: &Point) -> Map<String, Value> {
    point
        .values
        .iter()
        .map(|(k, v)| (k.clone(), serde_json::to_value(v).unwrap_or(Value::Null)))
        .collect()
}

/// A spatial robot's point: its run with the spatial metrics (`simulate`'s metrics.json keys
/// for a spatial robot), steps and RHS evaluations.
fn run_spatial(scenario: Scenario, observer: &mut Observer, buffer: SeriesBuffer) -> Outcome {
    let measured = |run: &cdpr_bench::core::runner::Run,
                    metrics: &cdpr_bench::analysis::spatial::SpatialMetrics| {
        let mut map = match serde_json::to_value(metrics) {
            Ok(Value::Object(map)) => map,
            _ => Map::new(),
        };
        map.insert("steps".into(), Value::from(run.stats.steps_accepted));
        map.insert("rhs_evaluations".into(), Value::from(run.stats.rhs_evals));
        map
    };
    match cdpr_bench::simulate_spatial_into(&scenario, observer, buffer) {
        Ok(done) => {
            let map = measured(&done.run, &done.metrics);
            Outcome::Spatial(map, done.run.t_reached, done.run.series.into_buffer(), None)
        }
        Err(Error::Run(failure)) => match (failure.error, failure.partial) {
            (RunError::Interrupted { .. }, _) => Outcome::Interrupted,
            (error, Some(run)) => match cdpr_bench::spatial_metrics_of(&scenario, &run) {
                Ok(metrics) => Outcome::Spatial(
                    measured(&run, &metrics),
                    run.t_reached,
                    run.series.into_buffer(),
                    Some(error.to_string()),
                ),
                Err(e) => Outcome::Failed(format!("{error}; its metrics: {e}")),
            },
            (error, None) => Outcome::Failed(error.to_string()),
        },
        Err(e) => Outcome::Failed(e.to_string()),
    }
}
