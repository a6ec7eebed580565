//! `cargo xtask modes`: the modes of [`cdpr_studies::modes`] written as `modes.csv`,
//! `damping_sweep.csv`, `modes.md` and a figure of the spectrum of modes per position (frequency
//! vs damping ratio).

use crate::figures::{Drawing, model_color, power_label, render_drawing};
use crate::output::write_atomic;
use anyhow::{Result, bail};
use cdpr_bench::ModelKind;
use cdpr_bench::analysis::modes::Analysis;
use cdpr_bench::core::scenario::ControllerKind;
use cdpr_studies::modes::{ModesReport, compute};
use plotters::prelude::*;
use std::path::Path;

/// modes.csv (every mode), damping_sweep.csv and one figure per position.
pub fn write_files(report: &ModesReport, out: &Path) -> Result<()> {
    write_atomic(&out.join("modes.csv"), |w| report.write_modes_csv(w))?;
    write_atomic(&out.join("damping_sweep.csv"), |w| {
        report.write_damping_sweep_csv(w)
    })?;
    for x in report.positions() {
        spectrum_figure(&report.closed_at(x), x, out)?;
    }
    Ok(())
}

/// `cargo xtask modes`: writes modes.csv, modes.md, damping_sweep.csv and the spectrum figure(s).
pub fn run(
    scenario: Option<&Path>,
    controller: Option<ControllerKind>,
    at: Vec<f64>,
    out: &Path,
) -> Result<()> {
    let mut base = crate::simulate::load_scenario(scenario, None)?;
    if let Some(kind) = controller {
        base.controller.kind = kind;
        base.trajectory.z_ref = None;
        base.validate()?;
    }
    if base.robot.anchors.is_some() {
        return spatial(&base, &at, out);
    }
    let at = match at[..] {
        [] => None,
        [x] => Some(x),
        _ => bail!("--at {at:?}: one position x [m] for the planar robot"),
    };
    let xs = match at {
        Some(x) => vec![x],
        None => vec![base.trajectory.x1, base.trajectory.x2],
    };
    crate::simulate::writable_out(out)?;
    let report = compute(&base, &xs, at.unwrap_or(base.trajectory.x2))?;
    for note in &report.skipped {
        eprintln!("note: skipped {note}");
    }
    write_files(&report, out)?;
    write_atomic(&out.join("modes.md"), |w| {
        writeln!(w, "# Modes of the three models\n")?;
        report.write_section(w, &[])
    })?;
    println!(
        "{} analyses, {} modes → {}",
        report.analyses.len(),
        report.analyses.iter().map(|a| a.modes.len()).sum::<usize>(),
        out.join("modes.md").display()
    );
    Ok(())
}

/// ζ on a symmetric log axis: sign(ζ)·log10(1 + |ζ|/ZETA0), so that the growing modes
/// (ζ ≈ −1e-4) and the neutral string modes (|ζ| ~ 1e-9) are visible next to the PID's real
/// poles (ζ = 1).
const ZETA0: f64 = 1e-10;

fn symlog(z: f64) -> f64 {
    z.signum() * (1.0 + z.abs() / ZETA0).log10()
}

fn symlog_label(v: f64) -> String {
    let r = v.round();
    if (v - r).abs() > 1e-6 {
        return String::new();
    }
    if r == 0.0 {
        "0".into()
    } else {
        let e = r.abs() as i32 - 10;
        format!("{}1e{e}", if r < 0.0 { "−" } else { "" })
    }
}

/// Frequency |λ| (log) vs damping ratio ζ (symmetric log) of every closed-loop mode at x, one
/// colour per model; SVG and 2× PNG like the report's figures.
fn spectrum_figure(analyses: &[&Analysis], x: f64, out: &Path) -> Result<()> {
    let spectrum = ModeSpectrum {
        analyses,
        title: format!("Closed-loop modes at x = {x} m: |λ| vs damping ratio ζ (< 0: growing)"),
    };
    render_drawing(&spectrum, &format!("modes_x{x}"), out)
}

