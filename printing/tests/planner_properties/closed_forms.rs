//! Plans checked against closed forms derived by hand from Klipper's method: the square corner,
//! junction speeds, two-move and lone-move times, reversals and an extrusion change.

use super::*;

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
