//! A plan: the trapezoidal segments a firmware's step generators receive, and the reference
//! p(t), v(t), a(t) they describe (at rest between segments: dwells, extrude-only moves).

use super::moves::QueuedMove;
use crate::gcode::MoveKind;
use std::fmt::Write;

/// One moving segment (Klipper's `trapq_append` arguments, in SI, plus where it came from).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// Start time [s] (0 at the first move).
    pub t_start: f64,
    /// Acceleration phase [s].
    pub accel_t: f64,
    /// Cruise phase [s].
    pub cruise_t: f64,
    /// Deceleration phase [s].
    pub decel_t: f64,
    /// Start position [m] (the file's X, Y, Z).
    pub start: [f64; 3],
    /// Unit direction.
    pub dir: [f64; 3],
    /// Start speed [m/s].
    pub start_v: f64,
    /// Cruise speed [m/s].
    pub cruise_v: f64,
    /// End speed [m/s].
    pub end_v: f64,
    /// Acceleration of both ramps [m/s²].
    pub accel: f64,
    /// 1-based G-code line of the move.
    pub line: usize,
    /// What it prints.
    pub kind: MoveKind,
    /// Its layer.
    pub layer: usize,
}

impl Segment {
    /// The segment of a planned move (mm) in SI.
    pub(crate) fn of(m: &QueuedMove, t_start: f64) -> Segment {
        let t = &m.trapezoid;
        let si = |mm: f64| mm / 1000.0;
        Segment {
            t_start,
            accel_t: t.accel_t,
            cruise_t: t.cruise_t,
            decel_t: t.decel_t,
            start: [si(m.start[0]), si(m.start[1]), si(m.start[2])],
            dir: [m.axes_r[0], m.axes_r[1], m.axes_r[2]],
            start_v: si(t.start_v),
            cruise_v: si(t.cruise_v),
            end_v: si(t.end_v),
            accel: si(m.accel),
            line: m.tag.line,
            kind: m.tag.kind,
            layer: m.tag.layer,
        }
    }

    /// Duration [s].
    pub fn duration(&self) -> f64 {
        self.accel_t + self.cruise_t + self.decel_t
    }

    /// Path length [m] (the trapezoid's area).
    pub fn length(&self) -> f64 {
        0.5 * (self.start_v + self.cruise_v) * self.accel_t
            + self.cruise_v * self.cruise_t
            + 0.5 * (self.cruise_v + self.end_v) * self.decel_t
    }

    /// Distance along the segment [m], speed [m/s] and acceleration [m/s²] at `t` seconds into
    /// it (clamped to the segment), as Klipper's trapq evaluates it per phase.
    pub fn along(&self, t: f64) -> (f64, f64, f64) {
        let t = t.clamp(0.0, self.duration());
        if t < self.accel_t {
            let v = self.start_v + self.accel * t;
            return ((self.start_v + 0.5 * self.accel * t) * t, v, self.accel);
        }
        let accel_d = 0.5 * (self.start_v + self.cruise_v) * self.accel_t;
        let t = t - self.accel_t;
        if t < self.cruise_t {
            return (accel_d + self.cruise_v * t, self.cruise_v, 0.0);
        }
        let t = t - self.cruise_t;
        let cruise_d = accel_d + self.cruise_v * self.cruise_t;
        let v = self.cruise_v - self.accel * t;
        (
            cruise_d + (self.cruise_v - 0.5 * self.accel * t) * t,
            v,
            -self.accel,
        )
    }
}

/// A planned program.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Plan {
    /// Moving segments in time order.
    pub segments: Vec<Segment>,
    /// Total print time [s]: the last move's end, dwells and extrude-only moves included.
    pub print_time: f64,
}

/// The reference at one instant: position [m], velocity [m/s], acceleration [m/s²].
pub type Reference = ([f64; 3], [f64; 3], [f64; 3]);

impl Plan {
    /// Index of the segment running at `t` (the last one started by then), or `None` before
    /// the first.
    pub fn segment_at(&self, t: f64) -> Option<usize> {
        self.segments
            .partition_point(|s| s.t_start <= t)
            .checked_sub(1)
    }

