//! The printer study's building blocks against closed forms: the length-driven loop's modes
//! are the locked-reel robot's, damped by the line's Kelvin–Voigt damping as stiffness-
//! proportional damping predicts, and `"auto"` shaper frequencies pick them.

use cdpr_bench::core::scenario::{ControllerKind, Designed, FirmwareShaper, Scenario};
use cdpr_studies::print_study::{auto_frequencies, needs_auto, resolve_auto};
use cdpr_studies::spatial_modes::{SpatialLoop, at_pose};

fn printer(kind: ControllerKind) -> Scenario {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/printing/hangprinter.toml"
    );
    let mut s = cdpr_bench::scenario_from_file(std::path::Path::new(path)).unwrap();
    s.controller.kind = kind;
    s
}

/// Reels driven by length hold the locked-reel robot, K = Σ (EA/l_i) u_i u_iᵀ + s I with
/// s = Σ T_i/l_i (a cable of fixed l0 stiffens along itself by EA/l0 − T/l = EA/l). The line's
/// damping C (l̇/l0) acts along each cable with C/l0 = (C/EA)(EA + T_i)/l_i, so a mode φ of K
/// decays at σ = −(C/EA)[M ω² − s + Σ (T_i/l_i)(u_i·φ)²]/(2M) to first order in the damping
/// (the damping is not quite proportional: the error is second order, ~ζ² ≈ 1e-3 of σ at
/// most) and rings at √(ω² − σ²). The closed loop's modes (central differences of its
/// Jacobian) must agree to 1e-4 in frequency and 2e-4 in decay; dropping the tension terms
/// errs by 2.4e-3 on the vertical mode, and a sign error in the damping's chord rate made the
/// loop unstable.
#[test]
fn the_length_loop_is_the_locked_robot_damped_by_its_line() {
    let s = printer(ControllerKind::Length);
    let modes = at_pose(&s, [0.0, 0.0, 0.0002]).unwrap();
    let ea = s.cable.axial_stiffness();
    let c = s.cable.axial_damping;
    let robot = s.spatial_robot().unwrap();
    let pose = cdpr_bench::core::robot::Vector::<3>::from(modes.pose);
    let geometric: f64 = (0..robot.cables())
        .map(|i| modes.tensions[i] / robot.chord(i, &pose).length)
        .sum::<f64>()
        / robot.effector_mass;
    let locked: Vec<_> = modes
        .modes
        .iter()
        .filter(|m| m.linearisation == SpatialLoop::LockedReels)
        .collect();
    let closed: Vec<_> = modes
        .modes
        .iter()
        .filter(|m| m.linearisation == SpatialLoop::Closed && m.omega_rad_s > 0.0)
        .collect();
    assert_eq!(closed.len(), 3, "{closed:?}");
    for l in locked {
        let phi = cdpr_bench::core::robot::Vector::<3>::from(l.direction);
        let along: f64 = (0..robot.cables())
            .map(|i| {
                let chord = robot.chord(i, &pose);
                modes.tensions[i] / chord.length * chord.direction.dot(&phi).powi(2)
            })
            .sum::<f64>()
            / robot.effector_mass;
        let sigma = -c / ea * (l.omega_rad_s.powi(2) - geometric + along) / 2.0;
        let ringing = (l.omega_rad_s.powi(2) - sigma * sigma).sqrt();
        let m = closed
            .iter()
            .min_by(|a, b| {
                (a.omega_rad_s - ringing)
                    .abs()
                    .total_cmp(&(b.omega_rad_s - ringing).abs())
            })
            .unwrap();
        assert!(
            (m.omega_rad_s / ringing - 1.0).abs() < 1e-4,
            "{m:?} against {ringing}"
        );
        assert!((m.growth / sigma - 1.0).abs() < 2e-4, "{m:?}: σ {sigma}");
    }
}

/// `"auto"` picks, per axis, the least-damped mode along it: for the length loop the locked
/// robot's x and y modes (19.9 and 22.6 Hz at the bed's centre).
#[test]
fn auto_frequencies_are_the_modes_along_each_axis() {
    let mut s = printer(ControllerKind::Length);
    let modes = at_pose(&s, [0.0, 0.0, 0.0002]).unwrap();
    let [x, y, _] = auto_frequencies(&modes);
    let along = |k: usize| {
        modes
            .modes
            .iter()
            .filter(|m| m.linearisation == SpatialLoop::Closed && m.direction[k].abs() > 0.9)
            .map(|m| m.omega_rad_s / (2.0 * std::f64::consts::PI))
            .next()
            .unwrap()
    };
    assert_eq!((x.unwrap(), y.unwrap()), (along(0), along(1)));
    assert!((19.0..21.0).contains(&along(0)) && (22.0..23.5).contains(&along(1)));
    let printer = s.printer.as_mut().unwrap();
    printer.shaper = FirmwareShaper::Zv;
    assert!(needs_auto(&s));
    let resolved = resolve_auto(&s, [0.0, 0.0, 0.0002]).unwrap();
    let p = resolved.printer.unwrap();
    assert_eq!(p.shaper_freq_x, Designed::Value(along(0)));
    assert_eq!(p.shaper_freq_y, Designed::Value(along(1)));
}
