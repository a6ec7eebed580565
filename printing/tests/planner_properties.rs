//! Properties of the motion planner over random G-code programs, each checked against what
//! Klipper's method (`/work/notes/klipper-planner.md`) implies and against closed forms derived
//! by hand from it (not by re-running the planner's code).
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

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Every segment of a random program obeys the limits in force for its line and is a
    /// consistent trapezoid:
    /// * `start_v`, `cruise_v`, `end_v` ≤ min(max_velocity, requested F/60) (relative
    ///   [`ULPS`]: the limit goes SI → mm → SI and a speed through v² and √);
    /// * `start_v ≤ cruise_v ≥ end_v` exactly (each end speed² is a `min` with cruise², and √
    ///   and ÷1000 are monotone);
    /// * 0 < `accel` ≤ max_accel (relative [`ULPS`]);
    /// * phase times ≥ −1e-15 s (the cruise distance is a difference, Klipper's own plans show
    ///   −8e-18 s; an error of a few ulp of the move's length over its speed stays below 1e-16 s
    ///   for these lengths and accelerations);
    /// * `start_v + accel·accel_t = cruise_v` and `cruise_v − accel·decel_t = end_v` within
    ///   1e-12 m/s (the phase time is the phase's distance over its mean speed: a few ulp of
    ///   the speed, ~1e-16 m/s);
    /// * the start is the previous target bit for bit (positions pass through unchanged, /1000),
    ///   `Segment::length` equals the distance to the line's target to 1e-12 relative (computed
    ///   from the file's millimetres, so only the trapezoid's round-off counts) and the
    ///   distance from its SI start to the next segment's SI start to 1e-12 relative + 1e-16 m
    ///   (each SI coordinate is rounded once, ≤ 1.4e-17 m at 0.2 m);
    /// * the direction is the unit vector to the target (1e-12).
    #[test]
    fn segments_obey_limits_and_are_trapezoids(
        config in random_limits(),
        ops in prop::collection::vec(op(), 1..40),
    ) {
        let (text, expects) = build(&config, &ops);
        let plan = plan_text(&text, [0.0; 3], &config);
        let tl = timeline(&expects);
        prop_assert_eq!(plan.segments.len(), tl.segments.len(), "{}", text);
        for (k, (s, e)) in plan.segments.iter().zip(&tl.segments).enumerate() {
            let Expect::Segment { line, start, end, speed, max_velocity, max_accel } = *e else {
                unreachable!()
            };
            prop_assert_eq!(s.line, line);
            let cap = max_velocity.min(speed) / 1000.0 * (1.0 + ULPS);
            prop_assert!(s.start_v <= cap && s.cruise_v <= cap && s.end_v <= cap,
                "line {}: speeds {:?} above {}", line, (s.start_v, s.cruise_v, s.end_v), cap);
            prop_assert!(s.start_v <= s.cruise_v && s.end_v <= s.cruise_v, "line {}: {:?}", line, s);
            prop_assert!(s.start_v >= 0.0 && s.cruise_v > 0.0 && s.end_v >= 0.0);
            prop_assert!(s.accel > 0.0 && s.accel <= max_accel / 1000.0 * (1.0 + ULPS),
                "line {}: accel {} above {}", line, s.accel, max_accel / 1000.0);
            for phase in [s.accel_t, s.cruise_t, s.decel_t] {
                prop_assert!(phase >= -1e-15, "line {}: phase {} s", line, phase);
            }
            prop_assert!((s.start_v + s.accel * s.accel_t - s.cruise_v).abs() <= 1e-12,
                "line {}: accel phase does not reach cruise: {:?}", line, s);
            prop_assert!((s.cruise_v - s.accel * s.decel_t - s.end_v).abs() <= 1e-12,
                "line {}: decel phase does not reach the end speed: {:?}", line, s);

            prop_assert_eq!(s.start, start.map(|x| x / 1000.0), "line {}", line);
            let d_mm = (0..3).map(|i| (end[i] - start[i]).powi(2)).sum::<f64>().sqrt();
            prop_assert!(close(s.length(), d_mm / 1000.0, 1e-12, 0.0),
                "line {}: length {} vs distance {}", line, s.length(), d_mm / 1000.0);
            for i in 0..3 {
                let u = (end[i] - start[i]) / d_mm;
                prop_assert!((s.dir[i] - u).abs() <= 1e-12, "line {}: dir {:?}", line, s.dir);
            }
            if let Some(next) = plan.segments.get(k + 1) {
                let d_si = (0..3).map(|i| (next.start[i] - s.start[i]).powi(2)).sum::<f64>().sqrt();
                prop_assert!(close(s.length(), d_si, 1e-12, 1e-16),
                    "line {}: length {} vs distance to the next start {}", line, s.length(), d_si);
            }
        }
    }

    /// Time and speed continuity of a random program:
    /// * the first segment starts after the pauses before it (dwells and extrude-only moves,
    ///   timed by hand, see [`extrude_only_time`]) and each next one after the previous one's
    ///   end plus the pauses between them, within 1e-12 s · (1 + t) (the clock is a running sum
    ///   of O(1 s) terms: a few ulp each);
    /// * `print_time` = Σ segment durations + Σ dwells + Σ extrude-only move times, to
    ///   1e-12 relative (same reason), and equally the last segment's end plus what follows it;
    /// * consecutive segments contiguous in time (within 1e-12 s) have end_v of one = start_v
    ///   of the next within 1e-12 m/s (both are √ of the same min(next start², cruise²) up to a
    ///   tie between equal values);
    /// * a dwell, M400 or extrude-only move between two segments stops the toolhead exactly
    ///   (v = 0: a flush plans the queue end to rest, and Klipper computes no junction next to
    ///   an extrude-only move), as do the program's start and end.
    #[test]
    fn clock_and_junction_continuity(
        config in random_limits(),
        ops in prop::collection::vec(op(), 1..40),
    ) {
        let (text, expects) = build(&config, &ops);
        let plan = plan_text(&text, [0.0; 3], &config);
        let tl = timeline(&expects);
        let segs = &plan.segments;
        prop_assert_eq!(segs.len(), tl.segments.len());
        let mut end_of_last = 0.0;
        for (k, s) in segs.iter().enumerate() {
            let expected = end_of_last + tl.gap_time[k];
            prop_assert!(close(s.t_start, expected, 1e-12, 1e-12),
                "segment {} starts at {} s, expected {} s\n{}", k, s.t_start, expected, text);
            if k == 0 || tl.gap_stops[k] {
                prop_assert_eq!(s.start_v, 0.0, "segment {} after a stop", k);
            }
            if k > 0 {
                let p = &segs[k - 1];
                if tl.gap_stops[k] {
                    prop_assert_eq!(p.end_v, 0.0, "segment {} before a stop", k - 1);
                }
                if (s.t_start - (p.t_start + p.duration())).abs() <= 1e-12 {
                    prop_assert!((p.end_v - s.start_v).abs() <= 1e-12,
                        "segments {} and {} meet at {} and {} m/s", k - 1, k, p.end_v, s.start_v);
                }
            }
            end_of_last = s.t_start + s.duration();
        }
        if let Some(last) = segs.last() {
            prop_assert_eq!(last.end_v, 0.0);
        }
        let trailing = tl.gap_time[segs.len()];
        prop_assert!(close(plan.print_time, end_of_last + trailing, 1e-12, 1e-12),
            "print_time {} vs {} + {}", plan.print_time, end_of_last, trailing);
        let sum: f64 = segs.iter().map(Segment::duration).sum::<f64>()
            + tl.gap_time.iter().sum::<f64>();
        prop_assert!(close(plan.print_time, sum, 1e-12, 1e-12),
            "print_time {} vs the sum {}", plan.print_time, sum);
    }
}

