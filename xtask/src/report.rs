//! `cargo xtask report`: the paper scenario with every available model (in parallel), the paper's
//! figures as SVG and PNG, `REPORT.md` with the paper's numbers next to ours, and `metrics.json`.
//!
//! Every number in the report is reproducible bit for bit except the wall times, which are kept
//! in their own table.

use crate::figures::{self, Curve, Figure, Line, Marker, Panel};
use crate::output::{write_atomic, write_json};
use crate::simulate::load_scenario;
use anyhow::{Result, bail};
use cdpr_bench::Assessed as Outcome;
use cdpr_bench::ModelKind;
use cdpr_bench::analysis::linearise::EndState;
use cdpr_bench::analysis::metrics::{Metrics, Windows};
use cdpr_bench::core::channel::Channel;
use cdpr_bench::core::runner::Run;
use cdpr_bench::core::scenario::Scenario;
use cdpr_bench::core::trajectory::Step5;
use cdpr_bench::numerics::eigen::Mode;
use cdpr_studies::paper::PaperRuns;
use cdpr_studies::paper_report::{self, ReportInputs};
use cdpr_verify::acceptance::Check;
use indicatif::{MultiProgress, ProgressBar, ProgressStyle};
use plotters::style::RGBColor;
use std::io::IsTerminal;
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
    x2_effector_z: f64,
    x2_force: f64,
}

fn bars(kinds: &[ModelKind]) -> (MultiProgress, Vec<ProgressBar>) {
    let multi = MultiProgress::new();
    let visible = std::io::stderr().is_terminal();
    let bars = kinds
        .iter()
        .map(|k| {
            if !visible {
                return ProgressBar::hidden();
            }
            let bar = multi.add(ProgressBar::new(1000));
            bar.set_style(
                ProgressStyle::with_template(
                    "{prefix:>8} [{bar:40}] {percent:>3}% {elapsed_precise}",
                )
                .expect("static template")
                .progress_chars("=> "),
            );
            bar.set_prefix(k.name());
            bar
        })
        .collect();
    (multi, bars)
}

pub fn run(scenario: Option<&Path>, out: &Path) -> Result<()> {
    let base = load_scenario(scenario, None)?;
    crate::simulate::writable_out(out)?;
    let (_multi, bars) = bars(&ModelKind::ALL);
    let paper =
        cdpr_studies::paper::compute(&base, &|k, f| bars[k].set_position((f * 1000.0) as u64))?;
    for bar in &bars {
        bar.finish();
    }
    let PaperRuns {
        outcomes,
        ends,
        eq15_rad_s: eq15,
        checks,
    } = paper;

    let names = write_figures(&base, &outcomes, eq15, out)?;
    // Every model's modes at x1 and x2 and the axial-damping sweep (~1 s).
    let (x1, x2) = (base.trajectory.x1, base.trajectory.x2);
    let modes = cdpr_studies::modes::compute(&base, &[x1, x2], x2)?;
    crate::modes::write_files(&modes, out)?;
    let control_section = beyond_the_paper(&base, out)?;
    write_json(
        &out.join("metrics.json"),
        &ReportFile {
            eq15_rad_s: eq15,
            models: outcomes
                .iter()
                .zip(&ends)
                .map(|(o, end)| ModelEntry {
                    metrics: &o.metrics,
                    vertical_mode: end.mode,
                    x2_effector_z: end.effector_height(),
                    x2_force: end.equilibrium.force(),
                })
                .collect(),
            checks: &checks,
        },
    )?;
    write_markdown(
        &base,
        &outcomes,
        &ends,
        &checks,
        eq15,
        &names,
        &modes,
        &control_section,
        out,
    )?;
    let failed = checks.iter().filter(|c| !c.pass).count();
    println!(
        "{} models, {} checks, {} failed → {}",
        outcomes.len(),
        checks.len(),
        failed,
        out.join("REPORT.md").display()
    );
    if failed > 0 {
        bail!(
            "{failed} of {} MODELS.md §8 checks failed (see {})",
            checks.len(),
            out.join("REPORT.md").display()
        );
    }
    Ok(())
}

