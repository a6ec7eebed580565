//! The modes of the FE cables in space with the reels locked (`cdpr_analysis::rest_modes` on
//! `cdpr_fe::spatial::FeSpatial`: the generalised problem K φ = ω² M φ with the consistent mass
//! matrix, l_i and ρ_i held), checked against what they did not produce:
//! - a weightless robot's taut lines: the transverse modes of a string of linear elements with
//!   consistent mass, in closed form;
//! - the Hangprinter's effector modes: the massless elastic lines' locked-reel stiffness at the
//!   same unstrained lengths, the gap first order in μ (Rayleigh);
//! - the lumped lines' named modes at the same pose: the same cables, the other discretisation.

use cdpr_bench::analysis::modes::ModeKind;
use cdpr_bench::analysis::rest_modes::{RestModes, rest_modes};
use cdpr_bench::core::model::{CableModel, PoseRule};
use cdpr_bench::core::robot::{Tensions, Vector};
use cdpr_bench::core::scenario::Scenario;
use cdpr_bench::fe::spatial::FeSpatial;

/// The Hangprinter example on FE cables of `elements` elements, line density `density`
/// [kg/m³] (the example's 970).
fn hangprinter(elements: usize, density: f64) -> Scenario {
    cdpr_verify::spatial::hangprinter("fe", elements, density)
}

/// `scenario`'s FE robot at rest at `p` under `tensions`, its reels then locked.
fn locked(scenario: &Scenario, p: &Vector<3>, tensions: Tensions) -> (FeSpatial, Vec<f64>) {
    let config = cdpr_bench::ModelConfig::from_scenario(scenario).unwrap();
    let mut model = FeSpatial::from_scenario(scenario, config.fe().unwrap()).unwrap();
    let rest = model
        .equilibrium(&PoseRule::new(p, tensions))
        .unwrap()
        .state;
    model.lock_reels(true);
    (model, rest)
}

/// The QP's tensions holding the effector's weight at `p`.
fn holding(scenario: &Scenario, p: &Vector<3>) -> Tensions {
    use cdpr_bench::core::robot::distribution::{DistributionMethod, TensionBox, distribute};
    let robot = scenario.spatial_robot().unwrap();
    let lift = Vector::<3>::new(0.0, 0.0, robot.effector_mass * robot.gravity);
    let limits = TensionBox {
        t_min: 10.0,
        t_max: 70.0,
    };
    let w = robot.structure_matrix(p);
    distribute(DistributionMethod::Qp, &w, &lift, limits)
        .unwrap()
        .tensions
}

/// A taut line's transverse modes are a string's of linear elements with consistent mass: a
/// weightless robot (g = 0) with anchors on a regular tetrahedron (circumradius 1.5 m) around
/// its effector, every line straight under 10 N, the effector held by a mass of 1e9 kg (its
/// own modes then ~1e-4 rad/s, its coupling to the strings 1e-9 of theirs). Each line is N
/// elements of stretched length d and unstrained h0 = l/N between fixed ends, across the line
/// K = (T/d) tridiag(−1, 2, −1) and M = (μ h0/6) tridiag(1, 4, 1), so
/// ω_k² = 6T/(μ h0 d) (1 − cos θ_k)/(2 + cos θ_k), θ_k = kπ/N, k = 1 … N − 1, each in two
/// directions on each of the four lines (8 copies), all below the axial modes. After the
/// effector's three, the 8(N − 1) lowest frequencies match them to 1e-7: the stiffness is the
/// element kernel's central differences (~1e-9 relative) and the masses its forward ones.
#[test]
fn a_taut_lines_transverse_modes_are_the_consistent_strings() {
    let elements = 8;
    let r = 1.5;
    let (a, b) = ((8.0f64 / 9.0).sqrt(), (2.0f64 / 9.0).sqrt());
    let c = (2.0f64 / 3.0).sqrt();
    let mut scenario = hangprinter(elements, 970.0);
    scenario.robot.anchors = Some(vec![
        vec![r * a, 0.0, -r / 3.0],
        vec![-r * b, r * c, -r / 3.0],
        vec![-r * b, -r * c, -r / 3.0],
        vec![0.0, 0.0, r],
    ]);
    scenario.robot.gravity = 0.0;
    scenario.robot.effector_mass = 1e9;
    let tension = 10.0;
    let p = Vector::<3>::zeros();
    let (mut model, rest) = locked(&scenario, &p, Tensions::from_fn(4, |_| tension));
    let named = rest_modes(&mut model, &rest, &[0.0; 4]).unwrap();
    let asymmetry = named.asymmetry.unwrap();
    assert!(asymmetry <= 1e-8, "asymmetry {asymmetry:e}");
    let omega: Vec<f64> = named.modes.iter().map(|m| m.mode.omega).collect();
    assert!(
        omega[2] < 1e-2,
        "the held effector's modes {:?}",
        &omega[..3]
    );
    let mu = model.material.mu;
    for cable in 0..4 {
        let t = model.element_tension(&rest, cable, 1);
        assert!(
            (t - tension).abs() <= 1e-9 * tension,
            "cable {cable}: {t} N"
        );
    }
    let l = model.free_length(&rest, 0);
    let (h0, d) = (l / elements as f64, r / elements as f64);
    for k in 1..elements {
        let theta = k as f64 * std::f64::consts::PI / elements as f64;
        let expected =
            (6.0 * tension / (mu * h0 * d) * (1.0 - theta.cos()) / (2.0 + theta.cos())).sqrt();
        for copy in 0..8 {
            let got = omega[3 + 8 * (k - 1) + copy];
            assert!(
                (got - expected).abs() <= 1e-7 * expected,
                "mode {k}, copy {copy}: {got} rad/s against {expected} rad/s"
            );
        }
    }
}

