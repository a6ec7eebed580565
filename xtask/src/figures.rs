//! The paper's figures (Fig. 5–8) and the `step5` reference, for any set of model runs.
//!
//! A figure is described once as data ([`Figure`]: stacked panels of lines and markers) and
//! rendered twice: SVG (vector, the primary output) and PNG at twice the size with thicker
//! strokes, because the bitmap backend draws without anti-aliasing. Fonts are embedded (DejaVu
//! Sans), so no system font is needed. Logarithmic axes are drawn as log10 of the data on a
//! linear axis with power-of-ten labels, which keeps one drawing path for every panel.
//! Long series are thinned per pixel column by min/max envelopes, so oscillations keep their
//! amplitude; spectra keep the maximum per logarithmic frequency bucket, so peaks keep height.

use crate::output::write_atomic;
use anyhow::{Context, Result, anyhow};
use cdpr_bench::ModelKind;

use cdpr_bench::core::runner::Run;
use plotters::coord::Shift;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::path::Path;
use std::sync::Once;

pub use cdpr_studies::samples::{channel, envelope, spectrum, step5_lines};

/// SVG size [px]; the PNG is twice as large.
const SIZE: (u32, u32) = (960, 640);
// The samples drawn keep two points per pixel column of the SVG.
const _: () = assert!(cdpr_studies::samples::MAX_POINTS == 2 * SIZE.0 as usize);

/// One curve of a panel.
pub struct Line {
    pub label: String,
    pub color: RGBColor,
    pub dashed: bool,
    /// Stroke width [SVG px]: wider lines are drawn first, so a thin line on top of a wide one
    /// stays visible where two curves coincide.
    pub width: f64,
    pub points: Vec<(f64, f64)>,
}

/// The stroke width of a line that shares its panel with no coinciding curve [SVG px].
pub const LINE_WIDTH: f64 = 1.5;

/// A vertical or horizontal reference line with a label.
pub enum Marker {
    Vertical(f64, String),
    Horizontal(f64, String),
}

/// One chart of a figure.
pub struct Panel {
    pub x_label: String,
    pub y_label: String,
    pub log_x: bool,
    pub log_y: bool,
    pub lines: Vec<Line>,
    pub markers: Vec<Marker>,
}

/// A figure: a title and panels stacked top to bottom; written as `<name>.svg` and `<name>.png`.
pub struct Figure {
    pub name: String,
    pub title: String,
    pub panels: Vec<Panel>,
}

/// One model's run, with its colour and legend label.
pub struct Curve<'a> {
    pub label: &'a str,
    pub color: RGBColor,
    pub width: f64,
    pub run: &'a Run,
}

/// The stroke width of each model in every figure, in [`ModelKind::ALL`]'s order [SVG px]: FE
/// widest, drawn first, elastic narrowest, drawn last, so that the three remain distinguishable
/// where they coincide.
const MODEL_WIDTHS: [f64; 3] = [1.0, 2.0, 4.0];
/// The colour of each model in every figure, in [`ModelKind::ALL`]'s order.
const MODEL_COLORS: [RGBColor; 3] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
];

/// The stroke width of `kind` in every figure [SVG px].
pub fn model_width(kind: ModelKind) -> f64 {
    MODEL_WIDTHS[kind.index()]
}

/// The colour of `kind` in every figure.
pub fn model_color(kind: ModelKind) -> RGBColor {
    MODEL_COLORS[kind.index()]
}

pub(crate) fn register_fonts() {
    static FONTS: Once = Once::new();
    FONTS.call_once(|| {
        // The font is compiled in; registering it cannot fail for a valid TTF.
        plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular())
            .map_err(|_| ())
            .expect("DejaVu Sans is a valid font");
    });
}

/// Something drawn at a scale (1: the SVG, 2: the PNG, whose bitmap backend does not
/// anti-alias): the report's figures and the modes' spectrum share [`render_drawing`].
pub(crate) trait Drawing {
    fn draw_on<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        scale: f64,
    ) -> Result<(), String>
    where
        DB::ErrorType: 'static;
}

impl Drawing for Figure {
    fn draw_on<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        scale: f64,
    ) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        draw(root, self, scale)
    }
}

/// Writes `figure` as `<dir>/<name>.svg` and `<dir>/<name>.png`, atomically.
pub fn render(figure: &Figure, dir: &Path) -> Result<()> {
    render_drawing(figure, &figure.name, dir)
}