/// The studies beyond the paper, their files into `out`: every controller on every model, every
/// input shaper with the paper's PID, the parameter studies and the printing frontier. Returns
/// their sections of REPORT.md.
fn beyond_the_paper(base: &Scenario, out: &Path) -> Result<String> {
    // Every controller on every model (the leaderboard, ~2 s on two cores).
    let control = cdpr_studies::control::compute(base)?;
    let control_figures = crate::control::write(&control, out)?;
    // Every input shaper on every model with the paper's PID (~40 s on two cores).
    let shaping = cdpr_studies::shaping::compute(base)?;
    let shaping_figures = crate::shaping::write(&shaping, out)?;
    // The mass × move-time parameter studies on every model: controllers (150 points) and
    // shapers (225 points), ~45 s on two cores.
    let mut study_section = String::from(
        "## Parameter studies\n\nBeyond the paper: the paper's move x 0.5 → 0.6 m with effector mass \
         0.25–4 kg (log) × move end t2 0.1–0.5 s on each cable model, samples every 0.1 ms.\n\n",
    );
    for spec in cdpr_studies::sweeps::STUDIES {
        let study = cdpr_studies::sweeps::compute(spec, base, out)?;
        let figures = crate::sweep_study::write(&study, out)?;
        study_section.push_str(&study.section(&figures));
    }
    study_section.push_str(&printing_section(out)?);
    // What the lines' mass does to the Hangprinter-like and CoGiRo-like printers (~15 s on two
    // cores).
    study_section.push_str(&crate::spatial_report::run(out, SPATIAL_POINTS)?);
    Ok(format!(
        "{}\n## Input shaping with the paper's PID\n\nBeyond the paper (`cargo xtask shaping`; shaping.csv has \
         every run).\n\n{}\n{}",
        control.section(&control_figures),
        shaping.section(&shaping_figures),
        study_section
    ))
}

/// Targets per axis of the spatial section's build-volume grids.
const SPATIAL_POINTS: usize = 5;

/// The printer's speed–accuracy frontier (160 prints of two first layers on elastic cables, ~30
/// s on two cores; the cube at 3 000 mm/s² on the massive lines, 20 prints of seconds each):
/// its files into `out`, its section of REPORT.md returned.
fn printing_section(out: &Path) -> Result<String> {
    let printing = cdpr_studies::print_study::run(
        &crate::print_study::printer_scenario()?,
        &crate::print_study::parts()?,
        &[3000.0],
    )?;
    crate::print_study::write(&printing, out)?;
    Ok(printing.section("print-frontier"))
}

fn curves(outcomes: &[Outcome]) -> Vec<Curve<'_>> {
    outcomes
        .iter()
        .map(|o| Curve {
            label: o.kind.name(),
            color: figures::model_color(o.kind),
            width: figures::model_width(o.kind),
            run: &o.run,
        })
        .collect()
}

fn lines(curves: &[Curve], f: impl Fn(&Run) -> Vec<(f64, f64)>) -> Vec<Line> {
    curves
        .iter()
        .map(|c| Line {
            label: c.label.to_owned(),
            color: c.color,
            dashed: false,
            width: c.width,
            points: f(c.run),
        })
        .collect()
}

/// Draws every figure; returns (file stem, caption) in report order.
fn write_figures(
    base: &Scenario,
    outcomes: &[Outcome],
    eq15: f64,
    out: &Path,
) -> Result<Vec<(String, String)>> {
    let c = curves(outcomes);
    let t_end = base.simulation.t_final;
    let step5 = Step5::from(&base.trajectory);
    let settled_from = Windows::new(step5.t1, step5.t2, t_end).settled_start();
    let figures_out = [
        fig5_position(&c, outcomes, t_end),
        fig6_error(&c, t_end),
        fig7_spectrum(&c, settled_from, base.simulation.sample_period, eq15),
        fig8_tensions(&c, base.trajectory.t2, t_end),
        step5_reference(&step5),
    ];
    let mut names = Vec::new();
    for f in &figures_out {
        figures::render(f, out)?;
        names.push((f.name.clone(), f.title.clone()));
    }
    Ok(names)
}

