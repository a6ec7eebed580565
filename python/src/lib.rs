//! The Python module `cdpr_bench`: the CLI's runs from a notebook. A scenario (or a sweep's
//! grid) is TOML text, a path to a file, or a dict with the file's structure; everything is read
//! and checked by the same code as `cargo xtask`, so results equal the CLI's bit for bit and bad
//! input raises `ScenarioError` naming the key, its value and the allowed range.
//!
//! ```python
//! import cdpr_bench
//! metrics, series = cdpr_bench.simulate({"model": {"kind": "fe"}, "simulation": {"integrator": "implicit"}})
//! metrics["z_p2p"], series["z"][-1]
//! ```

use numpy::IntoPyArray;
use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use registry::analysis::modes::Loop;
use registry::core::runner::Observer;
use registry::core::scenario::Scenario;
use registry::{Assessed, Error, ModelKind};
use serde_json::Value;
use std::path::PathBuf;

create_exception!(
    cdpr_bench,
    ScenarioError,
    PyValueError,
    "A scenario or grid that cannot be run: the message names the key, its value and the allowed range."
);
create_exception!(
    cdpr_bench,
    SimulationError,
    PyRuntimeError,
    "A run that stopped early (a slack cable, the effector leaving the workspace, ...)."
);

/// TOML text of a scenario or grid given as text, a path or a dict.
fn toml_text(obj: &Bound<'_, PyAny>) -> PyResult<String> {
    if obj.is_instance_of::<PyDict>() {
        let json = to_json(obj)?;
        let table: toml::Value = toml::Value::try_from(json)
            .map_err(|e| ScenarioError::new_err(format!("the dict is not a TOML table: {e}")))?;
        return Ok(toml::to_string(&table).expect("a TOML table prints"));
    }
    if let Ok(text) = obj.extract::<String>() {
        let path = PathBuf::from(&text);
        if !text.contains('\n') && !text.contains('=') {
            return std::fs::read_to_string(&path).map_err(|e| {
                ScenarioError::new_err(format!("cannot read {}: {e}", path.display()))
            });
        }
        return Ok(text);
    }
    if let Ok(path) = obj.extract::<PathBuf>() {
        return std::fs::read_to_string(&path)
            .map_err(|e| ScenarioError::new_err(format!("cannot read {}: {e}", path.display())));
    }
    Err(ScenarioError::new_err(
        "give the scenario as TOML text, a path or a dict with the file's sections",
    ))
}

/// The scenario, validated whole, with an optional model override.
fn scenario(obj: &Bound<'_, PyAny>, model: Option<&str>) -> PyResult<Scenario> {
    let text = toml_text(obj)?;
    let s = registry::scenario_from_toml_str(&text)
        .map_err(|e| ScenarioError::new_err(e.to_string()))?;
    match model {
        None => Ok(s),
        Some(name) => {
            let kind: ModelKind = name.parse().map_err(ScenarioError::new_err)?;
            registry::with_model_kind(&s, kind).map_err(|e| ScenarioError::new_err(e.to_string()))
        }
    }
}

fn error(e: Error) -> PyErr {
    match e {
        Error::Scenario(e) => ScenarioError::new_err(e.to_string()),
        Error::Model(e) => ScenarioError::new_err(e.to_string()),
        Error::Loop(e) => ScenarioError::new_err(e.to_string()),
        Error::Run(failure) => SimulationError::new_err(failure.to_string()),
        Error::Analysis(e) => SimulationError::new_err(e.to_string()),
        Error::Reference(e) => ScenarioError::new_err(e.to_string()),
        Error::Gcode(e) => ScenarioError::new_err(e.to_string()),
        Error::Plan(e) => ScenarioError::new_err(e.to_string()),
    }
}

/// simulate(scenario, model=None) -> (metrics, series)
///
/// Runs the scenario as `cargo xtask simulate` does: `metrics` has the keys of its
/// metrics.json (with "status" and "t_reached"), `series` one numpy array per channel of its
/// timeseries.csv. A run that stops early raises SimulationError.
#[pyfunction]
#[pyo3(signature = (scenario, model = None))]
fn simulate<'py>(
    py: Python<'py>,
    scenario: &Bound<'py, PyAny>,
    model: Option<&str>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyDict>)> {
    let s = self::scenario(scenario, model)?;
    let (run, map) = py
        .detach(|| {
            if s.robot.anchors.is_some() {
                // A spatial robot: the metrics of `simulate`'s spatial metrics.json.
                let done = registry::simulate_spatial(&s, &mut Observer::progress(&mut |_| {}))?;
                let Value::Object(mut map) =
                    serde_json::to_value(&done.metrics).expect("metrics serialise")
                else {
                    unreachable!("a struct serialises to an object")
                };
                map.insert("status".into(), "complete".into());
                map.insert("t_reached".into(), Value::from(done.run.t_reached));
                return Ok::<_, Error>((done.run, map));
            }
            let assessed: Assessed = registry::assess(&s, &mut |_| {})?;
            let mut map = cdpr_sweep::metrics_map(&s, &assessed);
            map.insert("status".into(), "complete".into());
            map.insert("t_reached".into(), Value::from(assessed.run.t_reached));
            Ok::<_, Error>((assessed.run, map))
        })
        .map_err(error)?;
    let metrics = to_py(py, &Value::Object(map))?;
    // The samples are stored column by column: each becomes a numpy array as it is.
    let run = &run.series;
    let columns: Vec<Vec<f64>> = (0..run.width())
        .map(|j| run.column_at(j).to_vec())
        .collect();
    let series = PyDict::new(py);
    for (name, column) in run.names().iter().zip(columns) {
        series.set_item(name, column.into_pyarray(py))?;
    }
    Ok((metrics, series))
}

