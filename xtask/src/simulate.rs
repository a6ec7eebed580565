//! `cargo xtask simulate`: one scenario → `timeseries.csv` and `metrics.json`.

use crate::output::{progress_bar, write_csv, write_json};
use anyhow::{Context, Result, bail};
use cdpr_bench::analysis::metrics::Metrics;
use cdpr_bench::core::scenario::Scenario;
use cdpr_bench::{Error, ModelConfig, ModelKind};
use std::path::Path;

/// `metrics.json`: the §7 metrics at the top level plus the frequencies they are judged against.
#[derive(serde::Serialize)]
pub struct MetricsFile<'a> {
    #[serde(flatten)]
    pub metrics: &'a Metrics,
    /// Closed-loop vertical eigenfrequency at the x2 equilibrium [rad/s].
    pub vertical_mode_rad_s: f64,
    /// Its growth rate [1/s] (negative: damped).
    pub vertical_mode_growth: f64,
    /// Paper eq. 15 at x2 [rad/s].
    pub eq15_rad_s: f64,
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

pub fn run(
    scenario: Option<&Path>,
    model: Option<ModelKind>,
    out: &Path,
    every: usize,
) -> Result<()> {
    let scenario = load_scenario(scenario, model)?;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let bar = progress_bar(model_kind(&scenario)?.name());
    let result = cdpr_bench::assess(&scenario, &mut |f| bar.set_position((f * 1000.0) as u64));
    bar.finish_and_clear();
    let assessed = match result {
        Ok(assessed) => assessed,
        Err(Error::Run(failure)) => {
            if let Some(partial) = &failure.partial {
                write_csv(&out.join("timeseries.csv"), &partial.series, every)?;
            }
            bail!(
                "{failure}; partial time series in {}",
                out.join("timeseries.csv").display()
            );
        }
        Err(e) => return Err(e.into()),
    };
    let (run, metrics, mode) = (&assessed.run, &assessed.metrics, assessed.end.mode);
    write_csv(&out.join("timeseries.csv"), &run.series, every)?;
    write_json(
        &out.join("metrics.json"),
        &MetricsFile {
            metrics,
            vertical_mode_rad_s: mode.omega,
            vertical_mode_growth: mode.growth,
            eq15_rad_s: cdpr_bench::eq15_at_end(&scenario),
        },
    )?;
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
    Ok(())
}
