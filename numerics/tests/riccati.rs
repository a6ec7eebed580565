//! The CARE solver against closed forms (the double integrator) and, for random stabilisable
//! systems, against its own definition: the Riccati residual, a stable closed loop A − B K and a
//! symmetric positive semi-definite X.

use cdpr_numerics::eigen::modes;
use cdpr_numerics::riccati::{RiccatiError, care};
use faer::Mat;
use proptest::prelude::*;

fn double_integrator() -> (Mat<f64>, Mat<f64>) {
    let a = Mat::from_fn(2, 2, |i, j| if (i, j) == (0, 1) { 1.0 } else { 0.0 });
    let b = Mat::from_fn(2, 1, |i, _| if i == 1 { 1.0 } else { 0.0 });
    (a, b)
}

/// ẍ = u, R = 1: with Q = diag(1, 0) the CARE's closed form is X = [[√2, 1], [1, √2]],
/// K = [1, √2]; with Q = I it is X = [[√3, 1], [1, √3]], K = [1, √3] (solve the three scalar
/// equations b² = 1 + q₁₁·0 …: b = 1, a = c, c² = 2b + q₂₂). Round-off only: 1e-12.
#[test]
fn double_integrator_matches_the_closed_form() {
    let (a, b) = double_integrator();
    let r = Mat::<f64>::identity(1, 1);
    for (q22, c) in [(0.0, 2f64.sqrt()), (1.0, 3f64.sqrt())] {
        let q = Mat::from_fn(2, 2, |i, j| match (i, j) {
            (0, 0) => 1.0,
            (1, 1) => q22,
            _ => 0.0,
        });
        let lqr = care(&a, &b, &q, &r).unwrap();
        assert!((lqr.gain[(0, 0)] - 1.0).abs() < 1e-12, "{:?}", lqr.gain);
        assert!((lqr.gain[(0, 1)] - c).abs() < 1e-12, "{:?}", lqr.gain);
        for (i, j, expected) in [(0, 0, c), (0, 1, 1.0), (1, 0, 1.0), (1, 1, c)] {
            assert!((lqr.x[(i, j)] - expected).abs() < 1e-12, "X = {:?}", lqr.x);
        }
        assert!(lqr.residual < 1e-12);
    }
}

/// A random n × n system (entries in [−2, 2]) with B of full rank (so every mode is
/// controllable generically), Q = CᵀC + 0.1 I > 0, R diagonal in [0.1, 10].
fn system(n: usize, m: usize, entries: &[f64]) -> (Mat<f64>, Mat<f64>, Mat<f64>, Mat<f64>) {
    let mut k = 0;
    let mut next = || {
        k += 1;
        entries[k % entries.len()]
    };
    let a = Mat::from_fn(n, n, |_, _| 2.0 * next());
    let b = Mat::from_fn(n, m, |i, j| if i == j { 1.0 } else { next() });
    let c = Mat::from_fn(n, n, |_, _| next());
    let q = Mat::from_fn(n, n, |i, j| {
        (0..n).map(|l| c[(l, i)] * c[(l, j)]).sum::<f64>() + if i == j { 0.1 } else { 0.0 }
    });
    let r = Mat::from_fn(m, m, |i, j| {
        if i == j {
            0.1 + 9.9 * next().abs()
        } else {
            0.0
        }
    });
    (a, b, q, r)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// For random stabilisable systems of 2 to 6 states and 1 to 3 inputs: the residual is at
    /// round-off of the equation's terms (1e-10 of the largest), X is symmetric and positive
    /// semi-definite (its smallest eigenvalue ≥ −1e-10 of its largest), and every eigenvalue of
    /// A − B K has Re < 0.
    #[test]
    fn random_systems_get_the_stabilising_solution(
        n in 2usize..7,
        m in 1usize..4,
        entries in prop::collection::vec(-1.0f64..1.0, 64),
    ) {
        let m = m.min(n);
        let (a, b, q, r) = system(n, m, &entries);
        let lqr = care(&a, &b, &q, &r).unwrap();
        let x = &lqr.x;
        let scale = (0..n).flat_map(|i| (0..n).map(move |j| (i, j))).fold(1.0f64, |s, (i, j)| s.max(x[(i, j)].abs()).max(a[(i, j)].abs()));
        prop_assert!(lqr.residual < 1e-10 * scale * scale, "residual {:e}", lqr.residual);
        for i in 0..n {
            for j in 0..n {
                prop_assert_eq!(x[(i, j)], x[(j, i)]);
            }
        }
        let lambda = modes(x).unwrap();
        let largest = lambda.iter().fold(0.0f64, |s, l| s.max(l.growth.abs()));
        for l in &lambda {
            prop_assert!(l.omega.abs() < 1e-9 * largest && l.growth >= -1e-10 * largest, "X eigenvalue {:?}", l);
        }
        let closed = &a - &b * &lqr.gain;
        for mode in modes(&closed).unwrap() {
            prop_assert!(mode.growth < 0.0, "closed-loop mode {:?}", mode);
        }
    }
}

