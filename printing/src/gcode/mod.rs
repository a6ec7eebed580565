//! The G-code reader: a slicer's file → the moves, dwells and limit changes a firmware's
//! toolhead receives, with the semantics of Klipper's `gcode_move` (G90/G91 also make E
//! relative, G92 shifts the base position, F in mm/min, the speed 25 mm/s before the first F).
//!
//! The reader keeps the file's units (mm, mm/s, mm/s²) and does the firmware's arithmetic in
//! them: the planner's junction speed at a reversal goes as √sin(θ/2), so a direction one ulp
//! off (0.2 mm read as 2e-4 m and normalised) turns a stop into 3.3e-7 m/s. The plan
//! ([`crate::planner`]) is SI. Numbers are parsed as f64 (a f32 parse moves a 200 mm coordinate
//! by up to 7.6 µm). Positions are in the file's own axes (X, Y, Z, E); placing them in the
//! robot's frame is the caller's business.
//!
//! Carried out: G0/G1 (X Y Z E F), G4 (P ms), G21, G28 (to the home position the caller
//! gives), G90/G91, G92, M82/M83, M204 (S, or P and T), M220/M221 (speed and extrusion
//! overrides), M400/M109/M190 (wait for the moves: the toolhead stops), SET_VELOCITY_LIMIT.
//! Refused by name: G2/G3 (arcs), G20 (inches), G10/G11 (firmware retraction), G4 S (Klipper
//! reads only P, milliseconds). Anything else (fans,
//! temperatures without waiting, progress) is listed once in [`Program::skipped`] and skipped.

mod error;
mod words;

pub use error::GcodeError;
use words::Line;

/// What a slicer says a move prints (its `;TYPE:` comment), or a travel when it does not extrude.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum MoveKind {
    /// The outermost perimeter: the part's visible surface.
    ExternalPerimeter,
    /// Inner (and overhang) perimeters.
    Perimeter,
    /// Solid, sparse, top, bridge infill, gap fill and ironing.
    Infill,
    /// Moves that do not extrude (E not increasing), including extrude-only moves.
    Travel,
    /// Extruding moves of any other type (skirt, brim, support, custom).
    Other,
}

impl MoveKind {
    /// Every kind, in report order.
    pub const ALL: [MoveKind; 5] = [
        MoveKind::ExternalPerimeter,
        MoveKind::Perimeter,
        MoveKind::Infill,
        MoveKind::Travel,
        MoveKind::Other,
    ];

    /// Snake-case name for metrics keys.
    pub fn name(self) -> &'static str {
        match self {
            MoveKind::ExternalPerimeter => "external_perimeter",
            MoveKind::Perimeter => "perimeter",
            MoveKind::Infill => "infill",
            MoveKind::Travel => "travel",
            MoveKind::Other => "other",
        }
    }

    /// The kind of a PrusaSlicer/SuperSlicer/OrcaSlicer `;TYPE:` name.
    fn of_slicer_type(name: &str) -> MoveKind {
        let lower = name.to_ascii_lowercase();
        if lower.contains("external perimeter") || lower.contains("outer wall") {
            MoveKind::ExternalPerimeter
        } else if lower.contains("perimeter") || lower.contains("wall") {
            MoveKind::Perimeter
        } else if lower.contains("infill") || lower.contains("gap fill") || lower == "ironing" {
            MoveKind::Infill
        } else {
            MoveKind::Other
        }
    }
}

/// A G0/G1 after the modes are resolved: where the toolhead goes, how fast it may.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Move {
    /// 1-based line of the file.
    pub line: usize,
    /// End position X, Y, Z [mm] and filament position E [mm] in the file's machine coordinates.
    pub end: [f64; 4],
    /// Requested speed (F with the M220 override) [mm/s].
    pub speed: f64,
    /// What it prints.
    pub kind: MoveKind,
    /// Layer: 0 before the first `;LAYER_CHANGE`, then 1, 2, …
    pub layer: usize,
}

/// Limits a file changes on the fly (M204, SET_VELOCITY_LIMIT); `None` leaves one as it is.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LimitChange {
    /// max_velocity [mm/s].
    pub max_velocity: Option<f64>,
    /// max_accel [mm/s²].
    pub max_accel: Option<f64>,
    /// square_corner_velocity [mm/s].
    pub square_corner_velocity: Option<f64>,
    /// minimum_cruise_ratio [-].
    pub minimum_cruise_ratio: Option<f64>,
}

/// What the toolhead is told, in file order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Instruction {
    /// G0/G1.
    Move(Move),
    /// G4: stop, then wait [s].
    Dwell { line: usize, seconds: f64 },
    /// M400, M109, M190: the toolhead stops (firmware flushes its lookahead to wait).
    WaitForMoves { line: usize },
    /// G28: stop; the homed axes are at the home position [mm] (machine coordinates).
    Home { line: usize, position: [f64; 3] },
    /// M204, SET_VELOCITY_LIMIT.
    Limits { line: usize, change: LimitChange },
}

/// A command the reader skipped, listed once.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Skipped {
    /// The command word.
    pub command: String,
    /// Its first line.
    pub first_line: usize,
    /// How many lines carried it.
    pub count: usize,
}

