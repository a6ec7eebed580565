//! The variable-length FE cables in space (`cdpr_fe::spatial::FeSpatial`), checked against what
//! they did not produce:
//! - two cables in the x–z plane are the planar FE model (MODELS.md §5, itself checked against
//!   FE.10's numbers): the same accelerations at any state, none across the plane;
//! - at rest each cable lies in the vertical plane through its pulley and the effector (any
//!   azimuth), on Irvine's elastic catenary at second order in 1/N;
//! - the Hangprinter move: the energy balance with the reels' work (FE.7), the rest tensions of
//!   the lumped lines to within the lines' weight, and the elastic cables' path as μ → 0;
//! - reels driven by length on the implicit path, converging to DOPRI5 at second order;
//! - what it does not run yet is refused by name.

use cdpr_bench::core::model::{CableModel, PoseRule, SplitRule};
use cdpr_bench::core::robot::Vector;
use cdpr_bench::core::runner::Observer;
use cdpr_bench::core::scenario::Scenario;
use cdpr_bench::fe::spatial::FeSpatial;
use cdpr_bench::fe::{Fe, Params};
use cdpr_verify::irvine::Catenary;
use nalgebra::Vector3;
use proptest::prelude::*;

/// The paper's robot spelled as a spatial one: anchors (0, 0, 0) and (d, 0, 0).
fn paper_in_space() -> Scenario {
    let mut s = Scenario::paper();
    let d = s.robot.anchor_distance;
    s.robot.anchors = Some(vec![vec![0.0, 0.0, 0.0], vec![d, 0.0, 0.0]]);
    s
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// At any state near the paper's rest (x ∈ [0.5, 0.7] m, nodes moved by up to 5 mm and
    /// moving at up to 0.5 m/s, l and ρ rates up to 0.5 m/s), N = 1 … 12, both mass variants:
    /// the spatial model's accelerations are the planar model's to 1e-9 of the largest (the two
    /// solve the same M q'' = F by different eliminations), and exactly 0 across the plane.
    #[test]
    fn two_cables_in_the_xz_plane_are_the_planar_fe(
        x in 0.5f64..0.7, elements in 1usize..=12, lumped in any::<bool>(),
        seed in 0u64..1000, t1 in 80.0f64..120.0, t2 in 80.0f64..120.0,
    ) {
        let params = Params {
            elements,
            mass: if lumped { cdpr_bench::fe::FeMass::Lumped } else { cdpr_bench::fe::FeMass::Consistent },
            ..Params::default()
        };
        let mut planar = Fe::new(&Scenario::paper(), params).unwrap();
        let mut spatial = FeSpatial::from_scenario(&paper_in_space(), params).unwrap();
        let rest = planar.equilibrium(&SplitRule::new(x, 200.0)).unwrap().state;
        let mut state = seed as f64 * 0.618;
        let mut jiggle = |scale: f64| {
            state = (state * 9301.0 + 49297.0) % 233280.0;
            scale * (state / 116640.0 - 1.0)
        };
        let (np2, np3, n) = (planar.positions_len(), spatial.positions_len(), elements);
        let mut y2 = rest.clone();
        for v in &mut y2[..np2 - 4] {
            *v += jiggle(5e-3);
        }
        for v in &mut y2[np2..] {
            *v = jiggle(0.5);
        }
        // The planar state in the spatial layout, y = 0.
        let mut y3 = vec![0.0; 2 * np3];
        let mut pairs = Vec::new();
        for cable in 0..2 {
            for k in 1..=n {
                let j = planar.chain_index(cable, k).unwrap();
                for (axis2, axis3) in [(0, 0), (1, 2)] {
                    let from = planar.node_coordinate(j, axis2);
                    let to = if k == n {
                        spatial.effector_index(axis3)
                    } else {
                        spatial.node_index(cable, k, axis3)
                    };
                    pairs.push((from, to));
                }
            }
            pairs.push((planar.l_index(cable), spatial.l_index(cable)));
            pairs.push((planar.rho_index(cable).unwrap(), spatial.l_index(cable) + 1));
        }
        for &(from, to) in &pairs {
            y3[to] = y2[from];
            y3[np3 + to] = y2[np2 + from];
        }
        let (mut a2, mut a3) = (vec![0.0; np2], vec![0.0; np3]);
        prop_assert!(planar.accelerations(&y2, [t1, t2], &mut a2));
        prop_assert!(spatial.accelerations(&y3, &[t1, t2], &mut a3));
        let scale = a2.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for &(from, to) in &pairs {
            prop_assert!(
                (a2[from] - a3[to]).abs() <= 1e-9 * scale,
                "q[{from}]'' = {} planar, {} spatial (scale {scale:e})", a2[from], a3[to]
            );
        }
        for cable in 0..2 {
            for k in 1..n {
                prop_assert_eq!(a3[spatial.node_index(cable, k, 1)], 0.0);
            }
        }
        prop_assert_eq!(a3[spatial.effector_index(1)], 0.0);
        // The same energy, term by term, to round-off.
        let (e2, e3) = (planar.energy(&y2), spatial.energy(&y3));
        prop_assert!((e2.total() - e3.total()).abs() <= 1e-12 * e2.total().abs().max(1.0));
    }
}

