//! The motion planner: Klipper's toolhead (`klippy/toolhead.py`, with the extruder's checks of
//! `kinematics/extruder.py`) rewritten from its method. Limits in SI, computed in the
//! firmware's millimetres (see [`crate::gcode`] on why), the plan in SI. A [`Program`] in, a [`Plan`] of
//! trapezoidal segments out, each equal to what Klipper hands its step generators
//! (`trapq_append`) for the same file and limits, and timed from 0 at the first move (Klipper
//! starts its clock 0.25 s ahead of the MCU; the offset is dropped).
//!
//! The kinematics add no limits: cable robots (Klipper's `winch`) check nothing per axis.
//!
//! # Examples
//! A single 10 cm move at 0.1 m/s with 1 m/s²: accelerate 0.1 s over 5 mm, cruise 0.9 s, brake.
//! ```
//! use cdpr_printing::{gcode, planner};
//! let program = gcode::read("G1 X100 F6000", [0.0; 3])?;
//! let plan = planner::plan(&program, &planner::Limits::new(0.1, 1.0))?;
//! let s = &plan.segments[0];
//! assert!((s.accel_t - 0.1).abs() < 1e-12 && (s.cruise_t - 0.9).abs() < 1e-12);
//! assert!((plan.print_time - 1.1).abs() < 1e-12);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod limits;
mod lookahead;
mod moves;
mod plan;

pub use limits::{ExtruderLimits, Limits, PlanError};
pub use plan::{Plan, Reference, Segment};

use crate::gcode::{Instruction, LimitChange, Program};
use lookahead::{FLUSH_TIME_AFTER_STOP, Lookahead};
use moves::{InForce, QueuedMove, Tag};

/// Plans a program under `limits` (validated first).
pub fn plan(program: &Program, limits: &Limits) -> Result<Plan, PlanError> {
    limits.validate()?;
    let mut toolhead = Toolhead::new(limits.in_millimetres(), program.start);
    for instruction in &program.instructions {
        toolhead.run(instruction)?;
    }
    toolhead.stop();
    Ok(Plan {
        segments: toolhead.segments,
        print_time: toolhead.print_time,
    })
}

/// Klipper's toolhead without the hardware: the commanded position, the limits in force, the
/// lookahead and the print clock (all in mm).
struct Toolhead {
    /// The configured limits: the extruder's derived limits follow these, never M204's.
    config: Limits,
    /// The limits in force (M204 and SET_VELOCITY_LIMIT change them).
    limits: Limits,
    in_force: InForce,
    commanded: [f64; 4],
    lookahead: Lookahead,
    flushed: Vec<QueuedMove>,
    print_time: f64,
    segments: Vec<Segment>,
}

impl Toolhead {
    fn new(limits: Limits, start: [f64; 4]) -> Self {
        Toolhead {
            in_force: InForce::new(
                limits.max_velocity,
                limits.max_accel,
                limits.square_corner_velocity,
                limits.minimum_cruise_ratio,
            ),
            config: limits,
            limits,
            commanded: start,
            lookahead: Lookahead::new(),
            flushed: Vec::new(),
            print_time: 0.0,
            segments: Vec::new(),
        }
    }

    fn run(&mut self, instruction: &Instruction) -> Result<(), PlanError> {
        match *instruction {
            Instruction::Move(m) => {
                let tag = Tag {
                    line: m.line,
                    kind: m.kind,
                    layer: m.layer,
                };
                self.queue(tag, m.end, m.speed)?;
            }
            Instruction::Dwell { seconds, .. } => {
                self.stop();
                self.print_time += seconds.max(0.0);
            }
            Instruction::WaitForMoves { .. } => self.stop(),
            Instruction::Home { line, position } => {
                self.stop();
                let [x, y, z, e] = self.commanded;
                if [x, y, z] != position {
                    // A robot that knows its pose drives home in a straight line.
                    let tag = Tag {
                        line,
                        kind: crate::gcode::MoveKind::Travel,
                        layer: 0,
                    };
                    self.queue(
                        tag,
                        [position[0], position[1], position[2], e],
                        f64::INFINITY,
                    )?;
                    self.stop();
                }
            }
            Instruction::Limits { change, .. } => self.change_limits(change),
        }
        Ok(())
    }

    /// Klipper's `ToolHead.move`: the extruder's check, then the lookahead (a lazy flush when
    /// its time budget is spent).
    fn queue(&mut self, tag: Tag, end: [f64; 4], speed: f64) -> Result<(), PlanError> {
        let Some(mut m) = QueuedMove::new(tag, self.commanded, end, speed, &self.in_force) else {
            return Ok(());
        };
        if m.axes_d[3] != 0.0 {
            m.check_extrusion(&self.config)?;
        }
        self.commanded = m.end;
        let corner = self.limits.extruder.instantaneous_corner_velocity;
        if self.lookahead.add(m, corner) {
            self.process(true);
        }
        Ok(())
    }

    /// Plans what the lookahead releases and appends it to the clock.
    fn process(&mut self, lazy: bool) {
        self.flushed.clear();
        self.lookahead.flush(lazy, &mut self.flushed);
        for m in &self.flushed {
            if m.kinematic {
                self.segments.push(Segment::of(m, self.print_time));
            }
            let t = &m.trapezoid;
            // Klipper's order of additions (the clock is a long sum).
            self.print_time = self.print_time + t.accel_t + t.cruise_t + t.decel_t;
        }
    }

    /// The toolhead comes to rest (Klipper's `_flush_lookahead`).
    fn stop(&mut self) {
        self.process(false);
        self.lookahead.junction_flush = FLUSH_TIME_AFTER_STOP;
    }

    /// M204 / SET_VELOCITY_LIMIT: moves queued from now on see the new limits.
    fn change_limits(&mut self, change: LimitChange) {
        let l = &mut self.limits;
        l.max_velocity = change.max_velocity.unwrap_or(l.max_velocity);
        l.max_accel = change.max_accel.unwrap_or(l.max_accel);
        l.square_corner_velocity = change
            .square_corner_velocity
            .unwrap_or(l.square_corner_velocity);
        l.minimum_cruise_ratio = change
            .minimum_cruise_ratio
            .unwrap_or(l.minimum_cruise_ratio);
        self.in_force = InForce::new(
            l.max_velocity,
            l.max_accel,
            l.square_corner_velocity,
            l.minimum_cruise_ratio,
        );
    }
}
