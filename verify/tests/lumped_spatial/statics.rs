//! The lumped spatial model's statics: every node at rest and every cable in its vertical plane
//! by the model's own force assembly, each span against Irvine's elastic catenary at first
//! order, and the rest with the reels locked at the firmware's flex-compensated lengths against
//! the continuous lines' balance.

use super::*;

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// At the statics' rest every coordinate's net force vanishes — the effector's, each free
    /// node's, each stored node's along its reel line — by the model's force assembly, which the
    /// shooting does not use: to 1e-9 N per node (the shooting ends within 1e-12 m of the
    /// effector; a spring of k0 = EA/l0 ≈ 1.3e5 N/m turns that into ~1e-7 N at the effector,
    /// whose balance Newton then closes to 1e-11 of the load), and every cable in the vertical
    /// plane through its pulley and the effector (any azimuth) to 1e-12 m.
    #[test]
    fn the_rest_is_at_rest_and_each_cable_in_its_vertical_plane(
        x in -0.3..0.3f64,
        y in -0.3..0.3f64,
        z in 0.0..0.5f64,
        density in 970.0..20000.0f64,
        elements in 6usize..30,
        shift in prop::array::uniform4(prop::array::uniform3(-0.1..0.1f64)),
    ) {
        let mut model = robot(elements, density, shift);
        let p = Vector3::new(x, y, z);
        // Shifted anchors can leave the pose outside the wrench-feasible workspace.
        let tensions = holding_if_feasible(&model, &p);
        prop_assume!(tensions.is_some());
        let tensions = tensions.unwrap();
        let eq = model.equilibrium(&PoseRule::new(&p, tensions)).unwrap();
        let mut rate = vec![0.0; model.state_len()];
        model.rhs(0.0, &eq.state, &eq.tensions, &mut rate);
        let np = model.positions_len();
        let load = 9.81 + eq.tensions.iter().sum::<f64>();
        for (k, a) in rate[np..].iter().enumerate() {
            let mass = if k >= np - 3 { 1.0 } else { model.node_mass };
            prop_assert!((a * mass).abs() <= 1e-9 * load.max(1.0), "coordinate {k}: {} N", a * mass);
        }
        for cable in 0..4 {
            let a = model.pulley(cable);
            let normal = Vector3::z().cross(&(p - a)).normalize();
            for j in model.stored()[cable]..model.elements {
                let off = (model.node(&eq.state, cable, j) - a).dot(&normal);
                prop_assert!(off.abs() <= 1e-12, "cable {cable} node {j}: {off} m out of plane");
            }
        }
    }
}

/// One cable's free span against Irvine's catenary with the same free unstrained length from
/// the pulley to the effector: the difference of the tension at the pulley and of the force on
/// the effector, over the tension.
fn irvine_gap(elements: usize, p: Vector3<f64>, tension: f64, density: f64) -> f64 {
    let model = robot(elements, density, [[0.0; 3]; 4]);
    let cable = 0;
    let h = hang(&model, cable, &p, tension).unwrap();
    let a = model.pulley(cable);
    let d = p - a;
    let horizontal = Vector3::new(d.x, d.y, 0.0);
    let unit = horizontal.normalize();
    let c = Catenary::through(
        [horizontal.norm(), d.z],
        h.free_length,
        model.node_mass / model.segment * 9.81,
        model.stiffness * model.segment,
    )
    .unwrap();
    let at_end = c.vertical + c.weight * h.free_length;
    let pull = -(unit * c.horizontal + Vector3::z() * at_end);
    let at_pulley = c.horizontal.hypot(c.vertical);
    ((h.straddle_tension - at_pulley).abs() + (h.pull - pull).norm()) / tension
}