/// The Hangprinter example on FE cables of `elements` elements, line density `density`
/// [kg/m³] (the example's 970).
fn hangprinter(elements: usize, density: f64) -> Scenario {
    cdpr_verify::spatial::hangprinter("fe", elements, density)
}

/// The rest at `p` under the QP's tensions there, N elements, line density `density`.
fn rest(elements: usize, density: f64, p: [f64; 3]) -> (FeSpatial, Vec<f64>) {
    let s = hangprinter(elements, density);
    let config = cdpr_bench::ModelConfig::from_scenario(&s).unwrap();
    let mut model = FeSpatial::from_scenario(&s, config.fe().unwrap()).unwrap();
    let p = Vector::<3>::from(p);
    let w = model.robot().structure_matrix(&p);
    let lift = Vector::<3>::new(0.0, 0.0, model.robot().effector_mass * 9.81);
    let limits = cdpr_bench::core::robot::distribution::TensionBox {
        t_min: 10.0,
        t_max: 70.0,
    };
    let d = cdpr_bench::core::robot::distribution::distribute(
        cdpr_bench::core::robot::distribution::DistributionMethod::Qp,
        &w,
        &lift,
        limits,
    )
    .unwrap();
    let eq = model.equilibrium(&PoseRule::new(&p, d.tensions)).unwrap();
    (model, eq.state)
}

/// The largest distance of a cable's nodes from Irvine's catenary with the same free unstrained
/// length between the same ends [m].
fn irvine_gap(model: &FeSpatial, y: &[f64]) -> f64 {
    let n = model.elements;
    let p = model.effector(y).position;
    let w = model.material.mu * model.material.gravity;
    let mut worst = 0.0f64;
    for cable in 0..model.robot().cables() {
        let a = model.pulley(cable);
        let d = p - a;
        let horizontal = Vector3::new(d.x, d.y, 0.0);
        let l = model.free_length(y, cable);
        if horizontal.norm() < 1e-9 {
            continue; // a plumb line: no catenary
        }
        let unit = horizontal.normalize();
        let c = Catenary::through([horizontal.norm(), d.z], l, w, model.material.ea).unwrap();
        for k in 1..n {
            let [s, z] = c.position(l * k as f64 / n as f64);
            let on = a + unit * s + Vector3::z() * z;
            worst = worst.max((model.node(y, cable, k).0 - on).norm());
        }
    }
    worst
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(8))]

    /// Anywhere in the Hangprinter's volume, every node of every cable at rest lies in the
    /// vertical plane through its pulley and the effector (1e-12 m: nothing pushes across it).
    #[test]
    fn each_cable_rests_in_its_vertical_plane(
        x in -0.3f64..0.3, y in -0.3f64..0.3, z in 0.0f64..0.6,
    ) {
        let (model, state) = rest(6, 970.0, [x, y, z]);
        let p = model.effector(&state).position;
        for cable in 0..4 {
            let a = model.pulley(cable);
            let across = Vector3::z().cross(&(p - a));
            if across.norm() < 1e-9 {
                continue;
            }
            let normal = across.normalize();
            for k in 1..model.elements {
                let off = (model.node(&state, cable, k).0 - a).dot(&normal);
                prop_assert!(off.abs() <= 1e-12, "cable {cable} node {k}: {off:e} m");
            }
        }
    }
}

