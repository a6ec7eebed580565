//! `cargo xtask`: the cdpr-bench command line.
//!
//! - `simulate`: one scenario → `timeseries.csv` and `metrics.json`;
//! - `report`: the paper scenario for every available model → `REPORT.md` and `metrics.json`;
//! - `work-precision`: error vs cost of DOPRI5 and generalised-α on the massive-cable models;
//! - `modes`: closed- and open-loop modes of every model and the axial-damping sweep;
//! - `control`: every controller on every model on the paper's move → the leaderboard;
//! - `shaping`: every input shaper on every model with the paper's PID → residuals and robustness;
//! - `statics-sweep`: the static equilibrium over a grid of starts, counting failures;
//! - `spatial`: what the lines' mass does to the Hangprinter-like and CoGiRo-like printers.
//!
//! Errors are printed for a person and give a non-zero exit; a failed run keeps its output.

mod control;
mod cost;
mod csv_stream;
mod distribution;
mod figures;
mod flex_error;
mod heatmap;
mod modes;
mod output;
mod print;
mod print_figures;
mod print_study;
mod report;
mod robot_picture;
mod shaping;
mod simulate;
mod simulate_spatial;
mod spatial_figures;
mod spatial_moves;
mod spatial_report;
mod statics_sweep;
mod sweep;
mod sweep_study;
mod work_precision;

