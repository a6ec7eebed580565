//! The lumped cable in space (MODELS.md §4 along each cable's path, §11) checked from outside:
//! its statics against its own right-hand side (which the shooting does not use) and against
//! Irvine's elastic catenary per span; its dynamics against the planar lumped model, an
//! independent implementation, on a robot whose cables lie in the x–z plane.

use cdpr_bench::core::model::{CableModel, PoseRule};
use cdpr_bench::core::robot::distribution::{DistributionMethod, TensionBox, distribute};
use cdpr_bench::core::robot::{Robot, Vector};
use cdpr_bench::core::scenario::Scenario;
use cdpr_bench::lumped::spatial::{CableProperties, LumpedSpatial, default_reel_directions, hang};
use cdpr_bench::lumped::{Lumped, Params};
use cdpr_verify::irvine::Catenary;
use nalgebra::Vector3;
use proptest::prelude::*;

/// The Hangprinter example's anchors [m] (examples/robots/hangprinter.toml).
const HANGPRINTER: [[f64; 3]; 4] = [
    [0.0, -1.61098, -0.13153],
    [1.31422, 1.26814, -0.12128],
    [-1.41573, 0.70761, -0.12182],
    [0.0, 0.0, 2.29983],
];

/// A Hangprinter-like robot with lumped lines of `elements` springs and density ρ [kg/m³]
/// (the example's line: 970), the anchors moved by `shift` [m].
fn robot(elements: usize, density: f64, shift: [[f64; 3]; 4]) -> LumpedSpatial {
    let anchors: Vec<Vector3<f64>> = HANGPRINTER
        .iter()
        .zip(shift)
        .map(|(a, s)| Vector3::from(*a) + Vector3::from(s))
        .collect();
    let robot = Robot::new(&anchors, 1.0, 9.81).unwrap();
    let cable = CableProperties {
        elements,
        modelled_length: 3.2,
        mass_per_length: density * 9.503e-7,
        axial_stiffness: 2.105e10 * 9.503e-7,
        axial_damping: 0.0,
    };
    LumpedSpatial::new(robot, cable, &default_reel_directions(&anchors)).unwrap()
}

/// The QP's tensions in [10, 70] N holding the weight at `p`, if the box holds it there.
fn holding_if_feasible(
    model: &LumpedSpatial,
    p: &Vector3<f64>,
) -> Option<cdpr_bench::core::robot::Tensions> {
    let w = model.robot().structure_matrix(p);
    let box_ = TensionBox {
        t_min: 10.0,
        t_max: 70.0,
    };
    let d = distribute(
        DistributionMethod::Qp,
        &w,
        &Vector::<3>::new(0.0, 0.0, 9.81),
        box_,
    )
    .ok()?;
    d.feasible.then_some(d.tensions)
}

/// The QP's tensions in [10, 70] N holding the weight at `p` (a pose where the box holds it).
fn holding(model: &LumpedSpatial, p: &Vector3<f64>) -> cdpr_bench::core::robot::Tensions {
    holding_if_feasible(model, p).expect("a pose whose weight the box holds")
}

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