/// A heavy line (ρ = 2e4 kg/m³, 20 times the example's sag: ~4 mm on 1.5 m at 13 N) at two
/// poses: the nodes approach Irvine's catenary at second order — the gap falls by 0.2–0.3 per
/// doubling of N (0.25 for a second-order method; measured 0.2502–0.2508) — and lie within
/// 4 µm (1e-3 of the sag) of it at N = 16; at N = 1000 (the sparse statics) within 2e-9 m,
/// where second order from N = 16 predicts 7e-10 m.
#[test]
fn each_span_tends_to_irvines_catenary_at_second_order() {
    for p in [[0.1, 0.05, 0.02], [-0.2, 0.2, 0.4]] {
        let gaps: Vec<f64> = [4, 8, 16]
            .iter()
            .map(|&n| {
                let (model, state) = rest(n, 2e4, p);
                irvine_gap(&model, &state)
            })
            .collect();
        for k in 1..gaps.len() {
            let ratio = gaps[k] / gaps[k - 1];
            assert!(
                (0.2..=0.3).contains(&ratio),
                "gaps {gaps:?} at {p:?}: ratio {ratio}"
            );
        }
        assert!(gaps[2] < 4e-6, "{gaps:?}");
        let (model, state) = rest(1000, 2e4, p);
        let fine = irvine_gap(&model, &state);
        eprintln!("N = 4, 8, 16: {gaps:?}; N = 1000: {fine:e} m");
        assert!(fine < 2e-9, "N = 1000: {fine:e} m from Irvine's catenary");
    }
}

/// The Hangprinter move (computed-torque, QP, 0.4 s) on FE cables of 10 elements.
fn run(s: &Scenario) -> cdpr_bench::SpatialRun {
    let mut quiet = |_: f64| {};
    cdpr_bench::simulate_spatial(s, &mut Observer::progress(&mut quiet)).unwrap()
}

/// Largest distance between the effector positions of two runs sampled alike [m].
fn path_gap(a: &cdpr_bench::SpatialRun, b: &cdpr_bench::SpatialRun) -> f64 {
    use cdpr_bench::core::channel::Channel;
    let path = |r: &cdpr_bench::SpatialRun| {
        let c = |ch| r.run.series.column(ch).unwrap();
        (c(Channel::X), c(Channel::Y), c(Channel::Z))
    };
    let ((x, y, z), (x0, y0, z0)) = (path(a), path(b));
    (0..x.len())
        .map(|i| ((x[i] - x0[i]).powi(2) + (y[i] - y0[i]).powi(2) + (z[i] - z0[i]).powi(2)).sqrt())
        .fold(0.0, f64::max)
}

fn short(mut s: Scenario) -> Scenario {
    s.simulation.t_final = 0.4;
    s.validate().unwrap();
    s
}

/// The move's energy balance with the reels' work W = ∫ Σ T_i ρ_i' dt (FE.7) closes to 1e-6 J
/// (DOPRI5 at the default tolerances; measured 1e-8 J over the 1.2 s move) on ~3 J of work; the
/// rest at the start carries the same tensions as the lumped lines' to within a third of one
/// line's weight (both models carry the lines' weight, each to its discretisation's order).
#[test]
fn the_move_balances_energy_and_rests_as_the_lumped_lines() {
    let fe = run(&short(hangprinter(10, 970.0)));
    let m = &fe.metrics;
    assert!(
        m.energy_residual_max < 1e-6,
        "{:e} J",
        m.energy_residual_max
    );
    let mut lumped_scenario = short(hangprinter(10, 970.0));
    lumped_scenario =
        cdpr_bench::with_model_kind(&lumped_scenario, cdpr_bench::ModelKind::Lumped).unwrap();
    let lumped = run(&lumped_scenario);
    let line_weight = 970.0 * 9.503e-7 * 2.3 * 9.81;
    for (a, b) in m.rest_tensions.iter().zip(&lumped.metrics.rest_tensions) {
        assert!(
            (a - b).abs() < line_weight / 3.0,
            "rest tensions {:?} against the lumped {:?}",
            m.rest_tensions,
            lumped.metrics.rest_tensions
        );
    }
}

