//! A print's figure per layer: the commanded path (grey) and the simulated nozzle's path, its
//! deviation from the path magnified so that the largest becomes 0.5 mm on the page, coloured
//! from blue (on the path) to red (the layer's largest error). Top view, millimetres in the
//! robot's frame.

use crate::figures::{Drawing, register_fonts, render_drawing};
use anyhow::Result;
use cdpr_bench::PreparedPrint;
use cdpr_bench::analysis::contour::contour_sample;
use cdpr_bench::core::runner::Run;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Most nozzle points drawn per layer.
const POINTS: usize = 20_000;
/// The largest deviation's size on the page after magnification [mm].
const SHOWN_DEVIATION: f64 = 0.5;

/// One layer's figure.
struct LayerFigure {
    title: String,
    /// Commanded segments, (x, y) [mm].
    commanded: Vec<[(f64, f64); 2]>,
    /// The nozzle's magnified points (x, y) [mm] and their error over the layer's largest.
    nozzle: Vec<((f64, f64), f64)>,
}

/// `layer_NNN.svg|png` for every printed layer with moves.
pub fn write(print: &PreparedPrint, run: &Run, out: &Path) -> Result<()> {
    register_fonts();
    let path = &print.path;
    let plan = path.plan();
    let samples: Vec<_> = cdpr_bench::positions(run)
        .map(|(t, p)| (p, contour_sample(path, t, &p)))
        .collect();
    for layer in print.layers.clone() {
        let commanded: Vec<[(f64, f64); 2]> = (0..plan.segments.len())
            .filter(|&i| plan.segments[i].layer == layer)
            .map(|i| {
                let (a, b) = path.segment_ends(i);
                [(a[0] * 1e3, a[1] * 1e3), (b[0] * 1e3, b[1] * 1e3)]
            })
            .collect();
        if commanded.is_empty() {
            continue;
        }
        let mine: Vec<_> = samples.iter().filter(|(_, c)| c.layer == layer).collect();
        let largest = mine.iter().map(|(_, c)| c.error).fold(0.0, f64::max);
        let magnification = if largest > 0.0 {
            (SHOWN_DEVIATION * 1e-3 / largest).clamp(1.0, 1e5)
        } else {
            1.0
        };
        let every = mine.len().div_ceil(POINTS).max(1);
        let nozzle = mine
            .iter()
            .step_by(every)
            .map(|(p, c)| {
                let shown = c.nearest + (p - c.nearest) * magnification;
                let share = if largest > 0.0 {
                    c.error / largest
                } else {
                    0.0
                };
                ((shown[0] * 1e3, shown[1] * 1e3), share)
            })
            .collect();
        let figure = LayerFigure {
            title: format!(
                "layer {layer}: contour error up to {:.1} µm, shown ×{magnification:.0}",
                largest * 1e6
            ),
            commanded,
            nozzle,
        };
        render_drawing(&figure, &format!("layer_{layer:03}"), out)?;
    }
    Ok(())
}

/// Blue (0) to red (1).
fn heat(share: f64) -> RGBColor {
    let s = share.clamp(0.0, 1.0);
    RGBColor(
        (30.0 + 200.0 * s) as u8,
        (60.0 * (1.0 - s)) as u8,
        (220.0 * (1.0 - s)) as u8,
    )
}

impl Drawing for LayerFigure {
    fn draw_on<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        scale: f64,
    ) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("{e:?}");
        root.fill(&WHITE).map_err(err)?;
        let px = |v: f64| (v * scale).round() as u32;
        let points = self
            .commanded
            .iter()
            .flatten()
            .copied()
            .chain(self.nozzle.iter().map(|(p, _)| *p));
        let (mut lo, mut hi) = (
            (f64::INFINITY, f64::INFINITY),
            (f64::NEG_INFINITY, f64::NEG_INFINITY),
        );
        for (a, b) in points {
            lo = (lo.0.min(a), lo.1.min(b));
            hi = (hi.0.max(a), hi.1.max(b));
        }
        // Equal scales on both axes: the wider span sets both.
        let span = (hi.0 - lo.0).max(hi.1 - lo.1).max(1e-3) * 1.05;
        let centre = (0.5 * (lo.0 + hi.0), 0.5 * (lo.1 + hi.1));
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, ("sans-serif", px(18.0)).into_font())
            .margin(px(10.0))
            .x_label_area_size(px(40.0))
            .y_label_area_size(px(60.0))
            .build_cartesian_2d(
                centre.0 - 0.75 * span..centre.0 + 0.75 * span,
                centre.1 - 0.5 * span..centre.1 + 0.5 * span,
            )
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("x [mm]")
            .y_desc("y [mm]")
            .label_style(("sans-serif", px(14.0)))
            .draw()
            .map_err(err)?;
        let grey = RGBColor(170, 170, 170).stroke_width(px(2.0));
        for [a, b] in &self.commanded {
            chart
                .draw_series(std::iter::once(PathElement::new(vec![*a, *b], grey)))
                .map_err(err)?;
        }
        chart
            .draw_series(self.nozzle.windows(2).map(|w| {
                PathElement::new(vec![w[0].0, w[1].0], heat(w[1].1).stroke_width(px(1.0)))
            }))
            .map_err(err)?;
        Ok(())
    }
}