    /// The plan's times [s] where its reference may jump in velocity or acceleration, ascending:
    /// every segment's start (a junction turns the velocity at the junction speed, Klipper's
    /// square-corner model) and the ends of its phases (the acceleration steps between ±a and
    /// 0). Between two consecutive times the reference is a polynomial of degree ≤ 2, so an
    /// error-controlled integrator that stops there never steps across a jump.
    pub fn breakpoints(&self) -> Vec<f64> {
        let mut times = Vec::with_capacity(4 * self.segments.len());
        for s in &self.segments {
            let accel_end = s.t_start + s.accel_t;
            let cruise_end = accel_end + s.cruise_t;
            times.extend([s.t_start, accel_end, cruise_end, cruise_end + s.decel_t]);
        }
        times.sort_by(f64::total_cmp);
        times.dedup();
        times
    }

    /// The reference at `t` [s]: on a segment, its trapezoid; between segments and after the
    /// last, at rest where the last one ended; before the first, at its start.
    pub fn reference(&self, t: f64) -> Option<Reference> {
        let first = self.segments.first()?;
        let Some(i) = self.segment_at(t) else {
            return Some((first.start, [0.0; 3], [0.0; 3]));
        };
        let s = &self.segments[i];
        let (d, v, a) = s.along(t - s.t_start);
        let at = |k: usize, x: f64| s.dir[k] * x;
        let (v, a) = if t - s.t_start >= s.duration() {
            (0.0, 0.0)
        } else {
            (v, a)
        };
        Some((
            [0, 1, 2].map(|k| s.start[k] + at(k, d)),
            [0, 1, 2].map(|k| at(k, v)),
            [0, 1, 2].map(|k| at(k, a)),
        ))
    }

    /// The part that prints `layers`: from the last rest before its first move to the first
    /// rest after its last, re-timed from 0 (None when those layers do not move).
    pub fn select_layers(&self, layers: std::ops::RangeInclusive<usize>) -> Option<Plan> {
        let s = &self.segments;
        let mut first = s.iter().position(|g| layers.contains(&g.layer))?;
        let mut last = s.iter().rposition(|g| layers.contains(&g.layer))?;
        while first > 0 && s[first].start_v > 0.0 {
            first -= 1;
        }
        while last + 1 < s.len() && s[last].end_v > 0.0 {
            last += 1;
        }
        let t0 = s[first].t_start;
        let segments: Vec<Segment> = s[first..=last]
            .iter()
            .map(|g| Segment {
                t_start: g.t_start - t0,
                ..*g
            })
            .collect();
        let end = segments.last().map_or(0.0, |g| g.t_start + g.duration());
        Some(Plan {
            segments,
            print_time: end,
        })
    }

    /// `plan.csv`: one row per moving segment, columns
    /// `t_start,accel_t,cruise_t,decel_t,start_x,start_y,start_z,dir_x,dir_y,dir_z,start_v,cruise_v,end_v,accel`
    /// (s, m, unit vector, m/s, m/s²), start positions offset by `origin` [m]; every number in
    /// the shortest form that reads back to the same f64.
    pub fn csv(&self, origin: [f64; 3]) -> String {
        let mut out = String::from(
            "t_start,accel_t,cruise_t,decel_t,start_x,start_y,start_z,dir_x,dir_y,dir_z,\
             start_v,cruise_v,end_v,accel\n",
        );
        for s in &self.segments {
            let row = [
                s.t_start,
                s.accel_t,
                s.cruise_t,
                s.decel_t,
                origin[0] + s.start[0],
                origin[1] + s.start[1],
                origin[2] + s.start[2],
                s.dir[0],
                s.dir[1],
                s.dir[2],
                s.start_v,
                s.cruise_v,
                s.end_v,
                s.accel,
            ];
            for (i, v) in row.iter().enumerate() {
                let sep = if i == 0 { "" } else { "," };
                let _ = write!(out, "{sep}{v:?}");
            }
            out.push('\n');
        }
        out
    }
}