/// modes(scenario, x=None, loop="closed", model=None) -> dict
///
/// Every mode of the model at the static equilibrium at effector position x (default: the
/// move's end x2), with the paper's PID ("closed") or fixed tensions ("open"): the analysis
/// `cargo xtask modes` tabulates, as a dict (model, x, z, tensions, modes: growth [1/s],
/// omega [rad/s], kind, order, purity).
#[pyfunction]
#[pyo3(signature = (scenario, x = None, r#loop = "closed", model = None))]
fn modes<'py>(
    py: Python<'py>,
    scenario: &Bound<'py, PyAny>,
    x: Option<f64>,
    r#loop: &str,
    model: Option<&str>,
) -> PyResult<Bound<'py, PyAny>> {
    let s = self::scenario(scenario, model)?;
    let feedback = match r#loop {
        "closed" => Loop::Closed,
        "open" => Loop::Open,
        other => {
            return Err(ScenarioError::new_err(format!(
                "loop = {other:?}: allowed \"closed\" or \"open\""
            )));
        }
    };
    let x = x.unwrap_or(s.trajectory.x2);
    let analysis = py
        .detach(|| registry::analyse(&s, x, feedback))
        .map_err(error)?;
    let json = serde_json::to_value(&analysis).expect("an analysis serialises");
    to_py(py, &json)
}

fn grid(obj: &Bound<'_, PyAny>) -> PyResult<cdpr_sweep::Grid> {
    let text = toml_text(obj)?;
    cdpr_sweep::Grid::from_toml_str(&text, "grid")
        .map_err(|e| ScenarioError::new_err(e.to_string()))
}

fn sweep_error(e: cdpr_sweep::SweepError) -> PyErr {
    match e {
        cdpr_sweep::SweepError::Io { .. }
        | cdpr_sweep::SweepError::Busy { .. }
        | cdpr_sweep::SweepError::Interrupted(_) => PyRuntimeError::new_err(e.to_string()),
        _ => ScenarioError::new_err(e.to_string()),
    }
}

/// sweep(grid, out, jobs=None, shard=None) -> list of records
///
/// `cargo xtask sweep --grid GRID --out OUT [--jobs J] [--shard I/N]`: every point checked,
/// then run metrics-only on `jobs` threads (default: every core) into OUT/results.jsonl and
/// OUT/results.csv, resuming what OUT already holds. Returns the records (dicts), point order.
#[pyfunction]
#[pyo3(signature = (grid, out, jobs = None, shard = None))]
fn sweep<'py>(
    py: Python<'py>,
    grid: &Bound<'py, PyAny>,
    out: PathBuf,
    jobs: Option<usize>,
    shard: Option<&str>,
) -> PyResult<Bound<'py, PyAny>> {
    let g = self::grid(grid)?;
    let shard = match shard {
        Some(s) => s.parse().map_err(sweep_error)?,
        None => cdpr_sweep::Shard::ALL,
    };
    let jobs = cdpr_sweep::jobs(jobs).map_err(sweep_error)?;
    py.detach(|| {
        cdpr_sweep::run(
            &g,
            &out,
            cdpr_sweep::Options {
                jobs,
                shard,
                stop: None,
            },
            &mut |_| {},
        )
    })
    .map_err(sweep_error)?;
    let (_, mut records) = cdpr_sweep::store::read_records(&out.join(cdpr_sweep::store::RESULTS))
        .map_err(sweep_error)?;
    records.sort_by_key(|r| r.point);
    to_py(
        py,
        &serde_json::to_value(records).expect("records serialise"),
    )
}

/// grid_points(grid) -> int: the number of points of a grid (for a scheduler of one's own).
#[pyfunction]
fn grid_points(grid: &Bound<'_, PyAny>) -> PyResult<usize> {
    let g = self::grid(grid)?;
    cdpr_sweep::point::check_all(&g, cdpr_sweep::all_cores(), None, &mut |_, _| {})
        .map_err(sweep_error)?;
    Ok(g.len())
}

