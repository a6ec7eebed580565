//! `cargo xtask work-precision`: error of the effector trajectory against a tight-tolerance
//! reference versus cost, for DOPRI5 (rtol sweep), generalised-α at a fixed step (step sweep)
//! and generalised-α under error control (tolerance sweep) on both massive-cable models → `work_precision.csv` and the figure `work_precision.{svg,png}`.
//!
//! The horizon is the transition and 50 ms of settling, [0, 0.25] s: it contains every pulley
//! event of the transition, and ends before the lumped model's first "hovering" node (≈ 0.29 s),
//! whose event time is ill-conditioned (a µm of cable vibration moves it by milliseconds, see
//! verify/tests/implicit.rs), so that beyond it no integrator converges to one reference.
//! Error: max over the 1e-4 s sample grid of |(x, z) − (x, z)_ref| [m]. Cost: right-hand-side
//! (residual) evaluations, the honest measure, and wall time (minimum of two runs, so a
//! scheduler hiccup does not count).

use crate::figures::{self, Figure, Line, Panel};
use crate::output::write_atomic;
use anyhow::{Context, Result};
use cdpr_bench::ModelKind;
use cdpr_bench::core::channel::Channel;
use cdpr_bench::core::runner::Run;
use cdpr_bench::core::scenario::{IntegratorKind, Scenario};
use std::path::Path;

/// Simulated horizon [s] and sample period [s] of the study.
const HORIZON: f64 = 0.25;
const SAMPLE_PERIOD: f64 = 1e-4;
/// DOPRI5 relative tolerances (atol = 1e-4·rtol) and generalised-α steps [s] (ρ∞ = 0.9).
const RTOLS: [f64; 5] = [1e-4, 1e-5, 1e-6, 1e-7, 1e-8];
const STEPS: [f64; 6] = [4e-4, 2e-4, 1e-4, 5e-5, 2.5e-5, 1.25e-5];
/// Error-controlled generalised-α tolerances (rtol = atol).
const TOLS: [f64; 5] = [1e-4, 1e-5, 1e-6, 1e-7, 1e-8];

/// How a point was integrated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Method {
    Dopri5,
    /// Generalised-α at a fixed step.
    FixedAlpha,
    /// Generalised-α under error control (`adaptive = true`).
    AdaptiveAlpha,
}

impl Method {
    const ALL: [Method; 3] = [Method::Dopri5, Method::FixedAlpha, Method::AdaptiveAlpha];

    /// The CSV's spelling.
    fn name(self) -> &'static str {
        match self {
            Method::Dopri5 => "dopri5",
            Method::FixedAlpha => "implicit",
            Method::AdaptiveAlpha => "implicit-adaptive",
        }
    }

    /// The figure's legend.
    fn label(self) -> &'static str {
        match self {
            Method::Dopri5 => "DOPRI5",
            Method::FixedAlpha => "generalised-α, fixed h",
            Method::AdaptiveAlpha => "generalised-α, error-controlled",
        }
    }
}
/// The reference: DOPRI5 at rtol 1e-10, atol 1e-14.
const REFERENCE_RTOL: f64 = 1e-10;

/// One point of the study.
struct Point {
    model: ModelKind,
    method: Method,
    /// rtol (DOPRI5, error-controlled generalised-α) or step [s] (fixed generalised-α).
    parameter: f64,
    error: f64,
    wall_s: f64,
    rhs_evals: u64,
    steps: u64,
    newton_iterations: u64,
    factorisations: u64,
}

fn scenario(model: ModelKind, method: Method, parameter: f64) -> Result<Scenario> {
    let mut s = Scenario::paper();
    s.model = model.into();
    s.simulation.t_final = HORIZON;
    s.simulation.sample_period = SAMPLE_PERIOD;
    let sim = &mut s.simulation;
    match method {
        Method::Dopri5 => {
            sim.rtol = parameter;
            sim.atol = 1e-4 * parameter;
        }
        Method::FixedAlpha => {
            sim.integrator = IntegratorKind::Implicit;
            sim.step = parameter;
        }
        Method::AdaptiveAlpha => {
            sim.integrator = IntegratorKind::Implicit;
            sim.adaptive = true;
            sim.rtol = parameter;
            sim.atol = parameter;
        }
    }
    cdpr_bench::validate(&s)?;
    Ok(s)
}

/// The run, the faster of two (identical: runs are deterministic) for the wall time.
fn run(s: &Scenario) -> Result<Run> {
    let first = cdpr_bench::simulate(s, &mut |_| {})?;
    let second = cdpr_bench::simulate(s, &mut |_| {})?;
    Ok(if second.wall_s < first.wall_s {
        second
    } else {
        first
    })
}

