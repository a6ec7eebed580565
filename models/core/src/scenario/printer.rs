//! `[printer]`: what the firmware of a printing robot is told (Klipper's `[printer]`,
//! `[extruder]` and `[input_shaper]` sections, in SI) and where the G-code's coordinates sit in
//! the robot's frame. Only `cargo xtask plan` and `print` read it.

use super::{Designed, ScenarioError, finite, non_negative, out_of_range};
use cdpr_printing::planner::{ExtruderLimits, Limits};
use cdpr_printing::shaper::Shaper;
use serde::Deserialize;

/// The input shaper a firmware applies per Cartesian axis (Klipper's names and definitions).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FirmwareShaper {
    #[default]
    None,
    Zv,
    Mzv,
    Zvd,
    Ei,
    #[serde(rename = "2hump_ei")]
    TwoHumpEi,
    #[serde(rename = "3hump_ei")]
    ThreeHumpEi,
}

impl FirmwareShaper {
    /// The scenario file's (and Klipper's) spelling.
    pub fn name(self) -> &'static str {
        match self {
            FirmwareShaper::None => "none",
            FirmwareShaper::Zv => "zv",
            FirmwareShaper::Mzv => "mzv",
            FirmwareShaper::Zvd => "zvd",
            FirmwareShaper::Ei => "ei",
            FirmwareShaper::TwoHumpEi => "2hump_ei",
            FirmwareShaper::ThreeHumpEi => "3hump_ei",
        }
    }

    /// The design whose pulses it applies (None: unshaped).
    pub fn pulses_of(self) -> Option<Shaper> {
        match self {
            FirmwareShaper::None => None,
            FirmwareShaper::Zv => Some(Shaper::Zv),
            FirmwareShaper::Mzv => Some(Shaper::Mzv),
            FirmwareShaper::Zvd => Some(Shaper::Zvd),
            FirmwareShaper::Ei => Some(Shaper::Ei),
            FirmwareShaper::TwoHumpEi => Some(Shaper::TwoHumpEi),
            FirmwareShaper::ThreeHumpEi => Some(Shaper::ThreeHumpEi),
        }
    }
}

/// `[printer]`; every key optional.
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(default, deny_unknown_fields)]
pub struct Printer {
    /// Where the file's (0, 0, 0) sits in the robot's frame [m]: [x, y, z], or [x, z] for the
    /// planar robot, which prints the file's X and Z. Default: the origin.
    pub origin: Vec<f64>,
    /// max_velocity [m/s] (default 0.3).
    pub max_velocity: f64,
    /// max_accel [m/s²] (default 3; M204 in the file overrides it as in Klipper).
    pub max_accel: f64,
    /// square_corner_velocity [m/s] (Klipper: 0.005).
    pub square_corner_velocity: f64,
    /// minimum_cruise_ratio (Klipper: 0.5).
    pub minimum_cruise_ratio: f64,
    /// nozzle_diameter [m] (0.4 mm).
    pub nozzle_diameter: f64,
    /// filament_diameter [m] (1.75 mm).
    pub filament_diameter: f64,
    /// instantaneous_corner_velocity [m/s] (Klipper: 0.001).
    pub instantaneous_corner_velocity: f64,
    /// max_extrude_cross_section [m²] (Klipper: 4 nozzle_diameter²).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_extrude_cross_section: Option<f64>,
    /// max_extrude_only_velocity [m/s] (Klipper: derived from max_velocity).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_extrude_only_velocity: Option<f64>,
    /// max_extrude_only_accel [m/s²] (Klipper: derived from max_accel).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_extrude_only_accel: Option<f64>,
    /// max_extrude_only_distance [m] (Klipper: 0.05).
    pub max_extrude_only_distance: f64,
    /// The input shaper of every axis (Klipper's `shaper_type`).
    pub shaper: FirmwareShaper,
    /// shaper_freq_x [Hz] or "auto" (from the robot's modes at the layer's centre); 0 leaves
    /// the axis unshaped (Klipper's convention).
    pub shaper_freq_x: Designed,
    /// shaper_freq_y [Hz] or "auto".
    pub shaper_freq_y: Designed,
    /// shaper_freq_z [Hz] or "auto".
    pub shaper_freq_z: Designed,
    /// damping_ratio of the shapers (Klipper: 0.1).
    pub damping_ratio: f64,
}

impl Default for Printer {
    fn default() -> Self {
        let e = ExtruderLimits::default();
        Printer {
            origin: vec![0.0; 3],
            max_velocity: 0.3,
            max_accel: 3.0,
            square_corner_velocity: 0.005,
            minimum_cruise_ratio: 0.5,
            nozzle_diameter: e.nozzle_diameter,
            filament_diameter: e.filament_diameter,
            instantaneous_corner_velocity: e.instantaneous_corner_velocity,
            max_extrude_cross_section: None,
            max_extrude_only_velocity: None,
            max_extrude_only_accel: None,
            max_extrude_only_distance: e.max_extrude_only_distance,
            shaper: FirmwareShaper::None,
            shaper_freq_x: Designed::default(),
            shaper_freq_y: Designed::default(),
            shaper_freq_z: Designed::default(),
            damping_ratio: 0.1,
        }
    }
}