/// The effector's x, y and vertical modes, ascending [rad/s], each ≥ 90 % effector motion.
fn pure_effector_modes(named: &RestModes) -> Vec<f64> {
    let mut effector: Vec<f64> = [ModeKind::EffectorX, ModeKind::EffectorY, ModeKind::Vertical]
        .into_iter()
        .map(|kind| {
            let mode = named
                .modes
                .iter()
                .find(|m| m.kind == kind && m.order == 1)
                .unwrap_or_else(|| panic!("no {kind} mode"));
            assert!(mode.purity >= 0.9, "{kind}: purity {}", mode.purity);
            mode.mode.omega
        })
        .collect();
    effector.sort_by(f64::total_cmp);
    effector
}

/// The effector's three modes [rad/s], ascending, on massless elastic lines locked at the FE
/// lines' unstrained lengths l_i (MODELS.md §11: K = Σ (EA/l_i) u_i u_iᵀ + (T_i/d_i)(I − u_i
/// u_iᵀ), d_i the chord, T_i the line's tension at the effector).
fn elastic_locked_modes(model: &FeSpatial, rest: &[f64]) -> Vec<f64> {
    let p = model.effector(rest).position;
    let n = model.elements;
    let mut stiffness = nalgebra::Matrix3::<f64>::zeros();
    for cable in 0..4 {
        let chord = model.pulley(cable) - p;
        let (d, u) = (chord.norm(), chord.normalize());
        let t = model.element_tension(rest, cable, n);
        let l = model.free_length(rest, cable);
        stiffness += u * u.transpose() * (model.material.ea / l)
            + (nalgebra::Matrix3::identity() - u * u.transpose()) * (t / d);
    }
    cdpr_verify::spatial::point_mass_modes(&stiffness, model.robot().effector_mass)
}

/// The Hangprinter at rest at (0.1, 0.05, 0) m on FE lines (N = 10), reels locked: its
/// effector's x, y and vertical modes are the massless elastic lines' at the same unstrained
/// lengths within 0.5 % (the lines' 3 g each against the 1 kg effector, as the lumped lines'),
/// and the gap is first order in μ: 0.4–0.6 when μ halves from 1/8 of the example's (the
/// lines' inertia and their sag, both ∝ μ). K is symmetric to 1e-8 (conservative forces, the
/// stiffness by central differences of the element kernel).
#[test]
fn the_effector_modes_tend_to_the_elastic_lines_as_the_mass_vanishes() {
    let p = Vector::<3>::zeros();
    let gaps = |density: f64| -> Vec<f64> {
        let scenario = hangprinter(10, density);
        let (mut model, rest) = locked(&scenario, &p, holding(&scenario, &p));
        let named = rest_modes(&mut model, &rest, &[0.0; 4]).unwrap();
        let asymmetry = named.asymmetry.unwrap();
        assert!(asymmetry <= 1e-8, "asymmetry {asymmetry:e}");
        let fe = pure_effector_modes(&named);
        let elastic = elastic_locked_modes(&model, &rest);
        eprintln!("density {density}: FE {fe:?}, elastic {elastic:?} rad/s");
        fe.iter()
            .zip(&elastic)
            .map(|(f, e)| (f - e).abs() / e)
            .collect()
    };
    let example = gaps(970.0);
    let (coarse, fine) = (gaps(970.0 / 8.0), gaps(970.0 / 16.0));
    for k in 0..3 {
        assert!(example[k] < 5e-3, "mode {k}: {} relative", example[k]);
        let ratio = fine[k] / coarse[k];
        assert!(
            (0.4..=0.6).contains(&ratio),
            "mode {k}: gaps {} and {}",
            coarse[k],
            fine[k]
        );
    }
}

