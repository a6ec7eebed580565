//! A spatial robot drawn in 3-D: its anchors, its cables from pulley to effector with their sag
//! magnified (each point's offset from the chord scaled, so that 0.2 mm of sag on a 1.5 m line
//! shows), the effector and its path so far. One picture as SVG and PNG ([`render_drawing`]),
//! or a run's frames as an animated GIF ([`write_gif`]).

use crate::figures::{Drawing, register_fonts};
use crate::spatial_figures::CABLE_COLORS;
use anyhow::{Context, Result, anyhow};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// One picture of the robot.
pub struct RobotPicture {
    pub title: String,
    /// Pulleys A_i [m].
    pub anchors: Vec<[f64; 3]>,
    /// Per cable, its points from the pulley to the effector [m], sag already magnified.
    pub cables: Vec<Vec<[f64; 3]>>,
    /// The effector's path so far [m] (may be empty).
    pub trail: Vec<[f64; 3]>,
}

/// `path` (pulley first, effector last) with each point's offset from the straight chord
/// between its ends multiplied by `factor`: the chord point is the point's projection on it.
pub fn magnify(path: &[[f64; 3]], factor: f64) -> Vec<[f64; 3]> {
    let (Some(a), Some(b)) = (path.first(), path.last()) else {
        return Vec::new();
    };
    let d: [f64; 3] = std::array::from_fn(|k| b[k] - a[k]);
    let dd: f64 = d.iter().map(|v| v * v).sum();
    path.iter()
        .map(|q| {
            let s = if dd > 0.0 {
                (0..3).map(|k| (q[k] - a[k]) * d[k]).sum::<f64>() / dd
            } else {
                0.0
            };
            std::array::from_fn(|k| {
                let chord = a[k] + s * d[k];
                chord + factor * (q[k] - chord)
            })
        })
        .collect()
}

/// The box around the anchors [m], as drawn (x, vertical, y): plotters' 3-D charts draw their
/// second axis upwards.
fn bounds(anchors: &[[f64; 3]]) -> [(f64, f64); 3] {
    std::array::from_fn(|k| {
        let (lo, hi) = anchors
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), a| {
                (l.min(a[k]), h.max(a[k]))
            });
        let pad = 0.05 * (hi - lo).max(1e-3);
        (lo - pad, hi + pad)
    })
}

/// A point [m] in the chart's axes (x, vertical z, y).
fn drawn(p: &[f64; 3]) -> (f64, f64, f64) {
    (p[0], p[2], p[1])
}

impl Drawing for RobotPicture {
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
        let [x, y, z] = bounds(&self.anchors);
        let mut chart = ChartBuilder::on(root)
            .caption(
                format!("{} (x, y horizontal, z up; m)", self.title),
                ("sans-serif", px(16.0)).into_font(),
            )
            .margin(px(12.0))
            .build_cartesian_3d(x.0..x.1, z.0..z.1, y.0..y.1)
            .map_err(err)?;
        chart.with_projection(|mut p| {
            p.pitch = 0.35;
            p.yaw = 0.65;
            p.scale = 0.8;
            p.into_matrix()
        });
        chart
            .configure_axes()
            .label_style(("sans-serif", px(11.0)).into_font())
            .max_light_lines(2)
            .draw()
            .map_err(err)?;
        for (i, cable) in self.cables.iter().enumerate() {
            let color = CABLE_COLORS[i % CABLE_COLORS.len()];
            chart
                .draw_series(LineSeries::new(
                    cable.iter().map(drawn),
                    color.stroke_width(px(1.5)),
                ))
                .map_err(err)?;
        }
        if self.trail.len() > 1 {
            chart
                .draw_series(LineSeries::new(
                    self.trail.iter().map(drawn),
                    BLACK.stroke_width(px(1.0)),
                ))
                .map_err(err)?;
        }
        let effector = self.cables.first().and_then(|c| c.last());
        chart
            .draw_series(
                self.anchors
                    .iter()
                    .map(|a| Circle::new(drawn(a), px(4.0), BLACK.filled())),
            )
            .map_err(err)?;
        if let Some(e) = effector {
            chart
                .draw_series(std::iter::once(Circle::new(
                    drawn(e),
                    px(5.0),
                    RGBColor(200, 0, 0).filled(),
                )))
                .map_err(err)?;
        }
        Ok(())
    }
}

/// The GIF's size [px] and the delay between its frames [ms].
const GIF_SIZE: (u32, u32) = (640, 480);

/// Writes `frames` as an animated GIF at `path` (atomically: drawn beside it, then renamed),
/// `delay_ms` between frames.
pub fn write_gif(frames: &[RobotPicture], path: &Path, delay_ms: u32) -> Result<()> {
    register_fonts();
    let name = path
        .file_name()
        .map_or("robot.gif".into(), |n| n.to_string_lossy().into_owned());
    let tmp = path.with_file_name(format!(".{name}.tmp-{}.gif", std::process::id()));
    let drawn = (|| -> std::result::Result<(), String> {
        let root = BitMapBackend::gif(&tmp, GIF_SIZE, delay_ms)
            .map_err(|e| format!("{e:?}"))?
            .into_drawing_area();
        for frame in frames {
            frame.draw_on(&root, 1.0)?;
            root.present().map_err(|e| format!("{e:?}"))?;
        }
        Ok(())
    })();
    if let Err(e) = drawn {
        let _ = std::fs::remove_file(&tmp);
        return Err(anyhow!("drawing {}: {e}", path.display()));
    }
    std::fs::rename(&tmp, path).with_context(|| format!("writing {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::magnify;

    /// Points on the chord stay; an offset from it scales by the factor, along the chord's
    /// normal; factor 1 draws the line as it is.
    #[test]
    fn magnify_scales_the_offset_from_the_chord() {
        let path = [
            [0.0, 0.0, 2.0],
            [0.5, 0.1, 1.5],
            [1.0, 0.0, 1.0],
            [2.0, 0.0, 0.0],
        ];
        assert_eq!(magnify(&path, 1.0), path.to_vec());
        let drawn = magnify(&path, 10.0);
        assert_eq!(drawn[0], path[0]);
        assert_eq!(drawn[3], path[3]);
        assert_eq!(drawn[2], path[2], "a point on the chord stays");
        // (0.5, 0.1, 1.5) lies 0.1 off the chord along y, beside its point (0.5, 0, 1.5).
        for (k, expected) in [0.5, 1.0, 1.5].into_iter().enumerate() {
            assert!((drawn[1][k] - expected).abs() < 1e-12, "{:?}", drawn[1]);
        }
    }
}
