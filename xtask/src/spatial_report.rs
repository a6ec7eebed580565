//! `cargo xtask spatial --out DIR`: what the lines' mass does to a printer
//! ([`cdpr_studies::spatial_printers`]) for the Hangprinter-like and the CoGiRo-like robots on
//! lumped lines → DIR/spatial.json, DIR/spatial.md (the section of REPORT.md) and the figures:
//! per robot the maps of its lowest modes and of the flex-compensation error over its build
//! volume and a 3-D picture of it at rest (sag magnified); the Hangprinter's move as a picture
//! and as an animated GIF of its cables.

use crate::figures::render_drawing;
use crate::heatmap::{HeatMap, HeatPanel};
use crate::output::{write_atomic, write_json};
use crate::robot_picture::{RobotPicture, magnify, write_gif};
use anyhow::{Context, Result};
use cdpr_bench::core::scenario::Scenario;
use cdpr_studies::flex_error::{self, FlexError};
use cdpr_studies::spatial_printers::{self, ModeMap, ModelMoves};
use std::path::{Path, PathBuf};

/// A printer of the study: its scenario file (lumped lines), its build volume [m] and how much
/// its drawings magnify the sag.
struct Printer {
    key: &'static str,
    name: &'static str,
    file: &'static str,
    low: [f64; 3],
    high: [f64; 3],
    sag_factor: f64,
}

/// The printers: the boxes of docs/spatial.md's flex-error table.
const PRINTERS: [Printer; 2] = [
    Printer {
        key: "hangprinter",
        name: "Hangprinter-like (4 cables, 1.1 mm UHMWPE)",
        file: "examples/robots/hangprinter-lumped.toml",
        low: [-0.3, -0.3, 0.0],
        high: [0.3, 0.3, 0.6],
        sag_factor: 200.0,
    },
    Printer {
        key: "cogiro",
        name: "CoGiRo-like (8 cables, 4 mm steel)",
        file: "examples/robots/cogiro-lumped.toml",
        low: [-4.0, -3.0, 0.5],
        high: [4.0, 3.0, 3.5],
        sag_factor: 10.0,
    },
];

/// Frames of the Hangprinter's move in the GIF [s apart].
const FRAME_PERIOD: f64 = 0.04;

/// How much slower than real time the GIF plays.
const SLOW_MOTION: f64 = 5.0;

/// Everything in spatial.json.
#[derive(serde::Serialize)]
struct SpatialFile<'a> {
    printers: Vec<PrinterEntry<'a>>,
    leaderboard: &'a [ModelMoves],
}

#[derive(serde::Serialize)]
struct PrinterEntry<'a> {
    name: &'a str,
    scenario: &'a str,
    modes: &'a ModeMap,
    flex_error: &'a FlexError,
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn scenario(p: &Printer) -> Result<Scenario> {
    let path = root().join(p.file);
    cdpr_bench::scenario_from_file(&path).with_context(|| format!("reading {}", path.display()))
}