/// A panel on a linear time axis (log y where asked).
fn panel(x: &str, y: &str, lines: Vec<Line>, markers: Vec<Marker>, log_y: bool) -> Panel {
    Panel {
        x_label: x.into(),
        y_label: y.into(),
        log_x: false,
        log_y,
        lines,
        markers,
    }
}

const BLACK: RGBColor = RGBColor(0, 0, 0);

/// Fig. 5: x (with the reference) and z of every model.
fn fig5_position(c: &[Curve], outcomes: &[Outcome], t_end: f64) -> Figure {
    let mut x_lines = lines(c, |r| figures::channel(r, Channel::X, 0.0, t_end, 1.0));
    if let Some(first) = outcomes.first() {
        x_lines.push(Line {
            label: "x_ref (step5)".into(),
            color: BLACK,
            dashed: true,
            width: figures::LINE_WIDTH,
            points: figures::channel(&first.run, Channel::XRef, 0.0, t_end, 1.0),
        });
    }
    Figure {
        name: "fig5_position".into(),
        title: "Fig. 5: effector position x and z".into(),
        panels: vec![
            panel("t [s]", "x [m]", x_lines, vec![], false),
            panel(
                "t [s]",
                "z [mm]",
                lines(c, |r| figures::channel(r, Channel::Z, 0.0, t_end, 1e3)),
                vec![],
                false,
            ),
        ],
    }
}

/// Fig. 6: the error, linear and on a log scale against the paper's 1e-5 m after 1 s.
fn fig6_error(c: &[Curve], t_end: f64) -> Figure {
    Figure {
        name: "fig6_error".into(),
        title: "Fig. 6: position error x_ref − x".into(),
        panels: vec![
            panel(
                "t [s]",
                "error [mm]",
                lines(c, |r| figures::channel(r, Channel::Error, 0.0, t_end, 1e3)),
                vec![],
                false,
            ),
            panel(
                "t [s]",
                "|error| [m]",
                lines(c, |r| figures::channel(r, Channel::Error, 0.0, t_end, 1.0)),
                vec![
                    Marker::Horizontal(1e-5, "1e-5 m (paper: after 1 s)".into()),
                    Marker::Vertical(1.0, "t = 1 s".into()),
                ],
                true,
            ),
        ],
    }
}

/// Fig. 7: amplitude spectra of the error and of z over the settled window, eq. 15 marked.
fn fig7_spectrum(c: &[Curve], settled_from: f64, dt: f64, eq15: f64) -> Figure {
    let spectrum_panel = |channel: Channel, label: &str| Panel {
        x_label: "ω [rad/s]".into(),
        y_label: label.into(),
        log_x: true,
        log_y: true,
        lines: lines(c, |r| {
            figures::spectrum(r, channel, settled_from, dt, (1.0, 2.0e5))
        }),
        markers: vec![Marker::Vertical(eq15, format!("eq. 15: {eq15:.2} rad/s"))],
    };
    Figure {
        name: "fig7_spectrum".into(),
        title: "Fig. 7: amplitude spectra over [1, 5] s (Hann window, 16× zero padding)".into(),
        panels: vec![
            spectrum_panel(Channel::Error, "|error| amplitude [m]"),
            spectrum_panel(Channel::Z, "|z| amplitude [m]"),
        ],
    }
}