impl Printer {
    /// The planner's limits.
    pub fn limits(&self) -> Limits {
        Limits {
            max_velocity: self.max_velocity,
            max_accel: self.max_accel,
            square_corner_velocity: self.square_corner_velocity,
            minimum_cruise_ratio: self.minimum_cruise_ratio,
            extruder: ExtruderLimits {
                nozzle_diameter: self.nozzle_diameter,
                filament_diameter: self.filament_diameter,
                max_extrude_cross_section: self.max_extrude_cross_section,
                max_extrude_only_velocity: self.max_extrude_only_velocity,
                max_extrude_only_accel: self.max_extrude_only_accel,
                max_extrude_only_distance: self.max_extrude_only_distance,
                instantaneous_corner_velocity: self.instantaneous_corner_velocity,
            },
        }
    }

    /// The origin as a 3-vector [m] (a planar robot's [x, z] with y = 0).
    pub fn origin3(&self) -> [f64; 3] {
        match self.origin.as_slice() {
            [x, z] => [*x, 0.0, *z],
            [x, y, z] => [*x, *y, *z],
            _ => [0.0; 3],
        }
    }

    /// Every key in range, for a robot of `dimension` (2: planar, 3: spatial).
    pub fn validate(&self, dimension: usize) -> Result<(), ScenarioError> {
        if self.origin.len() != dimension || !self.origin.iter().all(|v| v.is_finite()) {
            let allowed = if dimension == 2 {
                "[x, z] m (the planar robot prints the file's X and Z)"
            } else {
                "[x, y, z] m"
            };
            return Err(out_of_range(
                "printer.origin",
                format!("{:?}", self.origin),
                allowed,
            ));
        }
        self.limits().validate().map_err(|e| match e {
            cdpr_printing::planner::PlanError::Limit {
                key,
                value,
                allowed,
            } => out_of_range(key, value, allowed),
            other => out_of_range("printer", other.to_string(), "valid limits"),
        })?;
        non_negative("printer.damping_ratio", self.damping_ratio)?;
        if self.damping_ratio >= 1.0 {
            return Err(out_of_range(
                "printer.damping_ratio",
                self.damping_ratio,
                "0 ≤ ζ < 1",
            ));
        }
        for (key, f) in [
            ("printer.shaper_freq_x", self.shaper_freq_x),
            ("printer.shaper_freq_y", self.shaper_freq_y),
            ("printer.shaper_freq_z", self.shaper_freq_z),
        ] {
            if let Designed::Value(hz) = f {
                finite(key, hz)?;
                non_negative(key, hz)?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::scenario::Scenario;

    const SPATIAL: &str = "[robot]\nanchors = [[0.0, -1.6, -0.1], [1.3, 1.3, -0.1], \
        [-1.4, 0.7, -0.1], [0.0, 0.0, 2.3]]\n[controller]\nkind = \"computed-torque\"\n\
        t_min = 10.0\nt_max = 70.0\n[trajectory]\nstart = [0.0, 0.0, 0.0]\nend = [0.0, 0.0, 0.0]\n";

    /// Every `[printer]` key out of its range is refused by name, with its value and range,
    /// before any work; a valid section reads back in SI.
    #[test]
    fn printer_keys_are_checked_by_name() {
        for (line, key) in [
            ("max_accel = -1.0", "printer.max_accel"),
            ("max_velocity = 0.0", "printer.max_velocity"),
            ("minimum_cruise_ratio = 1.0", "printer.minimum_cruise_ratio"),
            (
                "square_corner_velocity = -0.001",
                "printer.square_corner_velocity",
            ),
            ("filament_diameter = 0.0001", "printer.filament_diameter"),
            (
                "max_extrude_only_accel = 0.0",
                "printer.max_extrude_only_accel",
            ),
            ("origin = [0.0, 0.0]", "printer.origin"),
            ("shaper_freq_x = -20.0", "printer.shaper_freq_x"),
            ("damping_ratio = 1.0", "printer.damping_ratio"),
        ] {
            let text = format!("{SPATIAL}[printer]\n{line}\n");
            let err = Scenario::from_toml_str(&text).unwrap_err().to_string();
            assert!(err.contains(key), "{line}: {err}");
        }
        let ok = Scenario::from_toml_str(&format!(
            "{SPATIAL}[printer]\norigin = [-0.1, -0.1, 0.0]\nmax_accel = 5.0\nshaper = \"mzv\"\n\
             shaper_freq_x = 0.0\nshaper_freq_y = 40.0\n"
        ))
        .unwrap();
        let p = ok.printer.unwrap();
        assert_eq!(p.origin3(), [-0.1, -0.1, 0.0]);
        assert_eq!(p.limits().max_accel, 5.0);
        assert_eq!(p.limits().max_velocity, 0.3, "Klipper-like default");
        // The names are the file's words (serde's spelling).
        for shaper in [super::FirmwareShaper::Mzv, super::FirmwareShaper::TwoHumpEi] {
            let text = format!("{SPATIAL}[printer]\nshaper = \"{}\"\n", shaper.name());
            let read = Scenario::from_toml_str(&text)
                .unwrap()
                .printer
                .unwrap()
                .shaper;
            assert_eq!(read, shaper);
        }
    }
}
