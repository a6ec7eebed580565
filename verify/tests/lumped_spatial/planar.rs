//! The lumped spatial model on a robot whose cables lie in the x–z plane against the planar
//! lumped model, an independent implementation.

use super::*;

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
