//! `cargo xtask control`: the leaderboard of [`cdpr_studies::control`] written as `control.md`,
//! `control.csv` and the figures of the x and z errors and of the z spectrum, one panel per model.

use crate::figures::{self, Figure, Line, Marker, Panel};
use crate::output::write_atomic;
use anyhow::Result;
use cdpr_bench::ModelKind;
use cdpr_bench::analysis::control_metrics::SETTLE_BAND;
use cdpr_bench::core::scenario::ControllerKind;
use cdpr_studies::control::{Entry, Leaderboard, compute};
use plotters::style::RGBColor;
use std::path::Path;

/// The error and spectrum figures; returns (file stem, title) of each.
pub fn figures(board: &Leaderboard, out: &Path) -> Result<Vec<(String, String)>> {
    let panels = |f: &dyn Fn(&Entry) -> Vec<(f64, f64)>,
                  y: &str,
                  log_x: bool,
                  markers: &dyn Fn() -> Vec<Marker>| {
        ModelKind::ALL
            .into_iter()
            .map(|model| Panel {
                x_label: if log_x {
                    "ω [rad/s]".into()
                } else {
                    "t [s]".into()
                },
                y_label: format!("{} {y}", model.name()),
                log_x,
                log_y: true,
                lines: board
                    .entries
                    .iter()
                    .filter(|e| e.model == model)
                    .map(|e| Line {
                        label: e.controller.name().into(),
                        color: controller_color(e.controller),
                        dashed: false,
                        width: figures::LINE_WIDTH,
                        points: figures::envelope(&f(e)),
                    })
                    .collect(),
                markers: markers(),
            })
            .collect::<Vec<_>>()
    };
    let floor = |v: f64| v.abs().max(1e-9);
    let band = || vec![Marker::Horizontal(SETTLE_BAND, "10 µm".into())];
    let list = [
        Figure {
            name: "control_ex".into(),
            title: "|e_x| = |x_ref − x| per controller (floor 1 nm)".into(),
            panels: panels(
                &|e| e.errors.iter().map(|r| (r[0], floor(r[1]))).collect(),
                "|e_x| [m]",
                false,
                &band,
            ),
        },
        Figure {
            name: "control_ez".into(),
            title: "|e_z| = |z − z0| per controller (floor 1 nm)".into(),
            panels: panels(
                &|e| e.errors.iter().map(|r| (r[0], floor(r[2]))).collect(),
                "|e_z| [m]",
                false,
                &band,
            ),
        },
        Figure {
            name: "control_spectrum".into(),
            title: "Amplitude spectrum of z over [1, 5] s per controller".into(),
            panels: panels(
                &|e| {
                    e.z_spectrum
                        .iter()
                        .map(|&(w, a)| (w, a.max(1e-12)))
                        .collect()
                },
                "|Z| [m]",
                true,
                &Vec::new,
            ),
        },
    ];
    let mut names = Vec::new();
    for figure in &list {
        figures::render(figure, out)?;
        names.push((figure.name.clone(), figure.title.clone()));
    }
    Ok(names)
}

/// Writes control.md, control.csv and the figures into `out`; returns the figures' (stem,
/// title).
pub fn write(board: &Leaderboard, out: &Path) -> Result<Vec<(String, String)>> {
    std::fs::create_dir_all(out)?;
    let names = figures(board, out)?;
    let csv = board.csv();
    write_atomic(&out.join("control.csv"), |w| w.write_all(csv.as_bytes()))?;
    let mut md = String::from("# Vibration control: every controller on every cable model\n\n");
    md.push_str(&board.section(&names));
    write_atomic(&out.join("control.md"), |w| w.write_all(md.as_bytes()))?;
    Ok(names)
}

/// The colour of each controller in the control figures.
pub fn controller_color(kind: ControllerKind) -> RGBColor {
    match kind {
        ControllerKind::Pid => RGBColor(0, 0, 0),
        ControllerKind::PidXz => RGBColor(255, 127, 14),
        ControllerKind::ComputedTorque => RGBColor(31, 119, 180),
        ControllerKind::Lqr => RGBColor(148, 103, 189),
        ControllerKind::Length => RGBColor(44, 160, 44),
    }
}

/// `cargo xtask control --out DIR [--scenario FILE]`.
pub fn run(scenario: Option<&Path>, out: &Path) -> Result<()> {
    let base = crate::simulate::load_scenario(scenario, None)?;
    crate::simulate::writable_out(out)?;
    let board = compute(&base)?;
    write(&board, out)?;
    println!(
        "{} runs → {}",
        board.entries.len(),
        out.join("control.md").display()
    );
    Ok(())
}
