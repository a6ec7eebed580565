//! The commands the reader carries out, each as Klipper's `gcode_move` and `toolhead` define it.

use super::words::Line;
use super::{GcodeError, Instruction, LimitChange, Move, MoveKind, Reader};

impl Reader {
    /// G0/G1: X Y Z absolute (to the base position) or relative (G91); E relative under G91 or
    /// M83; F [mm/min] must be positive. A line that changes nothing gives no move.
    pub(super) fn linear_move(
        &mut self,
        number: usize,
        text: &str,
        line: &Line,
    ) -> Result<Option<Instruction>, GcodeError> {
        let start = self.last;
        for (letter, value) in line.parameters(number, text)? {
            let value = required(number, text, letter, value)?;
            match letter {
                'X' | 'Y' | 'Z' => {
                    let axis = (letter as u8 - b'X') as usize;
                    self.last[axis] = if self.absolute_coordinates {
                        value + self.base[axis]
                    } else {
                        self.last[axis] + value
                    };
                }
                'E' => {
                    let value = value * self.extrude_factor;
                    self.last[3] = if self.absolute_coordinates && self.absolute_extrusion {
                        value + self.base[3]
                    } else {
                        self.last[3] + value
                    };
                }
                'F' => {
                    if value <= 0.0 {
                        return Err(out_of_range(number, text, "F", value, "> 0 mm/min"));
                    }
                    self.speed = value * self.speed_factor;
                }
                other => return Err(unknown_parameter(number, text, other, "X, Y, Z, E, F")),
            }
        }
        if self.last == start {
            return Ok(None);
        }
        let moves = (0..3).any(|i| self.last[i] != start[i]);
        let kind = if moves && self.last[3] > start[3] {
            self.kind
        } else {
            MoveKind::Travel
        };
        Ok(Some(Instruction::Move(Move {
            line: number,
            end: self.last,
            speed: self.speed,
            kind,
            layer: self.layer,
        })))
    }

    /// G4 P milliseconds (0 without P). Klipper reads no S: a Marlin-style `G4 S2` would dwell
    /// 0 s there, so it is refused rather than read either way.
    pub(super) fn dwell(
        &mut self,
        number: usize,
        text: &str,
        line: &Line,
    ) -> Result<Instruction, GcodeError> {
        let mut millis = 0.0;
        for (letter, value) in line.parameters(number, text)? {
            let value = required(number, text, letter, value)?;
            match letter {
                'P' if value < 0.0 => {
                    return Err(out_of_range(number, text, "P", value, "≥ 0 ms"));
                }
                'P' => millis = value,
                'S' => {
                    return Err(GcodeError::Unsupported {
                        line: number,
                        text: text.to_string(),
                        command: "G4 S".to_string(),
                        hint: "Klipper dwells by P (milliseconds) only: write G4 P…".to_string(),
                    });
                }
                other => return Err(unknown_parameter(number, text, other, "P")),
            }
        }
        Ok(Instruction::Dwell {
            line: number,
            seconds: millis / 1000.0,
        })
    }

    /// G28 [X] [Y] [Z]: the named axes (all when none is named) go to the home position.
    pub(super) fn home(
        &mut self,
        number: usize,
        text: &str,
        line: &Line,
    ) -> Result<Instruction, GcodeError> {
        let words = line.parameters(number, text)?;
        let mut axes = [words.is_empty(); 3];
        for (letter, _) in words {
            match letter {
                'X' | 'Y' | 'Z' => axes[(letter as u8 - b'X') as usize] = true,
                other => return Err(unknown_parameter(number, text, other, "X, Y, Z")),
            }
        }
        for (axis, homed) in axes.into_iter().enumerate() {
            if homed {
                self.last[axis] = self.home[axis];
                // Homing clears G92's offset of the axis (Klipper: home_rails_end).
                self.base[axis] = 0.0;
            }
        }
        Ok(Instruction::Home {
            line: number,
            position: [self.last[0], self.last[1], self.last[2]],
        })
    }

    /// G92: the given axes read the given values from now on; no value resets all four.
    pub(super) fn set_position(
        &mut self,
        number: usize,
        text: &str,
        line: &Line,
    ) -> Result<(), GcodeError> {
        let words = line.parameters(number, text)?;
        if words.is_empty() {
            self.base = self.last;
        }
        for (letter, value) in words {
            let value = required(number, text, letter, value)?;
            let axis = match letter {
                'X' | 'Y' | 'Z' => (letter as u8 - b'X') as usize,
                'E' => 3,
                other => return Err(unknown_parameter(number, text, other, "X, Y, Z, E")),
            };
            let factor = if axis == 3 { self.extrude_factor } else { 1.0 };
            self.base[axis] = self.last[axis] - value * factor;
        }
        Ok(())
    }