/// The study into `out` with `per_axis` targets per axis of each build volume; returns the
/// section of REPORT.md (also written as DIR/spatial.md).
pub fn run(out: &Path, per_axis: usize) -> Result<String> {
    anyhow::ensure!(
        (2..=20).contains(&per_axis),
        "--points {per_axis}: 2 to 20 targets per axis"
    );
    crate::simulate::writable_out(out)?;
    let mut section = String::from(
        "## What the lines' mass does to a printer\n\nBeyond the paper (`cargo xtask spatial`; \
         docs/spatial.md): the Hangprinter-like and CoGiRo-like robots on their massive lines \
         (lumped, MODELS.md §11) against massless elastic cables; the leaderboard adds the \
         finite-element cables (N = 10).\n\n",
    );
    let mut maps = Vec::new();
    for p in &PRINTERS {
        let s = scenario(p)?;
        let modes = spatial_printers::mode_map(&s, p.low, p.high, per_axis)?;
        let elements = modes.elements;
        let flex = flex_error::over_box(&s, p.low, p.high, per_axis, elements)?;
        draw_maps(p, &modes, &flex, out)?;
        let centre: [f64; 3] = std::array::from_fn(|k| 0.5 * (p.low[k] + p.high[k]));
        let rest = spatial_printers::rest_paths(&s, centre)?;
        let picture = picture(
            &s,
            format!("{} at rest at {centre:?} m, sag ×{}", p.name, p.sag_factor),
            &rest,
            p.sag_factor,
            Vec::new(),
        )?;
        render_drawing(&picture, &format!("spatial_{}_rest", p.key), out)?;
        section += &format!(
            "### {}\n\nBuild volume x ∈ [{}, {}], y ∈ [{}, {}], z ∈ [{}, {}] m, {per_axis}³ \
             targets (`{}`).\n\n{}\n{}\n![modes](spatial_{key}_modes.svg)\n\
             ![flex error](spatial_{key}_flex.svg)\n![at rest](spatial_{key}_rest.svg)\n\n",
            p.name,
            p.low[0],
            p.high[0],
            p.low[1],
            p.high[1],
            p.low[2],
            p.high[2],
            p.file,
            spatial_printers::mode_markdown(&modes),
            flex_error::markdown(&flex),
            key = p.key,
        );
        maps.push((p, modes, flex));
    }
    let hang = scenario(&PRINTERS[0])?;
    let board = spatial_printers::leaderboard(&hang)?;
    section += &format!(
        "### The Hangprinter move on every cable model\n\nThe move of `{}` (0.11 m in 0.2 s, \
         box [10, 70] N, {} distribution) under every controller; `length/…` is the \
         firmware's length control with each flex compensation (on the lumped lines the reels \
         feed the commanded unstrained length, on FE cables they prescribe the free \
         length).\n\n{}\n",
        PRINTERS[0].file,
        hang.controller.distribution.name(),
        spatial_printers::leaderboard_markdown(&board)
    );
    section += &draw_move(&PRINTERS[0], &hang, out)?;
    write_json(
        &out.join("spatial.json"),
        &SpatialFile {
            printers: maps
                .iter()
                .map(|(p, modes, flex)| PrinterEntry {
                    name: p.name,
                    scenario: p.file,
                    modes,
                    flex_error: flex,
                })
                .collect(),
            leaderboard: &board,
        },
    )?;
    write_atomic(&out.join("spatial.md"), |w| w.write_all(section.as_bytes()))?;
    Ok(section)
}

/// The robot's picture with `cables` (pulley → effector) magnified about their chords.
fn picture(
    s: &Scenario,
    title: String,
    cables: &[Vec<[f64; 3]>],
    factor: f64,
    trail: Vec<[f64; 3]>,
) -> Result<RobotPicture> {
    let robot = cdpr_bench::spatial_robot(s)?;
    Ok(RobotPicture {
        title,
        anchors: robot.anchors().iter().map(|a| [a.x, a.y, a.z]).collect(),
        cables: cables.iter().map(|c| magnify(c, factor)).collect(),
        trail,
    })
}

/// The Hangprinter's move on its lumped lines under the scenario's controller: a frame every
/// [`FRAME_PERIOD`] into DIR/spatial_hangprinter_move.gif and the frame at the move's end as a
/// picture; returns the lines of the section about them.
fn draw_move(p: &Printer, s: &Scenario, out: &Path) -> Result<String> {
    let (run, frames) = spatial_printers::move_frames(s, FRAME_PERIOD)?;
    let mut trail = Vec::new();
    let mut pictures = Vec::new();
    for f in &frames {
        if let Some(e) = f.cables.first().and_then(|c| c.last()) {
            trail.push(*e);
        }
        pictures.push(picture(
            s,
            format!(
                "Hangprinter move, {} on lumped lines, t = {:.2} s, sag ×{}",
                s.controller.kind.name(),
                f.t,
                p.sag_factor
            ),
            &f.cables,
            p.sag_factor,
            trail.clone(),
        )?);
    }
    let end = run.metrics.move_end_s;
    let at_end = frames
        .iter()
        .position(|f| f.t >= end - 1e-12)
        .unwrap_or(frames.len().saturating_sub(1));
    if let Some(still) = pictures.get(at_end) {
        render_drawing(still, "spatial_hangprinter_move", out)?;
    }
    write_gif(
        &pictures,
        &out.join("spatial_hangprinter_move.gif"),
        (FRAME_PERIOD * 1000.0 * SLOW_MOTION) as u32,
    )?;
    Ok(format!(
        "The move drawn ({} frames, {SLOW_MOTION}× slower than real time, sag ×{}): \
         [spatial_hangprinter_move.gif](spatial_hangprinter_move.gif); at its end:\n\n\
         ![move](spatial_hangprinter_move.svg)\n",
        frames.len(),
        p.sag_factor
    ))
}

/// Heat maps over x and y at the lowest, middle and highest layers of the grid: the lowest
/// effector mode on the elastic and on the lumped lines and the lines' lowest string mode
/// (DIR/spatial_KEY_modes), and the flex-compensation error (DIR/spatial_KEY_flex).
fn draw_maps(p: &Printer, modes: &ModeMap, flex: &FlexError, out: &Path) -> Result<()> {
    let grid = MapGrid {
        p,
        n: modes.per_axis,
    };
    let layers = [0, grid.n / 2, grid.n - 1];
    draw_mode_maps(&grid, &layers, modes, out)?;
    draw_flex_maps(&grid, &layers, flex, out)
}

