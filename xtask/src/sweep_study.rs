//! The report's parameter studies drawn: heat maps of [`cdpr_studies::sweeps`]' records.

use crate::heatmap::{HeatMap, HeatPanel};
use anyhow::Result;
use cdpr_studies::sweeps::{MASS, METRICS, MOVE, SweepStudy, axis};
use std::path::Path;

/// Writes the heat maps; returns their names.
pub fn write(study: &SweepStudy, out: &Path) -> Result<Vec<String>> {
    let first = &study.sweeps[0].grid;
    let x_labels: Vec<String> = axis(first, MOVE)
        .iter()
        .map(|t| format!("{t:.1}"))
        .collect();
    let y_labels: Vec<String> = axis(first, MASS)
        .iter()
        .map(|m| format!("{m:.2}"))
        .collect();
    let mut names = Vec::new();
    let spec = &study.spec;
    for (metric, suffix, title) in METRICS {
        let name = format!("{}_{suffix}", spec.figure_prefix);
        let mut panels = Vec::new();
        for g in spec.groups {
            for s in &study.sweeps {
                panels.push(HeatPanel {
                    title: format!("{} · {g}", s.kind.name()),
                    x_labels: x_labels.clone(),
                    y_labels: y_labels.clone(),
                    values: s.table(spec.group_key, g, metric),
                });
            }
        }
        let map = HeatMap {
            title: title.into(),
            x_name: "move end t2 [s]".into(),
            y_name: "effector mass [kg]".into(),
            value_name: "log10".into(),
            rows: spec.groups.len(),
            cols: study.sweeps.len(),
            panels,
        };
        crate::figures::render_drawing(&map, &name, out)?;
        names.push(name);
    }
    Ok(names)
}