/// The planar state `planar` (of [`Lumped`]) written into the spatial model's layout, y = 0.
fn to_spatial(planar: &Lumped, spatial: &LumpedSpatial, y: &[f64]) -> Vec<f64> {
    let (n, np2, np3) = (
        planar.elements,
        planar.positions_len(),
        spatial.positions_len(),
    );
    let mut out = vec![0.0; 2 * np3];
    for cable in 0..2 {
        for j in 0..=n {
            for (axis, from) in [(0, planar.x_index(cable, j)), (2, planar.z_index(cable, j))] {
                let to = spatial.index(cable, j, axis);
                out[to] = y[from];
                out[np3 + to] = y[np2 + from];
            }
        }
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Two cables in the x–z plane: the spatial model's right-hand side, energy and event
    /// functions equal the planar model's (written independently, MODELS.md §4) on shaken
    /// states with any stored split and any reel tensions — to 1e-12 relative (the same
    /// arithmetic, up to a zero y added in), y's rates exactly zero.
    #[test]
    fn in_the_plane_it_is_the_planar_model(
        shake in prop::collection::vec(-0.01..0.01f64, 400),
        stored in (3usize..37, 3usize..37),
        tensions in (20.0..200.0f64, 20.0..200.0f64),
        damping in prop::sample::select(vec![0.0, 2.0]),
    ) {
        let mut s = Scenario::paper();
        s.cable.axial_damping = damping;
        let mut planar = Lumped::new(&s, Params::default()).unwrap();
        let anchors = [Vector3::zeros(), Vector3::new(s.robot.anchor_distance, 0.0, 0.0)];
        let robot = Robot::new(&anchors, s.robot.effector_mass, s.robot.gravity).unwrap();
        let cable = CableProperties {
            elements: planar.elements,
            modelled_length: s.cable.modelled_length,
            mass_per_length: s.cable.mass_per_length(),
            axial_stiffness: s.cable.axial_stiffness(),
            axial_damping: damping,
        };
        let mut spatial =
            LumpedSpatial::new(robot, cable, &default_reel_directions(&anchors)).unwrap();
        let eq = planar
            .equilibrium(&cdpr_bench::core::model::SplitRule::new(0.5, 200.0))
            .unwrap();
        planar.set_stored([stored.0, stored.1]);
        spatial.set_stored(&[stored.0, stored.1]);
        let mut y = eq.state.clone();
        for (k, v) in y.iter_mut().enumerate() {
            *v += shake[k % shake.len()] * if k < planar.positions_len() { 0.1 } else { 1.0 };
        }
        // Stored nodes on the reel line, as the planar model keeps them.
        let np = planar.positions_len();
        for cable in 0..2 {
            for j in 0..planar.stored()[cable] {
                let (iz, ix) = (planar.z_index(cable, j), planar.x_index(cable, j));
                y[iz] = 0.0;
                y[np + iz] = 0.0;
                let pulley = planar.pulley(cable).x;
                y[ix] = pulley + (pulley - y[ix]).abs().max(1e-3) * cdpr_bench::lumped::TOWARD_REEL[cable];
            }
        }
        let y3 = to_spatial(&planar, &spatial, &y);
        let t = [tensions.0, tensions.1];
        let (mut r2, mut r3) = (vec![0.0; y.len()], vec![0.0; y3.len()]);
        planar.rhs(0.0, &y, &t, &mut r2);
        spatial.rhs(0.0, &y3, &t, &mut r3);
        let expected = to_spatial(&planar, &spatial, &r2);
        let scale = expected.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (k, (a, b)) in r3.iter().zip(&expected).enumerate() {
            prop_assert!((a - b).abs() <= 1e-12 * scale, "rate {k}: {a} vs {b}");
        }
        let (e2, e3) = (planar.energy(&y), spatial.energy(&y3));
        prop_assert!((e2.total() - e3.total()).abs() <= 1e-12 * (e2.elastic + e2.kinetic + e2.gravity.abs()));
        let (mut g2, mut g3) = (vec![0.0; planar.event_count()], vec![0.0; spatial.event_count()]);
        planar.event_functions(&y, &mut g2);
        spatial.event_functions(&y3, &mut g3);
        for (a, b) in g2.iter().zip(&g3) {
            prop_assert!((a - b).abs() <= 1e-15, "{g2:?} vs {g3:?}");
        }
    }
}

/// The Hangprinter example's move on lumped lines of `elements` springs and density ρ.
fn hangprinter_move(kind: &str, elements: usize, density: f64) -> cdpr_bench::SpatialRun {
    hangprinter_move_on(kind, elements, density, None)
}

/// [`hangprinter_move`] on the implicit path with a fixed `step` [s] (None: DOPRI5 at the
/// default tolerance; 0: DOPRI5 at rtol 1e-10).
fn hangprinter_move_on(
    kind: &str,
    elements: usize,
    density: f64,
    step: Option<f64>,
) -> cdpr_bench::SpatialRun {
    run(&hangprinter_scenario(kind, elements, density, step))
}

/// The scenario of [`hangprinter_move_on`].
fn hangprinter_scenario(kind: &str, elements: usize, density: f64, step: Option<f64>) -> Scenario {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../examples/robots/hangprinter.toml"
    ))
    .unwrap();
    let mut s: Scenario = cdpr_bench::scenario_from_toml_str(&text).unwrap();
    s.cable.density = density;
    s.cable.modelled_length = 3.2;
    s.simulation.t_final = 0.4;
    s.simulation.sample_period = 1e-3;
    let mut table = toml::Table::new();
    table.insert("kind".into(), kind.into());
    if kind == "lumped" {
        table.insert("elements".into(), (elements as i64).into());
    }
    s.model = cdpr_bench::core::scenario::ModelSection(table);
    match step {
        // Step 0: DOPRI5 at rtol 1e-10, far below the implicit path's error (the reference).
        Some(0.0) => {
            s.simulation.rtol = 1e-10;
            s.simulation.atol = 1e-13;
        }
        Some(h) => {
            s.simulation.integrator = cdpr_bench::core::scenario::IntegratorKind::Implicit;
            s.simulation.step = h;
        }
        None => {}
    }
    s
}

/// Runs a spatial scenario to its end.
fn run(s: &Scenario) -> cdpr_bench::SpatialRun {
    cdpr_bench::simulate_spatial(
        s,
        &mut cdpr_bench::core::runner::Observer::progress(&mut |_| {}),
    )
    .unwrap()
}

/// Largest distance between the effector paths of two runs [m].
fn path_gap(a: &cdpr_bench::SpatialRun, b: &cdpr_bench::SpatialRun) -> f64 {
    let axis = |r: &cdpr_bench::SpatialRun, name: &str| r.run.series.column_named(name).unwrap();
    let mut gap = 0.0f64;
    for name in ["x", "y", "z"] {
        let (a, b) = (axis(a, name), axis(b, name));
        gap = a.iter().zip(&b).fold(gap, |m, (a, b)| m.max((a - b).abs()));
    }
    gap
}

