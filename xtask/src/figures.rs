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
use cdpr_bench::analysis::metrics::PAD;
use cdpr_bench::analysis::spectrum::{Spectrum, Window};
use cdpr_bench::core::channel::Channel;
use cdpr_bench::core::runner::Run;
use cdpr_bench::core::trajectory::Step5;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::path::Path;
use std::sync::Once;

/// SVG size [px]; the PNG is twice as large.
const SIZE: (u32, u32) = (960, 640);
/// Points kept per line (two per pixel column of the SVG).
const MAX_POINTS: usize = 2 * SIZE.0 as usize;

/// One curve of a panel.
pub struct Line {
    pub label: String,
    pub color: RGBColor,
    pub dashed: bool,
    pub points: Vec<(f64, f64)>,
}

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
    pub run: &'a Run,
}

/// The colour of each model in every figure.
pub fn model_color(kind: ModelKind) -> RGBColor {
    match kind {
        ModelKind::Elastic => RGBColor(31, 119, 180),
        ModelKind::Lumped => RGBColor(214, 39, 40),
        ModelKind::Fe => RGBColor(44, 160, 44),
    }
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

/// Keeps at most [`MAX_POINTS`] points: per bucket of equal x width, the minimum and maximum in
/// their time order, so an oscillation keeps its envelope.
pub fn envelope(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    if points.len() <= MAX_POINTS {
        return points.to_vec();
    }
    let buckets = MAX_POINTS / 2;
    let per = points.len().div_ceil(buckets);
    let mut out = Vec::with_capacity(2 * buckets);
    for chunk in points.chunks(per) {
        let (mut lo, mut hi) = (0, 0);
        for (i, p) in chunk.iter().enumerate() {
            if p.1 < chunk[lo].1 {
                lo = i;
            }
            if p.1 > chunk[hi].1 {
                hi = i;
            }
        }
        let (a, b) = if lo <= hi { (lo, hi) } else { (hi, lo) };
        out.push(chunk[a]);
        if b != a {
            out.push(chunk[b]);
        }
    }
    out
}

/// `channel` of `run` against time, over [t0, t1] s, scaled by `scale`, thinned.
pub fn channel(run: &Run, channel: Channel, t0: f64, t1: f64, scale: f64) -> Vec<(f64, f64)> {
    let s = &run.series;
    let (Some(it), Some(iv)) = (s.index(Channel::Time), s.index(channel)) else {
        return Vec::new();
    };
    let points: Vec<(f64, f64)> = (0..s.len())
        .map(|i| s.row(i))
        .filter(|r| r[it] >= t0 && r[it] <= t1)
        .map(|r| (r[it], r[iv] * scale))
        .collect();
    envelope(&points)
}

/// The refined amplitude spectrum (Hann, 16× padding) of `channel` over [`from`, t_final) (the
/// metrics' settled window), as (ω, amplitude) with the maximum kept per logarithmic bucket
/// between `w0` and `w1` rad/s.
pub fn spectrum(
    run: &Run,
    channel: Channel,
    from: f64,
    dt: f64,
    (w0, w1): (f64, f64),
) -> Vec<(f64, f64)> {
    let (Some(t), Some(v)) = (run.series.column(Channel::Time), run.series.column(channel)) else {
        return Vec::new();
    };
    let t_end = t.last().copied().unwrap_or(0.0);
    let start = t.partition_point(|&x| x < from - 0.5 * dt);
    let end = t.partition_point(|&x| x < t_end - 0.5 * dt);
    if end <= start + 2 {
        return Vec::new();
    }
    let spec = Spectrum::new(&v[start..end], dt, Window::Hann, PAD);
    let buckets = MAX_POINTS;
    let (l0, l1) = (w0.ln(), w1.ln());
    let mut best = vec![(0.0f64, 0.0f64); buckets];
    for (k, &a) in spec.amplitude.iter().enumerate().skip(1) {
        let w = spec.omega(k);
        if w < w0 || w > w1 {
            continue;
        }
        let b = (((w.ln() - l0) / (l1 - l0)) * buckets as f64) as usize;
        let slot = &mut best[b.min(buckets - 1)];
        if a > slot.1 {
            *slot = (w, a);
        }
    }
    best.into_iter().filter(|p| p.1 > 0.0).collect()
}

/// The `step5` reference over [t1 − 0.05, t2 + 0.05] s as position, velocity and acceleration.
pub fn step5_lines(step5: &Step5) -> [Vec<(f64, f64)>; 3] {
    let span = step5.t2 - step5.t1;
    let (a, b) = (step5.t1 - 0.25 * span, step5.t2 + 0.25 * span);
    let ts: Vec<f64> = (0..=MAX_POINTS)
        .map(|k| a + (b - a) * k as f64 / MAX_POINTS as f64)
        .collect();
    [
        ts.iter().map(|&t| (t, step5.position(t))).collect(),
        ts.iter().map(|&t| (t, step5.velocity(t))).collect(),
        ts.iter().map(|&t| (t, step5.acceleration(t))).collect(),
    ]
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
    for (panel, area) in figure.panels.iter().zip(areas.iter()) {
        draw_panel(area, panel, scale).map_err(err)?;
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
    scale: f64,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let px = |v: f64| (v * scale).round() as u32;
    let tx = |x: f64| if panel.log_x { x.log10() } else { x };
    let ty = |y: f64| {
        if panel.log_y {
            y.abs().max(1e-300).log10()
        } else {
            y
        }
    };
    let valid = |p: &&(f64, f64)| (!panel.log_x || p.0 > 0.0) && (!panel.log_y || p.1 != 0.0);
    let all = || {
        panel
            .lines
            .iter()
            .flat_map(|l| l.points.iter().filter(valid))
    };
    let (mut x0, mut x1) = bounds(all().map(|p| tx(p.0)));
    let (mut y0, mut y1) = bounds(all().map(|p| ty(p.1)));
    if panel.log_x {
        (x0, x1) = (x0.floor(), x1.ceil());
    }
    if panel.log_y {
        (y0, y1) = (y0.floor(), y1.ceil());
    }
    for m in &panel.markers {
        match m {
            Marker::Horizontal(y, _) => (y0, y1) = (y0.min(ty(*y)), y1.max(ty(*y))),
            Marker::Vertical(x, _) => (x0, x1) = (x0.min(tx(*x)), x1.max(tx(*x))),
        }
    }
    let label_font = ("sans-serif", px(14.0)).into_font();
    let mut chart = ChartBuilder::on(area)
        .margin(px(8.0))
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
    let stroke = px(1.5);
    for m in &panel.markers {
        let grey = RGBColor(110, 110, 110).stroke_width(px(1.0));
        let (points, text, at) = match m {
            Marker::Vertical(x, text) => (vec![(tx(*x), y0), (tx(*x), y1)], text, (tx(*x), y1)),
            Marker::Horizontal(y, text) => (vec![(x0, ty(*y)), (x1, ty(*y))], text, (x0, ty(*y))),
        };
        chart.draw_series(DashedLineSeries::new(points, px(6.0), px(4.0), grey))?;
        chart.draw_series(std::iter::once(Text::new(
            format!(" {text}"),
            at,
            ("sans-serif", px(12.0))
                .into_font()
                .color(&RGBColor(80, 80, 80)),
        )))?;
    }
    for line in &panel.lines {
        let style = line.color.stroke_width(stroke);
        let pts: Vec<(f64, f64)> = line
            .points
            .iter()
            .filter(valid)
            .map(|p| (tx(p.0), ty(p.1)))
            .collect();
        let color = line.color;
        let legend = move |(x, y): (i32, i32)| {
            PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(3))
        };
        if line.dashed {
            chart
                .draw_series(DashedLineSeries::new(pts, px(8.0), px(5.0), style))?
                .label(line.label.as_str())
                .legend(legend);
        } else {
            chart
                .draw_series(LineSeries::new(pts, style))?
                .label(line.label.as_str())
                .legend(legend);
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font(label_font)
        .background_style(WHITE.mix(0.85))
        .border_style(RGBColor(160, 160, 160))
        .draw()?;
    Ok(())
}