use cdpr_bench::ModelKind;
use cdpr_bench::core::scenario::ControllerKind;
use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "cargo xtask",
    version,
    about = "cdpr-bench: cable-driven parallel robot benchmark"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run one scenario and write DIR/timeseries.csv and DIR/metrics.json.
    Simulate {
        /// Scenario file (TOML, MODELS.md §9); absent = the paper's scenario.
        #[arg(long)]
        scenario: Option<PathBuf>,
        /// Cable model, overriding the scenario's [model] kind.
        #[arg(long, value_enum)]
        model: Option<ModelKind>,
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// Write every K-th sample to the CSV (metrics always use every sample); K ≥ 1.
        #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..))]
        every: u64,
    },
    /// Run the paper scenario with every available model and write the reproduction report.
    Report {
        /// Output directory.
        #[arg(long, default_value = "reports")]
        out: PathBuf,
        /// Scenario file overriding the paper's (for quick checks).
        #[arg(long)]
        scenario: Option<PathBuf>,
    },
    /// Error of the effector trajectory vs cost for DOPRI5 and the implicit path (lumped, FE):
    /// DIR/work_precision.csv and DIR/work_precision.{svg,png}.
    WorkPrecision {
        /// Output directory.
        #[arg(long, default_value = "reports")]
        out: PathBuf,
    },
    /// Closed- and open-loop modes of the three models (CSV, Markdown, spectrum figure) and the
    /// smallest axial damping that makes every mode decay.
    Modes {
        /// Scenario file (TOML, MODELS.md §9); absent = the paper's scenario.
        #[arg(long)]
        scenario: Option<PathBuf>,
        /// Controller, overriding the scenario's `[controller] kind`.
        #[arg(long, value_enum)]
        controller: Option<ControllerKind>,
        /// Effector position x [m] (a spatial robot: X,Y,Z); absent = the trajectory's x1 and x2
        /// (a spatial robot: the move's end).
        #[arg(
            long,
            value_delimiter = ',',
            num_args = 1,
            allow_negative_numbers = true
        )]
        at: Vec<f64>,
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
    },
    /// Every controller × every cable model on the paper's move with tension limits [10, 400] N:
    /// DIR/control.md (the leaderboard and the goals), DIR/control.csv and figures.
    Control {
        /// Scenario file overriding the paper's (its controller kind and limits are replaced).
        #[arg(long)]
        scenario: Option<PathBuf>,
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
    },
    /// Every input shaper on every cable model with the paper's PID, designed from the modal
    /// analysis: residual vibration, move-time penalty, robustness to frequency error →
    /// DIR/shaping.md, DIR/shaping.csv and a figure per model.
    Shaping {
        /// Scenario file overriding the paper's (its shaper keys are replaced).
        #[arg(long)]
        scenario: Option<PathBuf>,
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
    },
    /// The static equilibrium (MODELS.md §2) at every start of an x × ΣT grid (cell midpoints);
    /// prints the starts that fail and exits non-zero if any does. The defaults are the lumped
    /// property test's ranges at 2000 × 250 points (~2 min for lumped or FE).
    StaticsSweep(statics_sweep::Args),
    /// The firmware's motion plan of a G-code file (Klipper's planner, `[printer]` limits)
    /// → DIR/plan.csv, one row per moving segment in the robot's frame.
    Plan {
        /// Scenario file with `[printer]` (absent: Klipper's defaults, origin at 0).
        #[arg(long)]
        scenario: Option<PathBuf>,
        /// G-code file (a slicer's output, millimetres).
        #[arg(long)]
        gcode: PathBuf,
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
    },
    /// A G-code file printed by a simulated spatial robot → DIR/metrics.json (contour error
    /// overall and per move type), DIR/print.csv and a figure per layer.
    Print {
        /// Scenario file with `[robot] anchors` and `[printer]` (e.g. examples/printing/hangprinter.toml).
        #[arg(long)]
        scenario: PathBuf,
        /// G-code file (a slicer's output, millimetres).
        #[arg(long)]
        gcode: PathBuf,
        /// Layers to print, `A..B` or `A` (0 = before the first `;LAYER_CHANGE`); absent: all.
        #[arg(long, value_parser = print::parse_layers)]
        layers: Option<std::ops::RangeInclusive<usize>>,
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// Write every K-th sample to print.csv (metrics always use every sample); K ≥ 1.
        #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..))]
        every: u64,
    },
    /// The printer's speed–accuracy frontier: the first layers of the sliced cube and cylinder
    /// on the Hangprinter-like robot at 1 000 … 10 000 mm/s², every controller unshaped and
    /// best-shaped → DIR/print-study.json|md, DIR/print-frontier.svg|png.
    PrintStudy {
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
    },
    /// A spatial robot's move (`[trajectory] start`, `end`) under every controller and every
    /// tension distribution → DIR/moves.json and DIR/moves.md (docs/spatial.md's table).
    SpatialMoves {
        /// Scenario file with `[robot] anchors` and a move (e.g. examples/robots/hangprinter.toml).
        #[arg(long)]
        scenario: PathBuf,
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
    },
    /// A spatial robot's statics at one pose: cable lengths, every tension distribution method
    /// (MODELS.md §11) holding the effector's weight in the scenario's box [t_min, t_max], and
    /// the largest uniform margin → DIR/distribution.json.
    Distribution {
        /// Scenario file with `[robot] anchors` (see examples/robots/).
        #[arg(long)]
        scenario: PathBuf,
        /// Effector position X,Y,Z [m].
        #[arg(
            long,
            value_delimiter = ',',
            num_args = 1,
            allow_negative_numbers = true
        )]
        at: Vec<f64>,
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
    },
    /// Firmware's static flex compensation on sagging lines: over a grid of targets in a box,
    /// the lengths the firmware commands (straight elastic lines holding the weight), the rest
    /// of the effector with the reels locked there on the lumped lines, and the position error
    /// → DIR/flex-error.json and DIR/flex-error.md.
    FlexError {
        /// Scenario file with `[robot] anchors` and its line (`[cable]`, `modelled_length`).
        #[arg(long)]
        scenario: PathBuf,
        /// The box of targets: X0,X1,Y0,Y1,Z0,Z1 [m].
        #[arg(
            long = "box",
            value_delimiter = ',',
            num_args = 1,
            allow_negative_numbers = true
        )]
        bounds: Vec<f64>,
        /// Targets per axis (the grid has this many cubed).
        #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..=50))]
        points: u32,
        /// Springs per line of the lumped statics.
        #[arg(long, default_value_t = 40, value_parser = clap::value_parser!(u32).range(3..=2000))]
        elements: u32,
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
    },
    /// What the lines' mass does to a printer, for the Hangprinter-like and CoGiRo-like robots
    /// on lumped lines: over a grid of each build volume the lowest effector modes (elastic and
    /// lumped) and the lowest string mode, firmware's flex-compensation error; the Hangprinter
    /// move under every controller on every cable model; maps, 3-D pictures and an animated GIF
    /// → DIR/spatial.json, DIR/spatial.md and the figures.
    Spatial {
        /// Output directory (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// Targets per axis of each build volume (the grid has this many cubed).
        #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(2..=20))]
        points: u32,
    },
    /// A parameter study: every point of a grid file (a base scenario and axes over dotted
    /// scenario keys) run metrics-only on all cores → DIR/results.jsonl and DIR/results.csv.
    /// An interrupted sweep resumes; `--shard I/N` runs points i ≡ I (mod N) (a Slurm array
    /// task); `--merge DIR...` combines the shards' results into `--out`.
    Sweep {
        /// Grid file (TOML: [scenario], [axes], [sweep]).
        #[arg(long, required_unless_present = "merge")]
        grid: Option<PathBuf>,
        /// Output directory (created if missing; a sweep's own results there are resumed).
        #[arg(long)]
        out: PathBuf,
        /// Worker threads; default: every core.
        #[arg(long)]
        jobs: Option<usize>,
        /// Run only shard I of N (points i with i mod N = I).
        #[arg(long)]
        shard: Option<cdpr_sweep::Shard>,
        /// Merge these shards' result directories (or results.jsonl files) into --out.
        #[arg(long, num_args = 1.., conflicts_with_all = ["grid", "shard", "jobs"])]
        merge: Vec<PathBuf>,
    },
}