// ---------------------------------------------------------------------------------------------
// Closed forms
// ---------------------------------------------------------------------------------------------

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// A 90° corner between two long moves at a high F, without extrusion, is taken at exactly
    /// square_corner_velocity: Klipper's junction deviation δ = scv²(√2 − 1)/a and the circle
    /// radius R = δ·sin(θ/2)/(1 − sin(θ/2)) give v² = R·a = scv² at θ = 90° (every other limit
    /// is far above: 100 mm moves, a ≥ 500 mm/s², mcr ≤ 0.9, scv ≤ 10 mm/s). Relative 1e-12
    /// (in exact arithmetic it is scv; in f64 a few ulp).
    #[test]
    fn right_angle_corner_is_square_corner_velocity(
        v in 0.05..0.5f64,
        a in 0.5..20.0f64,
        scv in 0.0005..0.01f64,
        mcr in 0.0..0.9f64,
        turn in 0usize..6,
    ) {
        // From (100, 100, 100): first axis, then a perpendicular one, either sign.
        let (first, second) = [
            ("X200", "Y200"), ("X200", "Y0"), ("Y0", "X0"), ("Y200", "X200"),
            ("X0", "Z200"), ("Z0", "Y0"),
        ][turn];
        let text = format!("G1 {first} F60000\nG1 {second}\n");
        let plan = plan_text(&text, [100.0; 3], &limits(v, a, scv, mcr));
        prop_assert_eq!(plan.segments.len(), 2);
        let (s1, s2) = (&plan.segments[0], &plan.segments[1]);
        prop_assert!(close(s1.end_v, scv, 1e-12, 0.0), "{} vs scv {}", s1.end_v, scv);
        prop_assert!(close(s2.start_v, scv, 1e-12, 0.0), "{} vs scv {}", s2.start_v, scv);
        prop_assert!(s1.cruise_v > 2.0 * scv && s2.cruise_v > 2.0 * scv);
    }

    /// The junction speed between two moves at a general angle, by hand: with θ the angle
    /// between the reversed first direction and the second (θ = 180° straight on, 90° a square
    /// corner; computed here with atan2 on the file's coordinates, the planner uses dot
    /// products), s = sin(θ/2), t = tan(θ/2), δ_k = 2·L_k·a (the reach of move k) and
    /// μ_k = 2·L_k·a·(1 − mcr) (its reach under the minimum-cruise-ratio pseudo-acceleration),
    /// V_k = min(F_k/60, max_velocity):
    ///
    /// J = min(V₁², V₂², δ₁, scv²(√2 − 1)·s/(1 − s), δ₁·t/4, δ₂·t/4)
    ///   (both cruise speeds, the first move's reach from rest, junction deviation with
    ///   R·δ_jd·a, and the centripetal mid-move limit v² ≤ Δv²·tan(θ/2)/4 of either move);
    /// the second move must stop at the end: S = min(J, δ₂);
    /// the mcr budget: m = min(J, μ₁, μ₂) at the junction; the first move's peak is
    /// (m + μ₁)/2 unless it is a full (mcr) acceleration into a second move that peaks
    /// itself (μ₁ = m < μ₂), then the shared peak (m + μ₂)/2;
    /// junction speed² = min(S, peak). With mcr = 0 it is min(J, δ₂).
    ///
    /// Asserted: the first segment's end_v and the second's start_v, relative 1e-12 + 1e-15 m/s
    /// (the angle's two routes, atan2 here and a dot product there, differ by a few ulp in
    /// cos θ, which 1 − sin(θ/2) = 3.8e-3 at θ = 170° amplifies to ~1e-13 relative; the absolute
    /// term covers scv = 0; the peak's branch is continuous at its tie, so a tie decided by
    /// round-off moves the value only by round-off). 30 000 cases pass at this tolerance.
    #[test]
    fn junction_speed_by_hand(
        heading in 0.0..(2.0 * PI),
        theta_deg in 10.0..170.0f64,
        l1 in log_uniform(0.2, 100.0),
        l2 in log_uniform(0.2, 100.0),
        f1 in 600.0..30_000.0f64,
        f2 in 600.0..30_000.0f64,
        v in 0.05..0.5f64,
        a in 0.3..20.0f64,
        scv in 0.0..0.05f64,
        mcr in prop_oneof![Just(0.0), 0.0..0.95f64, 0.8..0.95f64],
    ) {
        let turn = PI - theta_deg.to_radians();
        let p0 = [100.0, 100.0];
        let p1 = [p0[0] + l1 * heading.cos(), p0[1] + l1 * heading.sin()];
        let p2 = [p1[0] + l2 * (heading + turn).cos(), p1[1] + l2 * (heading + turn).sin()];
        let text = format!(
            "G1 X{} Y{} F{f1}\nG1 X{} Y{} F{f2}\n", p1[0], p1[1], p2[0], p2[1]
        );
        let plan = plan_text(&text, [p0[0], p0[1], 0.0], &limits(v, a, scv, mcr));
        prop_assert_eq!(plan.segments.len(), 2);

        // By hand, in mm, from the coordinates as written.
        let (v_mm, a_mm, scv_mm) = (v * 1e3, a * 1e3, scv * 1e3);
        let w = [p1[0] - p0[0], p1[1] - p0[1]];
        let u = [p2[0] - p1[0], p2[1] - p1[1]];
        let (len1, len2) = (w[0].hypot(w[1]), u[0].hypot(u[1]));
        // Angle between −w and u.
        let theta = (-w[0] * u[1] + w[1] * u[0]).abs().atan2(-w[0] * u[0] - w[1] * u[1]);
        let (s, t) = ((theta / 2.0).sin(), (theta / 2.0).tan());
        let vel1 = (f1 / 60.0).min(v_mm);
        let vel2 = (f2 / 60.0).min(v_mm);
        let (d1, d2) = (2.0 * len1 * a_mm, 2.0 * len2 * a_mm);
        let (mu1, mu2) = (d1 * (1.0 - mcr), d2 * (1.0 - mcr));
        let j = (vel1 * vel1)
            .min(vel2 * vel2)
            .min(d1)
            .min(scv_mm * scv_mm * (SQRT_2 - 1.0) * s / (1.0 - s))
            .min(d1 * t / 4.0)
            .min(d2 * t / 4.0);
        let stop = j.min(d2);
        let m = j.min(mu1).min(mu2);
        let peak = if mu1 > m || m >= mu2 { (m + mu1) / 2.0 } else { (m + mu2) / 2.0 };
        let junction = stop.min(peak).sqrt() / 1000.0;
        if mcr == 0.0 {
            prop_assert!(close(junction, stop.sqrt() / 1000.0, 1e-12, 0.0));
        }
        let (s1, s2) = (&plan.segments[0], &plan.segments[1]);
        prop_assert!(close(s1.end_v, junction, 1e-12, 1e-15),
            "end_v {} vs by hand {} (θ = {}°)", s1.end_v, junction, theta.to_degrees());
        prop_assert!(close(s2.start_v, junction, 1e-12, 1e-15),
            "start_v {} vs by hand {}", s2.start_v, junction);
    }

    /// Without minimum_cruise_ratio the whole two-move plan follows by hand from the junction
    /// speed² S (previous property): move k cruises at min((v_start² + v_end² + δ_k)/2, V_k²)
    /// (the meeting point of full acceleration and full braking, or its speed limit) — i.e.
    /// (S + δ₁)/2 and (S + δ₂)/2 — and its phases are (v_c − v_s)/a, (v_c − v_e)/a and the
    /// rest of its length at v_c. Cruise speeds relative 1e-12, phase times and print_time
    /// within 1e-12 of the total time (the cruise phase is a difference of distances).
    #[test]
    fn two_move_plan_by_hand_without_mcr(
        theta_deg in 10.0..170.0f64,
        l1 in log_uniform(0.2, 100.0),
        l2 in log_uniform(0.2, 100.0),
        f1 in 600.0..30_000.0f64,
        f2 in 600.0..30_000.0f64,
        v in 0.05..0.5f64,
        a in 0.3..20.0f64,
        scv in 0.0..0.05f64,
    ) {
        let turn = PI - theta_deg.to_radians();
        let p1 = [l1, 0.0];
        let p2 = [p1[0] + l2 * turn.cos(), l2 * turn.sin()];
        let text = format!("G1 X{} F{f1}\nG1 X{} Y{} F{f2}\n", p1[0], p2[0], p2[1]);
        let plan = plan_text(&text, [0.0; 3], &limits(v, a, scv, 0.0));
        prop_assert_eq!(plan.segments.len(), 2);

        let (v_mm, a_mm, scv_mm) = (v * 1e3, a * 1e3, scv * 1e3);
        let u = [p2[0] - p1[0], p2[1] - p1[1]];
        let (len1, len2) = (p1[0], u[0].hypot(u[1]));
        let theta = u[1].abs().atan2(-u[0]); // the reversed first direction is −X
        let (s, t) = ((theta / 2.0).sin(), (theta / 2.0).tan());
        let vel = [(f1 / 60.0).min(v_mm), (f2 / 60.0).min(v_mm)];
        let (d1, d2) = (2.0 * len1 * a_mm, 2.0 * len2 * a_mm);
        let j = (vel[0] * vel[0])
            .min(vel[1] * vel[1])
            .min(d1)
            .min(scv_mm * scv_mm * (SQRT_2 - 1.0) * s / (1.0 - s))
            .min(d1 * t / 4.0)
            .min(d2 * t / 4.0);
        let junction2 = j.min(d2);
        let ends = [(0.0, junction2), (junction2, 0.0)];
        let lengths = [len1, len2];
        let mut total = 0.0;
        let mut hand = Vec::new();
        for k in 0..2 {
            let (vs2, ve2) = ends[k];
            let cruise2 = ((vs2 + ve2 + 2.0 * lengths[k] * a_mm) / 2.0).min(vel[k] * vel[k]);
            let (vs, vc, ve) = (vs2.sqrt(), cruise2.sqrt(), ve2.sqrt());
            let accel_t = (vc - vs) / a_mm;
            let decel_t = (vc - ve) / a_mm;
            let cruise_d = lengths[k] - (cruise2 - vs2) / (2.0 * a_mm) - (cruise2 - ve2) / (2.0 * a_mm);
            let cruise_t = cruise_d / vc;
            total += accel_t + cruise_t + decel_t;
            hand.push((vc / 1000.0, accel_t, cruise_t, decel_t));
        }
        for (s, &(vc, accel_t, cruise_t, decel_t)) in plan.segments.iter().zip(&hand) {
            prop_assert!(close(s.cruise_v, vc, 1e-12, 0.0), "cruise {} vs {}", s.cruise_v, vc);
            for (got, want) in [(s.accel_t, accel_t), (s.cruise_t, cruise_t), (s.decel_t, decel_t)] {
                prop_assert!((got - want).abs() <= 1e-12 * total,
                    "phase {} s vs by hand {} s (total {} s)", got, want, total);
            }
        }
        prop_assert!(close(plan.print_time, total, 1e-12, 0.0),
            "print_time {} vs by hand {}", plan.print_time, total);
    }

    /// A lone move of length L at requested speed v_r from rest to rest, V = min(v_r,
    /// max_velocity), acceleration a, minimum_cruise_ratio r. Klipper's backward pass gives it
    /// start² = 0 and (a new peak) peak² = (0 + 2·L·a(1 − r))/2 = L·a(1 − r); its cruise² is
    /// min((0 + 2La)/2, V², L·a(1 − r)) = min(V², L·a(1 − r)) since r ≥ 0. So:
    /// * if V² ≤ L·a(1 − r): T = L/V + V/a (a trapezoid cruising at V);
    /// * else v_p² = L·a(1 − r), T = L/v_p + v_p/a = √(L/a)·(1/√(1 − r) + √(1 − r)), and the
    ///   cruise covers exactly the fraction r of the length (the minimum cruise ratio's
    ///   meaning); with r = 0 this is the triangle T = 2√(L/a).
    ///
    /// Equivalently (r = 0): L ≥ V²/a → L/V + V/a, else 2√(L/a). Times relative 1e-12 (a few
    /// roundings of the same quantities), the cruise phase within 1e-12 of T (it is a
    /// difference and can be −1e-17 s when r = 0).
    #[test]
    fn lone_move_time_by_hand(
        length in log_uniform(0.01, 300.0),
        f in 60.0..60_000.0f64,
        v in 0.02..0.5f64,
        a in 0.3..20.0f64,
        mcr in prop_oneof![Just(0.0), 0.0..0.95f64],
        axis in 0usize..3,
    ) {
        let word = ["X", "Y", "Z"][axis];
        let plan = plan_text(&format!("G1 {word}{length} F{f}\n"), [0.0; 3], &limits(v, a, 0.005, mcr));
        prop_assert_eq!(plan.segments.len(), 1);
        let s = &plan.segments[0];
        let (v_mm, a_mm) = (v * 1e3, a * 1e3);
        let vel = (f / 60.0).min(v_mm);
        let peak2 = length * a_mm * (1.0 - mcr);
        let (cruise_v, total) = if vel * vel <= peak2 {
            (vel, length / vel + vel / a_mm)
        } else {
            let m = 1.0 - mcr;
            (peak2.sqrt(), (length / a_mm).sqrt() * (1.0 / m.sqrt() + m.sqrt()))
        };
        if mcr == 0.0 {
            let classic = if length >= vel * vel / a_mm {
                length / vel + vel / a_mm
            } else {
                2.0 * (length / a_mm).sqrt()
            };
            prop_assert!(close(total, classic, 1e-12, 0.0));
        }
        prop_assert!(close(plan.print_time, total, 1e-12, 0.0),
            "print_time {} vs by hand {}", plan.print_time, total);
        prop_assert!(close(s.duration(), total, 1e-12, 0.0));
        prop_assert!(close(s.cruise_v, cruise_v / 1000.0, 1e-12, 0.0));
        prop_assert!(close(s.accel_t, cruise_v / a_mm, 1e-12, 0.0));
        prop_assert!(close(s.decel_t, cruise_v / a_mm, 1e-12, 0.0));
        prop_assert!((s.cruise_t - (total - 2.0 * cruise_v / a_mm)).abs() <= 1e-12 * total);
        prop_assert_eq!((s.start_v, s.end_v), (0.0, 0.0));
        if vel * vel > peak2 {
            let cruise_share = s.cruise_v * s.cruise_t / s.length();
            prop_assert!((cruise_share - mcr).abs() <= 1e-12,
                "cruise share {} vs minimum_cruise_ratio {}", cruise_share, mcr);
        }
    }
}