/// The example's move (computed torque, QP) on lumped lines of 20 springs: nodes cross the
/// pulleys (events), and the energy balance E − E0 − W_reels + D − ΣΔE closes to 1e-5 J
/// (measured 1.4e-7 J at DOPRI5's rtol 1e-5; the reels' work is ~1 J, so a wrong sign or a lost
/// term shows by orders of magnitude). As the line's mass goes to zero the effector's path
/// tends to the massless elastic model's at first order: halving ρ halves the largest gap
/// (ratio within [0.4, 0.6]; measured 1.8 µm at the example's ρ = 970 kg/m³).
#[test]
fn the_hangprinter_move_runs_on_lumped_lines_and_tends_to_elastic() {
    let elastic = hangprinter_move("elastic", 0, 970.0);
    let heavy = hangprinter_move("lumped", 20, 970.0);
    let light = hangprinter_move("lumped", 20, 485.0);
    let residual = heavy
        .run
        .series
        .column(cdpr_bench::core::channel::Channel::EResidual)
        .unwrap();
    let worst = residual.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(!heavy.run.events.is_empty(), "no node crossed a pulley");
    // The run's metrics carry the audit.
    assert_eq!(heavy.metrics.energy_residual_max, worst);
    assert_eq!(heavy.metrics.pulley_events, heavy.run.events.len());
    assert_eq!(elastic.metrics.pulley_events, 0);
    assert!(worst < 1e-5, "energy balance residual {worst:e} J");
    let (gap_heavy, gap_light) = (path_gap(&heavy, &elastic), path_gap(&light, &elastic));
    let ratio = gap_light / gap_heavy;
    assert!(
        (0.4..=0.6).contains(&ratio),
        "gaps {gap_heavy:e} m (ρ = 970), {gap_light:e} m (ρ = 485)"
    );
}

/// Largest distance between the effector paths of two runs up to `until` [s].
fn path_gap_until(a: &cdpr_bench::SpatialRun, b: &cdpr_bench::SpatialRun, until: f64) -> f64 {
    let t = a.run.series.column_named("t").unwrap();
    let axis = |r: &cdpr_bench::SpatialRun, name: &str| r.run.series.column_named(name).unwrap();
    let mut gap = 0.0f64;
    for name in ["x", "y", "z"] {
        let (a, b) = (axis(a, name), axis(b, name));
        for k in (0..t.len()).take_while(|&k| t[k] <= until) {
            gap = gap.max((a[k] - b[k]).abs());
        }
    }
    gap
}

/// The implicit path (generalised-α on the second-order form) converges to DOPRI5's path (at
/// rtol 1e-10) at second order over the first 0.05 s, before any node crosses a pulley: the
/// gap shrinks by 3.2–5 when the step halves from 1e-4 to 5e-5 s (2² = 4 asymptotically;
/// measured ratios 1.9, 3.2, 3.8, 4.0 for steps 4e-4 … 2.5e-5 s). From the first crossing on
/// (0.0645 s) the paths differ by ~5e-8 m at any step down to 5e-6 s: the crossing's instant
/// rides on the undamped lines' axial ringing (~8 µm at ~9 kHz, which the implicit path damps
/// and DOPRI5 carries), so the node is released a few µs apart; the whole run stays within
/// 2e-7 m (measured 6.4e-8 m at 1e-4 s).
#[test]
fn the_implicit_path_converges_to_dormand_prince_at_second_order() {
    let reference = hangprinter_move_on("lumped", 20, 970.0, Some(0.0));
    let coarse = hangprinter_move_on("lumped", 20, 970.0, Some(1e-4));
    let fine = hangprinter_move_on("lumped", 20, 970.0, Some(5e-5));
    let first = reference.run.events[0].t;
    assert!(first > 0.05, "first crossing at {first} s");
    let window = 0.05;
    let (gap_coarse, gap_fine) = (
        path_gap_until(&coarse, &reference, window),
        path_gap_until(&fine, &reference, window),
    );
    assert!(
        (3.2..=5.0).contains(&(gap_coarse / gap_fine)),
        "gaps before the first crossing: {gap_coarse:e} m (1e-4 s), {gap_fine:e} m (5e-5 s)"
    );
    let whole = path_gap(&coarse, &reference);
    assert!(whole < 2e-7, "{whole:e} m over the run");
}

/// Every entry of the `analytic` iteration matrix within 1e-6 of the largest entry of S beyond
/// the masses (`differenced` − `masses`) of the `differenced` one.
fn matches_differences(
    analytic: &[f64],
    differenced: &[f64],
    masses: &[f64],
) -> Result<(), TestCaseError> {
    let scale = differenced
        .iter()
        .zip(masses)
        .fold(0.0f64, |m, (v, mass)| m.max((v - mass).abs()));
    prop_assert!(scale > 0.0);
    for (i, (a, d)) in analytic.iter().zip(differenced).enumerate() {
        prop_assert!(
            (a - d).abs() <= 1e-6 * scale,
            "entry {i}: {a:e} vs {d:e} (scale {scale:e})"
        );
    }
    Ok(())
}

