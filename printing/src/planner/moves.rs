//! One move of the toolhead's lookahead queue (Klipper's `toolhead.Move`): its speed limits in
//! squared velocity, the junction with the move before it, and, once the lookahead has chosen
//! its start, cruise and end speeds, its trapezoid.
//!
//! Junction speed ("approximated centripetal velocity", Klipper's docs/Kinematics.md): a corner
//! of angle θ between the moves' directions (cos θ = −u_prev · u) is taken at the speed of a
//! circle of radius R = δ sin(θ/2) / (1 − sin(θ/2)) with acceleration a, where the junction
//! deviation δ = scv² (√2 − 1) / a makes a 90° corner exactly scv (v² = R a). The circle may
//! not reach beyond either move's midpoint: v² ≤ Δv²/4 · tan(θ/2) with Δv² = 2 d a.

use super::Limits;
use crate::gcode::MoveKind;

/// A move in the queue, in the firmware's units: lengths [mm], speeds squared [mm²/s²]; the
/// filament (E) is axis 3.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct QueuedMove {
    pub tag: Tag,
    pub start: [f64; 4],
    /// The end position (an extrude-only move keeps the start's XYZ).
    pub end: [f64; 4],
    pub axes_d: [f64; 4],
    /// Unit direction (XYZ) and filament per metre of path (E).
    pub axes_r: [f64; 4],
    /// Path length [mm] (an extrude-only move: |ΔE|).
    pub move_d: f64,
    pub kinematic: bool,
    pub accel: f64,
    pub junction_deviation: f64,
    pub min_move_t: f64,
    pub max_start_v2: f64,
    pub max_cruise_v2: f64,
    pub delta_v2: f64,
    pub next_junction_v2: f64,
    pub max_mcr_start_v2: f64,
    pub mcr_delta_v2: f64,
    pub trapezoid: Trapezoid,
}

/// Where a move comes from: its line, what it prints, its layer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Tag {
    pub line: usize,
    pub kind: MoveKind,
    pub layer: usize,
}

/// The trapezoid the lookahead chose: phase durations [s] and speeds [mm/s].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Trapezoid {
    pub accel_t: f64,
    pub cruise_t: f64,
    pub decel_t: f64,
    pub start_v: f64,
    pub cruise_v: f64,
    pub end_v: f64,
}

/// Below this XYZ length [mm] a move only extrudes (Klipper's).
const KINEMATIC_LENGTH: f64 = 1e-9;
/// Klipper's acceleration of an extrude-only move before the extruder limits it [mm/s²].
const EXTRUDE_ONLY_ACCEL: f64 = 99_999_999.9;
/// Klipper's "no limit yet" on the next junction [mm²/s²].
const NO_JUNCTION_LIMIT: f64 = 999_999_999.9;

/// The toolhead's limits in force when a move is queued (M204 and SET_VELOCITY_LIMIT change
/// them between moves).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct InForce {
    pub max_velocity: f64,
    pub max_accel: f64,
    pub junction_deviation: f64,
    pub mcr_pseudo_accel: f64,
}

impl InForce {
    pub fn new(max_velocity: f64, max_accel: f64, scv: f64, minimum_cruise_ratio: f64) -> Self {
        InForce {
            max_velocity,
            max_accel,
            junction_deviation: scv * scv * (2f64.sqrt() - 1.0) / max_accel,
            mcr_pseudo_accel: max_accel * (1.0 - minimum_cruise_ratio),
        }
    }
}

impl QueuedMove {
    /// A move from `start` to `end` at the requested `speed` [mm/s]; `None` when it moves
    /// nothing (Klipper drops it and keeps its position).
    pub fn new(
        tag: Tag,
        start: [f64; 4],
        end: [f64; 4],
        speed: f64,
        limits: &InForce,
    ) -> Option<Self> {
        let mut axes_d = [0.0; 4];
        for i in 0..4 {
            axes_d[i] = end[i] - start[i];
        }
        let xyz = (axes_d[0] * axes_d[0] + axes_d[1] * axes_d[1] + axes_d[2] * axes_d[2]).sqrt();
        let mut end = end;
        let (move_d, kinematic, accel, velocity) = if xyz < KINEMATIC_LENGTH {
            axes_d[..3].fill(0.0);
            end[..3].copy_from_slice(&start[..3]);
            (axes_d[3].abs(), false, EXTRUDE_ONLY_ACCEL, speed)
        } else {
            (xyz, true, limits.max_accel, speed.min(limits.max_velocity))
        };
        if move_d == 0.0 {
            return None;
        }
        let inv = 1.0 / move_d;
        Some(QueuedMove {
            tag,
            start,
            end,
            axes_d,
            axes_r: axes_d.map(|d| d * inv),
            move_d,
            kinematic,
            accel,
            junction_deviation: limits.junction_deviation,
            min_move_t: move_d / velocity,
            max_start_v2: 0.0,
            max_cruise_v2: velocity * velocity,
            delta_v2: 2.0 * move_d * accel,
            next_junction_v2: NO_JUNCTION_LIMIT,
            max_mcr_start_v2: 0.0,
            mcr_delta_v2: 2.0 * move_d * limits.mcr_pseudo_accel,
            trapezoid: Trapezoid::default(),
        })
    }

