//! The LQR's gain follows its weights: the gain a run reports in `controller_gains` equals the
//! gain built here from the scenario's own keys — the plant linearised from the robot's geometry
//! (MODELS.md §11's structure matrix and the geometric stiffness of taut rigid cables at the
//! design point) and the CARE solved by a method the controller does not use (the Hamiltonian's
//! matrix sign function on states scaled to unit weight, Roberts 1971 with Byers' determinant
//! scaling, then Newton steps whose Lyapunov equations are solved as Kronecker systems, against
//! the controller's invariant subspace and Newton–Kleinman). Halving `q_position` in the
//! controller's code, or scaling it by 1e-3, changed no other test's outcome; this one fails.

use cdpr_bench::{assess, scenario_from_toml_str};
use nalgebra::{DMatrix, Matrix2, Vector2};
use proptest::prelude::*;

/// X of Aᵀ X + X A − X B R⁻¹ Bᵀ X + Q = 0 by the sign of H = [A, −B R⁻¹ Bᵀ; −Q, −Aᵀ]:
/// Z ← (Z/c + c Z⁻¹)/2, c = |det Z|^(1/2n), until Z² = I; then [W₁₂; W₂₂ + I] X = −[W₁₁ + I; W₂₁]
/// in least squares.
fn care_by_sign(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    q: &DMatrix<f64>,
    r: &DMatrix<f64>,
) -> DMatrix<f64> {
    let n = a.nrows();
    let r_inv = r.clone().try_inverse().expect("R invertible");
    let g = b * &r_inv * b.transpose();
    let mut z = DMatrix::zeros(2 * n, 2 * n);
    z.view_mut((0, 0), (n, n)).copy_from(a);
    z.view_mut((0, n), (n, n)).copy_from(&(-&g));
    z.view_mut((n, 0), (n, n)).copy_from(&(-q));
    z.view_mut((n, n), (n, n)).copy_from(&(-a.transpose()));
    for _ in 0..100 {
        let inv = z
            .clone()
            .try_inverse()
            .expect("H has no eigenvalue on the imaginary axis");
        let c = z.determinant().abs().powf(1.0 / (2 * n) as f64);
        let next = (&z / c + &inv * c) * 0.5;
        let change = (&next - &z).norm() / next.norm();
        z = next;
        if change < 1e-15 {
            break;
        }
    }
    let identity = DMatrix::<f64>::identity(n, n);
    let mut lhs = DMatrix::zeros(2 * n, n);
    lhs.view_mut((0, 0), (n, n))
        .copy_from(&z.view((0, n), (n, n)));
    lhs.view_mut((n, 0), (n, n))
        .copy_from(&(z.view((n, n), (n, n)) + &identity));
    let mut rhs = DMatrix::zeros(2 * n, n);
    rhs.view_mut((0, 0), (n, n))
        .copy_from(&(-(z.view((0, 0), (n, n)) + &identity)));
    rhs.view_mut((n, 0), (n, n))
        .copy_from(&(-z.view((n, 0), (n, n))));
    let x = lhs
        .svd(true, true)
        .solve(&rhs, 1e-14)
        .expect("least squares");
    (&x + x.transpose()) * 0.5
}

/// Newton's method on the CARE from the sign function's X: (A − G X)ᵀ X⁺ + X⁺ (A − G X) =
/// −Q − X G X with G = B R⁻¹ Bᵀ, each Lyapunov equation solved as its Kronecker system
/// (I ⊗ Aₖᵀ + Aₖᵀ ⊗ I) vec X⁺ = vec(…) by LU. Weights spanning 1e12 leave the sign iteration
/// alone up to ~1e-5 of the gain off (and off its own symmetry); the stabilising solution is
/// Newton's fixed point, so two or three steps take it to round-off.
fn newton_refined(
    a: &DMatrix<f64>,
    g: &DMatrix<f64>,
    q: &DMatrix<f64>,
    mut x: DMatrix<f64>,
) -> DMatrix<f64> {
    let n = a.nrows();
    let identity = DMatrix::<f64>::identity(n, n);
    for _ in 0..8 {
        let closed_t = (a - g * &x).transpose();
        let operator = identity.kronecker(&closed_t) + closed_t.kronecker(&identity);
        let rhs = -(q + &x * g * &x);
        let vec_rhs = nalgebra::DVector::from_column_slice(rhs.as_slice());
        let solution = operator.lu().solve(&vec_rhs).expect("Aₖ is stable");
        let next = DMatrix::from_column_slice(n, n, solution.as_slice());
        let next = (&next + next.transpose()) * 0.5;
        let change = (&next - &x).norm() / next.norm();
        x = next;
        if change < 1e-15 {
            break;
        }
    }
    x
}

