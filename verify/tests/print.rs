//! Printed paths on the simulated printer: the contour error measured against what it did not
//! produce (a path offset by a known vector, a nozzle late on its line), a straight printed line
//! on the elastic robot with computed-torque at the integrator's tolerance, the firmware's input
//! shapers against the project's designs where their definitions coincide, and the shaped
//! reference against the convolution it is defined by.

use cdpr_bench::analysis::contour::ContourMetrics;
use cdpr_bench::core::print_path::{AxisShaper, PRE_ROLL, PrintPath};
use cdpr_bench::core::robot::Vector;
use cdpr_bench::core::runner::Observer;
use cdpr_bench::core::scenario::Scenario;
use cdpr_bench::core::shaper::{Impulses, ShaperKind};
use cdpr_bench::printing::shaper::{Shaper, centred, pulses};
use cdpr_bench::printing::{gcode, planner};
use proptest::prelude::*;
use std::sync::Arc;

fn hangprinter_printer() -> Scenario {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/printing/hangprinter.toml"
    );
    cdpr_bench::scenario_from_file(std::path::Path::new(path)).unwrap()
}

/// The printer on massive lines of `kind` ("lumped", "fe") with `elements` per line, 3.2 m of
/// each modelled (enough for the build volume's corners).
fn printer_on_massive_lines(kind: &str, elements: i64) -> Scenario {
    let mut scenario = hangprinter_printer();
    scenario.cable.modelled_length = 3.2;
    let mut table = toml::Table::new();
    table.insert("kind".into(), kind.into());
    table.insert("elements".into(), elements.into());
    scenario.model = cdpr_bench::core::scenario::ModelSection(table);
    scenario
}

/// A square of 20 mm sides at 100 mm/s, 3 000 mm/s², unshaped, at the robot's origin.
fn square() -> PrintPath<3> {
    let text = "G1 X20 Y0 F6000\nG1 X20 Y20\nG1 X0 Y20\nG1 X0 Y0\n";
    let program = gcode::read(text, [0.0; 3]).unwrap();
    let plan = planner::plan(&program, &planner::Limits::new(0.3, 3.0)).unwrap();
    PrintPath::new(Arc::new(plan), [0.0; 3], Default::default()).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// A nozzle displaced from the commanded point by δ perpendicular to its line, at least
    /// 2 mm from a corner (farther than δ ≤ 1 mm from any other side), has contour error |δ|
    /// (to round-off of 20 mm coordinates, 1e-15 m); one displaced along its line, staying on
    /// it, has contour error 0 while its tracking error is the displacement.
    #[test]
    fn contour_error_of_an_offset_path_is_the_offset(
        side in 0usize..4,
        along in 0.1f64..0.9,
        normal in -1e-3f64..1e-3,
        vertical in -1e-3f64..1e-3,
        late in 0.0f64..1e-3,
    ) {
        let path = square();
        let plan = path.plan();
        let s = &plan.segments[side];
        // The plan time at which the commanded point is `along` of the side (2 mm … 18 mm).
        let target = 0.002 + along * 0.016;
        let mut t = s.t_start;
        while s.along(t - s.t_start).0 < target { t += 1e-5; }
        let on = path.commanded(t);
        let dir = Vector::<3>::new(s.dir[0], s.dir[1], s.dir[2]);
        let n = Vector::<3>::new(-dir[1], dir[0], 0.0);
        let offset = n * normal + Vector::<3>::new(0.0, 0.0, vertical);
        let loop_t = t + path.lead();
        let metrics = ContourMetrics::of(
            &path,
            [(loop_t, on + offset), (loop_t, on - dir * late)].into_iter(),
            0..=0,
        );
        let errors = metrics.overall;
        prop_assert!((errors.max - offset.norm()).abs() < 1e-15, "{errors:?} against {}", offset.norm());
        let mut only_late = ContourMetrics::of(&path, [(loop_t, on - dir * late)].into_iter(), 0..=0);
        prop_assert!(only_late.overall.max < 1e-15, "{:?}", only_late.overall);
        only_late.tracking.max -= late;
        prop_assert!(only_late.tracking.max.abs() < 1e-15, "{:?}", only_late.tracking);
    }
}

