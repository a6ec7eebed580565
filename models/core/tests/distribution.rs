//! Tension distribution (MODELS.md §11) checked from outside: the balance W T = w, the box, the
//! closed forms where m = D, the QP against directional optimality along random null-space
//! directions and against the exact minimiser of one degree of redundancy (a segment), and the
//! margin's sign against the QP's feasibility. Poses, anchors, boxes and cable counts are swept.

use cdpr_core::robot::distribution::{
    BOX_TOLERANCE, DistributionMethod, TensionBox, distribute, margin,
};
use cdpr_core::robot::{Robot, Vector};
use nalgebra::{DMatrix, DVector};
use proptest::prelude::*;

/// A 3-D robot of `m` anchors on a frame of half-width `a` and height `h` (alternately high and
/// low, as CoGiRo's), an effector of `mass` kg at `p`.
fn robot(m: usize, a: f64, h: f64, mass: f64) -> Robot<3> {
    let anchors: Vec<Vector<3>> = (0..m)
        .map(|i| {
            let phi = std::f64::consts::TAU * i as f64 / m as f64 + 0.3;
            let z = if i % 2 == 0 { h } else { 0.2 * h };
            Vector::<3>::new(a * phi.cos(), a * phi.sin(), z)
        })
        .collect();
    Robot::new(&anchors, mass, 9.81).unwrap()
}

/// I − W⁺W: the projector onto W's null space (W d = 0), by nalgebra's SVD pseudo-inverse.
fn null_space_projector(wm: &DMatrix<f64>) -> DMatrix<f64> {
    let m = wm.ncols();
    let pinv = wm.clone().pseudo_inverse(1e-14).unwrap();
    DMatrix::identity(m, m) - pinv * wm
}

/// ‖W T − w‖ allowed: round-off of W⁺ applied to tensions of size ‖T‖ (ε·m·‖T‖ with a factor
/// 100 for the Gram inverse's conditioning at these poses) on top of 1e-12 ‖w‖.
fn balance_tolerance(wrench: f64, tensions: f64) -> f64 {
    1e-12 * wrench + 1e-13 * tensions
}