/// X of the CARE for a diagonal Q > 0, solved on the states scaled to unit weight: x = T x̃ with
/// T = Q^(−1/2), so Ã = T⁻¹AT, B̃ = T⁻¹B, Q̃ = I and X = T⁻¹X̃T⁻¹. Weights spanning 1e12 make the
/// unscaled Hamiltonian as ill-conditioned, and its sign iteration can then end on a matrix that
/// is not stabilising (weights (1.04e10, 1e2, 6.98e11, 0.19) did: a closed-loop eigenvalue at
/// +26.7/s, and Newton from there at +8.7/s with 9 % residual). Scaled, the sign function's X is
/// stabilising and Newton takes it to round-off.
fn care_scaled(
    a: &DMatrix<f64>,
    b: &DMatrix<f64>,
    q: &DMatrix<f64>,
    r: &DMatrix<f64>,
) -> DMatrix<f64> {
    let n = a.nrows();
    let t = nalgebra::DVector::from_fn(n, |j, _| q[(j, j)].powf(-0.5));
    let scale = DMatrix::from_diagonal(&t);
    let unscale = DMatrix::from_diagonal(&t.map(|v| 1.0 / v));
    let a_s = &unscale * a * &scale;
    let b_s = &unscale * b;
    let q_s = &scale * q * &scale;
    let g_s = &b_s * r.clone().try_inverse().expect("R invertible") * b_s.transpose();
    let x_s = care_by_sign(&a_s, &b_s, &q_s, r);
    let x_s = newton_refined(&a_s, &g_s, &q_s, x_s);
    &unscale * x_s * &unscale
}

/// The LQR gain K (2 × 6, on (δx, δz, δẋ, δż, σx, σz)) of the paper's robot with pulleys at
/// (0, 0) and (d, 0), an effector of mass M at the design point p on rigid massless cables under
/// gravity g, for the weights Q = diag(qp, qp, qv, qv, qi, qi), R = r I.
fn expected_gain(d: f64, m: f64, g: f64, p: Vector2<f64>, weights: [f64; 4]) -> DMatrix<f64> {
    let anchors = [Vector2::new(0.0, 0.0), Vector2::new(d, 0.0)];
    let (l, u): (Vec<f64>, Vec<Vector2<f64>>) = anchors
        .iter()
        .map(|a| {
            let to_anchor = a - p;
            (to_anchor.norm(), to_anchor / to_anchor.norm())
        })
        .unzip();
    let w = Matrix2::from_columns(&[u[0], u[1]]);
    let hold = w.try_inverse().unwrap() * Vector2::new(0.0, m * g);
    let stiffness: Matrix2<f64> = (0..2)
        .map(|i| -hold[i] * (Matrix2::identity() - u[i] * u[i].transpose()) / l[i])
        .sum();
    let mut a = DMatrix::zeros(6, 6);
    let mut b = DMatrix::zeros(6, 2);
    for i in 0..2 {
        a[(i, 2 + i)] = 1.0;
        a[(4 + i, i)] = 1.0;
        for j in 0..2 {
            a[(2 + i, j)] = stiffness[(i, j)] / m;
            b[(2 + i, j)] = w[(i, j)] / m;
        }
    }
    let [qp, qv, qi, r] = weights;
    let q = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![qp, qp, qv, qv, qi, qi]));
    let r_matrix = DMatrix::identity(2, 2) * r;
    b.transpose() * care_scaled(&a, &b, &q, &r_matrix) / r
}

