//! Properties of the motion planner over random G-code programs, each checked against what
//! Klipper's method (docs/printing.md, "The planner: Klipper's toolhead") implies and against
//! closed forms derived by hand from it (not by re-running the planner's code). The properties
//! are in the two files beside this one; this one holds the programs' generator and helpers.
//!
//! Units: the G-code and the hand computations are in the firmware's millimetres (mm, mm/s,
//! mm/s²); a [`Segment`] is in SI, i.e. the planner's millimetre values divided by 1000.
//! Tolerances are stated per property: the planner computes in f64 and its results are rounded
//! a few times (a square root, a division by 1000), so "exact" bounds get a few ulp; where a
//! hand closed form takes another route (trigonometry instead of dot products), 1e-12 relative.

use cdpr_printing::gcode;
use cdpr_printing::planner::{self, Limits, Plan, Segment};
use proptest::prelude::*;
use std::f64::consts::{PI, SQRT_2};
use std::fmt::Write;

mod closed_forms;
mod random_programs;

/// A few ulp of relative round-off: the limits pass through ×1000 (SI → mm) and ÷1000
/// (mm → SI) and a speed through v² and √, each rounding once.
const ULPS: f64 = 16.0 * f64::EPSILON;

/// Klipper's default extrude-only ratio, 4 nozzle² / filament area (0.4 mm nozzle, 1.75 mm
/// filament): max_extrude_only_velocity and _accel are the configured max_velocity and
/// max_accel times this.
fn extrude_only_ratio() -> f64 {
    4.0 * 0.4 * 0.4 / (PI * (1.75f64 * 0.5).powi(2))
}

/// `|a − b| ≤ rel · max(|a|, |b|) + abs`.
fn close(a: f64, b: f64, rel: f64, abs: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()) + abs
}

fn plan_text(text: &str, home: [f64; 3], limits: &Limits) -> Plan {
    let program = gcode::read(text, home).expect("the generated G-code reads");
    planner::plan(&program, limits).expect("the generated G-code plans")
}

fn limits(max_velocity: f64, max_accel: f64, scv: f64, mcr: f64) -> Limits {
    Limits {
        square_corner_velocity: scv,
        minimum_cruise_ratio: mcr,
        ..Limits::new(max_velocity, max_accel)
    }
}

// ---------------------------------------------------------------------------------------------
// Random programs
// ---------------------------------------------------------------------------------------------

/// Where a G1 goes, on a 1 µm grid in a 200 × 200 × 10 mm box (so every XYZ move is either
/// nothing or at least 1 µm long).
#[derive(Debug, Clone, Copy)]
enum Target {
    /// Anywhere in the box [µm] (Z kept when `keep_z`): moves of ~100 mm.
    Anywhere { to: [u32; 3], keep_z: bool },
    /// A short XY step [µm] from where the toolhead is (clamped to the box), as a slicer's
    /// curves are: where junctions, reaches and the minimum-cruise-ratio peaks bind.
    Step { by: [i32; 2] },
}

/// One line of a random program (relative extrusion, M83; absolute XYZ).
#[derive(Debug, Clone)]
enum Op {
    /// G1 to `to`, extruding `e_ratio` mm per mm of path (negative: retracting while moving,
    /// at most 5 mm), with an optional F [mm/min].
    Move {
        to: Target,
        e_ratio: f64,
        f: Option<f64>,
    },
    /// G1 E (extrude-only), an optional F.
    ExtrudeOnly { e: f64, f: Option<f64> },
    /// G4 P [ms].
    Dwell { ms: f64 },
    /// M400.
    Wait,
    /// SET_VELOCITY_LIMIT with some of VELOCITY [mm/s], ACCEL [mm/s²], SQUARE_CORNER_VELOCITY
    /// [mm/s], MINIMUM_CRUISE_RATIO.
    SetLimits {
        velocity: Option<f64>,
        accel: Option<f64>,
        scv: Option<f64>,
        mcr: Option<f64>,
    },
}

/// Log-uniform in [lo, hi]: short moves are where the reach and mcr limits bind.
fn log_uniform(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (lo.ln()..hi.ln()).prop_map(f64::exp)
}

fn feed_rate() -> impl Strategy<Value = Option<f64>> {
    prop::option::weighted(0.7, 60.0..30_000.0f64)
}