struct ModeSpectrum<'a> {
    analyses: &'a [&'a Analysis],
    title: String,
}

impl Drawing for ModeSpectrum<'_> {
    fn draw_on<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, plotters::coord::Shift>,
        scale: f64,
    ) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        draw_spectrum(root, self.analyses, &self.title, scale)
    }
}

fn draw_spectrum<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    analyses: &[&Analysis],
    title: &str,
    scale: f64,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("{e:?}");
    let px = |v: f64| (v * scale).round() as u32;
    root.fill(&WHITE).map_err(err)?;
    let font = ("sans-serif", px(14.0)).into_font();
    let (y_lo, y_hi) = (symlog(-1e-2), symlog(1.0) + 0.5);
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", px(18.0)).into_font())
        .margin(px(10.0))
        .x_label_area_size(px(45.0))
        .y_label_area_size(px(80.0))
        .build_cartesian_2d(-1.0f64..6.0, y_lo..y_hi)
        .map_err(err)?;
    let y_fmt = |v: &f64| symlog_label(*v);
    chart
        .configure_mesh()
        .x_desc("|λ| [rad/s]")
        .y_desc("ζ = −σ/|λ| (symmetric log)")
        .x_labels(8)
        .y_labels(((y_hi - y_lo).ceil() as usize) + 1)
        .x_label_formatter(&power_label)
        .y_label_formatter(&y_fmt)
        .label_style(font.clone())
        .axis_desc_style(font.clone())
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(err)?;
    chart
        .draw_series(LineSeries::new(
            vec![(-1.0, 0.0), (6.0, 0.0)],
            RGBColor(110, 110, 110).stroke_width(px(1.0)),
        ))
        .map_err(err)?;
    for a in analyses {
        let kind: ModelKind = a.model.parse()?;
        let color = model_color(kind);
        let points: Vec<(f64, f64)> = a
            .modes
            .iter()
            .map(|m| {
                let magnitude = m.mode.growth.hypot(m.mode.omega).max(0.1);
                (magnitude.log10(), symlog(m.mode.damping_ratio()))
            })
            .collect();
        let radius = px(3.0);
        chart
            .draw_series(
                points
                    .iter()
                    .map(|&p| Circle::new(p, radius, color.stroke_width(px(1.0)))),
            )
            .map_err(err)?
            .label(a.model)
            .legend(move |(x, y)| Circle::new((x + 10, y), 4, color.filled()));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .label_font(font)
        .background_style(WHITE.mix(0.85))
        .border_style(RGBColor(160, 160, 160))
        .draw()
        .map_err(err)?;
    Ok(())
}

/// A spatial robot's modes at `--at X,Y,Z` (default: the move's end) → modes.json, modes.md.
fn spatial(scenario: &cdpr_bench::core::scenario::Scenario, at: &[f64], out: &Path) -> Result<()> {
    let pose = match (at, scenario.trajectory.spatial_move()) {
        (&[x, y, z], _) => [x, y, z],
        ([], Ok((_, end))) => end,
        // Two cables: the paper's rule at x, the statics find the rest.
        (&[x], _)
            if scenario
                .robot
                .anchors
                .as_ref()
                .is_some_and(|a| a.len() == 2) =>
        {
            [x, 0.0, 0.0]
        }
        ([], Err(_))
            if scenario
                .robot
                .anchors
                .as_ref()
                .is_some_and(|a| a.len() == 2) =>
        {
            [scenario.trajectory.x2, 0.0, 0.0]
        }
        _ => bail!("--at {at:?}: the effector's pose X,Y,Z [m] for a spatial robot"),
    };
    crate::simulate::writable_out(out)?;
    let report = cdpr_studies::spatial_modes::at_pose(scenario, pose)?;
    crate::output::write_json(&out.join("modes.json"), &report)?;
    let table = cdpr_studies::spatial_modes::markdown(&report);
    write_atomic(&out.join("modes.md"), |w| w.write_all(table.as_bytes()))?;
    print!("{table}");
    Ok(())
}