fn main() -> ExitCode {
    match run(Cli::parse().command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

/// One command, carried out.
fn run(command: Command) -> anyhow::Result<()> {
    match command {
        Command::Simulate {
            scenario,
            model,
            out,
            every,
        } => simulate::run(scenario.as_deref(), model, &out, every as usize),
        Command::Report { out, scenario } => report::run(scenario.as_deref(), &out),
        Command::WorkPrecision { out } => work_precision::run_study(&out),
        Command::Modes {
            scenario,
            controller,
            at,
            out,
        } => modes::run(scenario.as_deref(), controller, at, &out),
        Command::Control { scenario, out } => control::run(scenario.as_deref(), &out),
        Command::Shaping { scenario, out } => shaping::run_study(scenario.as_deref(), &out),
        Command::Distribution { scenario, at, out } => distribution::run(&scenario, &at, &out),
        Command::SpatialMoves { scenario, out } => spatial_moves::run(&scenario, &out),
        Command::FlexError {
            scenario,
            bounds,
            points,
            elements,
            out,
        } => flex_error::run(&scenario, &bounds, points as usize, elements as usize, &out),
        Command::PrintStudy { out } => print_study::run(&out),
        Command::Spatial { out, points } => {
            spatial_report::run(&out, points as usize).map(|section| print!("{section}"))
        }
        Command::Plan {
            scenario,
            gcode,
            out,
        } => print::plan(scenario.as_deref(), &gcode, &out),
        Command::Print {
            scenario,
            gcode,
            layers,
            out,
            every,
        } => print::print(&print::PrintOptions {
            scenario: &scenario,
            gcode: &gcode,
            layers,
            out: &out,
            every: every as usize,
        }),
        Command::Sweep {
            grid,
            out,
            jobs,
            shard,
            merge,
        } => match grid {
            Some(grid) => sweep::run(&grid, &out, jobs, shard.unwrap_or(cdpr_sweep::Shard::ALL)),
            None => sweep::merge(&merge, &out),
        },
        Command::StaticsSweep(args) => statics_sweep::run(&args),
    }
}