/// One straight printed line (20 mm by 10 mm at 100 mm/s, 3 000 mm/s²) on the Hangprinter-like
/// robot, elastic cables, computed-torque: the effector lags along its line (the velocity
/// filter) but never leaves it, so the contour error is the integration's: DOPRI5 at the
/// scenario's rtol = 1e-9 on positions of ~0.1 m errs by ~1e-10 m per step over a few hundred
/// steps; 1e-8 m is 10³ below the corners' tens of µm of a printed layer.
#[test]
fn a_straight_printed_line_stays_on_its_line() {
    let scenario = hangprinter_printer();
    let print = cdpr_bench::prepare_print(&scenario, "G28\nG1 X130 Y110 F6000\n", None).unwrap();
    let run = cdpr_bench::simulate_print(&scenario, &print, &mut Observer::progress(&mut |_| {}))
        .unwrap();
    let c = &run.contour;
    eprintln!("contour {:?}, tracking {:?}", c.overall, c.tracking);
    assert!(c.overall.max < 1e-8, "{:?}", c.overall);
    assert!(c.overall.samples > 300, "the whole line sampled");
    // The print starts at rest at the start pose after the pre-roll.
    assert_eq!(print.path.lead(), PRE_ROLL);
}

/// The same printed line on lumped lines (20 masses per line, the example's damped UHMWPE):
/// the lines' weight and their axial ringing are what the computed-torque controller does not
/// know, so the nozzle leaves its line — by 0.62 µm at most (rms 0.09 µm, one pulley passage),
/// against 1e-8 m on massless lines; bound 2 µm, a regression guard two orders below a layer's
/// 0.2 mm — while the energy balance closes (measured 2e-9 J; bound 1e-5 J of ~1 J of reel
/// work), and the print is refused by name where the lines cannot reach it.
#[test]
fn a_straight_printed_line_on_lumped_lines() {
    let mut scenario = printer_on_massive_lines("lumped", 20);
    let gcode = "G28\nG1 X130 Y110 F6000\n";
    let print = cdpr_bench::prepare_print(&scenario, gcode, None).unwrap();
    let run = cdpr_bench::simulate_print(&scenario, &print, &mut Observer::progress(&mut |_| {}))
        .unwrap();
    let c = &run.contour;
    let residual = run
        .run
        .series
        .column(cdpr_bench::core::channel::Channel::EResidual)
        .unwrap()
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(c.overall.max < 2e-6, "{:?}", c.overall);
    assert!(c.overall.samples > 300, "the whole line sampled");
    assert!(!run.run.events.is_empty(), "no node crossed a pulley");
    assert!(residual < 1e-5, "energy balance residual {residual:e} J");
    scenario.cable.modelled_length = 1.0;
    let Err(err) = cdpr_bench::prepare_print(&scenario, gcode, None) else {
        panic!("a 1 m line accepted for a 2.3 m chord");
    };
    assert!(err.to_string().contains("cable.modelled_length"), "{err}");
}

/// A 10 mm square from home at 100 mm/s, the corner tests' G-code.
const SMALL_SQUARE: &str = "G28\nG1 X110 Y100 F6000\nG1 X110 Y110\nG1 X100 Y110\nG1 X100 Y100\n";

