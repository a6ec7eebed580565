//! The iteration matrix's sparse LU against dense LU: patterns with duplicates, a dense border,
//! chains swept from both ends, refactorisation on reused pivots, singular and malformed input.

use cdpr_numerics::sparse::{IterationMatrix, SparseError};
use faer::Mat;
use faer::linalg::solvers::Solve;

/// A tridiagonal system with a duplicate entry against its known solution.
#[test]
fn solves_a_tridiagonal_system_with_summed_duplicates() {
    let n = 6;
    let mut entries = Vec::new();
    let mut values = Vec::new();
    for i in 0..n {
        entries.push((i, i));
        values.push(2.0);
        entries.push((i, i)); // duplicate: summed to 4
        values.push(2.0);
        if i + 1 < n {
            entries.push((i, i + 1));
            values.push(-1.0);
            entries.push((i + 1, i));
            values.push(-1.5);
        }
    }
    let mut s = IterationMatrix::new(n, &entries).unwrap();
    assert!(s.border().is_empty());
    s.factorise(&values).unwrap();
    let x: Vec<f64> = (0..n).map(|i| 1.0 + i as f64).collect();
    let mut b: Vec<f64> = (0..n)
        .map(|i| {
            4.0 * x[i]
                - if i + 1 < n { x[i + 1] } else { 0.0 }
                - if i > 0 { 1.5 * x[i - 1] } else { 0.0 }
        })
        .collect();
    s.solve_in_place(&mut b);
    for i in 0..n {
        // Well-conditioned 6 × 6: round-off only.
        assert!((b[i] - x[i]).abs() < 1e-13, "{i}: {} vs {}", b[i], x[i]);
    }
}

/// An arrow matrix (tridiagonal plus two dense rows and columns in the middle of the
/// numbering, as the FE model's l rows): the border is found and the solution matches a dense
/// LU of the same matrix.
#[test]
fn arrow_matrix_through_the_border_matches_dense_lu() {
    let n = 200;
    let dense_at = [57, 131];
    let mut m = TestMatrix::new(n);
    let mut push = |r: usize, c: usize, v: f64| m.push(r, c, v);
    for i in 0..n {
        push(i, i, 4.0 + (i % 7) as f64);
        if i + 1 < n {
            push(i, i + 1, -1.0 + 0.01 * i as f64);
            push(i + 1, i, -1.2);
        }
    }
    for (k, &d) in dense_at.iter().enumerate() {
        for j in 0..n {
            if j != d {
                push(d, j, 0.3 * ((j + k) as f64).sin());
                push(j, d, 0.2 * ((j * (k + 2)) as f64).cos());
            }
        }
    }
    let mut s = IterationMatrix::new(n, &m.entries).unwrap();
    assert_eq!(s.border(), &dense_at);
    s.factorise(&m.values).unwrap();
    let rhs: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
    for (i, (x, reference)) in solved_and_dense(&mut s, &m.full, &rhs)
        .into_iter()
        .enumerate()
    {
        // Diagonally dominant interior, O(1) entries: round-off of a 200 × 200 solve.
        assert!((x - reference).abs() < 1e-12, "{i}: {x} vs {reference}");
    }
    // Every entry moved by up to 5 %: a refactorisation on the first pivots (the diagonal
    // stays dominant), whose A⁻¹B and Schur complement are recomputed from the new factors.
    let mut moved = TestMatrix::new(n);
    for (k, (&(r, c), &v)) in m.entries.iter().zip(&m.values).enumerate() {
        moved.push(r, c, v * (1.0 + 0.05 * (k as f64 * 0.7).sin()));
    }
    s.factorise(&moved.values).unwrap();
    assert_eq!(s.pivotings(), 1);
    for (i, (x, reference)) in solved_and_dense(&mut s, &moved.full, &rhs)
        .into_iter()
        .enumerate()
    {
        assert!(
            (x - reference).abs() < 1e-12,
            "refactorised {i}: {x} vs {reference}"
        );
    }
}