/// The example on heavy lines (N = 20, ρ = 2e4 kg/m³) with axial damping `damping` [N s], the
/// stored split of its rest at `p` under the QP's tensions, and that rest shaken (None where the
/// box [10, 70] N cannot hold the weight at `p` — the corners of the sampled box, such as
/// (0.298, −0.299, 0.446) — or where the statics refuse the pose: a node resting on a pulley,
/// which no split can straddle):
/// every coordinate by up to `shake` [m], every node moving at up to `speed` [m/s], the stored
/// nodes put back on their reel lines and moving along them.
fn shaken_rest(
    p: Vector3<f64>,
    (shake, speed): (f64, f64),
    seed: u32,
    damping: f64,
) -> Option<(
    LumpedSpatial,
    Vec<f64>,
    cdpr_bench::core::model::Equilibrium,
)> {
    let mut model = robot(20, 2e4, [[0.0; 3]; 4]);
    let tensions = holding_if_feasible(&model, &p)?;
    let eq = model.equilibrium(&PoseRule::new(&p, tensions)).ok()?;
    let mut damped = LumpedSpatial::new(
        *model.robot(),
        CableProperties {
            elements: 20,
            modelled_length: 3.2,
            mass_per_length: 2e4 * 9.503e-7,
            axial_stiffness: 2.105e10 * 9.503e-7,
            axial_damping: damping,
        },
        &default_reel_directions(model.robot().anchors()),
    )
    .unwrap();
    damped.set_stored(model.stored());
    let np = model.positions_len();
    let mut state = eq.state.clone();
    for (k, q) in state.iter_mut().enumerate() {
        let wiggle = (1.7 * (f64::from(seed) + k as f64)).sin();
        *q += if k < np {
            shake * wiggle
        } else {
            speed * wiggle
        };
    }
    for cable in 0..4 {
        let (a, r) = (model.pulley(cable), model.reel(cable));
        for j in 0..model.stored()[cable] {
            let on_line = a + r * (model.node(&state, cable, j) - a).dot(&r);
            let along = r * model.node_velocity(&state, cable, j).dot(&r);
            for axis in 0..3 {
                state[model.index(cable, j, axis)] = on_line[axis];
                state[np + model.index(cable, j, axis)] = along[axis];
            }
        }
    }
    Some((damped, state, eq))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// The analytic iteration matrix (undamped lines) against coloured central differences of
    /// the residual, at rests shaken by up to 1e-4 m per coordinate, with any stored split the rest gives, over c_q of h = 1e-5 … 1e-3 s.
    /// Compared on c_q ∂F/∂q alone (the masses would swamp it), to 1e-6 of its largest entry:
    /// the differences' truncation is (δ/λ)² with δ ≤ a quarter of the stretch (~1e-4 m
    /// here) and λ ≈ l0 = 0.16 m, ~1e-7; a missing geometric term T/λ ≈ 400 N/m is 3e-3 of the
    /// axial k0 = 1.25e5 N/m.
    #[test]
    fn the_tangent_matrix_matches_coloured_differences(
        x in -0.3..0.3f64,
        y in -0.3..0.3f64,
        z in 0.0..0.5f64,
        shake in 0.0..1e-4f64,
        seed in 0u32..1000,
        h in 1e-5f64..1e-3,
    ) {
        use cdpr_bench::core::second_order::SecondOrderForm;
        let rest = shaken_rest(Vector3::new(x, y, z), (shake, 0.0), seed, 0.0);
        prop_assume!(rest.is_some());
        let (mut model, state, eq) = rest.unwrap();
        let c_q = 0.3 * h * h;
        let n = model.dofs();
        let qdd = vec![0.0; n];
        let len = model.iteration_pattern().len();
        let (mut analytic, mut differenced, mut masses) = (vec![0.0; len], vec![0.0; len], vec![0.0; len]);
        model.iteration_matrix(&state, &qdd, &eq.tensions, 0.0, c_q, &mut analytic);
        model.differenced_matrix(&state, &qdd, &eq.tensions, 0.0, c_q, &mut differenced);
        model.iteration_matrix(&state, &qdd, &eq.tensions, 0.0, 0.0, &mut masses);
        matches_differences(&analytic, &differenced, &masses)?;
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// The analytic iteration matrix of damped lines (the print example's axial damping C =
    /// 8.5 N s, c = C/l0 = 53 N s/m) against coloured central differences of the same model's
    /// residual, at rests shaken by up to 1e-4 m per coordinate with every node moving at up to
    /// `speed`, over c_v = γh and c_q = βh² of h = 1e-5 … 1e-3 s: S − diag(m) to 1e-6 of its
    /// largest entry. The velocity terms c u uᵀ are linear in q', so their differences are
    /// exact to round-off; the position terms' truncation is (δ/λ)² ≈ 1e-7 as for undamped
    /// lines, the differences' steps kept off the damping's clip at T = 0 (T/k0 away). Each
    /// damping term left out fails this test (checked): the velocity blocks c u uᵀ (1e-1 of
    /// the scale), a chord's c P Δv/λ (∂λ̇/∂q: 1e-6) and the straddling spring's free-side
    /// c P_b v_b/|A − b| (2e-6). Its stored side, c P_a v_a/|A − a|, vanishes on every state the
    /// model reaches (a stored node moves along its reel line, which is u_a).
    #[test]
    fn the_damped_tangent_matrix_matches_coloured_differences(
        x in -0.3..0.3f64,
        y in -0.3..0.3f64,
        z in 0.0..0.5f64,
        shake in 0.0..1e-4f64,
        speed in 0.0..0.05f64,
        seed in 0u32..1000,
        h in 1e-5f64..1e-3,
    ) {
        use cdpr_bench::core::second_order::SecondOrderForm;
        let rest = shaken_rest(Vector3::new(x, y, z), (shake, speed), seed, 8.5);
        prop_assume!(rest.is_some());
        let (mut damped, state, eq) = rest.unwrap();
        let np = damped.positions_len();
        let (c_v, c_q) = (0.6 * h, 0.3 * h * h);
        let qdd = vec![0.0; np];
        let len = damped.iteration_pattern().len();
        let (mut analytic, mut differenced, mut masses) = (vec![0.0; len], vec![0.0; len], vec![0.0; len]);
        damped.iteration_matrix(&state, &qdd, &eq.tensions, c_v, c_q, &mut analytic);
        damped.differenced_matrix(&state, &qdd, &eq.tensions, c_v, c_q, &mut differenced);
        damped.iteration_matrix(&state, &qdd, &eq.tensions, 0.0, 0.0, &mut masses);
        matches_differences(&analytic, &differenced, &masses)?;
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

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// A pulley passage in 3-D keeps every node's mass (the state's nodes and the stored count
    /// change, no mass does), moves only the passing node, keeps its momentum along the reel
    /// line, and records as its energy change exactly what the guide takes: −½ m |v_⊥|² when a
    /// free node is reeled in (its velocity across the line), and nothing else but the work of
    /// the ε = 1e-12 m shift off the pulley against the node's two springs (≤ (T_a + T_b) ε,
    /// allowed twice, plus 1e-12 J of round-off). The passing node is put on the pulley by hand,
    /// which stretches its springs far beyond any run's (kN): the bound scales with them.
    #[test]
    fn a_pulley_passage_keeps_mass_and_the_momentum_along_the_reel_line(
        cable in 0usize..4,
        velocity in prop::array::uniform3(-2.0..2.0f64),
        capture in any::<bool>(),
    ) {
        let mut model = robot(20, 2e4, [[0.0; 3]; 4]);
        let p = Vector3::new(0.05, -0.1, 0.2);
        let tensions = holding(&model, &p);
        let mut y = model.equilibrium(&PoseRule::new(&p, tensions)).unwrap().state;
        let np = model.positions_len();
        let r = model.stored()[cable];
        let j = if capture { r } else { r - 1 };
        let v = Vector3::from(velocity);
        let reel = model.reel(cable);
        // A stored node moves along its line only; the passing node sits at the pulley, where
        // its event function crosses 0.
        let v = if capture { v } else { reel * v.dot(&reel) };
        let pulley = model.pulley(cable);
        for axis in 0..3 {
            y[model.index(cable, j, axis)] = pulley[axis];
            y[np + model.index(cable, j, axis)] = v[axis];
        }
        let before = y.clone();
        let mass_before = model.cable_mass();
        let index = 3 * cable + if capture { 1 } else { 0 };
        // The ε shift moves the node against its two springs' pull: at most (T_a + T_b) ε.
        let pull = model.spring_force(&y, cable, j - 1) + model.spring_force(&y, cable, j);
        let event = model.apply_event(index, 0.0, &mut y).unwrap();
        prop_assert_eq!(model.cable_mass(), mass_before);
        prop_assert_eq!(model.stored()[cable], if capture { r + 1 } else { r - 1 });
        for (k, (a, b)) in y.iter().zip(&before).enumerate() {
            let passing = (0..3).any(|axis| {
                let i = model.index(cable, j, axis);
                k == i || k == np + i
            });
            if !passing {
                prop_assert_eq!(a, b, "coordinate {} moved", k);
            }
        }
        let after = model.node_velocity(&y, cable, j);
        prop_assert!((after.dot(&reel) - v.dot(&reel)).abs() <= 1e-15);
        let across = v - reel * v.dot(&reel);
        let taken = if capture { -0.5 * model.node_mass * across.norm_squared() } else { 0.0 };
        let shift = 2.0 * pull * cdpr_bench::lumped::PULLEY_OFFSET + 1e-12;
        prop_assert!(
            (event.energy_change - taken).abs() <= shift,
            "{} J vs {} J (ε shift bound {:e} J)",
            event.energy_change,
            taken,
            shift
        );
    }
}

/// The example's move with its reels driven by length (the `length` controller, flex
/// compensation by the static load's distribution as the firmware's, here the closed form's,
/// which keeps every line taut) on `kind` lines of `elements` springs, DOPRI5 at `rtol` (None:
/// the default).
fn hangprinter_length_move(
    kind: &str,
    elements: usize,
    rtol: Option<f64>,
) -> cdpr_bench::SpatialRun {
    run(&length_scenario(kind, elements, rtol))
}

/// The scenario of [`hangprinter_length_move`].
fn length_scenario(kind: &str, elements: usize, rtol: Option<f64>) -> Scenario {
    let mut s = hangprinter_scenario(kind, elements, 970.0, None);
    s.controller.kind = cdpr_bench::core::scenario::ControllerKind::Length;
    s.controller.distribution =
        cdpr_bench::core::robot::distribution::DistributionMethod::ClosedForm;
    if let Some(rtol) = rtol {
        s.simulation.rtol = rtol;
        s.simulation.atol = rtol * 1e-3;
    }
    s
}

/// Per cable, the largest difference over the run between the change of a lumped run's free
/// unstrained length (`l_free_i`) and the change of the commanded one (the elastic run's `l0_i`,
/// which reports the command) [m].
fn feed_gaps(lumped: &cdpr_bench::SpatialRun, elastic: &cdpr_bench::SpatialRun) -> Vec<f64> {
    (1..=4)
        .map(|i| {
            let paid = lumped
                .run
                .series
                .column_named(&format!("l_free_{i}"))
                .unwrap();
            let commanded = elastic.run.series.column_named(&format!("l0_{i}")).unwrap();
            paid.iter().zip(&commanded).fold(0.0f64, |gap, (p, c)| {
                gap.max(((p - paid[0]) - (c - commanded[0])).abs())
            })
        })
        .collect()
}

/// Reels driven by length on lumped lines (MODELS.md §11): each reel moves its stored line so
/// that the line crossing the pulley pays out the commanded unstrained length.
/// - The energy balance E − E0 − W_reels + D − ΣΔE closes: the reels' work is now that of the
///   forces driving the stored lines (0.75 J here). The residual is the integration's: 7e-6 J
///   at rtol 1e-6, 1.3e-6 J at 1e-7, 4.6e-7 J at 1e-8 (this test's), 2–7e-7 J below, where the
///   pulley passages' located instants set it. 2e-6 J are allowed; leaving the stored nodes'
///   weight out of the reels' work (a term of ~1e-4 J) leaves 1.5e-4 J.
/// - The free unstrained length of every cable changes as the command does but for the one
///   compliance the lumped reel has and the elastic reel has not: the straddling spring's
///   stored node is up to a segment behind the pulley, so that spring's stored part stretches
///   with the tension and its material slides over the pulley: d Δε ≤ l0 ΔT/EA per stretch of
///   the run between the cable's pulley passages (ΔT the pulley tension's range; measured 21–79
///   µm). That is first order in l0: doubling N halves the largest gap (ratio within [0.4,
///   0.65]; measured 0.54).
///   The same compliance, ≤ l0/l of a line's, shifts the effector's length-controlled modes by
///   as much, so the effector's ringing drifts in phase against the elastic model's (docs).
#[test]
fn reels_driven_by_length_pay_out_the_command() {
    let elastic = hangprinter_length_move("elastic", 0, None);
    let coarse = hangprinter_length_move("lumped", 20, None);
    let fine = hangprinter_length_move("lumped", 40, None);
    let tight = hangprinter_length_move("lumped", 20, Some(1e-8));
    let series = &tight.run.series;
    let residual = series
        .column(cdpr_bench::core::channel::Channel::EResidual)
        .unwrap();
    let worst = residual.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let work = series.column_named("w_reel").unwrap();
    let work = work.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(!coarse.run.events.is_empty(), "no node crossed a pulley");
    assert!(
        work > 0.1,
        "the driven reels did next to no work: {work:e} J"
    );
    assert!(
        worst < 1e-6,
        "energy balance residual {worst:e} J (reel work {work:e} J)"
    );
    let ea = hangprinter_scenario("lumped", 20, 970.0, None)
        .cable
        .axial_stiffness();
    let (gaps, gaps_fine) = (feed_gaps(&coarse, &elastic), feed_gaps(&fine, &elastic));
    let segment = 3.2 / 20.0;
    for (i, gap) in gaps.iter().enumerate() {
        let tension = coarse
            .run
            .series
            .column_named(&format!("T_pulley_{}", i + 1))
            .unwrap();
        let range = tension.iter().fold(f64::NEG_INFINITY, |m, &t| m.max(t))
            - tension.iter().fold(f64::INFINITY, |m, &t| m.min(t));
        let passages = coarse
            .run
            .events
            .iter()
            .filter(|e| e.cable == i + 1)
            .count();
        let bound = (1 + passages) as f64 * segment * range / ea;
        assert!(
            *gap <= bound,
            "cable {}: paid out vs commanded {gap:e} m > {bound:e} m",
            i + 1
        );
    }
    let (worst, worst_fine) = (
        gaps.iter().fold(0.0f64, |m, &g| m.max(g)),
        gaps_fine.iter().fold(0.0f64, |m, &g| m.max(g)),
    );
    let ratio = worst_fine / worst;
    assert!(
        (0.4..=0.65).contains(&ratio),
        "feed gaps {worst:e} m (N = 20), {worst_fine:e} m (N = 40)"
    );
}

/// Reels driven by length on lumped lines on the implicit path (generalised-α, the reels'
/// velocity loop of time constant τ = 1e-4 s in the stored nodes' rows and its c_v m/τ in the
/// iteration matrix), against DOPRI5 at rtol 1e-8 (2e-11 m from rtol 1e-10's path):
/// - Before the first pulley passage (0.069 s) the paths converge at second order: halving the
///   step from 1e-4 to 5e-5 s shrinks the gap by 3.2–5 (measured 4.0, 2.8e-8 → 7e-9 m).
/// - Over the run the gap stays within 5e-7 m (measured 2.6e-7 m at 1e-4 s): from the passages
///   on, the released node's instant rides on the lines' axial ringing, as with tension reels.
/// - The energy balance closes at first order in the step: the fixed step integrates across a
///   passage's kink in the straddling spring's length before the passage is located, and the
///   reel's speed command follows that length, so the audit is off by ~h times the jump of the
///   reels' power (measured 1.3e-3 J at 1e-4 s, 5.3e-4 J at 5e-5 s, of 0.20 J of reel work):
///   within 2e-3 J, and at least 1.8 times smaller at half the step.
/// - The stiff loop is what the implicit path is for: it takes fewer residual evaluations than
///   DOPRI5 at its default tolerance takes right-hand sides by a factor above 5 (measured 13 185
///   against 229 354).
#[test]
fn length_reels_on_lumped_lines_run_on_the_implicit_path() {
    let length_run = |step: Option<f64>, rtol: Option<f64>| {
        let mut s = length_scenario("lumped", 20, rtol);
        if let Some(h) = step {
            s.simulation.integrator = cdpr_bench::core::scenario::IntegratorKind::Implicit;
            s.simulation.step = h;
        }
        run(&s)
    };
    let reference = length_run(None, Some(1e-8));
    let default = length_run(None, None);
    let coarse = length_run(Some(1e-4), None);
    let fine = length_run(Some(5e-5), None);
    let first = reference.run.events[0].t;
    assert!(first > 0.065, "first crossing at {first} s");
    let (early_coarse, early_fine) = (
        path_gap_until(&coarse, &reference, 0.065),
        path_gap_until(&fine, &reference, 0.065),
    );
    assert!(
        (3.2..=5.0).contains(&(early_coarse / early_fine)),
        "gaps before the first crossing: {early_coarse:e} m (1e-4 s), {early_fine:e} m (5e-5 s)"
    );
    let whole = path_gap(&coarse, &reference);
    assert!(whole < 5e-7, "{whole:e} m over the run");
    let residual = |r: &cdpr_bench::SpatialRun| {
        let column = r
            .run
            .series
            .column(cdpr_bench::core::channel::Channel::EResidual)
            .unwrap();
        column.iter().fold(0.0f64, |m, v| m.max(v.abs()))
    };
    let (audit_coarse, audit_fine) = (residual(&coarse), residual(&fine));
    assert!(
        audit_coarse < 2e-3 && audit_coarse / audit_fine >= 1.8,
        "energy balance residual {audit_coarse:e} J (1e-4 s), {audit_fine:e} J (5e-5 s)"
    );
    let (implicit, explicit) = (coarse.run.stats.rhs_evals, default.run.stats.rhs_evals);
    assert!(
        5 * implicit < explicit,
        "{implicit} residual evaluations against DOPRI5's {explicit}"
    );
}

/// The Hangprinter example on lumped lines of `elements` springs at rest at the origin under
/// the QP's tensions, its reels then locked.
fn locked_at_origin(elements: usize) -> (LumpedSpatial, Vec<f64>) {
    let mut model = robot(elements, 970.0, [[0.0; 3]; 4]);
    let p = Vector3::zeros();
    let rest = model
        .equilibrium(&PoseRule::new(&p, holding(&model, &p)))
        .unwrap()
        .state;
    model.lock_reels(true);
    (model, rest)
}

/// The effector's three modes [rad/s], ascending, on massless elastic lines locked at the
/// lumped lines' lengths (MODELS.md §11: K = Σ (EA/L_i) u_i u_iᵀ + (T_i/l_i)(I − u_i u_iᵀ),
/// L_i = (N − r_i + 1) l0 the springs in series from the held stored node behind the pulley to
/// the effector, T_i the lumped line's tension at the effector).
fn elastic_locked_modes(model: &LumpedSpatial, rest: &[f64]) -> Vec<f64> {
    let n = model.elements;
    let p = model.effector(rest).position;
    let mut stiffness = nalgebra::Matrix3::<f64>::zeros();
    for cable in 0..4 {
        let d = model.pulley(cable) - p;
        let (l, u) = (d.norm(), d.normalize());
        let t = model.spring_force(rest, cable, n - 1);
        let locked = (n - model.stored()[cable] + 1) as f64 * model.segment;
        let ea = model.stiffness * model.segment;
        stiffness += u * u.transpose() * (ea / locked)
            + (nalgebra::Matrix3::identity() - u * u.transpose()) * (t / l);
    }
    cdpr_verify::spatial::point_mass_modes(&stiffness, model.robot().effector_mass)
}

/// The Hangprinter example on lumped lines at rest at its start pose, reels locked (the
/// firmware's robot between moves), every mode named (`cdpr_analysis::rest_modes`):
/// - K is symmetric to 1e-9 (conservative springs; the locked stored lines held).
/// - The effector's x, y and vertical modes are the massless elastic lines' with the same
///   locked lengths (MODELS.md §11: K = Σ (EA/L_i) u_i u_iᵀ + (T_i/l_i)(I − u_i u_iᵀ), L_i =
///   (N − r_i + 1) l0 the springs in series from the held stored node behind the pulley to the
///   effector) within 0.5 % (the lines' 3 g each against the 1 kg effector; 0.12–0.17 % with
///   one stored node, moordyn_spatial.rs), each ≥ 90 % effector motion.
/// - Every cable's lowest out-of-plane string mode is ≥ 90 % motion across its vertical plane,
///   and within 0.2 % of the lowest mode of its free nodes alone with the effector held, across
///   the plane every spring j pulls with its geometric stiffness T_j/λ_j only (exact at first
///   order for a chain in a plane, sagging or not): what differs is the effector's motion,
///   which at ~200 rad/s against its own ~120 rad/s answers the string's ~200 N/m with ~−3e4
///   N/m of inertia (≲ 0.1 %). Its in-plane partner exists; the plumb line under the ceiling
///   anchor has two in-plane families instead.
#[test]
fn the_locked_robots_modes_are_named_and_match_their_closed_forms() {
    use cdpr_bench::analysis::modes::ModeKind;
    let (mut model, rest) = locked_at_origin(20);
    let p = Vector3::zeros();
    let named = cdpr_bench::analysis::rest_modes::rest_modes(&mut model, &rest, &[0.0; 4]).unwrap();
    let asymmetry = named.asymmetry.unwrap();
    assert!(asymmetry <= 1e-9, "asymmetry {asymmetry:e}");
    let find = |kind: ModeKind| {
        named
            .modes
            .iter()
            .find(|m| m.kind == kind && m.order == 1)
            .unwrap_or_else(|| panic!("no {kind} mode"))
    };
    let n = model.elements;
    let elastic = elastic_locked_modes(&model, &rest);
    let mut effector: Vec<f64> = [ModeKind::EffectorX, ModeKind::EffectorY, ModeKind::Vertical]
        .into_iter()
        .map(|kind| {
            let mode = find(kind);
            assert!(mode.purity >= 0.9, "{kind}: purity {}", mode.purity);
            mode.mode.omega
        })
        .collect();
    effector.sort_by(f64::total_cmp);
    eprintln!("effector modes {effector:?}, elastic lines {elastic:?} rad/s");
    for (lumped, elastic) in effector.iter().zip(&elastic) {
        assert!(
            (lumped - elastic).abs() <= 5e-3 * elastic,
            "effector modes {effector:?} against the elastic lines' {elastic:?} rad/s"
        );
    }
    for cable in 0..4 {
        // A plumb line (the ceiling anchor's, straight above the effector) has no vertical plane
        // of its own: its two transverse families are both named in-plane.
        let chord = model.pulley(cable) - p;
        let plumb = chord.x.hypot(chord.y) < 1e-9 * chord.norm();
        let out = if plumb {
            assert!(
                named
                    .modes
                    .iter()
                    .any(|m| m.kind == ModeKind::InPlane(cable) && m.order == 2),
                "cable {}: one transverse family only",
                cable + 1
            );
            find(ModeKind::InPlane(cable))
        } else {
            find(ModeKind::InPlane(cable));
            find(ModeKind::OutOfPlane(cable))
        };
        assert!(
            out.purity >= 0.9,
            "cable {}: purity {}",
            cable + 1,
            out.purity
        );
        // The chain across its plane with the effector held: springs pull a node out of the
        // plane with T_j/λ_j each (the straddling spring's free part with T/|A − P_r|).
        let r = model.stored()[cable];
        let pull = |j: usize| {
            let t = model.spring_force(&rest, cable, j);
            if j + 1 == r {
                t / (model.pulley(cable) - model.node(&rest, cable, r)).norm()
            } else {
                t / model.spring_length(&rest, cable, j)
            }
        };
        let free = n - r;
        let chain = nalgebra::DMatrix::from_fn(free, free, |a, b| {
            let (j, k) = (r + a, r + b);
            if j == k {
                (pull(j - 1) + pull(j)) / model.node_mass
            } else if j + 1 == k {
                -pull(j) / model.node_mass
            } else if k + 1 == j {
                -pull(k) / model.node_mass
            } else {
                0.0
            }
        });
        let string = chain
            .symmetric_eigenvalues()
            .iter()
            .fold(f64::INFINITY, |m, &v| m.min(v))
            .sqrt();
        eprintln!(
            "cable {}: string {} rad/s, held chain {string} rad/s",
            cable + 1,
            out.mode.omega
        );
        assert!(
            (out.mode.omega - string).abs() <= 2e-3 * string,
            "cable {}: out-of-plane {} rad/s against the held chain's {string} rad/s",
            cable + 1,
            out.mode.omega
        );
    }
}

/// The effector's modes at any N, by shift-invert Lanczos on the sparse K − ω²M
/// (`rest_modes_near`, 60 steps): at N = 20 the six modes nearest 120 rad/s are the dense
/// solve's to 1e-9 relative (the Lanczos residuals' order); at N = 1000 — 12 000 coordinates,
/// six times the dense solve's limit — the effector's x, y and vertical modes are among the six
/// and within 0.5 % of the elastic lines' with the same locked lengths, as at N = 20.
#[test]
fn the_effectors_modes_at_any_n_by_shift_invert() {
    use cdpr_bench::analysis::rest_modes::{rest_modes, rest_modes_near};
    use cdpr_verify::spatial::{effector_modes, nearest};
    let (mut model, rest) = locked_at_origin(20);
    let dense = rest_modes(&mut model, &rest, &[0.0; 4]).unwrap();
    let (near, _) = rest_modes_near(&mut model, &rest, &[0.0; 4], (120.0, 6, 60)).unwrap();
    for (found, expected) in near.modes.iter().zip(&nearest(&dense, 120.0, 6)) {
        let omega = found.mode.omega;
        assert!(
            (omega - expected).abs() <= 1e-9 * expected,
            "{omega} rad/s against the dense {expected} rad/s"
        );
    }
    let (mut fine, fine_rest) = locked_at_origin(1000);
    let (near, residuals) =
        rest_modes_near(&mut fine, &fine_rest, &[0.0; 4], (120.0, 6, 60)).unwrap();
    let elastic = elastic_locked_modes(&fine, &fine_rest);
    let effector = effector_modes(&near);
    eprintln!(
        "N = 1000: effector {effector:?}, elastic {elastic:?} rad/s, residuals {residuals:?}"
    );
    for (lumped, elastic) in effector.iter().zip(&elastic) {
        assert!(
            (lumped - elastic).abs() <= 5e-3 * elastic,
            "effector modes {effector:?} against the elastic lines' {elastic:?} rad/s"
        );
    }
}
