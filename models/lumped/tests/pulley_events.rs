//! The pulley events of the lumped model checked from outside the model's energy code: after
//! every event the stored nodes lie on the reel line at rest across it (z = ż = 0, MODELS.md §4
//! eq. 6), the energy an event records is what its physics removes (the reeled-in node's vertical
//! kinetic energy, nothing when a node leaves the reel), and the cable's inertia is μ L0 per
//! cable before and after events.

use cdpr_core::model::{CableModel, SplitRule};
use cdpr_core::scenario::Scenario;
use cdpr_lumped::{Lumped, Params, TOWARD_REEL};
use proptest::prelude::*;

/// Event functions per cable, in order: last stored node leaves, first free node is reeled in,
/// ordering watch (`models/lumped/src/pulley.rs`).
const PER_CABLE: usize = 3;
const LEAVES: usize = 0;
const REELED_IN: usize = 1;

/// Node mass from the scenario, not from the model: m = ρ A L0 / N.
fn node_mass(s: &Scenario, n: usize) -> f64 {
    s.cable.density * s.cable.area * s.cable.modelled_length / n as f64
}

/// Every stored node of both cables is on the reel line at rest across it, on its side of the
/// pulley, and every free node on the other.
fn assert_stored_nodes_on_the_reel(m: &Lumped, y: &[f64]) -> Result<(), TestCaseError> {
    let np = m.positions_len();
    for (cable, e_out) in TOWARD_REEL.into_iter().enumerate() {
        let r = m.stored()[cable];
        for j in 0..m.elements {
            let (ix, iz) = (m.x_index(cable, j), m.z_index(cable, j));
            let beyond = (y[ix] - m.pulley(cable).x) * e_out;
            if j < r {
                prop_assert_eq!(y[iz], 0.0, "cable {}, stored node {}: z", cable, j);
                prop_assert_eq!(y[np + iz], 0.0, "cable {}, stored node {}: ż", cable, j);
                prop_assert!(
                    beyond > 0.0,
                    "cable {}, stored node {} is not on the reel side",
                    cable,
                    j
                );
            } else {
                prop_assert!(
                    beyond < 0.0,
                    "cable {}, free node {} is on the reel side",
                    cable,
                    j
                );
            }
        }
    }
    Ok(())
}

/// Tension of the spring between node positions `a` and `b` of `cable` [N], from MODELS.md §4
/// (k0 = EA N / L0, l0 = L0 / N, tension only), its length along the path over the pulley when
/// `straddles`: written here from the scenario, not taken from the model.
fn spring_tension(
    s: &Scenario,
    n: usize,
    pulley: (f64, f64),
    a: (f64, f64),
    b: (f64, f64),
    straddles: bool,
) -> f64 {
    let dist = |p: (f64, f64), q: (f64, f64)| (p.0 - q.0).hypot(p.1 - q.1);
    let length = if straddles {
        dist(a, pulley) + dist(pulley, b)
    } else {
        dist(a, b)
    };
    let l0 = s.cable.modelled_length / n as f64;
    let k0 = s.cable.youngs_modulus * s.cable.area / l0;
    (k0 * (length - l0)).max(0.0)
}