/// Fig. 8: T1 (solid) and T2 (dashed) in the transition and settling, the paper's values marked.
fn fig8_tensions(c: &[Curve], t2: f64, t_end: f64) -> Figure {
    let tensions = |t0: f64, t1: f64| {
        let mut v = lines(c, |r| figures::channel(r, Channel::T1, t0, t1, 1.0));
        for (line, curve) in v.iter_mut().zip(c) {
            line.label = format!("T1 {}", curve.label);
        }
        let mut t2_lines = lines(c, |r| figures::channel(r, Channel::T2, t0, t1, 1.0));
        for (line, curve) in t2_lines.iter_mut().zip(c) {
            line.label = format!("T2 {}", curve.label);
            line.dashed = true;
        }
        v.extend(t2_lines);
        v
    };
    Figure {
        name: "fig8_tensions".into(),
        title: "Fig. 8: commanded cable tensions (T1 solid, T2 dashed)".into(),
        panels: vec![
            panel(
                "t [s]",
                "tension [N] (transition)",
                tensions(0.0, (2.0 * t2).min(t_end)),
                vec![],
                false,
            ),
            panel(
                "t [s]",
                "tension [N] (settling)",
                tensions(1.0_f64.min(t_end), t_end),
                vec![
                    Marker::Horizontal(99.95, "paper: 99.95 N".into()),
                    Marker::Horizontal(100.05, "paper: 100.05 N".into()),
                ],
                false,
            ),
        ],
    }
}

/// The step5 reference with its analytic maximum speed and acceleration.
fn step5_reference(step5: &Step5) -> Figure {
    let [xs, vs, accs] = figures::step5_lines(step5);
    let [ta, tb] = step5.max_acceleration_times();
    let reference = |label: &str, points| {
        vec![Line {
            label: label.into(),
            color: BLACK,
            dashed: false,
            width: figures::LINE_WIDTH,
            points,
        }]
    };
    Figure {
        name: "step5_reference".into(),
        title: "step5 reference (eq. 13) with its analytic maxima".into(),
        panels: vec![
            panel("t [s]", "x_ref [m]", reference("x_ref", xs), vec![], false),
            panel(
                "t [s]",
                "v_ref [m/s]",
                reference("v_ref", vs),
                vec![Marker::Horizontal(
                    step5.max_speed(),
                    format!("v_max = {:.4} m/s", step5.max_speed()),
                )],
                false,
            ),
            panel(
                "t [s]",
                "a_ref [m/s²]",
                reference("a_ref", accs),
                vec![
                    Marker::Horizontal(
                        step5.max_acceleration(),
                        format!("±{:.3} m/s²", step5.max_acceleration()),
                    ),
                    Marker::Horizontal(-step5.max_acceleration(), String::new()),
                    Marker::Vertical(ta, format!("{ta:.4} s")),
                    Marker::Vertical(tb, format!("{tb:.4} s")),
                ],
                false,
            ),
        ],
    }
}

/// The git revision of the project this binary was built from (wherever it runs), marked when
/// tracked files other than the report's own output differ.
fn git_revision(out: &Path) -> String {
    match cdpr_bench::project_revision(Some(out)) {
        Some((head, true)) => format!("{head} (with uncommitted changes)"),
        Some((head, false)) => head,
        None => "unknown (not a git checkout)".into(),
    }
}

fn rustc_version() -> String {
    std::process::Command::new("rustc")
        .arg("--version")
        .output()
        .ok()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_owned())
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "unknown".into())
}

#[allow(clippy::too_many_arguments)]
fn write_markdown(
    base: &Scenario,
    outcomes: &[Outcome],
    ends: &[EndState],
    checks: &[Check],
    eq15: f64,
    figures: &[(String, String)],
    modes: &cdpr_studies::modes::ModesReport,
    control: &str,
    out: &Path,
) -> Result<()> {
    let software = [
        format!(
            "cdpr-bench {} at git revision {}",
            env!("CARGO_PKG_VERSION"),
            git_revision(out)
        ),
        rustc_version(),
    ];
    let inputs = ReportInputs {
        base,
        outcomes,
        ends,
        checks,
        eq15,
        figures,
        modes,
        control,
        software: &software,
    };
    write_atomic(&out.join("REPORT.md"), |w| paper_report::write(w, &inputs))
}