fn op() -> impl Strategy<Value = Op> {
    let e_ratio = prop_oneof![Just(0.0), 0.0..0.1f64, -0.3..0.0f64];
    prop_oneof![
        8 => (
            prop_oneof![
                ((0u32..=200_000, 0u32..=200_000, 0u32..=10_000), any::<bool>())
                    .prop_map(|((x, y, z), keep_z)| Target::Anywhere { to: [x, y, z], keep_z }),
                (-3000i32..=3000, -3000i32..=3000).prop_map(|(x, y)| Target::Step { by: [x, y] }),
            ],
            e_ratio,
            feed_rate()
        )
            .prop_map(|(to, e_ratio, f)| Op::Move { to, e_ratio, f }),
        1 => (0.05..5.0f64, any::<bool>(), feed_rate()).prop_map(|(e, retract, f)| {
            Op::ExtrudeOnly {
                e: if retract { -e } else { e },
                f,
            }
        }),
        1 => (0.0..500.0f64).prop_map(|ms| Op::Dwell { ms }),
        1 => Just(Op::Wait),
        1 => (
            prop::option::of(20.0..500.0f64),
            prop::option::of(300.0..20_000.0f64),
            prop::option::of(0.0..20.0f64),
            prop::option::of(0.0..0.95f64),
        )
            .prop_map(|(velocity, accel, scv, mcr)| Op::SetLimits {
                velocity,
                accel,
                scv,
                mcr
            }),
    ]
}

/// Random limits in SI: max_velocity, max_accel, square_corner_velocity, minimum_cruise_ratio.
fn random_limits() -> impl Strategy<Value = Limits> {
    (0.02..0.5f64, 0.3..20.0f64, 0.0..0.02f64, 0.0..0.95f64)
        .prop_map(|(v, a, scv, mcr)| limits(v, a, scv, mcr))
}

/// What a line of the program must give, worked out by hand from Klipper's rules (mm).
#[derive(Debug, Clone, Copy)]
enum Expect {
    /// A kinematic move: one segment from `start` to `end` at no more than the requested
    /// `speed` and the `max_velocity` in force, accelerating at no more than `max_accel`.
    Segment {
        line: usize,
        start: [f64; 3],
        end: [f64; 3],
        speed: f64,
        max_velocity: f64,
        max_accel: f64,
    },
    /// Time at rest for the XYZ axes [s]: a dwell, or an extrude-only move (its own trapezoid).
    Pause { seconds: f64 },
    /// The toolhead stops (M400) but no time passes.
    Stop,
}

/// The hand-computed time of an extrude-only move of `delta_e` mm at the requested `speed`
/// (Klipper: the velocity is the requested one, not clamped by max_velocity, then limited by
/// the extruder to max_extrude_only_velocity, and the acceleration to max_extrude_only_accel,
/// both derived from the *configured* max_velocity/max_accel; the minimum-cruise-ratio
/// pseudo-acceleration is the *in-force* max_accel (1 − mcr), capped by the extrude-only accel).
/// Both of its junctions are full stops, so it runs alone from rest to rest: its peak is
/// cruise² = min(v², d·A_e, d·A(1 − mcr)) (half the reach of each budget) and its time
/// d/v_c + v_c/A_e.
fn extrude_only_time(delta_e: f64, speed: f64, config: &Limits, accel: f64, mcr: f64) -> f64 {
    let ratio = extrude_only_ratio();
    let d = delta_e.abs();
    let v = speed.min(config.max_velocity * 1e3 * ratio);
    let a_e = config.max_accel * 1e3 * ratio;
    let cruise2 = (v * v).min(d * a_e).min(d * accel * (1.0 - mcr));
    let cruise_v = cruise2.sqrt();
    d / cruise_v + cruise_v / a_e
}