/// The solver of this test against closed forms: ẋ = u (X = √(qr)) and the double integrator
/// ẍ = u with Q = diag(q₁, q₂), whose gain is [√(q₁/r), √(q₂/r + 2√(q₁/r))].
#[test]
fn the_sign_function_solver_meets_the_closed_forms() {
    let one = |v: f64| DMatrix::from_element(1, 1, v);
    let x = care_by_sign(&one(0.0), &one(1.0), &one(4.0), &one(9.0));
    assert!((x[(0, 0)] - 6.0).abs() < 1e-12, "{x}");
    for (q1, q2, r) in [(1.0, 1.0, 1.0), (1e9, 1e4, 1.0), (3.0, 0.0, 0.5)] {
        let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 0.0, 0.0]);
        let b = DMatrix::from_row_slice(2, 1, &[0.0, 1.0]);
        let q = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![q1, q2]));
        let x = care_by_sign(&a, &b, &q, &one(r));
        let k = b.transpose() * x / r;
        let expected = [(q1 / r).sqrt(), (q2 / r + 2.0 * (q1 / r).sqrt()).sqrt()];
        for j in 0..2 {
            assert!(
                (k[(0, j)] - expected[j]).abs() <= 1e-9 * expected[j],
                "q = ({q1}, {q2}), r = {r}: {k} vs {expected:?}"
            );
        }
    }
}

/// The gain a run reports for the scenario's weights, against the gain built from those keys.
/// Tolerance 1e-9 of the gain's norm: both solvers end at round-off of a CARE whose weights span
/// up to 1e12 (3000 cases of this sweep and 1500 of the spatial one stayed below it with the
/// states scaled to unit weight and the sign function's X refined by Newton; unrefined, they
/// reached 8e-6, and unscaled one case ended on a non-stabilising X).
fn check(weights: [f64; 4], x2: f64) -> Result<(), TestCaseError> {
    let [qp, qv, qi, r] = weights;
    let scenario = scenario_from_toml_str(&format!(
        "[controller]\nkind = \"lqr\"\nq_position = {qp:e}\nq_velocity = {qv:e}\n\
         q_integral = {qi:e}\nr = {r:e}\n[trajectory]\nx2 = {x2}\n\
         [simulation]\nt_final = 0.01\nsample_period = 1e-3\n[analysis]\nmodes = \"off\"\n"
    ))
    .unwrap();
    let run = assess(&scenario, &mut |_| {}).unwrap();
    let gains = &run.metrics.control.controller_gains;
    let reported = DMatrix::from_row_slice(2, 6, &gains["lqr_gain"]);
    // The design point: the move's end at the start's height (the run's first sample).
    let p = Vector2::new(x2, run.metrics.z0);
    prop_assert_eq!(&gains["lqr_design_point"], &vec![p.x, p.y]);
    let robot = &scenario.robot;
    let expected = expected_gain(
        robot.anchor_distance,
        robot.effector_mass,
        robot.gravity,
        p,
        weights,
    );
    close_gains(&reported, &expected, weights)
}

/// The reported gain within 1e-9 of the expected one (relative, Frobenius).
fn close_gains(
    reported: &DMatrix<f64>,
    expected: &DMatrix<f64>,
    weights: [f64; 4],
) -> Result<(), TestCaseError> {
    let error = (reported - expected).norm() / expected.norm();
    prop_assert!(
        error < 1e-9,
        "weights {:?}: reported\n{}\nexpected\n{}\nrelative error {:e}",
        weights,
        reported,
        expected,
        error
    );
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// Over four decades of each weight around the defaults (1e9, 1e4, 1e10, 1), at the move's
    /// end of the paper (x2 = 0.6 m, where x and z couple) and at the middle (x and z decouple).
    #[test]
    fn the_reported_gain_follows_the_scenario_weights(
        qp in 7.0..11.0f64,
        qv in 2.0..6.0f64,
        qi in 8.0..12.0f64,
        r in -1.0..1.0f64,
        middle in any::<bool>(),
    ) {
        let weights = [10f64.powf(qp), 10f64.powf(qv), 10f64.powf(qi), 10f64.powf(r)];
        check(weights, if middle { 0.5 } else { 0.6 })?;
    }
}