/// Writes `drawing` as `<dir>/<name>.svg` (960 × 640) and `<dir>/<name>.png` (2×), atomically.
pub(crate) fn render_drawing(drawing: &impl Drawing, name: &str, dir: &Path) -> Result<()> {
    register_fonts();
    let svg_path = dir.join(format!("{name}.svg"));
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        drawing
            .draw_on(&root, 1.0)
            .map_err(|e| anyhow!("drawing {name}: {e}"))?;
        root.present()
            .map_err(|e| anyhow!("drawing {name}: {e:?}"))?;
    }
    write_atomic(&svg_path, |w| w.write_all(svg.as_bytes()))?;

    // The bitmap backend encodes by file extension: draw into a temporary `.png` beside the
    // target, then rename it into place (atomic, like every output).
    let png_path = dir.join(format!("{name}.png"));
    let tmp = dir.join(format!(".{name}.tmp-{}.png", std::process::id()));
    let drawn = (|| {
        let root = BitMapBackend::new(&tmp, (2 * SIZE.0, 2 * SIZE.1)).into_drawing_area();
        drawing.draw_on(&root, 2.0)?;
        root.present().map_err(|e| format!("{e:?}"))
    })();
    if let Err(e) = drawn {
        let _ = std::fs::remove_file(&tmp);
        return Err(anyhow!("drawing {name}: {e}"));
    }
    std::fs::rename(&tmp, &png_path).with_context(|| format!("writing {}", png_path.display()))
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    figure: &Figure,
    scale: f64,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("{e:?}");
    root.fill(&WHITE).map_err(err)?;
    let px = |v: f64| (v * scale).round() as u32;
    let titled = root
        .titled(&figure.title, ("sans-serif", px(20.0)).into_font())
        .map_err(err)?;
    let areas = titled.split_evenly((figure.panels.len(), 1));
    // One legend column for the figure, so that the panels' plots line up.
    let legend = figure.panels.iter().map(legend_width).fold(0.0, f64::max);
    for (panel, area) in figure.panels.iter().zip(areas.iter()) {
        draw_panel(area, panel, legend, scale).map_err(err)?;
    }
    Ok(())
}

fn bounds(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    if hi - lo < 1e-300 {
        let pad = if lo == 0.0 { 1.0 } else { 0.05 * lo.abs() };
        return (lo - pad, hi + pad);
    }
    let pad = 0.05 * (hi - lo);
    (lo - pad, hi + pad)
}

/// A linear-axis tick: at most 6 decimals, trailing zeros dropped ("0.15", not
/// "0.15000000000000002").
fn tick(v: f64) -> String {
    let s = format!("{v:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

/// Tick label of a log10 axis: "1eK" at the integer K, nothing between.
pub(crate) fn power_label(v: &f64) -> String {
    if (v - v.round()).abs() < 1e-9 {
        format!("1e{}", v.round() as i64)
    } else {
        String::new()
    }
}

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &Panel,
    legend_width: f64,
    scale: f64,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let px = |v: f64| (v * scale).round() as u32;
    let ((x0, x1), (y0, y1)) = panel_ranges(panel);
    let label_font = ("sans-serif", px(14.0)).into_font();
    let mut chart = ChartBuilder::on(area)
        .margin(px(8.0))
        .margin_right(px(8.0 + legend_width))
        .x_label_area_size(px(40.0))
        .y_label_area_size(px(80.0))
        .build_cartesian_2d(x0..x1, y0..y1)?;
    let x_fmt = |v: &f64| {
        if panel.log_x {
            power_label(v)
        } else {
            tick(*v)
        }
    };
    let y_fmt = |v: &f64| {
        if panel.log_y {
            power_label(v)
        } else {
            tick(*v)
        }
    };
    chart
        .configure_mesh()
        .x_desc(panel.x_label.as_str())
        .y_desc(panel.y_label.as_str())
        .x_labels(if panel.log_x {
            (x1 - x0) as usize + 1
        } else {
            10
        })
        .y_labels(if panel.log_y {
            (y1 - y0) as usize + 1
        } else {
            8
        })
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt)
        .label_style(label_font.clone())
        .axis_desc_style(label_font.clone())
        .light_line_style(RGBColor(235, 235, 235))
        .draw()?;
    // Reference lines; their labels go to the legend, where they collide with nothing.
    for m in &panel.markers {
        let points = match m {
            Marker::Vertical(x, _) => vec![(panel.plot_x(*x), y0), (panel.plot_x(*x), y1)],
            Marker::Horizontal(y, _) => vec![(x0, panel.plot_y(*y)), (x1, panel.plot_y(*y))],
        };
        let grey = MARKER_GREY.stroke_width(px(1.0));
        chart.draw_series(DashedLineSeries::new(points, px(6.0), px(4.0), grey))?;
    }
    draw_lines(&mut chart, panel, scale)?;
    draw_legend(area, &chart, panel, scale)
}