/// Each cable's lowest string mode across its vertical plane at rest at the origin, reels
/// locked: on FE lines it converges at second order in 1/N — the differences between N = 10,
/// 20 and 40 shrink 3.5–4.5 times (a string's consistent mass is high by ~(π/N)²/24) — and at
/// N = 10 it lies within 1 % of the lumped lines' (N = 40, about 20 springs on a free span,
/// low by ~(π/20)²/24): 0.5 % apart here, the two discretisations from either side.
#[test]
fn the_string_modes_converge_and_meet_the_lumped_lines() {
    use cdpr_bench::lumped::spatial::LumpedSpatial;
    let p = Vector::<3>::zeros();
    let across = |named: &RestModes, cable: usize| {
        named
            .modes
            .iter()
            .find(|m| m.kind == ModeKind::OutOfPlane(cable) && m.order == 1)
            .unwrap_or_else(|| panic!("cable {cable}: no out-of-plane mode"))
            .mode
            .omega
    };
    let fe = |elements: usize| {
        let scenario = hangprinter(elements, 970.0);
        let (mut model, rest) = locked(&scenario, &p, holding(&scenario, &p));
        rest_modes(&mut model, &rest, &[0.0; 4]).unwrap()
    };
    let runs = [fe(10), fe(20), fe(40)];
    let lumped_scenario = {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../examples/robots/hangprinter-lumped.toml");
        Scenario::from_toml_str(&std::fs::read_to_string(path).unwrap()).unwrap()
    };
    let mut lumped = LumpedSpatial::from_scenario(&lumped_scenario, 40).unwrap();
    let lumped_rest = lumped
        .equilibrium(&PoseRule::new(&p, holding(&lumped_scenario, &p)))
        .unwrap()
        .state;
    lumped.lock_reels(true);
    let lumped_modes = rest_modes(&mut lumped, &lumped_rest, &[0.0; 4]).unwrap();
    // The fourth line hangs from the ceiling straight above the origin: no vertical plane.
    for cable in 0..3 {
        let [a, b, c] = [0, 1, 2].map(|k| across(&runs[k], cable));
        let l = across(&lumped_modes, cable);
        let ratio = (a - b) / (b - c);
        eprintln!(
            "cable {}: across FE N = 10, 20, 40: {a}, {b}, {c}; lumped {l} rad/s; ratio {ratio}",
            cable + 1
        );
        assert!(
            (3.5..=4.5).contains(&ratio),
            "cable {}: ratio {ratio}",
            cable + 1
        );
        assert!(
            (a - l).abs() <= 1e-2 * l,
            "cable {}: {a} against {l}",
            cable + 1
        );
    }
}

/// The effector's modes at any N, by shift-invert Lanczos in the M inner product
/// (`rest_modes_near`, 60 steps, consistent masses): at N = 10 the six modes nearest 120 rad/s
/// are the dense solve's to 1e-8 relative — K's asymmetry (the element kernel's central
/// differences, ≤ 1e-8): the dense solve takes K's symmetric part, the sparse one K itself
/// (1.3e-9 measured); at N = 1000 — 12 011
/// coordinates, six times the dense solve's limit, the rest from the sparse statics — the
/// effector's x, y and vertical modes are among the twelve nearest and within 0.5 % of the
/// elastic lines' locked at the same lengths, as at N = 10.
#[test]
fn the_effectors_modes_at_any_n_by_shift_invert() {
    use cdpr_bench::analysis::rest_modes::rest_modes_near;
    let p = Vector::<3>::zeros();
    let scenario = hangprinter(10, 970.0);
    let (mut model, rest) = locked(&scenario, &p, holding(&scenario, &p));
    let dense = rest_modes(&mut model, &rest, &[0.0; 4]).unwrap();
    let (near, _) = rest_modes_near(&mut model, &rest, &[0.0; 4], (120.0, 6, 60)).unwrap();
    for (found, expected) in near
        .modes
        .iter()
        .zip(&cdpr_verify::spatial::nearest(&dense, 120.0, 6))
    {
        let omega = found.mode.omega;
        assert!(
            (omega - expected).abs() <= 1e-8 * expected,
            "{omega} rad/s against the dense {expected} rad/s"
        );
    }
    let fine_scenario = hangprinter(1000, 970.0);
    let (mut fine, fine_rest) = locked(&fine_scenario, &p, holding(&fine_scenario, &p));
    let (near, residuals) =
        rest_modes_near(&mut fine, &fine_rest, &[0.0; 4], (120.0, 12, 80)).unwrap();
    let elastic = elastic_locked_modes(&fine, &fine_rest);
    let effector = cdpr_verify::spatial::effector_modes(&near);
    eprintln!(
        "N = 1000: effector {effector:?}, elastic {elastic:?} rad/s, residuals {residuals:?}"
    );
    for (f, e) in effector.iter().zip(&elastic) {
        assert!(
            (f - e).abs() <= 5e-3 * e,
            "N = 1000: {effector:?} against {elastic:?}"
        );
    }
}