    /// M220 S (speed override) and M221 S (extrusion override) in percent (100 without S):
    /// Klipper rescales the current speed, and keeps the file's E position under the new factor.
    pub(super) fn override_factor(
        &mut self,
        number: usize,
        text: &str,
        line: &Line,
    ) -> Result<(), GcodeError> {
        let mut percent = 100.0;
        for (letter, value) in line.parameters(number, text)? {
            // Klipper reads S only: Marlin's B/R (backup, restore: flags without a value) and
            // D (tool) are not Klipper's and are ignored as Klipper ignores them.
            if letter != 'S' {
                continue;
            }
            let value = required(number, text, letter, value)?;
            if value <= 0.0 {
                return Err(out_of_range(number, text, "S", value, "> 0 %"));
            }
            percent = value;
        }
        if line.command == "M220" {
            let factor = percent / (60.0 * 100.0);
            self.speed = self.speed / self.speed_factor * factor;
            self.speed_factor = factor;
        } else {
            let factor = percent / 100.0;
            let e = (self.last[3] - self.base[3]) / self.extrude_factor;
            self.base[3] = self.last[3] - e * factor;
            self.extrude_factor = factor;
        }
        Ok(())
    }

    /// M204 S (or P and T: the smaller) [mm/s²]: the acceleration limit from now on. Without S
    /// and without both P and T Klipper answers "Invalid M204 command" and changes nothing; so
    /// does the reader (listed as skipped).
    pub(super) fn m204(
        &mut self,
        number: usize,
        text: &str,
        line: &Line,
    ) -> Result<Option<Instruction>, GcodeError> {
        let (mut s, mut p, mut t) = (None, None, None);
        for (letter, value) in line.parameters(number, text)? {
            match letter {
                'S' => s = Some(value),
                'P' => p = Some(value),
                'T' => t = Some(value),
                _ => {} // Marlin's R (retract acceleration) and the like: not Klipper's.
            }
        }
        let positive = |letter: char, value: Option<f64>| {
            let value = required(number, text, letter, value)?;
            if value <= 0.0 {
                let key = letter.to_string();
                return Err(out_of_range(number, text, &key, value, "> 0 mm/s²"));
            }
            Ok(value)
        };
        // Klipper's order: S, and only without S both P and T (each checked when given).
        let accel = match s {
            Some(s) => positive('S', s)?,
            None => {
                let p = p.map(|v| positive('P', v)).transpose()?;
                let t = t.map(|v| positive('T', v)).transpose()?;
                match (p, t) {
                    (Some(p), Some(t)) => p.min(t),
                    _ => {
                        self.skip(number, "M204 (without S, or P and T)");
                        return Ok(None);
                    }
                }
            }
        };
        Ok(Some(Instruction::Limits {
            line: number,
            change: LimitChange {
                max_accel: Some(accel),
                ..LimitChange::default()
            },
        }))
    }

    /// Klipper's SET_VELOCITY_LIMIT VELOCITY= ACCEL= SQUARE_CORNER_VELOCITY=
    /// MINIMUM_CRUISE_RATIO= (mm/s, mm/s², mm/s, ratio in [0, 1)).
    pub(super) fn velocity_limit(
        &mut self,
        number: usize,
        text: &str,
        line: &Line,
    ) -> Result<Instruction, GcodeError> {
        let mut change = LimitChange::default();
        for word in line.arguments.split_whitespace() {
            let malformed = |reason: String| GcodeError::Malformed {
                line: number,
                text: text.to_string(),
                reason,
            };
            let (key, value) = word
                .split_once('=')
                .ok_or_else(|| malformed(format!("`{word}`: expected KEY=value")))?;
            let key = key.to_ascii_uppercase();
            let value: f64 = value
                .parse()
                .ok()
                .filter(|v: &f64| v.is_finite())
                .ok_or_else(|| malformed(format!("{key}: `{value}` is not a number")))?;
            let (slot, allowed, ok) = match key.as_str() {
                "VELOCITY" => (&mut change.max_velocity, "> 0 mm/s", value > 0.0),
                "ACCEL" => (&mut change.max_accel, "> 0 mm/s²", value > 0.0),
                "SQUARE_CORNER_VELOCITY" => {
                    (&mut change.square_corner_velocity, "≥ 0 mm/s", value >= 0.0)
                }
                "MINIMUM_CRUISE_RATIO" => (
                    &mut change.minimum_cruise_ratio,
                    "0 ≤ ratio < 1",
                    (0.0..1.0).contains(&value),
                ),
                _ => {
                    return Err(GcodeError::Unsupported {
                        line: number,
                        text: text.to_string(),
                        command: format!("SET_VELOCITY_LIMIT {key}"),
                        hint: "VELOCITY, ACCEL, SQUARE_CORNER_VELOCITY and MINIMUM_CRUISE_RATIO \
                               are read"
                            .to_string(),
                    });
                }
            };
            if !ok {
                return Err(out_of_range(number, text, &key, value, allowed));
            }
            *slot = Some(value);
        }
        Ok(Instruction::Limits {
            line: number,
            change,
        })
    }
}

fn required(
    number: usize,
    text: &str,
    letter: char,
    value: Option<f64>,
) -> Result<f64, GcodeError> {
    value.ok_or_else(|| GcodeError::Malformed {
        line: number,
        text: text.to_string(),
        reason: format!("{letter} without a value"),
    })
}

fn out_of_range(number: usize, text: &str, key: &str, value: f64, allowed: &str) -> GcodeError {
    GcodeError::OutOfRange {
        line: number,
        text: text.to_string(),
        key: key.to_string(),
        value,
        allowed: allowed.to_string(),
    }
}

fn unknown_parameter(number: usize, text: &str, letter: char, known: &str) -> GcodeError {
    GcodeError::Malformed {
        line: number,
        text: text.to_string(),
        reason: format!("parameter {letter} is not one of {known}"),
    }
}