fn error(run: &Run, reference: &Run) -> Result<f64> {
    let col = |r: &Run, c: Channel| r.series.column(c).context("missing channel");
    let (x, z) = (col(run, Channel::X)?, col(run, Channel::Z)?);
    let (xr, zr) = (col(reference, Channel::X)?, col(reference, Channel::Z)?);
    Ok((0..x.len().min(xr.len()))
        .map(|i| (x[i] - xr[i]).hypot(z[i] - zr[i]))
        .fold(0.0, f64::max))
}

pub fn run_study(out: &Path) -> Result<()> {
    crate::simulate::writable_out(out)?;
    let mut points = Vec::new();
    for model in ModelKind::MASSIVE {
        points.extend(model_points(model)?);
    }
    write_csv(&out.join("work_precision.csv"), &points)?;
    write_figure(&points, out)?;
    eprintln!("→ {}", out.join("work_precision.csv").display());
    Ok(())
}

/// `model`'s reference run, then its points: DOPRI5 at each of [`RTOLS`], generalised-α at
/// each of [`STEPS`].
fn model_points(model: ModelKind) -> Result<Vec<Point>> {
    eprintln!("{model}: reference (DOPRI5, rtol {REFERENCE_RTOL:e})");
    let mut reference_scenario = scenario(model, Method::Dopri5, REFERENCE_RTOL)?;
    reference_scenario.simulation.atol = 1e-14;
    let reference = cdpr_bench::simulate(&reference_scenario, &mut |_| {})?;
    let sweeps = RTOLS
        .iter()
        .map(|&p| (Method::Dopri5, p))
        .chain(STEPS.iter().map(|&p| (Method::FixedAlpha, p)))
        .chain(TOLS.iter().map(|&p| (Method::AdaptiveAlpha, p)));
    let mut points = Vec::new();
    for (method, parameter) in sweeps {
        let r = run(&scenario(model, method, parameter)?)?;
        let point = Point {
            model,
            method,
            parameter,
            error: error(&r, &reference)?,
            wall_s: r.wall_s,
            rhs_evals: r.stats.rhs_evals,
            steps: r.stats.steps_accepted,
            newton_iterations: r.stats.newton_iterations,
            factorisations: r.stats.factorisations,
        };
        eprintln!(
            "{model} {} {parameter:e}: error {:.3e} m, {:.4} s, {} RHS",
            point.method.name(),
            point.error,
            point.wall_s,
            point.rhs_evals
        );
        points.push(point);
    }
    Ok(points)
}

fn write_csv(path: &Path, points: &[Point]) -> Result<()> {
    write_atomic(path, |w| {
        writeln!(
            w,
            "model,integrator,parameter,error_m,wall_s,rhs_evals,steps,newton_iterations,factorisations"
        )?;
        for p in points {
            writeln!(
                w,
                "{},{},{},{},{},{},{},{},{}",
                p.model,
                p.method.name(),
                p.parameter,
                p.error,
                p.wall_s,
                p.rhs_evals,
                p.steps,
                p.newton_iterations,
                p.factorisations
            )?;
        }
        Ok(())
    })?;
    Ok(())
}

/// Error against wall time and against RHS evaluations, a line per model and integrator.
fn write_figure(points: &[Point], out: &Path) -> Result<()> {
    let panel = |cost: &str, f: fn(&Point) -> f64| Panel {
        x_label: cost.into(),
        y_label: "max |effector − reference| over [0, 0.25] s [m]".into(),
        log_x: true,
        log_y: true,
        lines: ModelKind::MASSIVE
            .into_iter()
            .flat_map(|model| {
                Method::ALL.into_iter().map(move |method| Line {
                    label: format!("{model}, {}", method.label()),
                    color: figures::model_color(model),
                    dashed: method == Method::FixedAlpha,
                    width: if method == Method::AdaptiveAlpha {
                        2.0 * figures::LINE_WIDTH
                    } else {
                        figures::LINE_WIDTH
                    },
                    points: points
                        .iter()
                        .filter(|p| p.model == model && p.method == method)
                        .map(|p| (f(p), p.error.max(1e-16)))
                        .collect(),
                })
            })
            .collect(),
        markers: Vec::new(),
    };
    figures::render(
        &Figure {
            name: "work_precision".into(),
            title:
                "Work–precision over [0, 0.25] s: DOPRI5 rtol 1e-4 … 1e-8, generalised-α (ρ∞ = 0.9) h 4e-4 … 1.25e-5 s and tol 1e-4 … 1e-8 (thick)"
                    .into(),
            panels: vec![
                panel("wall time [s]", |p| p.wall_s),
                panel("right-hand-side evaluations", |p| p.rhs_evals as f64),
            ],
        },
        out,
    )?;
    Ok(())
}
