//! A pulley passage in 3-D: mass, momentum along the reel line and the recorded energy change.

use super::*;

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
