//! The implicit path's iteration matrix, undamped and damped, against coloured central
//! differences of the residual at shaken rests.

use super::*;

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
