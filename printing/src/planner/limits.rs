//! The printer's limits, as Klipper's `[printer]` and `[extruder]` sections give them, in SI.

use thiserror::Error;

/// Toolhead limits (Klipper's `[printer]`): the defaults are Klipper's where it has one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// max_velocity [m/s] (Klipper: required).
    pub max_velocity: f64,
    /// max_accel [m/s²] (Klipper: required).
    pub max_accel: f64,
    /// square_corner_velocity [m/s]: the junction speed of a 90° corner (Klipper: 5 mm/s).
    pub square_corner_velocity: f64,
    /// minimum_cruise_ratio [-]: the share of a move's length it must be able to cruise
    /// (Klipper: 0.5).
    pub minimum_cruise_ratio: f64,
    /// The extruder's limits.
    pub extruder: ExtruderLimits,
}

/// Extruder limits (Klipper's `[extruder]`); `None` derives the value as Klipper does.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExtruderLimits {
    /// nozzle_diameter [m] (0.4 mm).
    pub nozzle_diameter: f64,
    /// filament_diameter [m] (1.75 mm).
    pub filament_diameter: f64,
    /// max_extrude_cross_section [m²] (Klipper: 4 nozzle_diameter²).
    pub max_extrude_cross_section: Option<f64>,
    /// max_extrude_only_velocity [m/s] (Klipper: max_velocity × 4 nozzle² / filament area).
    pub max_extrude_only_velocity: Option<f64>,
    /// max_extrude_only_accel [m/s²] (Klipper: max_accel × the same ratio).
    pub max_extrude_only_accel: Option<f64>,
    /// max_extrude_only_distance [m] (Klipper: 50 mm).
    pub max_extrude_only_distance: f64,
    /// instantaneous_corner_velocity [m/s] (Klipper: 1 mm/s).
    pub instantaneous_corner_velocity: f64,
}

impl Default for ExtruderLimits {
    fn default() -> Self {
        ExtruderLimits {
            nozzle_diameter: 0.4e-3,
            filament_diameter: 1.75e-3,
            max_extrude_cross_section: None,
            max_extrude_only_velocity: None,
            max_extrude_only_accel: None,
            max_extrude_only_distance: 0.05,
            instantaneous_corner_velocity: 1e-3,
        }
    }
}

impl Limits {
    /// Limits of `max_velocity` [m/s] and `max_accel` [m/s²] with Klipper's other defaults.
    pub fn new(max_velocity: f64, max_accel: f64) -> Self {
        Limits {
            max_velocity,
            max_accel,
            square_corner_velocity: 5e-3,
            minimum_cruise_ratio: 0.5,
            extruder: ExtruderLimits::default(),
        }
    }

    /// Refuses a value outside Klipper's range, naming the `[printer]` key.
    pub fn validate(&self) -> Result<(), PlanError> {
        let e = &self.extruder;
        let optional_positive = |v: Option<f64>| (v.unwrap_or(1.0), v.is_none_or(|v| v > 0.0));
        let (cross, cross_ok) = optional_positive(e.max_extrude_cross_section);
        let (e_velocity, e_velocity_ok) = optional_positive(e.max_extrude_only_velocity);
        let (e_accel, e_accel_ok) = optional_positive(e.max_extrude_only_accel);
        #[rustfmt::skip]
        let checks: [(&'static str, f64, bool, &str); 11] = [
            ("printer.max_velocity", self.max_velocity, self.max_velocity > 0.0, "> 0 m/s"),
            ("printer.max_accel", self.max_accel, self.max_accel > 0.0, "> 0 m/s²"),
            ("printer.square_corner_velocity", self.square_corner_velocity,
                self.square_corner_velocity >= 0.0, "≥ 0 m/s"),
            ("printer.minimum_cruise_ratio", self.minimum_cruise_ratio,
                (0.0..1.0).contains(&self.minimum_cruise_ratio), "0 ≤ ratio < 1"),
            ("printer.nozzle_diameter", e.nozzle_diameter, e.nozzle_diameter > 0.0, "> 0 m"),
            ("printer.filament_diameter", e.filament_diameter,
                e.filament_diameter >= e.nozzle_diameter, "≥ nozzle_diameter"),
            ("printer.max_extrude_cross_section", cross, cross_ok, "> 0 m²"),
            ("printer.max_extrude_only_velocity", e_velocity, e_velocity_ok, "> 0 m/s"),
            ("printer.max_extrude_only_accel", e_accel, e_accel_ok, "> 0 m/s²"),
            ("printer.max_extrude_only_distance", e.max_extrude_only_distance,
                e.max_extrude_only_distance >= 0.0, "≥ 0 m"),
            ("printer.instantaneous_corner_velocity", e.instantaneous_corner_velocity,
                e.instantaneous_corner_velocity >= 0.0, "≥ 0 m/s"),
        ];
        for (key, value, ok, allowed) in checks {
            if !ok || !value.is_finite() {
                return Err(PlanError::Limit {
                    key,
                    value,
                    allowed: allowed.to_string(),
                });
            }
        }
        Ok(())
    }

    /// The same limits in the firmware's units (mm, mm/s, mm/s², mm²), in which the planner
    /// computes (see [`crate::gcode`] on why).
    pub(crate) fn in_millimetres(&self) -> Limits {
        let e = &self.extruder;
        let mm = |v: f64| v * 1e3;
        Limits {
            max_velocity: mm(self.max_velocity),
            max_accel: mm(self.max_accel),
            square_corner_velocity: mm(self.square_corner_velocity),
            minimum_cruise_ratio: self.minimum_cruise_ratio,
            extruder: ExtruderLimits {
                nozzle_diameter: mm(e.nozzle_diameter),
                filament_diameter: mm(e.filament_diameter),
                max_extrude_cross_section: e.max_extrude_cross_section.map(|a| a * 1e6),
                max_extrude_only_velocity: e.max_extrude_only_velocity.map(mm),
                max_extrude_only_accel: e.max_extrude_only_accel.map(mm),
                max_extrude_only_distance: mm(e.max_extrude_only_distance),
                instantaneous_corner_velocity: mm(e.instantaneous_corner_velocity),
            },
        }
    }

    /// Filament cross-section (in the limits' units squared).
    pub(crate) fn filament_area(&self) -> f64 {
        std::f64::consts::PI * (self.extruder.filament_diameter * 0.5).powi(2)
    }
}

/// Why a program cannot be planned.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PlanError {
    /// A limit outside its range.
    #[error("{key} = {value} is out of range: allowed {allowed}")]
    Limit {
        /// The key, e.g. `printer.max_accel`.
        key: &'static str,
        /// Its value (SI).
        value: f64,
        /// The allowed range.
        allowed: String,
    },
    /// A move the extruder refuses (Klipper's "Move exceeds maximum extrusion" and
    /// "Extrude only move too long").
    #[error("G-code line {line}: {reason}")]
    Extrusion {
        /// 1-based line of the move.
        line: usize,
        /// What limit it breaks, with the numbers.
        reason: String,
    },
}