/// The plotted ranges of `panel` (in the plotted, possibly log10, coordinates): its valid data
/// and its markers, whole decades on a log axis.
fn panel_ranges(panel: &Panel) -> ((f64, f64), (f64, f64)) {
    let all = || {
        panel
            .lines
            .iter()
            .flat_map(|l| l.points.iter().filter(|p| panel.plottable(p)))
    };
    let (mut x0, mut x1) = bounds(all().map(|p| panel.plot_x(p.0)));
    let (mut y0, mut y1) = bounds(all().map(|p| panel.plot_y(p.1)));
    if panel.log_x {
        (x0, x1) = (x0.floor(), x1.ceil());
    }
    if panel.log_y {
        (y0, y1) = (y0.floor(), y1.ceil());
    }
    for m in &panel.markers {
        match m {
            Marker::Horizontal(y, _) => {
                (y0, y1) = (y0.min(panel.plot_y(*y)), y1.max(panel.plot_y(*y)))
            }
            Marker::Vertical(x, _) => {
                (x0, x1) = (x0.min(panel.plot_x(*x)), x1.max(panel.plot_x(*x)))
            }
        }
    }
    ((x0, x1), (y0, y1))
}

impl Panel {
    /// x in the plotted coordinate (log10 on a log axis).
    fn plot_x(&self, x: f64) -> f64 {
        if self.log_x { x.log10() } else { x }
    }

    /// y in the plotted coordinate (log10 of |y| on a log axis).
    fn plot_y(&self, y: f64) -> f64 {
        if self.log_y {
            y.abs().max(1e-300).log10()
        } else {
            y
        }
    }

    /// A point a log axis can show.
    fn plottable(&self, p: &(f64, f64)) -> bool {
        (!self.log_x || p.0 > 0.0) && (!self.log_y || p.1 != 0.0)
    }
}

/// The panel's data lines onto `chart`.
fn draw_lines<DB: DrawingBackend>(
    chart: &mut ChartContext<DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    panel: &Panel,
    scale: f64,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let px = |v: f64| (v * scale).round() as u32;
    // Draw order: lines that oscillate far more than the others (a band, like the lumped
    // model's tensions while its axial mode rings) first, so the smoother curves stay visible on
    // top; among comparable lines the wider first, so a narrower one drawn over a coinciding
    // curve stays visible. Lines are a little transparent where they still overlap.
    let roughness = |l: &Line| {
        let variation: f64 = l.points.windows(2).map(|p| (p[1].1 - p[0].1).abs()).sum();
        variation.max(f64::MIN_POSITIVE).log2().floor()
    };
    let mut order: Vec<(f64, &Line)> = panel.lines.iter().map(|l| (roughness(l), l)).collect();
    order.sort_by(|(ra, a), (rb, b)| rb.total_cmp(ra).then(b.width.total_cmp(&a.width)));
    for (_, line) in order {
        let style = line
            .color
            .mix(LINE_OPACITY)
            .stroke_width(px(line.width).max(1));
        let pts: Vec<(f64, f64)> = line
            .points
            .iter()
            .filter(|p| panel.plottable(p))
            .map(|p| (panel.plot_x(p.0), panel.plot_y(p.1)))
            .collect();
        if line.dashed {
            chart.draw_series(DashedLineSeries::new(pts, px(8.0), px(5.0), style))?;
        } else {
            // Segment by segment: a polyline's mitre joins at the sharp turns of an oscillation
            // reach far beyond the data in the bitmap backend (which has no mitre limit).
            chart.draw_series(
                pts.windows(2)
                    .map(|s| PathElement::new(vec![s[0], s[1]], style)),
            )?;
        }
    }
    Ok(())
}

/// Opacity of the data lines.
const LINE_OPACITY: f64 = 0.75;

/// The colour of reference lines (markers).
const MARKER_GREY: RGBColor = RGBColor(110, 110, 110);

/// One entry of a panel's legend: label, colour, dashed, width [SVG px].
fn legend_entries(panel: &Panel) -> Vec<(String, RGBColor, bool, f64)> {
    let lines = panel
        .lines
        .iter()
        .map(|l| (l.label.clone(), l.color, l.dashed, l.width));
    // A marker without text (the second of a ± pair) needs no entry of its own.
    let markers = panel.markers.iter().filter_map(|m| match m {
        Marker::Vertical(_, text) | Marker::Horizontal(_, text) => {
            (!text.is_empty()).then(|| (text.clone(), MARKER_GREY, true, 1.0))
        }
    });
    lines.chain(markers).collect()
}

