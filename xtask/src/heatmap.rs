//! Heat maps of a sweep: one panel per (row, column) group, cells coloured by log10 of a metric
//! over two axes, failed points marked with a cross, a shared colour bar. Used by the report's
//! parameter-study section.

use crate::figures::{Drawing, power_label};
use plotters::coord::Shift;
use plotters::prelude::*;

/// One panel: cells over (x, y) grid indices, the value (None: the point failed).
pub struct HeatPanel {
    pub title: String,
    /// Tick labels of the columns (x) and rows (y).
    pub x_labels: Vec<String>,
    pub y_labels: Vec<String>,
    /// values[iy][ix]
    pub values: Vec<Vec<Option<f64>>>,
}

/// Panels in a `rows × cols` layout sharing one logarithmic colour scale.
pub struct HeatMap {
    pub title: String,
    pub x_name: String,
    pub y_name: String,
    /// The metric and its unit, for the colour bar.
    pub value_name: String,
    pub rows: usize,
    pub cols: usize,
    pub panels: Vec<HeatPanel>,
}

impl HeatMap {
    /// log10 range of every finite positive value.
    fn range(&self) -> (f64, f64) {
        let logs = self
            .panels
            .iter()
            .flat_map(|p| p.values.iter().flatten().flatten())
            .filter(|v| v.is_finite() && **v > 0.0)
            .map(|v| v.log10());
        let (lo, hi) = logs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
        if !lo.is_finite() {
            (0.0, 1.0)
        } else if hi - lo < 1e-9 {
            (lo - 0.5, hi + 0.5)
        } else {
            (lo, hi)
        }
    }
}

/// The label of the cell whose centre is at `v` (ticks fall at cell centres and edges; edges
/// get none).
fn cell_label(labels: &[String], v: f64) -> String {
    let k = v.floor() as usize;
    if (v - k as f64 - 0.5).abs() < 1e-9 {
        labels.get(k).cloned().unwrap_or_default()
    } else {
        String::new()
    }
}

/// `v` with three significant digits ("0.0123", "4.56", "7.89e-6").
fn significant(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let exponent = v.abs().log10().floor() as i32;
    if (-2..3).contains(&exponent) {
        format!("{v:.*}", (2 - exponent).max(0) as usize)
    } else {
        format!("{v:.2e}")
    }
}

/// Viridis-like ramp from dark blue (0) to yellow (1).
fn color(f: f64) -> RGBColor {
    const STOPS: [(f64, [f64; 3]); 5] = [
        (0.0, [68.0, 1.0, 84.0]),
        (0.25, [59.0, 82.0, 139.0]),
        (0.5, [33.0, 145.0, 140.0]),
        (0.75, [94.0, 201.0, 98.0]),
        (1.0, [253.0, 231.0, 37.0]),
    ];
    let f = f.clamp(0.0, 1.0);
    let k = STOPS.iter().position(|s| s.0 >= f).unwrap_or(4).max(1);
    let (a, b) = (STOPS[k - 1], STOPS[k]);
    let t = (f - a.0) / (b.0 - a.0);
    let c = |i: usize| (a.1[i] + t * (b.1[i] - a.1[i])).round() as u8;
    RGBColor(c(0), c(1), c(2))
}

impl Drawing for HeatMap {
    fn draw_on<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        scale: f64,
    ) -> Result<(), String>
    where
        DB::ErrorType: 'static,
    {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| format!("{e:?}");
        let px = |v: f64| (v * scale).round() as u32;
        root.fill(&WHITE).map_err(err)?;
        let titled = root
            .titled(&self.title, ("sans-serif", px(18.0)).into_font())
            .map_err(err)?;
        let (plots, bar) = titled.split_horizontally(titled.dim_in_pixel().0 - px(110.0));
        let range = self.range();
        let areas = plots.split_evenly((self.rows, self.cols));
        for (panel, area) in self.panels.iter().zip(areas.iter()) {
            self.draw_panel(panel, area, range, scale).map_err(err)?;
        }
        self.draw_colour_bar(&bar, range, scale).map_err(err)
    }
}