    /// Lowers the cruise speed [mm/s] and the acceleration [mm/s²].
    pub fn limit_speed(&mut self, speed: f64, accel: f64) {
        let speed2 = speed * speed;
        if speed2 < self.max_cruise_v2 {
            self.max_cruise_v2 = speed2;
            self.min_move_t = self.move_d / speed;
        }
        self.accel = self.accel.min(accel);
        self.delta_v2 = 2.0 * self.move_d * self.accel;
        self.mcr_delta_v2 = self.mcr_delta_v2.min(self.delta_v2);
    }

    /// The extruder's check (Klipper's `PrinterExtruder.check_move`; `limits` in mm): extrude-only and
    /// retracting moves limited to the extrude-only velocity and acceleration; a printing move
    /// above the maximum cross-section refused unless it extrudes next to nothing.
    pub fn check_extrusion(&mut self, limits: &Limits) -> Result<(), super::PlanError> {
        let e = &limits.extruder;
        let area = limits.filament_area();
        let default_ratio = 4.0 * e.nozzle_diameter * e.nozzle_diameter / area;
        let max_ratio = e
            .max_extrude_cross_section
            .unwrap_or(4.0 * e.nozzle_diameter * e.nozzle_diameter)
            / area;
        let (axis_r, axis_d) = (self.axes_r[3], self.axes_d[3]);
        if (self.axes_d[0] == 0.0 && self.axes_d[1] == 0.0) || axis_r < 0.0 {
            if axis_d.abs() > e.max_extrude_only_distance {
                return Err(super::PlanError::Extrusion {
                    line: self.tag.line,
                    reason: format!(
                        "extrude-only move of {:.3} mm, longer than max_extrude_only_distance {:.3} mm",
                        axis_d, e.max_extrude_only_distance
                    ),
                });
            }
            let inv = 1.0 / axis_r.abs();
            let velocity = e
                .max_extrude_only_velocity
                .unwrap_or(limits.max_velocity * default_ratio);
            let accel = e
                .max_extrude_only_accel
                .unwrap_or(limits.max_accel * default_ratio);
            self.limit_speed(velocity * inv, accel * inv);
        } else if axis_r > max_ratio && axis_d > e.nozzle_diameter * max_ratio {
            return Err(super::PlanError::Extrusion {
                line: self.tag.line,
                reason: format!(
                    "extrusion of {:.3} mm² exceeds max_extrude_cross_section {:.3} mm²",
                    axis_r * area,
                    max_ratio * area
                ),
            });
        }
        Ok(())
    }

    /// The largest junction speed² from `prev` into this move (Klipper's `calc_junction`):
    /// both moves' cruise speeds, what `prev` can reach, the extruder's instantaneous corner
    /// velocity over the change of filament per metre, junction deviation and the mid-move
    /// circle of either move.
    pub fn calc_junction(&mut self, prev: &QueuedMove, instant_corner_v: f64) {
        if !self.kinematic || !prev.kinematic {
            return;
        }
        let diff_r = self.axes_r[3] - prev.axes_r[3];
        let extruder_v2 = if diff_r != 0.0 {
            (instant_corner_v / diff_r.abs()).powi(2)
        } else {
            self.max_cruise_v2
        };
        let mut max_start_v2 = self
            .max_cruise_v2
            .min(prev.max_cruise_v2)
            .min(prev.next_junction_v2)
            .min(prev.max_start_v2 + prev.delta_v2)
            .min(extruder_v2);
        let (u, w) = (&self.axes_r, &prev.axes_r);
        let cos_theta = -(u[0] * w[0] + u[1] * w[1] + u[2] * w[2]);
        let sin_half = (0.5 * (1.0 - cos_theta)).max(0.0).sqrt();
        let cos_half = (0.5 * (1.0 + cos_theta)).max(0.0).sqrt();
        let one_minus_sin_half = 1.0 - sin_half;
        if one_minus_sin_half > 0.0 && cos_half > 0.0 {
            let r_jd = sin_half / one_minus_sin_half;
            let quarter_tan_half = 0.25 * sin_half / cos_half;
            max_start_v2 = max_start_v2
                .min(r_jd * self.junction_deviation * self.accel)
                .min(r_jd * prev.junction_deviation * prev.accel)
                .min(self.delta_v2 * quarter_tan_half)
                .min(prev.delta_v2 * quarter_tan_half);
        }
        self.max_start_v2 = max_start_v2;
        self.max_mcr_start_v2 = max_start_v2.min(prev.max_mcr_start_v2 + prev.mcr_delta_v2);
    }

    /// The trapezoid of start, cruise and end speeds² (Klipper's `set_junction`): each phase's
    /// length over its mean speed.
    pub fn set_junction(&mut self, start_v2: f64, cruise_v2: f64, end_v2: f64) {
        let half_inv_accel = 0.5 / self.accel;
        let accel_d = (cruise_v2 - start_v2) * half_inv_accel;
        let decel_d = (cruise_v2 - end_v2) * half_inv_accel;
        let cruise_d = self.move_d - accel_d - decel_d;
        let (start_v, cruise_v, end_v) = (start_v2.sqrt(), cruise_v2.sqrt(), end_v2.sqrt());
        self.trapezoid = Trapezoid {
            accel_t: accel_d / ((start_v + cruise_v) * 0.5),
            cruise_t: cruise_d / cruise_v,
            decel_t: decel_d / ((end_v + cruise_v) * 0.5),
            start_v,
            cruise_v,
            end_v,
        };
    }
}
