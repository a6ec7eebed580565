//! A print through a simulated printer: the slicer's G-code read and planned as the firmware
//! does ([`cdpr_printing`]), the plan (the chosen layers) placed in the robot's frame and
//! shaped per axis ([`PrintPath`]), checked for wrench feasibility, run through the robot's
//! cable model and controller, and measured by its contour error ([`ContourMetrics`]).

use crate::config::ModelConfig;
use crate::kind::ModelKind;
use crate::spatial::{SpatialVisitor, check_feasible, lumped_model, run_robot, with_spatial_model};
use crate::study::Error;
use cdpr_analysis::contour::ContourMetrics;
pub use cdpr_analysis::spatial::positions;
use cdpr_core::closed_loop::{ClosedLoop, Path};
use cdpr_core::model::CableModel;
use cdpr_core::print_path::{AxisShaper, PrintPath};
use cdpr_core::runner::{Observer, Run, RunOptions, simulate_observed_reusing};
use cdpr_core::scenario::{Designed, Printer, Scenario, out_of_range};
use cdpr_core::series::SeriesBuffer;
use cdpr_printing::gcode::{self, Program};
use cdpr_printing::planner::{self, Plan};
use cdpr_printing::shaper::pulses;
use std::ops::RangeInclusive;
use std::sync::Arc;

/// Time the loop runs on after the shaped reference has come to rest [s]: the ringing a
/// print leaves once it stops.
pub const SETTLE: f64 = 0.2;

/// Reference instants per second checked for wrench feasibility (every millisecond: a
/// segment of the plan lasts ≥ 2 ms at 10 000 mm/s² and 0.3 m/s).
pub const FEASIBILITY_RATE: f64 = 1000.0;

/// A print ready to run: the firmware's plan of the chosen layers and the robot's reference.
#[derive(Debug, Clone)]
pub struct PreparedPrint {
    /// The file as read (skipped commands listed).
    pub program: Program,
    /// The layers printed.
    pub layers: RangeInclusive<usize>,
    /// The reference: the layers' part of the plan, in the robot's frame, shaped.
    pub path: Arc<PrintPath<3>>,
}

/// A print's run and its metrics.
pub struct PrintRun {
    pub run: Run,
    pub contour: ContourMetrics,
}

/// Reads, plans and places `gcode` on the scenario's spatial robot (`[printer]`, or Klipper's
/// defaults), the layers `layers` (all: `None`), and checks the reference's feasibility.
pub fn prepare_print(
    scenario: &Scenario,
    gcode_text: &str,
    layers: Option<RangeInclusive<usize>>,
) -> Result<PreparedPrint, Error> {
    let (robot, kind) = run_robot(scenario)?;
    let printer = scenario.printer.clone().unwrap_or_default();
    let (program, layers, selected) = plan_layers(scenario, gcode_text, layers)?;
    let shapers = axis_shapers(&printer)?;
    let path = PrintPath::new(Arc::new(selected), printer.origin3(), shapers)
        .expect("a selection has segments");
    let rate = FEASIBILITY_RATE;
    let n = (path.duration() * rate).ceil() as usize;
    check_feasible(scenario, &robot, (0..=n).map(|k| k as f64 / rate), |t| {
        let [p, _, a] = path.reference(t, true);
        (p, a)
    })?;
    if kind == ModelKind::Lumped {
        // Lumped lines must reach every pose of the path from their reels.
        let poses: Vec<_> = (0..=n)
            .map(|k| path.reference(k as f64 / rate, false)[0])
            .collect();
        let t_max = scenario.controller.t_max.unwrap_or(0.0);
        lumped_model(scenario, &ModelConfig::from_scenario(scenario)?)?
            .check_poses(&poses, t_max)?;
    }
    Ok(PreparedPrint {
        program,
        layers,
        path: Arc::new(path),
    })
}

