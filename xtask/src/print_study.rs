//! `cargo xtask print-study`: the printer's speed–accuracy frontier
//! ([`cdpr_studies::print_study`]) → DIR/print-study.json, DIR/print-study.md and
//! DIR/print-frontier.svg|png (contour error against print time, every setup unshaped and
//! best-shaped, one panel per part, elastic cables); the cube on the massive lines at every
//! acceleration (80 prints of seconds each: minutes, where the report takes 3 000 mm/s² only).

use crate::figures::{Figure, LINE_WIDTH, Line, Marker, Panel, render};
use crate::output::{write_atomic, write_json};
use crate::simulate::writable_out;
use anyhow::{Context, Result};
use cdpr_bench::ModelKind;
use cdpr_bench::core::scenario::Scenario;
use cdpr_studies::print_study::{self, ACCELERATIONS, GOOD_CONTOUR, Part, PrintStudy, SETUPS};
use plotters::prelude::RGBColor;
use std::path::{Path, PathBuf};

/// The printing robot of the study.
pub fn printer_scenario() -> Result<Scenario> {
    let path = root().join("examples/printing/hangprinter.toml");
    cdpr_bench::scenario_from_file(&path).with_context(|| format!("reading {}", path.display()))
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The first layers of the sliced cube and cylinder (verify/data/print).
pub fn parts() -> Result<Vec<Part>> {
    ["cube", "cylinder"]
        .into_iter()
        .map(|name| {
            let path = root().join(format!("verify/data/print/{name}.gcode"));
            let gcode = std::fs::read_to_string(&path)
                .with_context(|| format!("reading {}", path.display()))?;
            Ok(Part {
                name: format!("20 mm {name}, first layer"),
                gcode,
                layers: 1..=1,
            })
        })
        .collect()
}

/// Runs the study into `out`.
pub fn run(out: &Path) -> Result<()> {
    writable_out(out)?;
    let study = print_study::run(&printer_scenario()?, &parts()?, &ACCELERATIONS)?;
    write(&study, out)?;
    print!("{}", study.markdown());
    Ok(())
}

/// The study's files.
pub fn write(study: &PrintStudy, out: &Path) -> Result<()> {
    write_json(&out.join("print-study.json"), study)?;
    let md = study.markdown();
    write_atomic(&out.join("print-study.md"), |w| w.write_all(md.as_bytes()))?;
    render(&frontier(study), out)
}

const SETUP_COLORS: [RGBColor; 5] = [
    RGBColor(127, 127, 127),
    RGBColor(31, 119, 180),
    RGBColor(148, 103, 189),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
];

/// Contour error [µm] against print time [s], per part.
fn frontier(study: &PrintStudy) -> Figure {
    let mut parts: Vec<&str> = study
        .rows
        .iter()
        .filter(|r| r.model == ModelKind::Elastic.name())
        .map(|r| r.part.as_str())
        .collect();
    parts.dedup();
    let panels = parts
        .into_iter()
        .map(|part| {
            let mut lines = Vec::new();
            for (setup, color) in SETUPS.iter().zip(SETUP_COLORS) {
                for (shaped, dashed) in [(false, true), (true, false)] {
                    let points = ACCELERATIONS
                        .iter()
                        .filter_map(|&a| {
                            study.pair(ModelKind::Elastic.name(), part, setup.label, a)
                        })
                        .map(|(u, b)| {
                            let r = if shaped { b } else { u };
                            (r.print_time_s, r.contour_err_max_printing * 1e6)
                        })
                        .collect();
                    lines.push(Line {
                        label: format!(
                            "{}, {}",
                            setup.label,
                            if shaped { "best shaper" } else { "unshaped" }
                        ),
                        color,
                        dashed,
                        width: LINE_WIDTH,
                        points,
                    });
                }
            }
            Panel {
                x_label: format!(
                    "{part}: print time [s] (accelerations {:?} mm/s²)",
                    ACCELERATIONS
                ),
                y_label: "printing moves: contour error max [µm]".into(),
                log_x: false,
                log_y: true,
                lines,
                markers: vec![Marker::Horizontal(
                    GOOD_CONTOUR * 1e6,
                    format!("{:.0} µm", GOOD_CONTOUR * 1e6),
                )],
            }
        })
        .collect();
    Figure {
        name: "print-frontier".into(),
        title: "Hangprinter-like printer, elastic cables: contour error against print time".into(),
        panels,
    }
}