/// A static equilibrium at `x` with random velocities on every free node (`seed` picks them).
fn moving_state(m: &mut Lumped, x: f64, tension_sum: f64, speed: f64, seed: u64) -> Vec<f64> {
    let eq = m.equilibrium(&SplitRule::new(x, tension_sum)).unwrap();
    let mut y = eq.state;
    let np = m.positions_len();
    for cable in 0..2 {
        for j in m.stored()[cable]..m.elements {
            let phase = (seed as f64) * 0.37 + (cable * 97 + j) as f64;
            y[np + m.x_index(cable, j)] = speed * (1.3 * phase).sin();
            y[np + m.z_index(cable, j)] = speed * (0.7 * phase).cos();
        }
    }
    y
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// The first free node arrives at the pulley point (A, z = 0) with a vertical speed ż and
    /// is reeled in: it becomes stored with z = ż = 0, every stored node stays on the reel line at
    /// rest across it, and the event records ΔE = −½ m ż², the vertical kinetic energy the
    /// constraint removes, with m from the scenario. The node moves by the pulley offset ε =
    /// 1e-12 m only, which changes its two springs' energy by at most ε (T_{r−1} + T_r) (the
    /// tensions from the geometry; up to ~1e4 N here, the node having been put at the pulley by
    /// hand): tolerance 2ε (T_{r−1} + T_r) + 1e-12 J, against ½ m ż² ≥ 1.4e-6 J. Then it leaves the
    /// reel again: ΔE = 0 to the same tolerance.
    #[test]
    fn events_remove_exactly_the_constrained_kinetic_energy(
        x in 0.35f64..0.65,
        tension_sum in 150.0f64..300.0,
        elements in prop::sample::select(vec![10usize, 40, 80]),
        cable in 0usize..2,
        vz in prop::sample::select(vec![-1.0f64, 1.0]).prop_flat_map(|s| (0.1f64..1.0).prop_map(move |v| s * v)),
        seed in 0u64..1000,
    ) {
        let mut s = Scenario::paper();
        s.cable.modelled_length = 1.7;
        let mut m = Lumped::new(&s, Params { elements }).unwrap();
        let mut y = moving_state(&mut m, x, tension_sum, 0.05, seed);
        let np = m.positions_len();
        let r = m.stored()[cable];
        let (ix, iz) = (m.x_index(cable, r), m.z_index(cable, r));
        // The first free node at the pulley point, crossing onto the reel side.
        let pulley = (m.pulley(cable).x, 0.0);
        y[ix] = pulley.0;
        y[iz] = 0.0;
        y[np + iz] = vz;
        let node = |j: usize| (y[m.x_index(cable, j)], y[m.z_index(cable, j)]);
        let next = if r + 1 == elements { (y[m.x_index(0, elements)], y[m.z_index(0, elements)]) } else { node(r + 1) };
        let tensions = spring_tension(&s, elements, pulley, node(r - 1), node(r), true)
            + spring_tension(&s, elements, pulley, node(r), next, false);
        let tolerance = 2.0 * cdpr_lumped::PULLEY_OFFSET * tensions + 1e-12;
        let event = m.apply_event(PER_CABLE * cable + REELED_IN, 0.1, &mut y).unwrap();
        prop_assert_eq!(m.stored()[cable], r + 1);
        assert_stored_nodes_on_the_reel(&m, &y)?;
        let removed = 0.5 * node_mass(&s, elements) * vz * vz;
        prop_assert!(
            (event.energy_change + removed).abs() < tolerance,
            "ΔE = {:e} J, −½ m ż² = {:e} J, tolerance {:e} J", event.energy_change, -removed, tolerance
        );
        let event = m.apply_event(PER_CABLE * cable + LEAVES, 0.2, &mut y).unwrap();
        prop_assert_eq!(m.stored()[cable], r);
        assert_stored_nodes_on_the_reel(&m, &y)?;
        prop_assert!(event.energy_change.abs() < tolerance, "leaving the reel: ΔE = {:e} J", event.energy_change);
    }

    /// Inertia from outside: every node and the effector moving along x at v (the stored nodes
    /// slide on their reel line) carry ½ (M + 2 ρ A L0) v² of kinetic energy, the cable masses
    /// taken from the scenario (ρ A L0 per cable), before and after a node is reeled in. Round-off
    /// only: 1e-12 relative.
    #[test]
    fn a_rigid_translation_carries_the_cables_mass(
        x in 0.35f64..0.65,
        elements in prop::sample::select(vec![10usize, 40, 80]),
        density in 1000.0f64..9000.0,
        area in 1e-6f64..3e-6,
        effector_mass in 0.5f64..2.0,
        v in -1.0f64..1.0,
        cable in 0usize..2,
    ) {
        let mut s = Scenario::paper();
        s.cable.density = density;
        s.cable.area = area;
        s.cable.modelled_length = 1.7;
        s.robot.effector_mass = effector_mass;
        let mut m = Lumped::new(&s, Params { elements }).unwrap();
        let mut y = m.equilibrium(&SplitRule::new(x, 200.0)).unwrap().state;
        let np = m.positions_len();
        let expected = 0.5 * (effector_mass + 2.0 * density * area * 1.7) * v * v;
        let translate = |m: &Lumped, y: &mut [f64]| {
            y[np..2 * np].fill(0.0);
            for c in 0..2 {
                for j in 0..m.elements {
                    y[np + m.x_index(c, j)] = v;
                }
            }
            y[np + m.x_index(0, m.elements)] = v;
        };
        translate(&m, &mut y);
        let kinetic = m.energy(&y).kinetic;
        prop_assert!((kinetic - expected).abs() <= 1e-12 * expected.max(1e-300), "{kinetic} vs {expected}");
        let r = m.stored()[cable];
        y[m.x_index(cable, r)] = m.pulley(cable).x;
        y[m.z_index(cable, r)] = 0.0;
        m.apply_event(PER_CABLE * cable + REELED_IN, 0.1, &mut y).unwrap();
        translate(&m, &mut y);
        let kinetic = m.energy(&y).kinetic;
        prop_assert!((kinetic - expected).abs() <= 1e-12 * expected.max(1e-300), "after the event: {kinetic} vs {expected}");
    }
}