/// Irvine per span, first order in 1/N as MODELS.md §4's lumping is: the gap halves when N
/// doubles (ratio within [0.4, 0.6]) and is below the cable's weight over N (in tension units),
/// for a heavy line (ρ = 2e4 kg/m³, so the sag is 10 times the example line's) at two poses.
#[test]
fn each_span_tends_to_irvines_catenary_at_first_order() {
    for (p, tension) in [
        (Vector3::new(0.1, 0.05, 0.02), 15.0),
        (Vector3::new(-0.2, 0.2, 0.4), 40.0),
    ] {
        let gaps: Vec<f64> = [20, 40, 80, 160]
            .iter()
            .map(|&n| irvine_gap(n, p, tension, 2e4))
            .collect();
        for k in 1..gaps.len() {
            let ratio = gaps[k] / gaps[k - 1];
            assert!(
                (0.4..=0.6).contains(&ratio),
                "gaps {gaps:?} at {p:?}: ratio {ratio}"
            );
        }
        let weight = 2e4 * 9.503e-7 * 9.81 * 2.0;
        assert!(gaps[0] * tension < weight / 20.0, "{gaps:?}");
    }
}

/// The firmware's static flex compensation on lumped lines: at `p` the QP's tensions holding
/// the weight, the unstrained lengths l_i/(1 + T_i/EA) the firmware commands (MODELS.md §11),
/// and where the effector rests with the reels locked at them. Returns the rest pose and the
/// robot.
fn firmware_rest(elements: usize, density: f64, p: Vector3<f64>) -> (Vector3<f64>, LumpedSpatial) {
    let model = robot(elements, density, [[0.0; 3]; 4]);
    let tensions = holding(&model, &p);
    let ea = model.stiffness * model.segment;
    let lengths: Vec<f64> = (0..4)
        .map(|i| (model.pulley(i) - p).norm() / (1.0 + tensions[i] / ea))
        .collect();
    let (rest, _) = cdpr_bench::lumped::spatial::rest_with_lengths(&model, &p, &lengths).unwrap();
    (rest, model)
}

/// Where the lumped rest with locked reels puts the effector, each line's Irvine catenary with
/// the line's free unstrained length (from the lumped statics) pulls it; with the weight their
/// sum is the continuous cables' imbalance there, which the lumping's first-order error leaves:
/// it halves when N doubles (for a line 20 times the example's density: 5.9e-2, 2.9e-2,
/// 1.5e-2 N at N = 20, 40, 80; ratio within 0.4–0.6). The rest moves off the commanded pose with
/// the lines' mass at first order (the firmware's flex compensation is exact for massless
/// straight lines): halving ρ from 1250 to 625 kg/m³ halves the error (ratio within
/// 0.45–0.55; from 2e4 kg/m³ down the ratios are 0.40, 0.44, 0.47, 0.48, 0.49 as a μ² part
/// fades; the error is 88 µm at 2e4 kg/m³, 1.7 µm at 625).
#[test]
fn locked_reels_at_the_firmwares_lengths_rest_where_irvine_balances() {
    let p = Vector3::new(0.1, 0.05, 0.3);
    let imbalance = |n: usize| {
        let (rest, model) = firmware_rest(n, 2e4, p);
        let ea = model.stiffness * model.segment;
        let w = model.node_mass / model.segment * 9.81;
        let tensions = holding(&model, &p);
        let mut sum = Vector3::new(0.0, 0.0, -9.81);
        for i in 0..4 {
            let a = model.pulley(i);
            let free = (a - p).norm() / (1.0 + tensions[i] / ea);
            let d = rest - a;
            let horizontal = Vector3::new(d.x, d.y, 0.0);
            let c = Catenary::through([horizontal.norm(), d.z], free, w, ea).unwrap();
            let at_end = c.vertical + c.weight * free;
            sum -= horizontal.normalize() * c.horizontal + Vector3::z() * at_end;
        }
        sum.norm()
    };
    let (i20, i40, i80) = (imbalance(20), imbalance(40), imbalance(80));
    for ratio in [i40 / i20, i80 / i40] {
        assert!(
            (0.4..=0.6).contains(&ratio),
            "imbalances {i20:e}, {i40:e}, {i80:e} N"
        );
    }
    let (heavy, _) = firmware_rest(40, 1250.0, p);
    let (light, _) = firmware_rest(40, 625.0, p);
    let ratio = (light - p).norm() / (heavy - p).norm();
    assert!(
        (0.45..=0.55).contains(&ratio),
        "rest errors {} m, {} m",
        (heavy - p).norm(),
        (light - p).norm()
    );
}