/// FE.5.7 asks that the axial damping's terms be checked by the dissipation identity before
/// they are relied on, and the print example's lines carry C = 8.5 N s: the Hangprinter move
/// (0.4 s, DOPRI5 at the default tolerances) on damped FE lines closes dE/dt = Σ T_i ρ_i' − D
/// to 1e-6 J, as the undamped move, while the damping dissipates D > 1e-4 J — a hundred times
/// the bound, so leaving D out of the balance (or a damping force that does not dissipate it)
/// fails.
#[test]
fn the_damped_move_balances_energy_with_its_dissipation() {
    use cdpr_bench::core::channel::Channel;
    let mut s = short(hangprinter(10, 970.0));
    s.cable.axial_damping = 8.5;
    let fe = run(&s);
    let dissipated = *fe
        .run
        .series
        .column(Channel::EDissipated)
        .unwrap()
        .last()
        .unwrap();
    let residual = fe.metrics.energy_residual_max;
    eprintln!("damped move: dissipated {dissipated:e} J, residual {residual:e} J");
    assert!(residual < 1e-6, "{residual:e} J");
    assert!(dissipated > 1e-4, "dissipated {dissipated:e} J");
}

/// As the lines' mass vanishes the FE robot's move tends to the massless elastic cables':
/// the largest distance between the two effector paths halves with the density (ratio within
/// [0.4, 0.6]: the lines' inertia and weight act at first order in μ).
#[test]
fn the_path_tends_to_the_elastic_cables_as_mu_goes_to_zero() {
    let elastic = run(&short(
        cdpr_bench::with_model_kind(&hangprinter(10, 970.0), cdpr_bench::ModelKind::Elastic)
            .unwrap(),
    ));
    let gaps: Vec<f64> = [970.0, 485.0, 242.5]
        .iter()
        .map(|&rho| path_gap(&run(&short(hangprinter(10, rho))), &elastic))
        .collect();
    for k in 1..gaps.len() {
        let ratio = gaps[k] / gaps[k - 1];
        assert!((0.4..=0.6).contains(&ratio), "gaps {gaps:?}: ratio {ratio}");
    }
}

/// What the spatial FE cables do not run yet is refused by name: the rigid stored cable before
/// any work, a mesh beyond the dense statics at the start.
#[test]
fn what_is_not_built_is_refused_by_name() {
    let refused = |s: Scenario, key: &str| {
        let e = cdpr_bench::prepare_spatial(&s)
            .err()
            .map(|e| e.to_string())
            .or_else(|| {
                let mut quiet = |_: f64| {};
                cdpr_bench::simulate_spatial(&s, &mut Observer::progress(&mut quiet))
                    .err()
                    .map(|e| e.to_string())
            })
            .unwrap_or_else(|| panic!("{key}: accepted"));
        assert!(e.contains(key), "{key}: {e}");
    };
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/robots/hangprinter-lumped.toml");
    let rigid = std::fs::read_to_string(path)
        .unwrap()
        .replace("kind = \"lumped\"", "kind = \"fe\"\nfe_stored = \"rigid\"")
        .replace("elements = 20", "elements = 10");
    refused(Scenario::from_toml_str(&rigid).unwrap(), "model.fe_stored");
}

/// Pseudo-random numbers in [−scale, scale) from a seed (a linear congruential sequence).
struct Jiggle(f64);

impl Jiggle {
    fn next(&mut self, scale: f64) -> f64 {
        self.0 = (self.0 * 9301.0 + 49297.0) % 233280.0;
        scale * (self.0 / 116640.0 - 1.0)
    }
}

/// The Hangprinter's rest near (0.1, 0.05, 0.02) m on FE cables of `elements` elements, its
/// nodes moved by up to 2 mm and every rate (nodes, l_i, ρ_i) set within ±`speed`, and the
/// sequence that did it, to go on.
fn shaken_rest(elements: usize, seed: u64, speed: f64) -> (FeSpatial, Vec<f64>, Jiggle) {
    let (model, mut y) = rest(elements, 970.0, [0.1, 0.05, 0.02]);
    let np = model.positions_len();
    let mut jiggle = Jiggle(seed as f64 * 0.618);
    for v in &mut y[..np - 8] {
        *v += jiggle.next(2e-3);
    }
    for v in &mut y[np..] {
        *v = jiggle.next(speed);
    }
    (model, y, jiggle)
}

