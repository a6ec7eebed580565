//! Random programs under random limits: every segment obeys the limits in force and is a
//! trapezoid, the clock and the junctions are continuous, and the reference is one quadratic
//! between the plan's breakpoints.

use super::*;

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