/// run_point(grid, index) -> record
///
/// One point of a grid, metrics-only: the record `cargo xtask sweep` writes for it. For
/// schedulers such as Dask: map it over range(grid_points(grid)), then write_results.
#[pyfunction]
fn run_point<'py>(
    py: Python<'py>,
    grid: &Bound<'py, PyAny>,
    index: usize,
) -> PyResult<Bound<'py, PyAny>> {
    let g = self::grid(grid)?;
    if index >= g.len() {
        return Err(ScenarioError::new_err(format!(
            "index = {index}: allowed 0 … {} (the grid's points)",
            g.len() - 1
        )));
    }
    let record = py
        .detach(|| cdpr_sweep::evaluate(&g, index, None))
        .ok_or_else(|| SimulationError::new_err("interrupted"))?;
    to_py(
        py,
        &serde_json::to_value(record).expect("a record serialises"),
    )
}

/// write_results(grid, records, out)
///
/// Writes OUT/results.jsonl and OUT/results.csv from records (e.g. gathered from Dask workers)
/// exactly as `cargo xtask sweep` and `--merge` write them.
#[pyfunction]
fn write_results(
    grid: &Bound<'_, PyAny>,
    records: &Bound<'_, PyAny>,
    out: PathBuf,
) -> PyResult<()> {
    let g = self::grid(grid)?;
    let json = to_json(records)?;
    let records: Vec<cdpr_sweep::Record> = serde_json::from_value(json)
        .map_err(|e| ScenarioError::new_err(format!("records: {e}")))?;
    cdpr_sweep::store::write_records(&out, &g, &records).map_err(sweep_error)
}

/// A Python object (dict, list, str, int, float, bool, None) as JSON.
fn to_json(obj: &Bound<'_, PyAny>) -> PyResult<Value> {
    if obj.is_none() {
        return Ok(Value::Null);
    }
    if let Ok(b) = obj.cast::<PyBool>() {
        return Ok(Value::Bool(b.is_true()));
    }
    if obj.is_instance_of::<PyInt>() {
        return Ok(Value::from(obj.extract::<i64>()?));
    }
    if let Ok(f) = obj.cast::<PyFloat>() {
        return Ok(Value::from(f.value()));
    }
    if let Ok(s) = obj.cast::<PyString>() {
        return Ok(Value::String(s.to_str()?.to_owned()));
    }
    if let Ok(d) = obj.cast::<PyDict>() {
        let mut map = serde_json::Map::new();
        for (k, v) in d.iter() {
            let key: String = k.extract().map_err(|_| {
                ScenarioError::new_err(format!("dict keys must be strings, not {k}"))
            })?;
            map.insert(key, to_json(&v)?);
        }
        return Ok(Value::Object(map));
    }
    if obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>() {
        return obj
            .try_iter()?
            .map(|item| to_json(&item?))
            .collect::<PyResult<Vec<_>>>()
            .map(Value::Array);
    }
    if let Ok(f) = obj.extract::<f64>() {
        return Ok(Value::from(f));
    }
    Err(ScenarioError::new_err(format!(
        "cannot use a {} here",
        obj.get_type().name()?
    )))
}

/// JSON as Python objects (null → None).
fn to_py<'py>(py: Python<'py>, v: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => PyBool::new(py, *b).to_owned().into_any(),
        Value::Number(n) => match n.as_i64() {
            Some(i) if !n.is_f64() => i.into_pyobject(py)?.into_any(),
            _ => PyFloat::new(py, n.as_f64().unwrap_or(f64::NAN)).into_any(),
        },
        Value::String(s) => PyString::new(py, s).into_any(),
        Value::Array(items) => {
            let list = PyList::empty(py);
            for item in items {
                list.append(to_py(py, item)?)?;
            }
            list.into_any()
        }
        Value::Object(map) => {
            let dict = PyDict::new(py);
            for (k, item) in map {
                dict.set_item(k, to_py(py, item)?)?;
            }
            dict.into_any()
        }
    })
}

/// The model kinds, for completion and checks.
#[pyfunction]
fn models() -> Vec<&'static str> {
    ModelKind::ALL.map(ModelKind::name).to_vec()
}

#[pymodule]
fn cdpr_bench(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("ScenarioError", m.py().get_type::<ScenarioError>())?;
    m.add("SimulationError", m.py().get_type::<SimulationError>())?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(modes, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(grid_points, m)?)?;
    m.add_function(wrap_pyfunction!(run_point, m)?)?;
    m.add_function(wrap_pyfunction!(write_results, m)?)?;
    m.add_function(wrap_pyfunction!(models, m)?)?;
    Ok(())
}
