//! The iteration matrix re-weighted for a new step size (`SecondOrderForm::reweighted_matrix`)
//! is the matrix the model evaluates at the same state with the new weights, to the bit: the
//! parts it keeps are the very difference quotients an evaluation takes, whatever the weights.
//! Swept over states near equilibria (disturbed positions and velocities), both mass variants,
//! axial damping on and off, and pairs of step sizes across three decades.

use crate::common;

use cdpr_core::model::CableModel;
use cdpr_core::scenario::Scenario;
use cdpr_fe::{Fe, FeMass, FeStored};
use common::*;
use proptest::prelude::*;

/// The generalised-α weights (c_v, c_q) of step h at ρ∞ = 0.9, the implicit path's default.
fn weights(h: f64) -> (f64, f64) {
    cdpr_numerics::AlphaCoefficients::new(0.9).derivatives(h)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn a_reweighted_matrix_is_the_evaluated_one(
        x in 0.3f64..0.7,
        seed in 0u64..1000,
        dq in 0.0f64..1e-5,
        v in 0.0f64..0.05,
        consistent in any::<bool>(),
        damping in prop::sample::select(vec![0.0, 2.0]),
        h1 in 1e-6f64..1e-3,
        h2 in 1e-6f64..1e-3,
    ) {
        let mass = if consistent { FeMass::Consistent } else { FeMass::Lumped };
        let mut scenario = Scenario::paper();
        scenario.cable.axial_damping = damping;
        let mut m = Fe::new(&scenario, params(10, mass, FeStored::Elastic)).unwrap();
        let y = random_state(&mut m, x, seed, dq, v);
        let tensions = tensions(200.0, 0.1);
        let form = m.second_order_mut().unwrap();
        let n = form.dofs();
        let len = form.iteration_pattern().len();
        let qdd: Vec<f64> = (0..n).map(|i| 0.1 * ((i % 7) as f64 - 3.0)).collect();
        let mut kept = vec![0.0; len];
        prop_assert!(!form.reweighted_matrix(1.0, 1.0, &mut kept), "nothing kept before a matrix");
        let ((v1, q1), (v2, q2)) = (weights(h1), weights(h2));
        let mut first = vec![0.0; len];
        form.iteration_matrix(&y, &qdd, &tensions, v1, q1, &mut first);
        prop_assert!(form.reweighted_matrix(v2, q2, &mut kept));
        let mut evaluated = vec![0.0; len];
        form.iteration_matrix(&y, &qdd, &tensions, v2, q2, &mut evaluated);
        for (k, (a, b)) in kept.iter().zip(&evaluated).enumerate() {
            prop_assert_eq!(a.to_bits(), b.to_bits(), "entry {}: {} against {}", k, a, b);
        }
        // The weights matter (the test could not pass by ignoring them).
        if (h1 / h2 - 1.0).abs() > 0.1 {
            prop_assert!(first.iter().zip(&evaluated).any(|(a, b)| a != b));
        }
    }
}