/// Two chains of `m1` and `m2` unknowns (bandwidth 2 each, as x and z of a node couple to
/// both of the next node's) closed into a loop through one more unknown e (the last), which
/// reads both chains' far ends and is read by them: the lumped model's shape. Returns the
/// matrix and e.
fn loop_of_two_chains(m1: usize, m2: usize) -> (TestMatrix, usize) {
    let e = m1 + m2;
    let n = e + 1;
    let mut matrix = TestMatrix::new(n);
    let mut push = |r: usize, c: usize, v: f64| matrix.push(r, c, v);
    for i in 0..n {
        push(i, i, 4.0 + (i % 5) as f64);
    }
    for chain in [0..m1, m1..e] {
        for i in chain.clone() {
            for j in [i + 1, i + 2].into_iter().filter(|j| chain.contains(j)) {
                push(i, j, -0.5 - 0.01 * i as f64);
                push(j, i, -0.6);
            }
        }
        for last in [chain.end - 2, chain.end - 1] {
            push(last, e, -0.9);
            push(e, last, -1.3);
        }
        // Feedback: the chain's far end reads e, and e reads it.
        push(chain.start, e, 0.05);
        push(e, chain.start, 0.04);
    }
    (matrix, e)
}

/// A solve that overflows leaves non-finite values behind; with an odd interior (two chains
/// of 50 and 51) the paired sweeps have a padding unknown, which must not carry them into
/// the next solve: after a right-hand side of f64::MAX, an ordinary one must solve as a
/// dense LU does (1e-12, as in the loop test).
#[test]
fn an_overflowing_solve_does_not_poison_the_next() {
    let (matrix, e) = loop_of_two_chains(50, 51);
    let n = e + 1;
    let mut s = IterationMatrix::with_coupled(n, &matrix.entries, &[e]).unwrap();
    s.factorise(&matrix.values).unwrap();
    assert!(s.solve_cost().paired && (n - s.border().len()) % 2 == 1);
    let mut huge = vec![f64::MAX; n];
    s.solve_in_place(&mut huge);
    assert!(
        huge.iter().any(|v| !v.is_finite()),
        "the test must overflow"
    );
    let rhs: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).cos()).collect();
    for (i, (x, reference)) in solved_and_dense(&mut s, &matrix.full, &rhs)
        .into_iter()
        .enumerate()
    {
        assert!((x - reference).abs() < 1e-12, "{i}: {x} vs {reference}");
    }
}

/// Two chains joined at one end by an "effector" e that also couples to both far ends (the
/// controller's feedback into the reel rows): a loop. Whichever layout the first
/// factorisation keeps (e in the border or not), the sweeps run from both ends at once, and
/// the solve matches a dense LU.
#[test]
fn loop_of_two_chains_is_swept_from_both_ends() {
    let m = 50;
    let (matrix, e) = loop_of_two_chains(m, m);
    let n = e + 1;
    let mut s = IterationMatrix::with_coupled(n, &matrix.entries, &[e]).unwrap();
    s.factorise(&matrix.values).unwrap();
    // One front along the 2m-long chain would chain about 2 × 2m unknowns through the two
    // sweeps; two fronts side by side, about 2 × m. Side by side, the factors' entries sit
    // at even distances, so the sweeps run in pairs: m pairs per sweep, plus one link for
    // each entry outside the band where the fronts meet (2 chains × bandwidth 2 × 2
    // triangles at most).
    let cost = s.solve_cost();
    assert!(cost.paired, "{cost:?}");
    assert!(cost.chain <= 2 * m + 8, "{cost:?}");
    let rhs: Vec<f64> = (0..n).map(|i| (i as f64 * 0.53).sin()).collect();
    for (i, (x, reference)) in solved_and_dense(&mut s, &matrix.full, &rhs)
        .into_iter()
        .enumerate()
    {
        // Diagonally dominant, O(1) entries: round-off of a 101 × 101 solve.
        assert!((x - reference).abs() < 1e-12, "{i}: {x} vs {reference}");
    }
    assert!(matches!(
        IterationMatrix::with_coupled(3, &[(0, 1)], &[3]),
        Err(SparseError::Coupled { index: 3, n: 3 })
    ));
}