/// The maps' grid over a printer's build volume: `n` points per axis, low corner to high.
struct MapGrid<'a> {
    p: &'a Printer,
    n: usize,
}

impl MapGrid<'_> {
    /// The coordinate [m] of the `k`-th grid point along `axis` (the box's centre if one point).
    fn coord(&self, axis: usize, k: usize) -> f64 {
        let (p, n) = (self.p, self.n);
        if n > 1 {
            p.low[axis] + k as f64 * (p.high[axis] - p.low[axis]) / (n - 1) as f64
        } else {
            0.5 * (p.low[axis] + p.high[axis])
        }
    }

    /// The tick labels along `axis`: each grid point's coordinate [m].
    fn labels(&self, axis: usize) -> Vec<String> {
        (0..self.n)
            .map(|k| format!("{:.2}", self.coord(axis, k)))
            .collect()
    }

    /// The grid point a study's pose [m] lies on, as indices per axis.
    fn index(&self, pose: [f64; 3]) -> [usize; 3] {
        let (p, n) = (self.p, self.n);
        std::array::from_fn(|a| {
            let span = p.high[a] - p.low[a];
            if span > 0.0 && n > 1 {
                ((pose[a] - p.low[a]) / span * (n - 1) as f64).round() as usize
            } else {
                0
            }
        })
    }

    /// One layer's panel over x and y of `values` at each grid point (None: nothing there).
    fn panel(&self, title: String, values: &dyn Fn(usize, usize) -> Option<f64>) -> HeatPanel {
        let n = self.n;
        HeatPanel {
            title,
            x_labels: self.labels(0),
            y_labels: self.labels(1),
            values: (0..n)
                .map(|iy| (0..n).map(|ix| values(ix, iy)).collect())
                .collect(),
        }
    }
}

/// Per layer, the lowest effector mode (elastic, lumped) and string mode (DIR/spatial_KEY_modes).
fn draw_mode_maps(grid: &MapGrid, layers: &[usize; 3], modes: &ModeMap, out: &Path) -> Result<()> {
    let p = grid.p;
    let hz = |w: f64| w / (2.0 * std::f64::consts::PI);
    let mode_at = |ix: usize, iy: usize, l: usize| {
        modes
            .points
            .iter()
            .find(|q| grid.index(q.pose) == [ix, iy, l])
    };
    let mut panels = Vec::new();
    for &l in layers {
        let z = grid.coord(2, l);
        panels.push(grid.panel(format!("elastic, z = {z:.2} m"), &|ix, iy| {
            mode_at(ix, iy, l).map(|q| hz(q.elastic_locked_rad_s))
        }));
        panels.push(grid.panel(format!("lumped, z = {z:.2} m"), &|ix, iy| {
            mode_at(ix, iy, l).and_then(|q| q.lumped_locked_rad_s.map(hz))
        }));
        panels.push(
            grid.panel(format!("lowest string, z = {z:.2} m"), &|ix, iy| {
                mode_at(ix, iy, l).and_then(|q| q.lowest_string_rad_s.map(hz))
            }),
        );
    }
    let map = HeatMap {
        title: format!(
            "{}: lowest effector mode (reels locked) and lowest string mode",
            p.name
        ),
        x_name: "x [m]".into(),
        y_name: "y [m]".into(),
        value_name: "f [Hz]".into(),
        rows: layers.len(),
        cols: 3,
        panels,
    };
    render_drawing(&map, &format!("spatial_{}_modes", p.key), out)
}

/// Static flex compensation's error on the sagging lines per layer (DIR/spatial_KEY_flex).
fn draw_flex_maps(grid: &MapGrid, layers: &[usize; 3], flex: &FlexError, out: &Path) -> Result<()> {
    let p = grid.p;
    let flex_at = |ix: usize, iy: usize, l: usize| {
        flex.points
            .iter()
            .find(|q| grid.index(q.target) == [ix, iy, l])
            .map(|q| q.error)
    };
    let panels = layers
        .iter()
        .map(|&l| {
            grid.panel(format!("z = {:.2} m", grid.coord(2, l)), &|ix, iy| {
                flex_at(ix, iy, l)
            })
        })
        .collect();
    let map = HeatMap {
        title: format!(
            "{}: static flex compensation's error on sagging lines",
            p.name
        ),
        x_name: "x [m]".into(),
        y_name: "y [m]".into(),
        value_name: "error [m]".into(),
        rows: 1,
        cols: layers.len(),
        panels,
    };
    render_drawing(&map, &format!("spatial_{}_flex", p.key), out)
}
