//! `cargo xtask shaping`: the study of [`cdpr_studies::shaping`] written as `shaping.md`,
//! `shaping.csv` and one robustness figure per model.

use crate::figures::{self, Figure, Line, Marker, Panel};
use crate::output::write_atomic;
use anyhow::Result;
use cdpr_bench::ModelKind;
use cdpr_bench::core::shaper::ShaperKind;
use cdpr_studies::shaping::{Study, compute};
use plotters::style::RGBColor;
use std::path::Path;

/// One figure per model: residual against frequency error, simulated (solid) and V (dashed).
pub fn figures(study: &Study, out: &Path) -> Result<Vec<(String, String)>> {
    let mut names = Vec::new();
    for model in ModelKind::ALL {
        let unshaped = study.unshaped(model);
        let mut lines = Vec::new();
        for shaper in ShaperKind::ALL.into_iter().skip(1) {
            let curve = study.curve(model, shaper);
            let pct = |v: f64| (100.0 * v).max(1e-3);
            lines.push(Line {
                label: format!("{} simulated", shaper.name()),
                color: shaper_color(shaper),
                dashed: false,
                width: figures::LINE_WIDTH,
                points: curve
                    .iter()
                    .map(|p| (100.0 * p.error, pct(p.z_p2p / unshaped)))
                    .collect(),
            });
            lines.push(Line {
                label: format!("{} V(ω, ζ)", shaper.name()),
                color: shaper_color(shaper),
                dashed: true,
                width: figures::LINE_WIDTH,
                points: curve
                    .iter()
                    .map(|p| (100.0 * p.error, pct(p.analytic)))
                    .collect(),
            });
        }
        let figure = Figure {
            name: format!("shaping_{}", model.name()),
            title: format!(
                "Residual vertical vibration against the shaper's frequency error, {} model",
                model.name()
            ),
            panels: vec![Panel {
                x_label: "frequency error of the shaper [%]".into(),
                y_label: "residual z p2p from 0.8 s after the move [% of unshaped]".into(),
                log_x: false,
                log_y: true,
                lines,
                markers: vec![
                    Marker::Horizontal(5.0, "5 %".into()),
                    Marker::Horizontal(10.0, "10 %".into()),
                ],
            }],
        };
        figures::render(&figure, out)?;
        names.push((figure.name, figure.title));
    }
    Ok(names)
}

/// Writes shaping.md, shaping.csv and the figures; returns the figures' (stem, title).
pub fn write(study: &Study, out: &Path) -> Result<Vec<(String, String)>> {
    std::fs::create_dir_all(out)?;
    let names = figures(study, out)?;
    let csv = study.csv();
    write_atomic(&out.join("shaping.csv"), |w| w.write_all(csv.as_bytes()))?;
    let md = format!(
        "# Input shaping with the paper's PID\n\n{}",
        study.section(&names)
    );
    write_atomic(&out.join("shaping.md"), |w| w.write_all(md.as_bytes()))?;
    Ok(names)
}

fn shaper_color(kind: ShaperKind) -> RGBColor {
    match kind {
        ShaperKind::None => RGBColor(0, 0, 0),
        ShaperKind::Zv => RGBColor(31, 119, 180),
        ShaperKind::Zvd => RGBColor(255, 127, 14),
        ShaperKind::Zvdd => RGBColor(44, 160, 44),
        ShaperKind::Mzv => RGBColor(214, 39, 40),
        ShaperKind::Ei => RGBColor(148, 103, 189),
        ShaperKind::TwoHumpEi => RGBColor(140, 86, 75),
        ShaperKind::ThreeHumpEi => RGBColor(227, 119, 194),
    }
}

/// `cargo xtask shaping --out DIR [--scenario FILE]`.
pub fn run_study(scenario: Option<&Path>, out: &Path) -> Result<()> {
    let base = crate::simulate::load_scenario(scenario, None)?;
    crate::simulate::writable_out(out)?;
    let study = compute(&base)?;
    write(&study, out)?;
    println!(
        "{} runs → {}",
        study.points.len(),
        out.join("shaping.md").display()
    );
    Ok(())
}