/// A printed square's corners turn the reference's velocity at the junction speed (Klipper's
/// square-corner model: 5 mm/s here), a jump in the command that a step across cannot make
/// small: the controller's states take half the jump in their rate times h. The
/// error-controlled implicit path stops just before each jump of velocity or acceleration and
/// restarts just after it (`runner/stops.rs`), so the print completes — without the stops the
/// step underflows at the first corner — and draws the square as the fixed step does: the
/// largest contour errors within 1 µm (the fixed step's h = 1e-4 s is the coarser of the two;
/// measured 0.23 µm apart), with a restart at each jump.
#[test]
fn an_error_controlled_print_turns_its_corners() {
    use cdpr_bench::core::scenario::IntegratorKind;
    let mut scenario = printer_on_massive_lines("fe", 4);
    scenario.simulation.integrator = IntegratorKind::Implicit;
    let gcode = SMALL_SQUARE;
    let print = cdpr_bench::prepare_print(&scenario, gcode, None).unwrap();
    let run =
        |s: &Scenario| cdpr_bench::simulate_print(s, &print, &mut Observer::progress(&mut |_| {}));
    let fixed = run(&scenario).unwrap();
    scenario.simulation.adaptive = true;
    let adaptive = run(&scenario).unwrap_or_else(|e| panic!("{e}"));
    let jumps = print.path.breakpoints().len() as u64;
    let (a, f) = (&adaptive.contour.overall, &fixed.contour.overall);
    eprintln!(
        "contour max {:.4e} vs {:.4e} m; {} steps, {} restarts for {jumps} jumps",
        a.max, f.max, adaptive.run.stats.steps_accepted, adaptive.run.stats.restarts
    );
    assert!((a.max - f.max).abs() < 1e-6, "{a:?} against {f:?}");
    assert!(a.samples > 300 && a.samples == f.samples);
    assert!(
        adaptive.run.stats.restarts >= jumps,
        "a restart at each jump"
    );
}

/// The controller's states are measured in metres by the error norm
/// (`Controller::state_weights`): the computed-torque's filtered velocity error by K_d/K_p and
/// its rate by K_d/(K_p ω_f). In their own units (m/s²) against atol = 1e-5 the filter's rate
/// set the steps: the same square on lumped lines at rtol 1e-3, atol 1e-5 on the effector's
/// norm took 3 590 steps. Now it draws the fixed h = 1e-4 s run's largest contour error within
/// 1 µm (measured 0.3 µm; 0.2 µm from an rtol 1e-6, atol 1e-9 run) in fewer than 1 000 steps
/// (measured 650).
#[test]
fn an_error_controlled_print_measures_the_controllers_states_in_metres() {
    use cdpr_bench::core::scenario::{ErrorNorm, IntegratorKind};
    let mut scenario = printer_on_massive_lines("lumped", 20);
    scenario.simulation.integrator = IntegratorKind::Implicit;
    let print = cdpr_bench::prepare_print(&scenario, SMALL_SQUARE, None).unwrap();
    let run =
        |s: &Scenario| cdpr_bench::simulate_print(s, &print, &mut Observer::progress(&mut |_| {}));
    let fixed = run(&scenario).unwrap();
    scenario.simulation.adaptive = true;
    (scenario.simulation.rtol, scenario.simulation.atol) = (1e-3, 1e-5);
    scenario.simulation.error_norm = ErrorNorm::Effector;
    let adaptive = run(&scenario).unwrap_or_else(|e| panic!("{e}"));
    let (a, f) = (&adaptive.contour.overall, &fixed.contour.overall);
    let steps = adaptive.run.stats.steps_accepted;
    eprintln!(
        "contour max {:.4e} vs {:.4e} m in {steps} steps",
        a.max, f.max
    );
    assert!((a.max - f.max).abs() < 1e-6, "{a:?} against {f:?}");
    assert!(steps < 1_000, "{steps} steps");
}

/// DOPRI5 stops at the reference's jumps too: the same 10 mm square on elastic lines at
/// rtol 1e-5 draws the contour of an rtol 1e-9 run to 2e-11 m in its largest error and 3e-11 m
/// in its rms (measured 4.4e-12 and 1.1e-11 m; stepping across the corners instead gave 1.0e-10
/// and 9.6e-10 m with 226 rejected steps against 59), restarting once at each jump.
#[test]
fn dopri5_prints_converge_across_their_corners() {
    let mut scenario = hangprinter_printer();
    let gcode = SMALL_SQUARE;
    let print = cdpr_bench::prepare_print(&scenario, gcode, None).unwrap();
    let mut run = |rtol: f64| {
        scenario.simulation.rtol = rtol;
        scenario.simulation.atol = 1e-12;
        cdpr_bench::simulate_print(&scenario, &print, &mut Observer::progress(&mut |_| {})).unwrap()
    };
    let (loose, tight) = (run(1e-5), run(1e-9));
    let (a, b) = (&loose.contour.overall, &tight.contour.overall);
    assert!((a.max - b.max).abs() < 2e-11, "{a:?} against {b:?}");
    assert!((a.rms - b.rms).abs() < 3e-11, "{a:?} against {b:?}");
    let jumps = print.path.breakpoints().len() as u64;
    assert!(
        loose.run.stats.restarts >= jumps - 1,
        "{} restarts",
        loose.run.stats.restarts
    );
}