/// The file read and planned under the scenario's `[printer]`, and the plan's part that prints
/// `layers` (all: `None`) — refused when those layers do not move.
pub fn plan_layers(
    scenario: &Scenario,
    gcode_text: &str,
    layers: Option<RangeInclusive<usize>>,
) -> Result<(Program, RangeInclusive<usize>, Plan), Error> {
    let printer = scenario.printer.clone().unwrap_or_default();
    let program = gcode::read(gcode_text, gcode_home(scenario))?;
    let plan = planner::plan(&program, &printer.limits())?;
    let layers = layers.unwrap_or(0..=program.layers);
    let selected = plan.select_layers(layers.clone()).ok_or_else(|| {
        out_of_range(
            "--layers",
            format!("{}..{}", layers.start(), layers.end()),
            format!("layers with moves among 0..{}", program.layers),
        )
    })?;
    Ok((program, layers, selected))
}

/// Where G28 brings the effector, the robot's start pose (`[trajectory] start`, else the
/// origin), in the file's millimetres.
pub fn gcode_home(scenario: &Scenario) -> [f64; 3] {
    let origin = scenario.printer.clone().unwrap_or_default().origin3();
    let start = scenario
        .trajectory
        .start
        .as_deref()
        .map_or([0.0; 3], |s| [s[0], s[1], s[2]]);
    [0, 1, 2].map(|k| (start[k] - origin[k]) * 1e3)
}

/// The firmware's shaper of each axis (None when `[printer] shaper = "none"`).
fn axis_shapers(printer: &Printer) -> Result<[Option<AxisShaper>; 3], Error> {
    let Some(shaper) = printer.shaper.pulses_of() else {
        return Ok([None, None, None]);
    };
    let axis = |key: &'static str, f: Designed| -> Result<Option<AxisShaper>, Error> {
        match f {
            Designed::Value(0.0) => Ok(None),
            Designed::Value(hz) => {
                let (a, t) = pulses(shaper, hz, printer.damping_ratio);
                Ok(Some(AxisShaper::from_pulses(&a, &t)))
            }
            Designed::Auto(_) => Err(out_of_range(
                key,
                "\"auto\"",
                "a frequency [Hz] (`cargo xtask modes --at X,Y,Z` gives the robot's modes at \
                 the layer's centre)",
            )
            .into()),
        }
    };
    Ok([
        axis("printer.shaper_freq_x", printer.shaper_freq_x)?,
        axis("printer.shaper_freq_y", printer.shaper_freq_y)?,
        axis("printer.shaper_freq_z", printer.shaper_freq_z)?,
    ])
}

/// The run's options: the scenario's integrator and sampling, to the print's end and
/// [`SETTLE`] after.
pub fn print_options(scenario: &Scenario, print: &PreparedPrint) -> RunOptions {
    RunOptions {
        t_final: print.path.duration() + SETTLE,
        ..RunOptions::from(scenario)
    }
}

/// Runs the print, watched and steered by `observer`, and measures it.
pub fn simulate_print(
    scenario: &Scenario,
    print: &PreparedPrint,
    observer: &mut Observer,
) -> Result<PrintRun, Error> {
    struct Print<'s, 'o, 'p> {
        scenario: &'s Scenario,
        print: &'s PreparedPrint,
        observer: &'o mut Observer<'p>,
    }
    impl SpatialVisitor for Print<'_, '_, '_> {
        type Output = PrintRun;
        fn visit<M: CableModel<3>>(self, model: M) -> Result<PrintRun, Error> {
            let mut sys = ClosedLoop::new(model, self.scenario)?;
            sys.path = Some(Path::Print(self.print.path.clone()));
            let options = print_options(self.scenario, self.print);
            let buffer = SeriesBuffer::default();
            let run = simulate_observed_reusing(&mut sys, &options, buffer, self.observer)?;
            let contour = contour_of(self.print, &run);
            Ok(PrintRun { run, contour })
        }
    }
    with_spatial_model(
        scenario,
        Print {
            scenario,
            print,
            observer,
        },
    )
}

/// The contour metrics of `run` (or of the part a failed run sampled).
pub fn contour_of(print: &PreparedPrint, run: &Run) -> ContourMetrics {
    ContourMetrics::of(&print.path, positions(run), print.layers.clone())
}