fn strategy() -> impl Strategy<Value = (usize, [f64; 3], [f64; 3], f64, f64)> {
    (
        4usize..=8,
        [-0.4..0.4f64, -0.4..0.4f64, 0.3..1.2f64],
        [-3.0..3.0f64, -3.0..3.0f64, -3.0..3.0f64],
        0.5..20.0f64,
        50.0..2000.0f64,
    )
        .prop_map(|(m, p, a, mass, t_max)| (m, p, a, mass, t_max))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Every method balances the wrench and, where feasible, keeps the box; the QP is never
    /// beaten along a null-space direction, nor by any other method's feasible answer.
    #[test]
    fn every_method_balances_and_the_qp_is_never_beaten(
        (m, p, acc, mass, t_max) in strategy(),
        seed in any::<u64>(),
    ) {
        let robot = robot(m, 1.5, 2.0, mass);
        let p = Vector::<3>::new(p[0], p[1], p[2]);
        let w = robot.structure_matrix(&p);
        let wrench = Vector::<3>::new(acc[0], acc[1], acc[2] + 9.81) * mass;
        let limits = TensionBox { t_min: 0.05 * t_max, t_max };
        let mut feasible_norms = Vec::new();
        for method in DistributionMethod::ALL {
            let d = distribute(method, &w, &wrench, limits).unwrap();
            let t_norm = d.tensions.iter().map(|t| t * t).sum::<f64>().sqrt();
            if d.feasible {
                let error = (w.force(&d.tensions) - wrench).norm();
                prop_assert!(error <= balance_tolerance(wrench.norm(), t_norm),
                    "{}: ‖WT − w‖ = {error:e}", method.name());
                for &t in d.tensions.iter() {
                    prop_assert!(t >= limits.t_min - BOX_TOLERANCE && t <= limits.t_max + BOX_TOLERANCE,
                        "{}: {t} outside {limits:?}", method.name());
                }
                feasible_norms.push((method, t_norm));
            }
        }
        let qp = distribute(DistributionMethod::Qp, &w, &wrench, limits).unwrap();
        let s = margin(&w, &wrench, limits).unwrap();
        // The margin's sign and the QP's feasibility agree (away from the boundary, where the
        // bisection's 1e-9 N and the QP's tolerances could each decide either way).
        if s.abs() > 1e-6 {
            prop_assert_eq!(qp.feasible, s > 0.0, "margin {}", s);
        }
        if !qp.feasible {
            prop_assert!(feasible_norms.is_empty(), "{feasible_norms:?} feasible, the QP not");
            return Ok(());
        }
        let t: Vec<f64> = qp.tensions.iter().copied().collect();
        let best = t.iter().map(|v| v * v).sum::<f64>();
        // A feasible answer may sit BOX_TOLERANCE outside a bound, which lowers ‖T‖² by at most
        // 2 ‖T‖ √m BOX_TOLERANCE.
        let slack = 2.0 * best.sqrt() * (m as f64).sqrt() * BOX_TOLERANCE + 1e-12 * best;
        for (method, norm) in &feasible_norms {
            prop_assert!(norm * norm >= best - slack, "{} beats the QP", method.name());
        }
        // Random null-space directions d (W d = 0): along T* + τ d inside the box, ‖·‖² has its
        // minimum at τ = 0.
        let wm = DMatrix::from_fn(3, m, |r, c| w.column(c)[r]);
        let projector = null_space_projector(&wm);
        let mut rng = seed;
        let mut next = || {
            rng = rng.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (rng >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for _ in 0..20 {
            let d = &projector * DVector::from_fn(m, |_, _| next());
            let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
            for i in 0..m {
                if d[i].abs() < 1e-15 { continue; }
                let a = (limits.t_min - t[i]) / d[i];
                let b = (limits.t_max - t[i]) / d[i];
                lo = lo.max(a.min(b));
                hi = hi.min(a.max(b));
            }
            let tv = DVector::from_vec(t.clone());
            let tau = (-tv.dot(&d) / d.dot(&d)).clamp(lo.min(0.0), hi.max(0.0));
            let moved = (&tv + &d * tau).norm_squared();
            prop_assert!(moved >= best - 1e-9 * best, "τ = {tau}: {moved} < {best}");
        }
    }

    /// One degree of redundancy (m = 4 in space): the QP's answer is the exact minimiser of ‖T‖²
    /// over the feasible segment of the line T_p + τ n, computed here in closed form.
    #[test]
    fn one_redundancy_qp_is_the_segments_minimiser(
        (_, p, acc, mass, t_max) in strategy(),
    ) {
        let robot = robot(4, 1.5, 2.0, mass);
        let p = Vector::<3>::new(p[0], p[1], p[2]);
        let w = robot.structure_matrix(&p);
        let wrench = Vector::<3>::new(acc[0], acc[1], acc[2] + 9.81) * mass;
        let limits = TensionBox { t_min: 0.05 * t_max, t_max };
        let wm = DMatrix::from_fn(3, 4, |r, c| w.column(c)[r]);
        let pinv = wm.clone().pseudo_inverse(1e-14).unwrap();
        let tp = &pinv * DVector::from_column_slice(wrench.as_slice());
        let projector = null_space_projector(&wm);
        let widest = (0..4).max_by(|&a, &b| {
            projector.column(a).norm().total_cmp(&projector.column(b).norm())
        }).unwrap();
        let n = projector.column(widest).normalize();
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        for i in 0..4 {
            let a = (limits.t_min - tp[i]) / n[i];
            let b = (limits.t_max - tp[i]) / n[i];
            lo = lo.max(a.min(b));
            hi = hi.min(a.max(b));
        }
        let qp = distribute(DistributionMethod::Qp, &w, &wrench, limits).unwrap();
        let tol = 1e-9 * limits.t_max;
        // Away from the boundary of feasibility (a segment of 1 µN or none by as much).
        if lo > hi + 1e-6 {
            prop_assert!(!qp.feasible);
        }
        if lo < hi - 1e-6 {
            prop_assert!(qp.feasible);
            // ‖T_p + τ n‖² is minimal at τ = −T_p·n (n unit, T_p ⟂ n: τ = 0), clamped.
            let tau = (-tp.dot(&n)).clamp(lo, hi);
            let expected = &tp + &n * tau;
            for i in 0..4 {
                prop_assert!((qp.tensions[i] - expected[i]).abs() <= tol,
                    "cable {}: {} vs {}", i + 1, qp.tensions[i], expected[i]);
            }
        }
    }

    /// m = D (no redundancy): every method gives W⁻¹ w.
    #[test]
    fn without_redundancy_every_method_is_the_inverse(
        (_, p, acc, mass, _) in strategy(),
    ) {
        let robot = robot(3, 1.5, 2.0, mass);
        let p = Vector::<3>::new(p[0], p[1], 0.2 * p[2]);
        let w = robot.structure_matrix(&p);
        let wrench = Vector::<3>::new(acc[0], acc[1], acc[2] + 9.81) * mass;
        let Some(exact) = w.square().and_then(|s| s.try_inverse()).map(|inv| inv * wrench) else {
            return Ok(());
        };
        let limits = TensionBox { t_min: -1e6, t_max: 1e6 };
        for method in DistributionMethod::ALL {
            let d = distribute(method, &w, &wrench, limits).unwrap();
            for i in 0..3 {
                prop_assert!((d.tensions[i] - exact[i]).abs() <= 1e-9 * exact.norm(),
                    "{}: {} vs {}", method.name(), d.tensions[i], exact[i]);
            }
        }
    }
}

/// The closed form is Pott's formula: the paper's two planar cables at mid-span, the middle of
/// the box shifted along W⁺ by the residual.
#[test]
fn closed_form_in_the_plane_is_potts() {
    let robot = Robot::<2>::new(
        &[Vector::<2>::new(0.0, 0.0), Vector::<2>::new(1.0, 0.0)],
        1.0,
        9.81,
    )
    .unwrap();
    let p = Vector::<2>::new(0.5, -0.1);
    let w = robot.structure_matrix(&p);
    let wrench = Vector::<2>::new(0.0, 9.81);
    let limits = TensionBox {
        t_min: 10.0,
        t_max: 400.0,
    };
    let d = distribute(DistributionMethod::ClosedForm, &w, &wrench, limits).unwrap();
    // Two cables in the plane: W is square, T = W⁻¹ w, each holding half the weight along u.
    let sin = 0.1 / (0.5f64.hypot(0.1));
    let expected = 9.81 / (2.0 * sin);
    assert!((d.tensions[0] - expected).abs() < 1e-12 * expected);
    assert!((d.tensions[1] - expected).abs() < 1e-12 * expected);
    assert!(d.feasible);
}

/// A wrench no box can hold is named infeasible by every method, with a negative margin; the
/// improved closed form says which cables it clamped, in order.
#[test]
fn an_impossible_wrench_is_infeasible_everywhere() {
    let robot = robot(4, 1.5, 2.0, 1.0);
    let p = Vector::<3>::new(0.0, 0.0, 0.5);
    let w = robot.structure_matrix(&p);
    let wrench = Vector::<3>::new(0.0, 0.0, 5000.0);
    let limits = TensionBox {
        t_min: 10.0,
        t_max: 70.0,
    };
    for method in DistributionMethod::ALL {
        let d = distribute(method, &w, &wrench, limits).unwrap();
        assert!(!d.feasible, "{}", method.name());
    }
    let d = distribute(DistributionMethod::ImprovedClosedForm, &w, &wrench, limits).unwrap();
    assert!(!d.clamped.is_empty());
    assert!(margin(&w, &wrench, limits).unwrap() < 0.0);
}

/// The case the proptest above once found: five cables, one on t_min, an ill-conditioned free
/// set whose Gram inverse left W T = w at 1.5e-10 N against a 1e-10 N tolerance; one step of
/// iterative refinement in the active-set enumeration takes it to 3e-12 N.
#[test]
fn an_ill_conditioned_free_set_still_balances() {
    let mass = 7.329690783446254;
    let robot = robot(5, 1.5, 2.0, mass);
    let p = Vector::<3>::new(-0.160457155443845, 0.09133843384223121, 0.6779932371600963);
    let w = robot.structure_matrix(&p);
    let wrench = Vector::<3>::new(0.7223305425063014, 0.0, -0.6600799543265027 + 9.81) * mass;
    let t_max = 947.966698394644;
    let limits = TensionBox {
        t_min: 0.05 * t_max,
        t_max,
    };
    let d = distribute(DistributionMethod::Qp, &w, &wrench, limits).unwrap();
    let t_norm = d.tensions.iter().map(|t| t * t).sum::<f64>().sqrt();
    let error = (w.force(&d.tensions) - wrench).norm();
    assert!(d.feasible);
    assert!(
        error <= balance_tolerance(wrench.norm(), t_norm),
        "‖WT − w‖ = {error:e}"
    );
}