/// Small diagonal, O(1) neighbours: partial pivoting swaps rows, so the solve's
/// gather (row pivots) and scatter (column ordering) are both exercised.
#[test]
fn pivoted_banded_system_matches_dense_lu() {
    let n = 60;
    let m = drifted_banded(n, 0.0);
    let mut s = IterationMatrix::new(n, &m.entries).unwrap();
    s.factorise(&m.values).unwrap();
    assert!(
        s.rows_exchanged() > 0,
        "the test matrix must make the LU pivot"
    );
    let rhs: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).cos()).collect();
    for (i, (x, reference)) in solved_and_dense(&mut s, &m.full, &rhs)
        .into_iter()
        .enumerate()
    {
        // Both are backward-stable LUs of a 60 × 60 matrix with condition ≲ 1e3: agreement to
        // 1e-10 leaves room for that amplification of round-off.
        assert!(
            (x - reference).abs() < 1e-10 * (1.0 + reference.abs()),
            "{i}: {x} vs {reference}"
        );
    }
}

/// A banded matrix (bandwidth 3) with a small diagonal under O(1) neighbours, so that partial
/// pivoting swaps rows, every entry scaled by 1 + `drift`·sin(…): what an aging iteration
/// matrix looks like.
fn drifted_banded(n: usize, drift: f64) -> TestMatrix {
    let mut m = TestMatrix::new(n);
    for i in 0..n {
        for j in i.saturating_sub(3)..(i + 4).min(n) {
            let v = if i == j {
                1e-3 * (1.0 + (i % 5) as f64)
            } else {
                ((7 * i + 3 * j) as f64 * 0.61).sin()
            };
            m.push(i, j, v * (1.0 + drift * ((i * 31 + j * 17) as f64).sin()));
        }
    }
    m
}

/// ‖A x − b‖∞ / (‖A‖∞ ‖x‖∞): what a backward-stable solve keeps at a small multiple of n ε
/// however ill-conditioned A is.
fn backward_error(full: &Mat<f64>, x: &[f64], b: &[f64]) -> f64 {
    let n = x.len();
    let (mut residual, mut norm) = (0.0f64, 0.0f64);
    for i in 0..n {
        let (mut r, mut row) = (-b[i], 0.0);
        for j in 0..n {
            r += full[(i, j)] * x[j];
            row += full[(i, j)].abs();
        }
        residual = residual.max(r.abs());
        norm = norm.max(row);
    }
    residual / (norm * x.iter().fold(0.0f64, |m, v| m.max(v.abs())))
}

proptest::proptest! {
    /// Refactorising with the first factorisation's pivots is backward stable: residual below
    /// 1e-14 ‖A‖‖x‖, i.e. within ~10 n ε for n = 60 (measured ~2e-16, as faer's own
    /// factorisation and a dense LU). Drifts of up to 1e-3 leave every pivot above the
    /// threshold, so none is chosen afresh (at a drift of 1e-2 one was: this matrix's pivots
    /// are off-diagonal O(1) entries of similar size).
    #[test]
    fn refactorisation_with_reused_pivots_is_backward_stable(
        drifts in proptest::collection::vec(-1e-3f64..1e-3, 1..4),
    ) {
        let n = 60;
        let first = drifted_banded(n, 0.0);
        let mut s = IterationMatrix::new(n, &first.entries).unwrap();
        s.factorise(&first.values).unwrap();
        let rhs: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).cos()).collect();
        for &drift in &drifts {
            let m = drifted_banded(n, drift);
            s.factorise(&m.values).unwrap();
            let mut x = rhs.clone();
            s.solve_in_place(&mut x);
            let error = backward_error(&m.full, &x, &rhs);
            proptest::prop_assert!(error < 1e-14, "backward error {:e}", error);
        }
        proptest::prop_assert_eq!(s.pivotings(), 1);
    }
}

