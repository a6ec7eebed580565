//! `cargo xtask report`: the paper scenario for every available model and the reproduction report
//! (MODELS.md §8 table). Figures arrive with the report issue; this writes the numbers.

use crate::output::{progress_bar, write_atomic, write_json};
use crate::simulate::load_scenario;
use anyhow::Result;
use cdpr_core::metrics::Metrics;
use cdpr_core::modal::Mode;
use cdpr_core::scenario::ModelKind;
use cdpr_verify::acceptance::{self, Check, ModelResult};
use std::path::Path;

#[derive(serde::Serialize)]
struct ReportFile<'a> {
    eq15_rad_s: f64,
    models: Vec<ModelEntry<'a>>,
    checks: &'a [Check],
}

#[derive(serde::Serialize)]
struct ModelEntry<'a> {
    #[serde(flatten)]
    metrics: &'a Metrics,
    vertical_mode: Mode,
}

/// A Markdown table cell: `|` (as in "max |error|") would end the cell.
fn cell(text: &str) -> String {
    text.replace('|', "\\|")
}

pub fn run(scenario: Option<&Path>, out: &Path) -> Result<()> {
    let base = load_scenario(scenario, None)?;
    std::fs::create_dir_all(out)?;
    let mut results: Vec<(ModelKind, Metrics, Mode)> = Vec::new();
    let mut skipped = Vec::new();
    for kind in [ModelKind::Elastic, ModelKind::Lumped, ModelKind::Fe] {
        let mut scenario = base.clone();
        scenario.model.kind = kind;
        let bar = progress_bar(kind.name());
        let run = cdpr_verify::simulate(&scenario, &mut |f| bar.set_position((f * 1000.0) as u64));
        bar.finish_and_clear();
        match run {
            Ok(run) => {
                let metrics = cdpr_verify::metrics(&scenario, &run);
                let mode = cdpr_verify::vertical_mode_at_end(&scenario)?;
                eprintln!("{kind}: done in {:.3} s", run.wall_s);
                results.push((kind, metrics, mode));
            }
            Err(cdpr_verify::SimulateError::ModelUnavailable(k)) => skipped.push(k),
            Err(e) => return Err(e.into()),
        }
    }
    let eq15 = cdpr_verify::eq15_at_end(&base);
    let views: Vec<ModelResult> = results
        .iter()
        .map(|(kind, metrics, mode)| ModelResult {
            kind: *kind,
            metrics,
            vertical_mode: mode.omega,
        })
        .collect();
    let mut checks: Vec<Check> = views.iter().flat_map(acceptance::model_checks).collect();
    checks.extend(acceptance::scenario_checks(eq15, &views));
    write_json(
        &out.join("metrics.json"),
        &ReportFile {
            eq15_rad_s: eq15,
            models: results
                .iter()
                .map(|(_, metrics, mode)| ModelEntry {
                    metrics,
                    vertical_mode: *mode,
                })
                .collect(),
            checks: &checks,
        },
    )?;
    write_atomic(&out.join("REPORT.md"), |w| {
        writeln!(w, "# cdpr-bench reproduction report\n")?;
        writeln!(
            w,
            "Paper scenario (MODELS.md §1), DOPRI5 rtol {:e}, atol {:e}, samples every {:e} s.\n",
            base.simulation.rtol, base.simulation.atol, base.simulation.sample_period
        )?;
        if !skipped.is_empty() {
            let names: Vec<&str> = skipped.iter().map(|k| k.name()).collect();
            writeln!(w, "Models not implemented yet: {}.\n", names.join(", "))?;
        }
        writeln!(w, "## MODELS.md §8: the paper's results\n")?;
        writeln!(w, "| quantity | model | paper | ours | accept | pass |")?;
        writeln!(w, "|---|---|---|---|---|---|")?;
        for c in &checks {
            let mark = if c.pass { "✅" } else { "❌" };
            let cells = [&c.quantity, &c.model, &c.paper, &c.ours, &c.accept].map(|s| cell(s));
            writeln!(w, "| {} | {mark} |", cells.join(" | "))?;
        }
        writeln!(w, "\n## Solver statistics\n")?;
        writeln!(w, "| model | RHS evaluations | accepted | rejected |")?;
        writeln!(w, "|---|---|---|---|")?;
        for (kind, m, _) in &results {
            writeln!(
                w,
                "| {kind} | {} | {} | {} |",
                m.rhs_evals, m.steps_accepted, m.steps_rejected
            )?;
        }
        Ok(())
    })?;
    let failed = checks.iter().filter(|c| !c.pass).count();
    println!(
        "{} checks, {} failed → {}",
        checks.len(),
        failed,
        out.join("REPORT.md").display()
    );
    Ok(())
}