/// The case that once failed CI: q_position 2.5e10 against q_integral 3.7e8, where the unscaled
/// sign iteration was 1.6e-7 off the controller's gain (and 1.4e-6 off its own symmetry).
#[test]
fn the_gain_follows_widely_spread_weights() {
    let weights = [
        10f64.powf(10.403918068441884),
        10f64.powf(3.3680800948310003),
        10f64.powf(8.570770153960993),
        1.0,
    ];
    check(weights, 0.6).unwrap();
}

/// The Hangprinter example's anchors [m] (examples/robots/hangprinter.toml).
const HANGPRINTER: [[f64; 3]; 4] = [
    [0.0, -1.61098, -0.13153],
    [1.31422, 1.26814, -0.12128],
    [-1.41573, 0.70761, -0.12182],
    [0.0, 0.0, 2.29983],
];

/// The spatial LQR's gain K (m × 9, on (δp, δṗ, σ)) for the robot with `anchors`, an effector
/// of mass M at the design point p, tensions at rest `hold`, weights Q = diag(qp I, qv I, qi I),
/// R = r I (MODELS.md §11: M δp̈ = W δT + G δp, G = −Σ T_i (I − u_i u_iᵀ)/l_i).
fn expected_spatial_gain(
    anchors: &[[f64; 3]],
    m: f64,
    p: nalgebra::Vector3<f64>,
    hold: &[f64],
    weights: [f64; 4],
) -> DMatrix<f64> {
    let cables = anchors.len();
    let mut a = DMatrix::zeros(9, 9);
    let mut b = DMatrix::zeros(9, cables);
    let mut stiffness = nalgebra::Matrix3::<f64>::zeros();
    for (i, anchor) in anchors.iter().enumerate() {
        let to_anchor = nalgebra::Vector3::from(*anchor) - p;
        let (l, u) = (to_anchor.norm(), to_anchor / to_anchor.norm());
        stiffness -= hold[i] * (nalgebra::Matrix3::identity() - u * u.transpose()) / l;
        for k in 0..3 {
            b[(3 + k, i)] = u[k] / m;
        }
    }
    for i in 0..3 {
        a[(i, 3 + i)] = 1.0;
        a[(6 + i, i)] = 1.0;
        for j in 0..3 {
            a[(3 + i, j)] = stiffness[(i, j)] / m;
        }
    }
    let [qp, qv, qi, r] = weights;
    let diagonal: Vec<f64> = [qp, qv, qi].iter().flat_map(|&w| [w; 3]).collect();
    let q = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(diagonal));
    let r_matrix = DMatrix::identity(cables, cables) * r;
    b.transpose() * care_scaled(&a, &b, &q, &r_matrix) / r
}