/// A reused pivot that would fall below the threshold is refused and the LU pivots afresh:
/// diagonally dominant first (diagonal pivots), then a tiny diagonal under unit neighbours.
#[test]
fn refactorisation_refuses_a_small_pivot_and_pivots_afresh() {
    let n = 12;
    let matrix = |diagonal: f64| {
        let mut m = TestMatrix::new(n);
        for i in 0..n {
            m.push(i, i, diagonal * (1.0 + 0.1 * i as f64));
            if i + 1 < n {
                m.push(i, i + 1, 1.0);
                m.push(i + 1, i, -1.0 + 0.05 * i as f64);
            }
        }
        m
    };
    let first = matrix(4.0);
    let mut s = IterationMatrix::new(n, &first.entries).unwrap();
    s.factorise(&first.values).unwrap();
    assert_eq!(s.pivotings(), 1);
    let second = matrix(1e-4);
    s.factorise(&second.values).unwrap();
    assert_eq!(s.pivotings(), 2, "the diagonal pivots fail the threshold");
    let rhs: Vec<f64> = (0..n).map(|i| 1.0 + (i as f64).sin()).collect();
    for (x, reference) in solved_and_dense(&mut s, &second.full, &rhs) {
        // Well-conditioned 12 × 12 (|det| ≈ 1 from the off-diagonals): round-off only.
        assert!(
            (x - reference).abs() < 1e-12 * (1.0 + reference.abs()),
            "{x} vs {reference}"
        );
    }
    // Back to dominance: whether the off-diagonal pivots pass the threshold after
    // elimination or not, the solve is backward stable.
    s.factorise(&first.values).unwrap();
    let mut x = rhs.clone();
    s.solve_in_place(&mut x);
    assert!(backward_error(&first.full, &x, &rhs) < 1e-15);
}

/// A numerically singular matrix (a zero column; faer takes the zero pivot without saying
/// so) is an error, not a solve full of infinities.
#[test]
fn a_singular_matrix_is_an_error() {
    let n = 5;
    let mut m = TestMatrix::new(n);
    for i in 0..n {
        for j in i.saturating_sub(1)..(i + 2).min(n) {
            let v = if j == 2 {
                0.0
            } else if i == j {
                4.0
            } else {
                -1.0
            };
            m.push(i, j, v);
        }
    }
    let mut s = IterationMatrix::new(n, &m.entries).unwrap();
    assert!(matches!(
        s.factorise(&m.values),
        Err(SparseError::Factorisation(_))
    ));
}

/// A test matrix entry by entry: the pattern and values as a system declares them
/// (duplicates allowed), and the same matrix dense for the reference LU.
struct TestMatrix {
    entries: Vec<(usize, usize)>,
    values: Vec<f64>,
    full: Mat<f64>,
}

impl TestMatrix {
    fn new(n: usize) -> Self {
        Self {
            entries: Vec::new(),
            values: Vec::new(),
            full: Mat::zeros(n, n),
        }
    }

    fn push(&mut self, row: usize, col: usize, value: f64) {
        self.entries.push((row, col));
        self.values.push(value);
        self.full[(row, col)] += value;
    }
}

/// (S⁻¹ rhs by the factorised `s`, the same by a dense LU of `full`) per entry.
fn solved_and_dense(s: &mut IterationMatrix, full: &Mat<f64>, rhs: &[f64]) -> Vec<(f64, f64)> {
    let mut x = rhs.to_vec();
    s.solve_in_place(&mut x);
    let reference = full
        .partial_piv_lu()
        .solve(Mat::from_fn(rhs.len(), 1, |i, _| rhs[i]));
    x.into_iter()
        .enumerate()
        .map(|(i, x)| (x, reference[(i, 0)]))
        .collect()
}

/// Tiny systems whose coupled unknowns would leave no interior keep the border-free layout
/// and still solve (no empty interior reaches the Schur step).
#[test]
fn coupled_unknowns_never_empty_the_interior() {
    for (n, coupled) in [(1, vec![0]), (2, vec![0, 1]), (2, vec![1])] {
        let mut m = TestMatrix::new(n);
        for i in 0..n {
            m.push(i, i, 3.0 + i as f64);
            if i + 1 < n {
                m.push(i, i + 1, 1.0);
                m.push(i + 1, i, -0.5);
            }
        }
        let mut s = IterationMatrix::with_coupled(n, &m.entries, &coupled).unwrap();
        s.factorise(&m.values).unwrap();
        assert!(s.border().len() < n, "n = {n}: border {:?}", s.border());
        let rhs: Vec<f64> = (0..n).map(|i| 1.0 + i as f64).collect();
        for (x, reference) in solved_and_dense(&mut s, &m.full, &rhs) {
            assert!((x - reference).abs() < 1e-14, "n = {n}: {x} vs {reference}");
        }
    }
}

#[test]
fn rejects_entries_outside_the_matrix() {
    assert!(matches!(
        IterationMatrix::new(3, &[(0, 3)]),
        Err(SparseError::Pattern {
            row: 0,
            col: 3,
            n: 3
        })
    ));
}
