//! `cargo xtask simulate`: one scenario → `timeseries.csv` and `metrics.json`.
//!
//! The run is guarded before it starts (the scenario checked whole, `--out` writable, the samples'
//! memory against the machine's), streams its samples to `timeseries.partial.csv` while it goes
//! (so a killed run leaves what it sampled), stops at the next step on SIGINT or SIGTERM, and
//! always ends with a `metrics.json` that says whether it completed, failed or was interrupted,
//! and where it came from.

use crate::output::{Progress, csv_row, write_json};
use anyhow::{Context, Result, bail};
use cdpr_bench::analysis::metrics::{Metrics, UNITS, memory_estimate};
use cdpr_bench::core::runner::{Observer, RunError, channel_names};
use cdpr_bench::core::scenario::Scenario;
use cdpr_bench::{Assessed, EndAnalysis, Error, ModelConfig, ModelKind, Provenance};
use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

/// Set by SIGINT/SIGTERM: the run stops after its current step.
static STOP: AtomicBool = AtomicBool::new(false);

/// The outputs of a run in `--out`; any of them left by an earlier run is removed first, so a
/// failed run never sits beside another run's files.
const TIMESERIES: &str = "timeseries.csv";
const PARTIAL: &str = "timeseries.partial.csv";
const METRICS: &str = "metrics.json";

/// Fraction of the machine's available memory a run's samples may take.
const MEMORY_SHARE: f64 = 0.5;

/// `metrics.json`: the run's status and provenance, the §7 metrics at the top level, the units of
/// every metric, and the modal analysis at the end of the move.
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
    #[serde(flatten)]
    pub metrics: &'a Metrics,
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

/// Creates `out`, checks that it takes files, and removes the outputs of an earlier run.
pub fn prepare_out(out: &Path) -> Result<()> {
    std::fs::create_dir_all(out).with_context(|| format!("creating --out {}", out.display()))?;
    let probe = out.join(format!(".write-probe-{}", std::process::id()));
    File::create(&probe)
        .and_then(|_| std::fs::remove_file(&probe))
        .with_context(|| format!("--out {} is not writable", out.display()))?;
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

/// Refuses a run whose samples (`channels` wide) and their metrics would take more than
/// [`MEMORY_SHARE`] of the available memory, naming the estimate and the keys that set it.
fn check_memory(scenario: &Scenario, channels: usize) -> Result<()> {
    let sim = &scenario.simulation;
    let samples = (sim.t_final / sim.sample_period).round() + 1.0;
    let bytes = memory_estimate(samples, channels);
    if let Some(available) = available_memory()
        && bytes > MEMORY_SHARE * available
    {
        bail!(
            "the run and its metrics need about {:.1} GB ({samples:e} samples of {channels} \
             channels, their columns and 16×-padded spectra), more than half of the {:.1} GB \
             available: raise simulation.sample_period (now {} s) or shorten \
             simulation.t_final (now {} s)",
            bytes / 1e9,
            available / 1e9,
            sim.sample_period,
            sim.t_final
        );
    }
    Ok(())
}

/// MemAvailable of /proc/meminfo [B], where there is one.
fn available_memory() -> Option<f64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024.0)
}

/// The time series written as the run samples it, every `every`-th row.
struct CsvStream {
    writer: BufWriter<File>,
    path: PathBuf,
    every: usize,
    rows: usize,
    error: Option<std::io::Error>,
}

impl CsvStream {
    fn create(path: PathBuf, names: &[String], every: usize) -> Result<Self> {
        let file = File::create(&path).with_context(|| format!("creating {}", path.display()))?;
        let mut writer = BufWriter::with_capacity(1 << 16, file);
        writeln!(writer, "{}", names.join(","))?;
        Ok(Self {
            writer,
            path,
            every: every.max(1),
            rows: 0,
            error: None,
        })
    }

    fn push(&mut self, row: &[f64]) {
        if self.rows.is_multiple_of(self.every) && self.error.is_none() {
            let mut line = String::with_capacity(24 * row.len());
            csv_row(&mut line, row);
            if let Err(e) = self.writer.write_all(line.as_bytes()) {
                self.error = Some(e);
            }
        }
        self.rows += 1;
    }

    /// Writes the rows the stream has not seen (those of a failing step), then renames the file
    /// into `target`.
    fn finish(mut self, rows: impl Iterator<Item = Vec<f64>>, target: &Path) -> Result<()> {
        for row in rows.skip(self.rows) {
            self.push(&row);
        }
        if let Some(e) = self.error.take() {
            return Err(e).with_context(|| format!("writing {}", self.path.display()));
        }
        let file = self.writer.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        std::fs::rename(&self.path, target)
            .with_context(|| format!("renaming into {}", target.display()))
    }
}

pub fn run(
    scenario: Option<&Path>,
    model: Option<ModelKind>,
    out: &Path,
    every: usize,
) -> Result<()> {
    let scenario = load_scenario(scenario, model)?;
    let provenance = Provenance::of(&scenario)?;
    prepare_out(out)?;
    let names = channel_names(&*cdpr_bench::build(&scenario)?);
    check_memory(&scenario, names.len())?;
    ctrlc::set_handler(|| STOP.store(true, Ordering::Relaxed))
        .context("installing the SIGINT/SIGTERM handler")?;
    let kind = model_kind(&scenario)?;

    let mut stream = CsvStream::create(out.join(PARTIAL), &names, every)?;
    let mut progress = Progress::new(kind.name());
    let result = {
        let mut on_sample = |row: &[f64]| stream.push(row);
        let mut report = |f: f64| progress.set(f);
        let mut observer = Observer {
            progress: &mut report,
            on_sample: Some(&mut on_sample),
            stop: Some(&STOP),
        };
        cdpr_bench::assess_observed(&scenario, &mut observer)
    };
    progress.finish();

    let (assessed, status, error) = match result {
        Ok(assessed) => (assessed, "complete", None),
        Err(Error::Run(failure)) => {
            let status = match failure.error {
                RunError::Interrupted { .. } => "interrupted",
                _ => "failed",
            };
            let Some(run) = failure.partial else {
                bail!("{}", failure.error);
            };
            let assessed = Assessed::partial(&scenario, kind, run);
            (assessed, status, Some(failure.error.to_string()))
        }
        Err(e) => return Err(e.into()),
    };
    let run = &assessed.run;
    let series = &run.series;
    stream.finish(
        (0..series.len()).map(|i| series.row(i).to_vec()),
        &out.join(TIMESERIES),
    )?;
    let end = assessed.end.state();
    write_json(
        &out.join(METRICS),
        &MetricsFile {
            status,
            error: error.clone(),
            t_reached: run.t_reached,
            provenance: &provenance,
            metrics: &assessed.metrics,
            vertical_mode_rad_s: end.map(|e| e.mode.omega),
            vertical_mode_growth: end.map(|e| e.mode.growth),
            modal_analysis: assessed.end.status(),
            modal_analysis_note: assessed.end.reason(),
            eq15_rad_s: cdpr_bench::eq15_at_end(&scenario),
            units: units(),
        },
    )?;
    if let EndAnalysis::Skipped { reason } | EndAnalysis::Failed { reason } = &assessed.end {
        eprintln!("note: modal analysis {}: {reason}", assessed.end.status());
    }
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
    match error {
        None => Ok(()),
        Some(e) => bail!(
            "{e}; {status} run kept up to t = {} s in {} and {}",
            run.t_reached,
            out.join(TIMESERIES).display(),
            out.join(METRICS).display()
        ),
    }
}