/// The QP's tensions holding M g at p for one degree of redundancy, computed here: on the line
/// W⁺w + s n (n by cofactors; W⁺w ⟂ n) the s nearest 0 inside the box.
fn one_redundancy_qp(
    anchors: &[[f64; 3]],
    m: f64,
    g: f64,
    p: nalgebra::Vector3<f64>,
    (t_min, t_max): (f64, f64),
) -> Vec<f64> {
    let w = DMatrix::from_fn(3, anchors.len(), |k, i| {
        let d = nalgebra::Vector3::from(anchors[i]) - p;
        d[k] / d.norm()
    });
    let wrench = nalgebra::DVector::from_vec(vec![0.0, 0.0, m * g]);
    let base = w.clone().pseudo_inverse(1e-14).unwrap() * &wrench;
    // The null vector by cofactors: n_i = (−1)^i det(W without column i).
    let null: Vec<f64> = (0..anchors.len())
        .map(|i| {
            let minor = w.clone().remove_column(i);
            let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
            sign * minor.determinant()
        })
        .collect();
    let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
    for i in 0..anchors.len() {
        let (x, y) = ((t_min - base[i]) / null[i], (t_max - base[i]) / null[i]);
        lo = lo.max(x.min(y));
        hi = hi.min(x.max(y));
    }
    assert!(lo <= hi, "the weight cannot be held in the box at {p}");
    let s = 0.0f64.clamp(lo, hi);
    (0..anchors.len()).map(|i| base[i] + s * null[i]).collect()
}

/// The spatial LQR (Hangprinter, 4 cables, designed at the move's end through the QP's tensions)
/// reports the gain built here from the scenario's keys, over four decades of each weight.
fn check_spatial(weights: [f64; 4], end: [f64; 3]) -> Result<(), TestCaseError> {
    let [qp, qv, qi, r] = weights;
    let anchors: Vec<String> = HANGPRINTER.iter().map(|a| format!("{a:?}")).collect();
    let scenario = scenario_from_toml_str(&format!(
        "[robot]\nanchors = [{}]\neffector_mass = 1.0\n[cable]\nyoungs_modulus = 2.105e10\n\
         area = 9.503e-7\n[controller]\nkind = \"lqr\"\nt_min = 10.0\nt_max = 70.0\n\
         q_position = {qp:e}\nq_velocity = {qv:e}\nq_integral = {qi:e}\nr = {r:e}\n\
         [trajectory]\nstart = [0.0, 0.0, 0.0]\nend = {end:?}\nt2 = 1.0\n\
         [simulation]\nt_final = 0.01\nsample_period = 1e-3\n",
        anchors.join(", ")
    ))
    .unwrap();
    let run = cdpr_bench::simulate_spatial(
        &scenario,
        &mut cdpr_bench::core::runner::Observer::progress(&mut |_| {}),
    )
    .unwrap()
    .run;
    let gains: std::collections::BTreeMap<_, _> = run.controller_gains.into_iter().collect();
    prop_assert_eq!(&gains["lqr_design_point"], &end.to_vec());
    let reported = DMatrix::from_row_slice(4, 9, &gains["lqr_gain"]);
    let p = nalgebra::Vector3::from(end);
    let hold = one_redundancy_qp(&HANGPRINTER, 1.0, 9.81, p, (10.0, 70.0));
    let expected = expected_spatial_gain(&HANGPRINTER, 1.0, p, &hold, weights);
    close_gains(&reported, &expected, weights)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Hangprinter's LQR at two end poses (the example's, and one where another cable rests on
    /// t_min), weights over four decades around the defaults.
    #[test]
    fn the_spatial_gain_follows_the_scenario_weights(
        qp in 7.0..11.0f64,
        qv in 2.0..6.0f64,
        qi in 8.0..12.0f64,
        r in -1.0..1.0f64,
        other in any::<bool>(),
    ) {
        let weights = [10f64.powf(qp), 10f64.powf(qv), 10f64.powf(qi), 10f64.powf(r)];
        let end = if other { [-0.2, 0.1, 0.3] } else { [0.1, 0.05, 0.02] };
        check_spatial(weights, end)?;
    }
}

/// The case that failed CI next: q_integral 7e11 against q_velocity 1e2, where the unscaled sign
/// iteration ended on a non-stabilising X (closed-loop eigenvalue +26.7/s) and the gains differed
/// by 140 %.
#[test]
fn the_gain_follows_weights_spanning_ten_decades() {
    let weights = [
        10f64.powf(10.018744343523993),
        100.0,
        10f64.powf(11.844035559543393),
        10f64.powf(-0.7172042264427931),
    ];
    check(weights, 0.6).unwrap();
}