/// Width of the legend column right of a panel's plot [SVG px]: the sample, a gap and the
/// longest label at ~7 px per character of the 13 px font.
fn legend_width(panel: &Panel) -> f64 {
    let chars = legend_entries(panel)
        .iter()
        .map(|e| e.0.chars().count())
        .max()
        .unwrap_or(0);
    40.0 + 7.0 * chars as f64
}

/// The legend in the column right of the plot, so it never covers data: each line's sample in
/// its own style (a dashed line's sample is dashed) and its label.
fn draw_legend<DB: DrawingBackend, CT: CoordTranslate>(
    area: &DrawingArea<DB, Shift>,
    chart: &ChartContext<DB, CT>,
    panel: &Panel,
    scale: f64,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let px = |v: f64| (v * scale).round() as i32;
    let (plot_x, plot_y) = chart.plotting_area().get_pixel_range();
    let (area_x, area_y) = area.get_pixel_range();
    let left = plot_x.end - area_x.start + px(10.0);
    let top = plot_y.start - area_y.start + px(4.0);
    let font = ("sans-serif", px(13.0) as u32).into_font();
    for (k, (label, color, dashed, width)) in legend_entries(panel).into_iter().enumerate() {
        let y = top + px(18.0) * k as i32 + px(8.0);
        let style = color.stroke_width((px(width) as u32).max(1));
        let sample = if dashed {
            vec![
                (left, y),
                (left + px(8.0), y),
                (left + px(14.0), y),
                (left + px(22.0), y),
            ]
        } else {
            vec![(left, y), (left + px(22.0), y)]
        };
        for pair in sample.chunks(2) {
            area.draw(&PathElement::new(pair.to_vec(), style))?;
        }
        area.draw(&Text::new(
            label,
            (left + px(28.0), y - px(7.0)),
            font.clone(),
        ))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pixels of the PNG of a one-panel figure: (width, height, RGB bytes).
    fn rendered(figure: &Figure) -> image::RgbImage {
        let dir = std::env::temp_dir().join(format!("cdpr-figure-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        render(figure, &dir).unwrap();
        let png = image::open(dir.join(format!("{}.png", figure.name)))
            .unwrap()
            .to_rgb8();
        let _ = std::fs::remove_dir_all(&dir);
        png
    }

    /// A dense zigzag (every turn acute, where a polyline's mitre joins spike in the bitmap
    /// backend: thousands of pixels over the tick labels in the report's Fig. 8) must stay
    /// inside the plot: no pixel of its colour above or below the plot's grid, or left of it,
    /// beyond the stroke's half width. The plot is found as the extent of the grid's light lines.
    #[test]
    fn png_draws_no_data_outside_the_plot() {
        let magenta = RGBColor(255, 0, 255);
        let points = (0..2000)
            .map(|k| {
                let sign = if k % 2 == 0 { -1.0 } else { 1.0 };
                (k as f64, sign * (1.0 + 0.3 * (k as f64 * 0.01).sin()))
            })
            .collect();
        let figure = Figure {
            name: "zigzag".into(),
            title: "zigzag".into(),
            panels: vec![Panel {
                x_label: "x".into(),
                y_label: "y".into(),
                log_x: false,
                log_y: false,
                lines: vec![Line {
                    label: "zigzag".into(),
                    color: magenta,
                    dashed: false,
                    width: LINE_WIDTH,
                    points,
                }],
                markers: vec![],
            }],
        };
        let png = rendered(&figure);
        let grid = |p: &image::Rgb<u8>| p.0 == [235, 235, 235];
        let (mut left, mut right, mut top, mut bottom) = (u32::MAX, 0, u32::MAX, 0);
        for (x, y, p) in png.enumerate_pixels() {
            if grid(p) {
                (left, right) = (left.min(x), right.max(x));
                (top, bottom) = (top.min(y), bottom.max(y));
            }
        }
        assert!(left < right && top < bottom, "no grid found");
        // Magenta at the lines' opacity over white or grid: red and blue high, green low.
        let line = |p: &image::Rgb<u8>| p.0[0] > 200 && p.0[2] > 200 && p.0[1] < 150;
        let slack = 3; // half the PNG stroke (3 px) rounded up
        let outside = png
            .enumerate_pixels()
            .filter(|(x, y, p)| {
                line(p)
                    && *x <= right
                    && (*x + slack < left || *y + slack < top || *y > bottom + slack)
            })
            .count();
        let inside = png.pixels().filter(|p| line(p)).count();
        assert!(inside > 10_000, "the zigzag was drawn ({inside} pixels)");
        assert_eq!(outside, 0, "pixels of data outside the plot");
    }
}
