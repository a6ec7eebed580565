//! Newton's method on small problems with known roots: dense and sparse Jacobians agree, the
//! convergence is quadratic, and a problem's step limit keeps every iterate on its side of a kink.

use cdpr_numerics::newton::*;

/// Two springs in series holding a weight: an exactly solvable nonlinear-free check plus a
/// nonlinear one (x³ + x − 2 = 0, root 1).
struct Cubic;
impl StaticProblem for Cubic {
    fn dimension(&self) -> usize {
        2
    }
    fn length_unknowns(&self) -> usize {
        1
    }
    fn residual(&mut self, u: &[f64], r: &mut [f64]) {
        r[0] = u[0].powi(3) + u[0] - 2.0;
        r[1] = 3.0 * u[1] - 6.0 * u[0];
    }
}

/// A nonlinear chain, k (u_{i+1} − 2u_i + u_{i−1}) − u_i³ + f_i = 0 with fixed ends, solved
/// with the dense Jacobian and with the declared tridiagonal pattern: the two paths must
/// reach the same root (1e-12: both converge to the 1e-7 N residual with quadratic
/// convergence, whose last step leaves ~1e-14), the sparse one with 2 × 3 residuals per
/// Jacobian instead of 2n.
struct Chain {
    n: usize,
    sparse: bool,
    evaluations: usize,
}
impl StaticProblem for Chain {
    fn dimension(&self) -> usize {
        self.n
    }
    fn length_unknowns(&self) -> usize {
        self.n
    }
    fn residual(&mut self, u: &[f64], r: &mut [f64]) {
        self.evaluations += 1;
        let k = 50.0;
        for i in 0..self.n {
            let left = if i > 0 { u[i - 1] } else { 0.0 };
            let right = if i + 1 < self.n { u[i + 1] } else { 0.0 };
            r[i] = k * (right - 2.0 * u[i] + left) - u[i].powi(3) + (i as f64 * 0.3).sin();
        }
    }
    fn pattern(&self) -> Option<Vec<(usize, usize)>> {
        self.sparse.then(|| {
            (0..self.n)
                .flat_map(|i| (i.saturating_sub(1)..(i + 2).min(self.n)).map(move |j| (i, j)))
                .collect()
        })
    }
}

#[test]
fn sparse_and_dense_jacobians_reach_the_same_root() {
    let n = 60;
    let mut roots = Vec::new();
    let mut evaluations = Vec::new();
    for sparse in [false, true] {
        let mut chain = Chain {
            n,
            sparse,
            evaluations: 0,
        };
        let mut u = vec![0.0; n];
        let report = solve(&mut chain, &mut u, NewtonOptions::default()).unwrap();
        assert!(report.residual < 1e-7, "{report:?}");
        roots.push(u);
        evaluations.push(chain.evaluations);
    }
    for (i, (dense, sparse)) in roots[0].iter().zip(&roots[1]).enumerate() {
        assert!((dense - sparse).abs() < 1e-12, "{i}: {dense} vs {sparse}");
    }
    assert!(evaluations[1] * 5 < evaluations[0], "{evaluations:?}");
}

#[test]
fn converges_quadratically_to_the_root() {
    let mut u = [3.0, 0.0];
    let report = solve(&mut Cubic, &mut u, NewtonOptions::default()).unwrap();
    assert!(
        (u[0] - 1.0).abs() < 1e-14 && (u[1] - 2.0).abs() < 1e-13,
        "{u:?}"
    );
    assert!(report.iterations < 12, "{report:?}");
}

/// R(u) = u + 1, root −1, with a step limit that keeps 1/10 of the distance to u = 0 (as a
/// node keeps to its side of a pulley's kink). Without the limit one Newton step from u = 1
/// lands on the root; with it the solver must never evaluate at u ≤ 0 and must end in an
/// error near u = 0, not at the root across the boundary.
struct Bounded {
    limited: bool,
    evaluated: Vec<f64>,
}
impl StaticProblem for Bounded {
    fn dimension(&self) -> usize {
        1
    }
    fn length_unknowns(&self) -> usize {
        1
    }
    fn residual(&mut self, u: &[f64], r: &mut [f64]) {
        self.evaluated.push(u[0]);
        r[0] = u[0] + 1.0;
    }
    /// Exact, so that every evaluation is an iterate or a line-search trial.
    fn pattern(&self) -> Option<Vec<(usize, usize)>> {
        Some(vec![(0, 0)])
    }
    fn jacobian(&mut self, _u: &[f64], values: &mut [f64]) -> bool {
        values[0] = 1.0;
        true
    }
    fn step_limit(&mut self, u: &[f64], delta: &[f64]) -> f64 {
        if self.limited && -delta[0] > 0.9 * u[0] {
            0.9 * u[0] / -delta[0]
        } else {
            1.0
        }
    }
}

#[test]
fn step_limit_keeps_every_iterate_on_its_side() {
    let mut free = Bounded {
        limited: false,
        evaluated: Vec::new(),
    };
    let mut u = [1.0];
    solve(&mut free, &mut u, NewtonOptions::default()).unwrap();
    assert_eq!(u[0], -1.0);

    let mut bounded = Bounded {
        limited: true,
        evaluated: Vec::new(),
    };
    let mut u = [1.0];
    assert!(solve(&mut bounded, &mut u, NewtonOptions::default()).is_err());
    assert!(bounded.evaluated.iter().all(|&v| v > 0.0));
    // Each step keeps 1/10 of the distance, until the residual's change (u itself) drops
    // below ulp(1) and the line search stops: u ≈ 1e-16.
    assert!(u[0] > 0.0 && u[0] < 1e-12, "u = {}", u[0]);
}