/// Where Klipper's definitions coincide with the project's trajectory shapers (ZV, ZVD, MZV
/// with their damping weights), the firmware's pulses, normalised, are the project's impulses
/// for the same mode (ω = 2π f, ζ) to round-off; the EI family differs by design (Klipper's
/// damped fits at V = 1/20 against the project's exact undamped forms).
#[test]
fn firmware_shapers_equal_the_projects_where_defined_alike() {
    for (firmware, ours) in [
        (Shaper::Zv, ShaperKind::Zv),
        (Shaper::Zvd, ShaperKind::Zvd),
        (Shaper::Mzv, ShaperKind::Mzv),
    ] {
        for (freq, zeta) in [(20.0, 0.0), (35.0, 0.1), (60.0, 0.3)] {
            let (a, t) = pulses(firmware, freq, zeta);
            let sum: f64 = a.iter().sum();
            let design =
                Impulses::design(ours, 2.0 * std::f64::consts::PI * freq, zeta, 0.05).unwrap();
            for i in 0..a.len() {
                assert!(
                    (a[i] / sum - design.amplitudes[i]).abs() < 1e-14,
                    "{firmware:?}"
                );
                assert!((t[i] - design.times[i]).abs() < 1e-15, "{firmware:?}");
            }
        }
    }
}

/// The shaped reference of an axis is Σ A_i p(t − τ_i) of the unshaped one, the other axes
/// untouched; it starts and ends where the plan does (pulses summing to 1).
#[test]
fn a_shaped_axis_is_the_convolution_of_its_plan() {
    let text = "G1 X20 Y0 F6000\nG1 X20 Y20\n";
    let program = gcode::read(text, [0.0; 3]).unwrap();
    let plan = Arc::new(planner::plan(&program, &planner::Limits::new(0.3, 3.0)).unwrap());
    let (a, t) = pulses(Shaper::Ei, 40.0, 0.1);
    let shaper = AxisShaper::from_pulses(&a, &t);
    let (amplitudes, offsets) = centred(&a, &t);
    let shaped = PrintPath::<3>::new(plan.clone(), [0.0; 3], [Some(shaper), None, None]).unwrap();
    let plain = PrintPath::<3>::new(plan, [0.0; 3], Default::default()).unwrap();
    assert!(
        shaped.lead() > plain.lead(),
        "the shaped reference starts early"
    );
    let shift = shaped.lead() - plain.lead();
    for k in 0..400 {
        let time = k as f64 * 0.002;
        let [p, v, acc] = shaped.reference(time, true);
        let mut expected = [0.0; 3];
        for (ai, tau) in amplitudes.iter().zip(&offsets) {
            let [q, w, b] = plain.reference(time - shift - tau, true);
            expected[0] += ai * q[0];
            expected[1] += ai * w[0];
            expected[2] += ai * b[0];
        }
        assert!((p[0] - expected[0]).abs() < 1e-15, "x at {time}");
        assert!((v[0] - expected[1]).abs() < 1e-13, "ẋ at {time}");
        assert!((acc[0] - expected[2]).abs() < 1e-10, "ẍ at {time}");
        let y = plain.reference(time - shift, false)[0][1];
        assert!((p[1] - y).abs() < 1e-15, "y unshaped at {time}");
    }
    assert!((shaped.end() - plain.end()).norm() < 1e-15);
    assert!((shaped.start() - plain.start()).norm() < 1e-15);
}
