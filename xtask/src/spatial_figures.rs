//! A spatial run's figures, written beside its time series: the effector's path in three
//! projections (top, front, side) against the straight reference segment, in millimetres from
//! the start, and each cable's tension against the box.

use crate::figures::{Figure, LINE_WIDTH, Line, Marker, Panel, render};
use anyhow::Result;
use cdpr_bench::core::channel::Channel;
use cdpr_bench::core::robot::CableId;
use cdpr_bench::core::runner::Run;
use cdpr_bench::core::scenario::Scenario;
use plotters::prelude::RGBColor;
use std::path::Path;

/// Most points of a projected path (it is not a function of time, so no envelope: every k-th
/// sample).
const PATH_POINTS: usize = 4000;

/// Cable colours, cable 1 first.
pub(crate) const CABLE_COLORS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
];

/// `path.svg|png` and `tensions.svg|png` of `run` into `out`.
pub fn write(scenario: &Scenario, run: &Run, out: &Path) -> Result<()> {
    if let Some(path) = path_figure(scenario, run) {
        render(&path, out)?;
    }
    render(&tensions_figure(scenario, run), out)
}

/// The path in the top, front and side views, millimetres from the start.
fn path_figure(scenario: &Scenario, run: &Run) -> Option<Figure> {
    let s = &run.series;
    let column = |c: Channel| s.channel(c).unwrap_or(&[]);
    let (x, y, z) = (column(Channel::X), column(Channel::Y), column(Channel::Z));
    if x.is_empty() {
        return None;
    }
    let origin = [x[0], y[0], z[0]];
    let every = x.len().div_ceil(PATH_POINTS).max(1);
    let axes = [(x, "x"), (y, "y"), (z, "z")];
    let end = scenario.trajectory.spatial_move().ok().map(|(_, e)| e);
    let panels = [
        (0, 1, "top (x, y)"),
        (0, 2, "front (x, z)"),
        (1, 2, "side (y, z)"),
    ]
    .into_iter()
    .map(|(a, b, view)| {
        let points = (0..x.len())
            .step_by(every)
            .map(|i| {
                (
                    (axes[a].0[i] - origin[a]) * 1e3,
                    (axes[b].0[i] - origin[b]) * 1e3,
                )
            })
            .collect();
        let mut lines = vec![Line {
            label: format!("effector, {view}"),
            color: RGBColor(0, 0, 0),
            dashed: false,
            width: LINE_WIDTH,
            points,
        }];
        if let Some(end) = end {
            lines.push(Line {
                label: "reference segment".into(),
                color: RGBColor(214, 39, 40),
                dashed: true,
                width: LINE_WIDTH,
                points: vec![
                    (0.0, 0.0),
                    ((end[a] - origin[a]) * 1e3, (end[b] - origin[b]) * 1e3),
                ],
            });
        }
        Panel {
            x_label: format!("{} − start [mm]", axes[a].1),
            y_label: format!("{} − start [mm]", axes[b].1),
            log_x: false,
            log_y: false,
            lines,
            markers: Vec::new(),
        }
    })
    .collect();
    Some(Figure {
        name: "path".into(),
        title: "Effector path in three projections".into(),
        panels,
    })
}

/// Each cable's tension against the box.
fn tensions_figure(scenario: &Scenario, run: &Run) -> Figure {
    let m = run.equilibrium.tensions.len();
    let t_end = run.t_reached;
    let lines = CableId::all(m)
        .map(|c| Line {
            label: format!("T{c}"),
            color: CABLE_COLORS[c.index() % CABLE_COLORS.len()],
            dashed: false,
            width: LINE_WIDTH,
            points: crate::figures::channel(run, Channel::Tension(c), 0.0, t_end, 1.0),
        })
        .collect();
    let c = &scenario.controller;
    let markers = [("t_min", c.t_min), ("t_max", c.t_max)]
        .into_iter()
        .filter_map(|(name, v)| v.map(|v| Marker::Horizontal(v, name.into())))
        .collect();
    Figure {
        name: "tensions".into(),
        title: "Cable tensions".into(),
        panels: vec![Panel {
            x_label: "t [s]".into(),
            y_label: "tension [N]".into(),
            log_x: false,
            log_y: false,
            lines,
            markers,
        }],
    }
}