/// An unstable mode no input reaches has no stabilising solution: a named error, no panic; so
/// are a singular R and mismatched dimensions.
#[test]
fn unstabilisable_and_malformed_problems_are_errors() {
    let a = Mat::from_fn(2, 2, |i, j| match (i, j) {
        (0, 0) => 1.0,
        (1, 1) => -1.0,
        _ => 0.0,
    });
    let b = Mat::from_fn(2, 1, |i, _| if i == 1 { 1.0 } else { 0.0 });
    let q = Mat::<f64>::identity(2, 2);
    let r = Mat::<f64>::identity(1, 1);
    let err = care(&a, &b, &q, &r).unwrap_err();
    assert!(
        matches!(
            err,
            RiccatiError::NoStableSubspace { .. } | RiccatiError::NotStabilisable
        ),
        "{err:?}"
    );
    let zero = Mat::<f64>::zeros(1, 1);
    let (a, b) = double_integrator();
    assert_eq!(
        care(&a, &b, &q, &zero).unwrap_err(),
        RiccatiError::SingularR
    );
    let err = care(&a, &b, &Mat::<f64>::identity(3, 3), &r).unwrap_err();
    assert!(matches!(err, RiccatiError::Dimensions(_)), "{err:?}");
}

/// K is invariant under scaling Q and R together (the cost scales, the minimiser does not), so
/// the printer-scale weights (position error of 10 µm against 1 N: Q ~ 1e10, R = 1) must give
/// the gain of the same problem scaled to Q ~ 1. Two decoupled axes of ẍ = u with integral
/// action, the shape of the LQR controller's design; counting Re λ < 0 in the Hamiltonian
/// failed here before (7 or 5 eigenvalues instead of 6).
#[test]
fn badly_scaled_weights_give_the_scaled_problem_s_gain() {
    let n = 6;
    let a = Mat::from_fn(n, n, |i, j| {
        // ξ = (x, z, ẋ, ż, ∫x, ∫z)
        if (i < 2 && j == i + 2) || (i >= 4 && j == i - 4) {
            1.0
        } else {
            0.0
        }
    });
    let b = Mat::from_fn(n, 2, |i, j| if i == j + 2 { 1.0 } else { 0.0 });
    for (qp, qv, qi) in [(1e10, 1e6, 1e10), (1e9, 1e5, 1e11), (3e8, 1e4, 3e9)] {
        let q = |scale: f64| {
            Mat::from_fn(n, n, |i, j| {
                if i != j {
                    0.0
                } else {
                    scale * [qp, qp, qv, qv, qi, qi][i]
                }
            })
        };
        let r = |scale: f64| Mat::from_fn(2, 2, |i, j| if i == j { scale } else { 0.0 });
        let big = care(&a, &b, &q(1.0), &r(1.0)).unwrap_or_else(|e| panic!("{qp:e}: {e}"));
        let small = care(&a, &b, &q(1.0 / qp), &r(1.0 / qp))
            .unwrap_or_else(|e| panic!("scaled {qp:e}: {e}"));
        for i in 0..2 {
            for j in 0..n {
                let (k1, k2) = (big.gain[(i, j)], small.gain[(i, j)]);
                // Both solves end at round-off of their X; the gains agree to 1e-8 relative.
                assert!(
                    (k1 - k2).abs() <= 1e-8 * k2.abs().max(1.0),
                    "{qp:e}: K[{i},{j}] {k1} vs {k2}"
                );
            }
        }
    }
}