impl HeatMap {
    /// One panel's cells, coloured by log10 of the value on `lo..hi`; a cell without a positive
    /// finite value crossed out.
    fn draw_panel<DB: DrawingBackend>(
        &self,
        panel: &HeatPanel,
        area: &DrawingArea<DB, Shift>,
        (lo, hi): (f64, f64),
        scale: f64,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let px = |v: f64| (v * scale).round() as u32;
        let nx = panel.x_labels.len();
        let ny = panel.y_labels.len();
        let mut chart = ChartBuilder::on(area)
            .caption(&panel.title, ("sans-serif", px(14.0)).into_font())
            .margin(px(6.0))
            .x_label_area_size(px(34.0))
            .y_label_area_size(px(44.0))
            .build_cartesian_2d(0.0..nx as f64, 0.0..ny as f64)?;
        let xl = |v: &f64| cell_label(&panel.x_labels, *v);
        let yl = |v: &f64| cell_label(&panel.y_labels, *v);
        chart
            .configure_mesh()
            .disable_mesh()
            .x_labels(2 * nx + 1)
            .y_labels(2 * ny + 1)
            .x_label_formatter(&xl)
            .y_label_formatter(&yl)
            .x_desc(&self.x_name)
            .y_desc(&self.y_name)
            .label_style(("sans-serif", px(11.0)).into_font())
            .axis_desc_style(("sans-serif", px(12.0)).into_font())
            .draw()?;
        for (iy, row) in panel.values.iter().enumerate() {
            for (ix, v) in row.iter().enumerate() {
                let (x, y) = (ix as f64, iy as f64);
                match v {
                    Some(v) if v.is_finite() && *v > 0.0 => {
                        let f = (v.log10() - lo) / (hi - lo);
                        chart.draw_series(std::iter::once(Rectangle::new(
                            [(x, y), (x + 1.0, y + 1.0)],
                            color(f).filled(),
                        )))?;
                    }
                    _ => {
                        let grey = RGBColor(160, 160, 160);
                        chart.draw_series([
                            PathElement::new(
                                vec![(x + 0.2, y + 0.2), (x + 0.8, y + 0.8)],
                                grey.stroke_width(px(2.0)),
                            ),
                            PathElement::new(
                                vec![(x + 0.2, y + 0.8), (x + 0.8, y + 0.2)],
                                grey.stroke_width(px(2.0)),
                            ),
                        ])?;
                    }
                }
            }
        }
        Ok(())
    }

    /// The colour bar: log10 of the value on `lo..hi`.
    fn draw_colour_bar<DB: DrawingBackend>(
        &self,
        bar: &DrawingArea<DB, Shift>,
        (lo, hi): (f64, f64),
        scale: f64,
    ) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let px = |v: f64| (v * scale).round() as u32;
        let mut chart = ChartBuilder::on(bar)
            .margin(px(20.0))
            .margin_left(px(10.0))
            .y_label_area_size(px(50.0))
            .caption(&self.value_name, ("sans-serif", px(12.0)).into_font())
            .build_cartesian_2d(0.0..1.0, lo..hi)?;
        // Under a decade, powers of ten would leave the bar unlabelled: label values instead.
        let narrow = hi - lo < 1.0;
        let label = |v: &f64| {
            if narrow {
                significant(10f64.powf(*v))
            } else {
                power_label(v)
            }
        };
        chart
            .configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_labels(if narrow {
                6
            } else {
                ((hi - lo).ceil() as usize + 1).max(2)
            })
            .y_label_formatter(&label)
            .label_style(("sans-serif", px(11.0)).into_font())
            .draw()?;
        let steps = 64;
        for k in 0..steps {
            let (a, b) = (k as f64 / steps as f64, (k + 1) as f64 / steps as f64);
            chart.draw_series(std::iter::once(Rectangle::new(
                [(0.0, lo + a * (hi - lo)), (1.0, lo + b * (hi - lo))],
                color(0.5 * (a + b)).filled(),
            )))?;
        }
        Ok(())
    }
}