/// Where the effector of `anchors` rests on continuous lines (Irvine's elastic catenary per
/// span, weight `w` [N/m], axial stiffness `ea` [N]) locked at unstrained free `lengths` [m]:
/// Newton on the effector's balance from `guess`, central differences of 1e-7 m. Written here
/// from the catenary alone: none of the lumped model's statics.
fn irvine_rest(
    anchors: &[Vector3<f64>],
    lengths: &[f64],
    (w, ea, weight): (f64, f64, f64),
    guess: Vector3<f64>,
) -> Vector3<f64> {
    let balance = |p: Vector3<f64>| {
        let mut sum = Vector3::new(0.0, 0.0, -weight);
        for (a, &l) in anchors.iter().zip(lengths) {
            let d = p - a;
            let horizontal = Vector3::new(d.x, d.y, 0.0);
            let c = Catenary::through([horizontal.norm(), d.z], l, w, ea).unwrap();
            sum -= horizontal.normalize() * c.horizontal + Vector3::z() * (c.vertical + w * l);
        }
        sum
    };
    let mut p = guess;
    for _ in 0..30 {
        let r = balance(p);
        if r.norm() < 1e-9 * weight {
            break;
        }
        let mut jacobian = nalgebra::Matrix3::zeros();
        for k in 0..3 {
            let e = Vector3::ith(k, 1e-7);
            jacobian.set_column(k, &((balance(p + e) - balance(p - e)) / 2e-7));
        }
        p -= jacobian.try_inverse().unwrap() * r;
    }
    p
}

/// `cargo xtask flex-error`'s study on the CoGiRo example's 4 mm steel lines at its worst target
/// (the box's corner [−4, 3, 0.5] m, where the firmware's straight-line lengths leave the
/// effector 1.9 mm off): the lumped rest tends at first order to the rest on continuous lines
/// computed here from Irvine's catenary (gap ratio within 0.4–0.6 when N doubles; measured 17.7,
/// 8.3, 4.3 µm at N = 20, 40, 80), and at N = 80 lies within 1 % of the error it measures from
/// it (the continuous lines' rest is 1.884 mm off the target).
#[test]
fn the_flex_error_study_tends_to_the_continuous_lines() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/robots/cogiro-lumped.toml"
    );
    let s = cdpr_bench::scenario_from_file(std::path::Path::new(path)).unwrap();
    let target = [-4.0, 3.0, 0.5];
    let study = |n: usize| {
        let points = cdpr_studies::flex_error::over_box(&s, target, target, 1, n)
            .unwrap()
            .points;
        points[0].clone()
    };
    let anchors: Vec<Vector3<f64>> = s
        .robot
        .anchors
        .as_ref()
        .unwrap()
        .iter()
        .map(|a| Vector3::new(a[0], a[1], a[2]))
        .collect();
    let ea = s.cable.axial_stiffness();
    let first = study(20);
    let lengths: Vec<f64> = anchors
        .iter()
        .zip(&first.assumed_tensions)
        .map(|(a, t)| (a - Vector3::from(target)).norm() / (1.0 + t / ea))
        .collect();
    let weight = s.robot.effector_mass * s.robot.gravity;
    let w = s.cable.mass_per_length() * s.robot.gravity;
    let continuous = irvine_rest(&anchors, &lengths, (w, ea, weight), Vector3::from(target));
    let gap = |p: &cdpr_studies::flex_error::FlexPoint| (Vector3::from(p.rest) - continuous).norm();
    let (g20, g40, g80) = (gap(&first), gap(&study(40)), gap(&study(80)));
    for ratio in [g40 / g20, g80 / g40] {
        assert!(
            (0.4..=0.6).contains(&ratio),
            "gaps {g20:e}, {g40:e}, {g80:e} m"
        );
    }
    let error = (continuous - Vector3::from(target)).norm();
    assert!(g80 < 0.01 * error, "{g80:e} m of {error:e} m");
}