/// The print example's axial damping C = 8.5 N s if `damped`; if `driven`, the reels driving
/// the lengths (Du's form) with commanded l̇0 within ±0.05 m/s and l̈0 within ±2 m/s² from
/// `seed`.
fn damp_and_drive(model: &mut FeSpatial, damped: bool, driven: bool, seed: u64) {
    use cdpr_bench::core::model::CableModel;
    use cdpr_bench::core::robot::PerCable;
    if damped {
        model.axial_damping = 8.5;
    }
    if driven {
        let mut jiggle = Jiggle(seed as f64 * 0.377);
        model.lock_reels(true);
        let rates = PerCable::from_fn(4, |_| jiggle.next(0.05));
        let accelerations = PerCable::from_fn(4, |_| jiggle.next(2.0));
        model.drive_reels(&rates, &accelerations);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// The implicit path's residual R = M q'' − F, summed from the element rows, vanishes at
    /// the explicit solve's q'' = M⁻¹F from the star's assembly (to 1e-9 of the largest force
    /// row), at states near the Hangprinter's rest (nodes moved by up to 2 mm and moving at up
    /// to 0.3 m/s), N = 1 … 12, with and without axial damping, under tension reels and driven
    /// by length (commanded l̇0 and l̈0 random): the two paths integrate one model. A dropped
    /// element, stored element or coupling leaves a residual of the order of the forces.
    /// Driven by length, M⁻¹F has l_i'' = the command, so the spans' reading l_i'' from the
    /// command rather than from q'' is checked apart: with every l_i'' in q'' moved by 1 m/s²,
    /// only the l_i rows change, each by 1 (to round-off).
    #[test]
    fn the_implicit_residual_vanishes_at_the_explicit_accelerations(
        elements in 1usize..=12, seed in 0u64..1000, damped in any::<bool>(), driven in any::<bool>(),
    ) {
        use cdpr_bench::core::second_order::SecondOrderForm;
        let (mut model, y, _) = shaken_rest(elements, seed, 0.3);
        damp_and_drive(&mut model, damped, driven, seed);
        let np = model.positions_len();
        let tensions = [14.0, 13.0, 11.0, 12.5];
        let mut qdd = vec![0.0; np];
        prop_assert!(model.accelerations(&y, &tensions, &mut qdd));
        let mut forces = vec![0.0; np];
        SecondOrderForm::residual(&mut model, &y, &vec![0.0; np], &tensions, &mut forces);
        let scale = forces.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let mut r = vec![0.0; np];
        SecondOrderForm::residual(&mut model, &y, &qdd, &tensions, &mut r);
        let worst = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        prop_assert!(worst <= 1e-9 * scale, "|R| = {worst:e} against forces of {scale:e} N");
        if driven {
            let l_rows: Vec<usize> = (0..4).map(|c| model.l_index(c)).collect();
            let mut moved = qdd.clone();
            for &l in &l_rows {
                moved[l] += 1.0;
            }
            let mut r_moved = vec![0.0; np];
            SecondOrderForm::residual(&mut model, &y, &moved, &tensions, &mut r_moved);
            for (i, (a, b)) in r_moved.iter().zip(&r).enumerate() {
                let expected = if l_rows.contains(&i) { 1.0 } else { 0.0 };
                prop_assert!((a - b - expected).abs() <= 1e-12, "row {}: {:e} -> {:e}", i, b, a);
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// The iteration matrix element by element (the kernel differenced in each block's local
    /// unknowns) against coloured central differences of the whole residual, at states near the
    /// Hangprinter's rest (nodes moved by up to 2 mm and moving at up to 0.05 m/s, l and ρ
    /// rates too), N = 1 … 12, with and without the print example's axial damping C = 8.5 N s,
    /// under tension reels and with the reels driving the lengths (Du's form rewritten from the
    /// blocks, commanded l̇0 and l̈0 random), over c_v = γh and c_q = βh² of h = 1e-5 … 1e-3 s:
    /// S − M(q) to 1e-6 of its largest entry.
    /// Both are central differences with the same steps' rule, each within ~1e-9 of the exact
    /// derivative; a block left out or a coupling dropped (the l columns of M(q), the effector's
    /// block) is of the order of the entries themselves. Both difference the same element
    /// kernel (the residual is summed from it), so this checks how the blocks are placed and
    /// rewritten; the kernel itself is tied to the star's M⁻¹F by the residual test above.
    #[test]
    fn the_element_matrix_matches_coloured_differences(
        elements in 1usize..=12, damped in any::<bool>(), driven in any::<bool>(),
        seed in 0u64..1000, h in 1e-5f64..1e-3,
    ) {
        use cdpr_bench::core::second_order::SecondOrderForm;
        let (mut model, y, mut jiggle) = shaken_rest(elements, seed, 0.05);
        damp_and_drive(&mut model, damped, driven, seed);
        let np = model.positions_len();
        let tensions = [14.0, 13.0, 11.0, 12.5];
        let qdd: Vec<f64> = (0..np).map(|_| jiggle.next(1.0)).collect();
        let (c_v, c_q) = (0.6 * h, 0.3 * h * h);
        let len = model.iteration_pattern().len();
        let (mut blocks, mut differenced, mut masses) = (vec![0.0; len], vec![0.0; len], vec![0.0; len]);
        model.iteration_matrix(&y, &qdd, &tensions, c_v, c_q, &mut blocks);
        model.differenced_matrix(&y, &qdd, &tensions, c_v, c_q, &mut differenced);
        model.iteration_matrix(&y, &qdd, &tensions, 0.0, 0.0, &mut masses);
        let scale = differenced
            .iter()
            .zip(&masses)
            .fold(0.0f64, |m, (d, mass)| m.max((d - mass).abs()));
        prop_assert!(scale > 0.0);
        for (i, (b, d)) in blocks.iter().zip(&differenced).enumerate() {
            prop_assert!((b - d).abs() <= 1e-6 * scale, "entry {}: {:e} vs {:e} (scale {:e})", i, b, d, scale);
        }
    }
}

/// The Hangprinter move (0.4 s) on the implicit path (generalised-α) against DOPRI5 at rtol
/// 1e-10: the largest distance between the effector's paths falls as h² — by 0.18–0.35 per
/// halving of h from the default 1e-4 s (0.25 for a second-order method; from 2e-4 s it is
/// still 0.55, pre-asymptotic as on the lumped lines) — and is below 1e-6 m (half the move's
/// path error) at the default step.
#[test]
fn the_implicit_path_converges_at_second_order() {
    use cdpr_bench::core::scenario::IntegratorKind;
    let mut reference = short(hangprinter(10, 970.0));
    reference.simulation.rtol = 1e-10;
    reference.simulation.atol = 1e-13;
    let reference = run(&reference);
    let gaps: Vec<f64> = [1e-4, 5e-5, 2.5e-5]
        .iter()
        .map(|&h| {
            let mut s = short(hangprinter(10, 970.0));
            s.simulation.integrator = IntegratorKind::Implicit;
            s.simulation.step = h;
            path_gap(&run(&s), &reference)
        })
        .collect();
    println!("implicit against DOPRI5 at h = 1e-4, 5e-5, 2.5e-5 s: {gaps:?} m");
    for k in 1..gaps.len() {
        let ratio = gaps[k] / gaps[k - 1];
        assert!(
            (0.18..=0.35).contains(&ratio),
            "gaps {gaps:?}: ratio {ratio}"
        );
    }
    assert!(gaps[0] < 1e-6, "{gaps:?}");
}

/// Reels driven by length (the `length` controller; Du's prescribed free lengths, MODELS.md
/// FE.5.6) on the Hangprinter move, 0.4 s:
/// - the energy balance closes with the reels' work ∫ Σ Q_l,i l_i' dt (FE.7 for prescribed
///   lengths: Q_l the force imposing l_i, from the span's own l-row) to 1e-6 J (dynamic flex
///   compensation: 1.5e-8 J measured over 1.2 s);
/// - the free lengths follow the command: their change stays within 2e-5 m of the commanded
///   change (the elastic run's l0_i; 9 µm measured: the velocity loop's drift over the move);
/// - with firmware's static compensation the path misses as on the elastic cables (within 5 %:
///   the miss is the compensation's, 1.5 mm, not the lines' mass).
#[test]
fn reels_driven_by_length_pay_out_the_command() {
    use cdpr_bench::core::scenario::{ControllerKind, FlexCompensation};
    let with = |model: cdpr_bench::ModelKind, flex: FlexCompensation| {
        let mut s = short(hangprinter(10, 970.0));
        s.controller.kind = ControllerKind::Length;
        s.controller.flex_compensation = flex;
        if model != cdpr_bench::ModelKind::Fe {
            s = cdpr_bench::with_model_kind(&s, model).unwrap();
        }
        s.validate().unwrap();
        run(&s)
    };
    let fe = with(cdpr_bench::ModelKind::Fe, FlexCompensation::Dynamic);
    let elastic = with(cdpr_bench::ModelKind::Elastic, FlexCompensation::Dynamic);
    assert!(
        fe.metrics.energy_residual_max < 1e-6,
        "{:e} J",
        fe.metrics.energy_residual_max
    );
    for i in 1..=4 {
        let paid = fe.run.series.column_named(&format!("l_free_{i}")).unwrap();
        let commanded = elastic.run.series.column_named(&format!("l0_{i}")).unwrap();
        let gap = paid.iter().zip(&commanded).fold(0.0f64, |gap, (p, c)| {
            gap.max(((p - paid[0]) - (c - commanded[0])).abs())
        });
        assert!(gap < 2e-5, "cable {i}: paid out {gap:e} m off the command");
    }
    let fe = with(cdpr_bench::ModelKind::Fe, FlexCompensation::Static);
    let elastic = with(cdpr_bench::ModelKind::Elastic, FlexCompensation::Static);
    let (a, b) = (
        fe.metrics.path_err_max_move,
        elastic.metrics.path_err_max_move,
    );
    assert!(
        (a - b).abs() < 0.05 * b,
        "static compensation: FE {a:e} m, elastic {b:e} m"
    );
}

/// Reels driven by length on the implicit path (Du's form: the assembly's l_i rows read
/// l_i'' = l̈0_i + (l̇0_i − l_i')/τ, τ = 1e-4 s, and the coloured differences take the loop's
/// ∂R/∂q' with the rest), the Hangprinter move with static flex compensation by the closed
/// form, which keeps every line taut (the QP's low pretension lets one go slack on the way,
/// and the tension-only kink is not smooth for any step), 0.4 s, against DOPRI5 at rtol 1e-10:
/// no pulley passes on FE cables, so the whole run is second order — the path gap and the
/// energy balance's residual fall by 0.18–0.35 per halving of h from 1e-4 s (measured 0.25 and
/// 0.25), the gap stays
/// below 1e-6 m and the residual below 2e-6 J at the default step. The loop is stiff for
/// DOPRI5 (its stability, not its tolerance, sets the step: rtol 1e-10 and 1e-5 take ~54 000
/// steps alike), so the implicit path needs a tenth of its evaluations or fewer (measured
/// 9 981 residuals against 372 374 right-hand sides).
#[test]
fn length_reels_run_on_the_implicit_path_at_second_order() {
    use cdpr_bench::core::robot::distribution::DistributionMethod;
    use cdpr_bench::core::scenario::{ControllerKind, IntegratorKind};
    let length = |step: Option<f64>| {
        let mut s = short(hangprinter(10, 970.0));
        s.controller.kind = ControllerKind::Length;
        s.controller.distribution = DistributionMethod::ClosedForm;
        match step {
            Some(h) => {
                s.simulation.integrator = IntegratorKind::Implicit;
                s.simulation.step = h;
            }
            None => {
                s.simulation.rtol = 1e-10;
                s.simulation.atol = 1e-13;
            }
        }
        s.validate().unwrap();
        run(&s)
    };
    let reference = length(None);
    let runs: Vec<_> = [1e-4, 5e-5, 2.5e-5]
        .iter()
        .map(|&h| length(Some(h)))
        .collect();
    let gaps: Vec<f64> = runs.iter().map(|r| path_gap(r, &reference)).collect();
    let audits: Vec<f64> = runs.iter().map(|r| r.metrics.energy_residual_max).collect();
    println!("length reels, h = 1e-4, 5e-5, 2.5e-5 s: path gaps {gaps:?} m, audits {audits:?} J");
    for k in 1..gaps.len() {
        let (path, audit) = (gaps[k] / gaps[k - 1], audits[k] / audits[k - 1]);
        assert!(
            (0.18..=0.35).contains(&path) && (0.18..=0.35).contains(&audit),
            "path gaps {gaps:?} m, energy residuals {audits:?} J"
        );
    }
    assert!(
        gaps[0] < 1e-6 && audits[0] < 2e-6,
        "{gaps:?} m, {audits:?} J"
    );
    let (implicit, explicit) = (runs[0].run.stats.rhs_evals, reference.run.stats.rhs_evals);
    assert!(
        10 * implicit < explicit,
        "{implicit} residuals against DOPRI5's {explicit} right-hand sides"
    );
}