/// The program's text and, per line, what it must give.
fn build(config: &Limits, ops: &[Op]) -> (String, Vec<Expect>) {
    let mut text = String::from("M83\n");
    let mut expects = Vec::new();
    let mut pos_um = [0i64; 3];
    let mut pos = [0.0f64; 3];
    let mut e_pos = 0.0f64;
    let mut speed = 25.0f64; // Klipper's speed before the first F [mm/s]
    let mut max_velocity = config.max_velocity * 1e3;
    let mut max_accel = config.max_accel * 1e3;
    let mut mcr = config.minimum_cruise_ratio;
    let set_speed = |text: &mut String, speed: &mut f64, f: Option<f64>| {
        if let Some(f) = f {
            let _ = write!(text, " F{f}");
            *speed = f * (1.0 / 60.0);
        }
    };
    // Line 1 is M83.
    for (line, op) in (2..).zip(ops) {
        match *op {
            Op::Move { to, e_ratio, f } => {
                match to {
                    Target::Anywhere { to, keep_z } => {
                        pos_um[0] = i64::from(to[0]);
                        pos_um[1] = i64::from(to[1]);
                        if !keep_z {
                            pos_um[2] = i64::from(to[2]);
                        }
                    }
                    Target::Step { by } => {
                        for i in 0..2 {
                            pos_um[i] = (pos_um[i] + i64::from(by[i])).clamp(0, 200_000);
                        }
                    }
                }
                let end = pos_um.map(|um| um as f64 / 1000.0);
                let d = (0..3)
                    .map(|i| (end[i] - pos[i]).powi(2))
                    .sum::<f64>()
                    .sqrt();
                let e = (e_ratio * d).max(-5.0);
                let _ = write!(text, "G1 X{} Y{} Z{}", end[0], end[1], end[2]);
                if e != 0.0 {
                    let _ = write!(text, " E{e}");
                }
                set_speed(&mut text, &mut speed, f);
                // The reader adds the increment to the E position, the toolhead differences.
                let delta_e = (e_pos + e) - e_pos;
                e_pos += e;
                if d > 0.0 {
                    expects.push(Expect::Segment {
                        line,
                        start: pos,
                        end,
                        speed,
                        max_velocity,
                        max_accel,
                    });
                } else if delta_e != 0.0 {
                    let seconds = extrude_only_time(delta_e, speed, config, max_accel, mcr);
                    expects.push(Expect::Pause { seconds });
                }
                pos = end;
            }
            Op::ExtrudeOnly { e, f } => {
                let _ = write!(text, "G1 E{e}");
                set_speed(&mut text, &mut speed, f);
                let delta_e = (e_pos + e) - e_pos;
                e_pos += e;
                let seconds = extrude_only_time(delta_e, speed, config, max_accel, mcr);
                expects.push(Expect::Pause { seconds });
            }
            Op::Dwell { ms } => {
                let _ = write!(text, "G4 P{ms}");
                expects.push(Expect::Pause {
                    seconds: ms / 1000.0,
                });
            }
            Op::Wait => {
                text.push_str("M400");
                expects.push(Expect::Stop);
            }
            Op::SetLimits {
                velocity,
                accel,
                scv,
                mcr: ratio,
            } => {
                text.push_str("SET_VELOCITY_LIMIT");
                if let Some(v) = velocity {
                    let _ = write!(text, " VELOCITY={v}");
                    max_velocity = v;
                }
                if let Some(a) = accel {
                    let _ = write!(text, " ACCEL={a}");
                    max_accel = a;
                }
                if let Some(s) = scv {
                    let _ = write!(text, " SQUARE_CORNER_VELOCITY={s}");
                }
                if let Some(r) = ratio {
                    let _ = write!(text, " MINIMUM_CRUISE_RATIO={r}");
                    mcr = r;
                }
            }
        }
        text.push('\n');
    }
    (text, expects)
}

/// The segments' expectations in order, and per gap between them (before the first, between
/// segment k − 1 and k, after the last) the time at rest there and whether the toolhead stops.
struct Timeline {
    segments: Vec<Expect>,
    gap_time: Vec<f64>,
    gap_stops: Vec<bool>,
}

fn timeline(expects: &[Expect]) -> Timeline {
    let mut t = Timeline {
        segments: Vec::new(),
        gap_time: vec![0.0],
        gap_stops: vec![false],
    };
    for e in expects {
        match *e {
            Expect::Segment { .. } => {
                t.segments.push(*e);
                t.gap_time.push(0.0);
                t.gap_stops.push(false);
            }
            Expect::Pause { seconds } => {
                *t.gap_time.last_mut().unwrap() += seconds;
                *t.gap_stops.last_mut().unwrap() = true;
            }
            Expect::Stop => *t.gap_stops.last_mut().unwrap() = true,
        }
    }
    t
}