/// A read file.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Program {
    /// The toolhead's instructions in file order.
    pub instructions: Vec<Instruction>,
    /// Commands skipped, in order of first appearance.
    pub skipped: Vec<Skipped>,
    /// Number of `;LAYER_CHANGE` comments.
    pub layers: usize,
    /// Where the toolhead starts: the home position, filament at 0 [mm].
    pub start: [f64; 4],
}

/// Reads G-code text. `home` is where G28 puts the homed axes, in the file's coordinates [mm];
/// the toolhead starts there too.
///
/// # Examples
/// ```
/// use cdpr_printing::gcode::{read, Instruction, MoveKind};
/// let program = read("G28\nM83\n;LAYER_CHANGE\n;TYPE:Perimeter\nG1 X10 Y0 E0.5 F1800\n", [0.0; 3])?;
/// let Instruction::Move(m) = program.instructions[1] else { panic!() };
/// assert_eq!((m.end[0], m.speed, m.kind, m.layer), (10.0, 30.0, MoveKind::Perimeter, 1));
/// # Ok::<(), cdpr_printing::gcode::GcodeError>(())
/// ```
pub fn read(text: &str, home: [f64; 3]) -> Result<Program, GcodeError> {
    let mut reader = Reader::new(home);
    for (index, line) in text.lines().enumerate() {
        reader.line(index + 1, line)?;
    }
    Ok(reader.program)
}

/// Klipper's `gcode_move` state, in the file's millimetres.
struct Reader {
    program: Program,
    home: [f64; 3],
    absolute_coordinates: bool,
    absolute_extrusion: bool,
    base: [f64; 4],
    last: [f64; 4],
    /// Requested speed [mm/s] (Klipper's 25 mm/s before the first F).
    speed: f64,
    /// F [mm/min] to mm/s times the M220 override (Klipper's `speed_factor`).
    speed_factor: f64,
    /// The M221 override of E (Klipper's `extrude_factor`).
    extrude_factor: f64,
    kind: MoveKind,
    layer: usize,
}

impl Reader {
    fn new(home: [f64; 3]) -> Self {
        Reader {
            program: Program {
                start: [home[0], home[1], home[2], 0.0],
                ..Program::default()
            },
            home,
            absolute_coordinates: true,
            absolute_extrusion: true,
            base: [0.0; 4],
            last: [home[0], home[1], home[2], 0.0],
            speed: 25.0,
            speed_factor: 1.0 / 60.0,
            extrude_factor: 1.0,
            kind: MoveKind::Other,
            layer: 0,
        }
    }

    fn line(&mut self, number: usize, text: &str) -> Result<(), GcodeError> {
        let line = Line::split(text);
        if let Some(comment) = line.comment {
            if comment == "LAYER_CHANGE" {
                self.layer += 1;
                self.program.layers += 1;
            } else if let Some(name) = comment.strip_prefix("TYPE:") {
                self.kind = MoveKind::of_slicer_type(name);
            }
        }
        let unsupported = |hint: &str| GcodeError::Unsupported {
            line: number,
            text: text.to_string(),
            command: line.command.clone(),
            hint: hint.to_string(),
        };
        let instruction = match line.command.as_str() {
            "" | "G21" => None,
            "G0" | "G1" => self.linear_move(number, text, &line)?,
            "G4" => Some(self.dwell(number, text, &line)?),
            "G28" => Some(self.home(number, text, &line)?),
            "G90" => {
                self.absolute_coordinates = true;
                None
            }
            "G91" => {
                self.absolute_coordinates = false;
                None
            }
            "M82" => {
                self.absolute_extrusion = true;
                None
            }
            "M83" => {
                self.absolute_extrusion = false;
                None
            }
            "G92" => {
                self.set_position(number, text, &line)?;
                None
            }
            "M204" => self.m204(number, text, &line)?,
            "SET_VELOCITY_LIMIT" => Some(self.velocity_limit(number, text, &line)?),
            "M400" | "M109" | "M190" => Some(Instruction::WaitForMoves { line: number }),
            "G2" | "G3" => {
                return Err(unsupported(
                    "arcs are not read: slice with arc fitting off (PrusaSlicer: arc_fitting = disabled)",
                ));
            }
            "G20" => {
                return Err(unsupported(
                    "positions in inches: slice in millimetres (G21)",
                ));
            }
            "M220" | "M221" => {
                self.override_factor(number, text, &line)?;
                None
            }
            "G10" | "G11" => {
                return Err(unsupported(
                    "firmware retraction is not modelled: slice with retraction in G1 E moves",
                ));
            }
            other => {
                self.skip(number, other);
                None
            }
        };
        if let Some(instruction) = instruction {
            self.program.instructions.push(instruction);
        }
        Ok(())
    }

    fn skip(&mut self, number: usize, command: &str) {
        match self
            .program
            .skipped
            .iter_mut()
            .find(|s| s.command == command)
        {
            Some(s) => s.count += 1,
            None => self.program.skipped.push(Skipped {
                command: command.to_string(),
                first_line: number,
                count: 1,
            }),
        }
    }
}

mod commands;