/// An exact reversal is a full stop (Klipper: θ = 0, sin(θ/2) = 0, so the junction-deviation
/// radius and with it the junction speed are 0), and an exactly straight continuation has no
/// geometric limit (θ = 180°: 1 − sin(θ/2) = 0 skips it): the junction is the lower cruise
/// speed. Exact equality: both are decided by exact comparisons in the method.
#[test]
fn reversal_stops_and_straight_line_keeps_speed() {
    let l = limits(0.3, 3.0, 0.005, 0.5);
    let plan = plan_text("G1 X100 F60000\nG1 X50\n", [0.0; 3], &l);
    assert_eq!(plan.segments.len(), 2);
    assert_eq!(plan.segments[0].end_v, 0.0);
    assert_eq!(plan.segments[1].start_v, 0.0);

    let plan = plan_text("G1 X100 F9000\nG1 X200 F6000\n", [0.0; 3], &l);
    assert_eq!(plan.segments.len(), 2);
    assert_eq!(plan.segments[0].end_v, 0.1);
    assert_eq!(plan.segments[1].start_v, 0.1);
}

/// The extruder's instantaneous corner velocity limits a straight junction where the filament
/// rate changes: v = icv / |Δ(E per mm)| (Klipper's extruder calc_junction); here 1 mm/s over
/// a change of 0.05 − 0.01 = 0.04 mm/mm: 25 mm/s. Relative 1e-12 (the rates are ratios of
/// rounded positions).
#[test]
fn extrusion_change_limits_a_straight_junction() {
    let l = limits(0.3, 3.0, 0.005, 0.0);
    let plan = plan_text("M83\nG1 X100 E5 F60000\nG1 X200 E1\n", [0.0; 3], &l);
    assert_eq!(plan.segments.len(), 2);
    let v = 1.0 / 0.04 / 1000.0;
    assert!(
        close(plan.segments[0].end_v, v, 1e-12, 0.0),
        "{}",
        plan.segments[0].end_v
    );
    assert!(close(plan.segments[1].start_v, v, 1e-12, 0.0));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// `Plan::breakpoints` holds every time the reference may jump: between two consecutive
    /// ones it is a single quadratic. At three interior points of each interval (intervals
    /// under 1 ns skipped: a phase end and its breakpoint are sums rounded apart by an ulp) the
    /// acceleration is the same bits (one phase: ±accel or 0 times the direction) and the
    /// velocity moves by a·Δt to 1e-12 m/s (speeds below 1 m/s, a few ulp each); every segment's
    /// start, where a junction turns the velocity, is one of them, and they ascend strictly.
    #[test]
    fn the_reference_is_one_quadratic_between_breakpoints(
        config in random_limits(),
        ops in prop::collection::vec(op(), 1..40),
    ) {
        let (text, _) = build(&config, &ops);
        let plan = plan_text(&text, [0.0; 3], &config);
        let b = plan.breakpoints();
        prop_assert!(b.windows(2).all(|w| w[0] < w[1]), "{:?}", b);
        for s in &plan.segments {
            prop_assert!(b.contains(&s.t_start), "segment start {} missing", s.t_start);
        }
        for w in b.windows(2).filter(|w| w[1] - w[0] >= 1e-9) {
            let ts = [0.25, 0.5, 0.75].map(|f| w[0] + f * (w[1] - w[0]));
            let r = ts.map(|t| plan.reference(t).unwrap());
            for k in 0..3 {
                prop_assert_eq!(r[0].2[k].to_bits(), r[1].2[k].to_bits(), "in {:?}", w);
                prop_assert_eq!(r[1].2[k].to_bits(), r[2].2[k].to_bits(), "in {:?}", w);
                let moved = r[0].1[k] + r[0].2[k] * (ts[2] - ts[0]);
                prop_assert!(
                    (r[2].1[k] - moved).abs() <= 1e-12,
                    "in {:?}: {} against {}", w, r[2].1[k], moved
                );
            }
        }
    }
}
