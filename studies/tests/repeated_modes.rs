//! The directions of modes that share an eigenvalue come from the eigenspace, not from the
//! eigen-solver's basis of it: any invertible mixing of a group's eigenvectors (what round-off
//! may hand back) gives the same directions and names. (The computed-torque loop's triples,
//! named x, y and z once each, are checked with the printer's other modes in print_study.rs.)

use cdpr_studies::repeated_modes::{Complex, axis_basis, groups};
use proptest::prelude::*;

/// Σ_j a_rj v_j for complex weights `a` (a row of the mixing matrix) over `vectors`.
fn mix(a: &[Complex], vectors: &[[Complex; 3]]) -> [Complex; 3] {
    let mut out = [(0.0, 0.0); 3];
    for (w, v) in a.iter().zip(vectors) {
        for (o, c) in out.iter_mut().zip(v) {
            o.0 += w.0 * c.0 - w.1 * c.1;
            o.1 += w.0 * c.1 + w.1 * c.0;
        }
    }
    out
}

/// |det| of a complex 2 × 2 or 3 × 3 matrix given by rows (the mixing must be invertible, and
/// well conditioned enough that the span stays the same to the 1e-6 the basis works to).
fn det_abs(rows: &[Vec<Complex>]) -> f64 {
    let mul = |a: Complex, b: Complex| (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0);
    let sub = |a: Complex, b: Complex| (a.0 - b.0, a.1 - b.1);
    let add = |a: Complex, b: Complex| (a.0 + b.0, a.1 + b.1);
    let d2 = |a: Complex, b: Complex, c: Complex, d: Complex| sub(mul(a, d), mul(b, c));
    let d = if rows.len() == 2 {
        d2(rows[0][0], rows[0][1], rows[1][0], rows[1][1])
    } else {
        let r = rows;
        let t0 = mul(r[0][0], d2(r[1][1], r[1][2], r[2][1], r[2][2]));
        let t1 = mul(r[0][1], d2(r[1][0], r[1][2], r[2][0], r[2][2]));
        let t2 = mul(r[0][2], d2(r[1][0], r[1][1], r[2][0], r[2][1]));
        add(sub(t0, t1), t2)
    };
    d.0.hypot(d.1)
}

fn complex_rows(n: usize, v: &[f64]) -> Vec<Vec<Complex>> {
    (0..n)
        .map(|r| {
            (0..n)
                .map(|c| (v[2 * (n * r + c)], v[2 * (n * r + c) + 1]))
                .collect()
        })
        .collect()
}

fn close(a: &[[Complex; 3]], b: &[[Complex; 3]], tol: f64) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(u, v)| {
            u.iter()
                .zip(v)
                .all(|(x, y)| (x.0 - y.0).abs() <= tol && (x.1 - y.1).abs() <= tol)
        })
}

const AXES: [[Complex; 3]; 3] = [
    [(1.0, 0.0), (0.0, 0.0), (0.0, 0.0)],
    [(0.0, 0.0), (1.0, 0.0), (0.0, 0.0)],
    [(0.0, 0.0), (0.0, 0.0), (1.0, 0.0)],
];

proptest! {
    /// A three-fold eigenspace whose effector motions span space (a controller with equal
    /// gains per axis): whatever basis the solver returns — any invertible complex mixing of
    /// the axes — the directions are the axes x, y, z themselves, to 1e-12 (round-off of a
    /// few Gram–Schmidt sweeps on a mixing with |det| ≥ 0.05).
    #[test]
    fn a_triple_spanning_space_is_named_by_the_axes(v in proptest::collection::vec(-1.0f64..1.0, 18)) {
        let rows = complex_rows(3, &v);
        prop_assume!(det_abs(&rows) > 0.05);
        let motions: Vec<[Complex; 3]> = rows.iter().map(|a| mix(a, &AXES)).collect();
        let basis = axis_basis(&motions);
        prop_assert!(close(&basis, &AXES, 1e-12), "{basis:?}");
    }

    /// A two-fold eigenspace of any plane (a symmetric robot's horizontal pair, or a tilted
    /// one): two mixings of one basis give the same directions to 1e-9, the axis the plane holds
    /// most of first.
    #[test]
    fn a_pair_is_named_by_its_plane_not_by_its_basis(
        plane in proptest::collection::vec(-1.0f64..1.0, 12),
        m1 in proptest::collection::vec(-1.0f64..1.0, 8),
        m2 in proptest::collection::vec(-1.0f64..1.0, 8),
    ) {
        let span: Vec<[Complex; 3]> = (0..2)
            .map(|r| std::array::from_fn(|k| (plane[6 * r + 2 * k], plane[6 * r + 2 * k + 1])))
            .collect();
        // Two independent vectors well apart (the plane is well defined).
        let gram = complex_rows(2, &[
            inner(&span[0], &span[0]).0, 0.0, inner(&span[0], &span[1]).0, inner(&span[0], &span[1]).1,
            inner(&span[1], &span[0]).0, inner(&span[1], &span[0]).1, inner(&span[1], &span[1]).0, 0.0,
        ]);
        prop_assume!(det_abs(&gram) > 0.05);
        let (a1, a2) = (complex_rows(2, &m1), complex_rows(2, &m2));
        prop_assume!(det_abs(&a1) > 0.05 && det_abs(&a2) > 0.05);
        let first = axis_basis(&a1.iter().map(|a| mix(a, &span)).collect::<Vec<_>>());
        let second = axis_basis(&a2.iter().map(|a| mix(a, &span)).collect::<Vec<_>>());
        prop_assert_eq!(first.len(), 2);
        prop_assert!(close(&first, &second, 1e-9), "{first:?} against {second:?}");
    }
}

/// u^H v.
fn inner(u: &[Complex; 3], v: &[Complex; 3]) -> Complex {
    u.iter().zip(v).fold((0.0, 0.0), |s, (a, b)| {
        (s.0 + a.0 * b.0 + a.1 * b.1, s.1 + a.0 * b.1 - a.1 * b.0)
    })
}

/// Eigenvalues one within 1e-6 of |λ| group together, in the list's order; others stay apart.
#[test]
fn groups_collect_the_modes_of_one_eigenvalue() {
    let lambdas = [
        (-1.0, 100.0),
        (-2.0, 50.0),
        (-1.0, 100.0 * (1.0 + 1e-9)),
        (-1.0, 100.0 * (1.0 + 1e-3)),
        (-2.0 + 1e-12, 50.0),
    ];
    assert_eq!(groups(&lambdas), vec![vec![0, 2], vec![1, 4], vec![3]]);
}
