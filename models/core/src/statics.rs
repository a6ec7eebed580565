//! Newton's method for the static equilibria every model needs (MODELS.md §2): the service that
//! turns a model's force residual into its initial state.
//!
//! Convergence follows MODELS.md §2: the largest force residual below 1e-7 N and the last update of
//! every length unknown below 1e-12 m. The round-off floor of the residual is stiffness × ulp of a
//! coordinate (1e-9 … 1e-8 N on the paper's meshes), so nothing stricter is asked; on fine meshes,
//! where the floor exceeds 1e-7 N (N = 1000: up to 3.2e-7 N), the problem's declared round-off
//! is the tolerance.

use crate::integrate::sparse::IterationMatrix;
use crate::second_order::{CBRT_EPSILON, ColouredDifferences, max_abs};
use faer::Mat;
use faer::prelude::Solve;

/// A square static problem R(u) = 0: unknowns u (lengths first, then forces), residual in N.
pub trait StaticProblem {
    /// Number of unknowns (= number of residual equations).
    fn dimension(&self) -> usize;
    /// How many leading unknowns are lengths [m] (the update criterion applies to them).
    fn length_unknowns(&self) -> usize;
    /// Residual forces R(u) [N].
    fn residual(&mut self, unknowns: &[f64], residual: &mut [f64]);

    /// Finite-difference scale of unknown `i`: the step is ε^(1/3)·scale ≈ 6e-6·scale. It must be
    /// small against the residual's features (a tension-only spring's stretch T/k: a step beyond
    /// it goes slack and corrupts the column) and large against its round-off. Default 1.
    fn scale(&self, _i: usize) -> f64 {
        1.0
    }

    /// The (row, col) entries of ∂R/∂u that may be non-zero, if the problem knows them: the
    /// Jacobian then comes from coloured differences (a few residuals per iteration instead of
    /// 2n) and is solved by the sparse LU of the implicit integrator (O(n) for a cable chain
    /// instead of the dense O(n³), which took minutes at N = 1000). None: dense.
    fn pattern(&self) -> Option<Vec<(usize, usize)>> {
        None
    }

    /// Round-off level of max |R| [N] near the last evaluated unknowns (0 if negligible): the
    /// residual tolerance is not set below it (fine meshes: up to 3.2e-7 N at N = 1000, see
    /// [`crate::second_order::spring_round_off`]).
    fn residual_round_off(&self) -> f64 {
        0.0
    }

    /// The largest fraction (≤ 1) of the Newton step `delta` from `unknowns` that keeps the
    /// residual smooth along it, where the problem has kinks (a cable bending over a point
    /// pulley): Newton's linear model knows nothing beyond a kink and can jump onto it, where no
    /// Jacobian steers. Default 1 (smooth everywhere).
    fn step_limit(&mut self, _unknowns: &[f64], _delta: &[f64]) -> f64 {
        1.0
    }

    /// ∂R/∂u at `unknowns` in the order of [`Self::pattern`], where the problem computes it
    /// itself; false: coloured differences do. Why: a dense row needs one colour per unknown it
    /// touches (the FE model's l rows: O(n²) per Jacobian, 2.7 s at N = 1000), while the
    /// elements' own differences cost O(n).
    fn jacobian(&mut self, _unknowns: &[f64], _values: &mut [f64]) -> bool {
        false
    }
}

/// A static problem's Jacobian pattern, from [`pattern_from_dynamics`].
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct StaticPattern {
    /// (equation, unknown): the dynamic pattern's entries whose row and column both map, in its
    /// order, then the column of the PID force F0.
    pub entries: Vec<(usize, usize)>,
    /// The index in the dynamic pattern of each mapped entry (the first `kept.len()` of
    /// `entries`): a problem whose Jacobian comes from the model's matrix values (in the dynamic
    /// order) takes them through these, without repeating the mapping.
    pub kept: Vec<usize>,
}

/// A static problem's Jacobian pattern from its model's second-order pattern (`dynamic`, over q):
/// rows and columns of q mapped to the problem's equations and unknowns (None: not one), and the
/// column of the PID force F0 (unknown `force`) in the rows of q where the commanded tensions act.
pub fn pattern_from_dynamics(
    dynamic: &[(usize, usize)],
    row_of: impl Fn(usize) -> Option<usize>,
    col_of: impl Fn(usize) -> Option<usize>,
    tension_rows: &[usize],
    force: usize,
) -> StaticPattern {
    let (kept, mut entries): (Vec<usize>, Vec<(usize, usize)>) = dynamic
        .iter()
        .enumerate()
        .filter_map(|(p, &(r, c))| Some((p, (row_of(r)?, col_of(c)?))))
        .unzip();
    entries.extend(
        tension_rows
            .iter()
            .filter_map(|&r| Some((row_of(r)?, force))),
    );
    StaticPattern { entries, kept }
}

/// The Newton direction's linear algebra: a dense LU of the full finite-difference Jacobian, or
/// coloured differences over the problem's pattern and a sparse LU (symbolic analysis once).
enum Linear {
    Dense {
        jacobian: Mat<f64>,
        rhs: Mat<f64>,
        plus: Vec<f64>,
        minus: Vec<f64>,
    },
    Sparse {
        /// Built at the first Jacobian the problem does not compute itself (the colouring of a
        /// pattern with dense rows is itself O(n²)).
        differences: Option<ColouredDifferences>,
        pattern: Vec<(usize, usize)>,
        matrix: Box<IterationMatrix>,
        values: Vec<f64>,
        steps: Vec<f64>,
    },
}

impl Linear {
    fn new<P: StaticProblem>(problem: &P, n: usize) -> Option<Self> {
        Some(match problem.pattern() {
            Some(pattern) => Self::Sparse {
                differences: None,
                matrix: Box::new(IterationMatrix::new(n, &pattern).ok()?),
                values: vec![0.0; pattern.len()],
                steps: (0..n).map(|j| CBRT_EPSILON * problem.scale(j)).collect(),
                pattern,
            },
            None => Self::Dense {
                jacobian: Mat::zeros(n, n),
                rhs: Mat::zeros(n, 1),
                plus: vec![0.0; n],
                minus: vec![0.0; n],
            },
        })
    }

    /// The Newton step −J⁻¹ r at `unknowns` into `r` (overwritten); false if J is singular.
    fn newton_step<P: StaticProblem>(
        &mut self,
        problem: &mut P,
        unknowns: &mut [f64],
        r: &mut [f64],
    ) -> bool {
        let n = r.len();
        match self {
            Self::Dense {
                jacobian,
                rhs,
                plus,
                minus,
            } => {
                for j in 0..n {
                    // Not relative to |u_j|: a coordinate's distance from the origin says
                    // nothing about the residual's features (stored lumped nodes sit 1.5 m out
                    // on 8e-6 m stretches).
                    let h = CBRT_EPSILON * problem.scale(j);
                    let saved = unknowns[j];
                    unknowns[j] = saved + h;
                    problem.residual(unknowns, plus);
                    unknowns[j] = saved - h;
                    problem.residual(unknowns, minus);
                    unknowns[j] = saved;
                    for i in 0..n {
                        jacobian[(i, j)] = (plus[i] - minus[i]) / (2.0 * h);
                    }
                }
                for i in 0..n {
                    rhs[(i, 0)] = -r[i];
                }
                let delta = jacobian.partial_piv_lu().solve(&*rhs);
                for i in 0..n {
                    r[i] = delta[(i, 0)];
                }
            }
            Self::Sparse {
                differences,
                pattern,
                matrix,
                values,
                steps,
            } => {
                if !problem.jacobian(unknowns, values) {
                    let n = unknowns.len();
                    differences
                        .get_or_insert_with(|| ColouredDifferences::new(n, pattern))
                        .jacobian(
                            &mut |u, out| problem.residual(u, out),
                            unknowns,
                            steps,
                            values,
                        );
                }
                if matrix.factorise(values).is_err() {
                    return false;
                }
                matrix.solve_in_place(r);
                r.iter_mut().for_each(|d| *d = -*d);
            }
        }
        r.iter().all(|d| d.is_finite())
    }
}

/// Settings of [`solve`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonOptions {
    /// Largest admissible force residual [N].
    pub residual_tol: f64,
    /// Largest admissible last update of a length unknown [m].
    pub update_tol: f64,
    /// Iteration limit.
    pub max_iterations: usize,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        Self {
            residual_tol: 1e-7,
            update_tol: 1e-12,
            max_iterations: 50,
        }
    }
}

/// Why Newton failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NewtonError {
    #[error(
        "no convergence after {iterations} iterations (largest residual {residual:e} N, last update {update:e} m)"
    )]
    NoConvergence {
        iterations: usize,
        residual: f64,
        update: f64,
    },
    #[error("singular or non-finite Jacobian at iteration {iteration}")]
    Singular { iteration: usize },
    #[error("non-finite residual at iteration {iteration}")]
    NonFinite { iteration: usize },
    #[error(
        "no step along the Newton direction reduces the residual at iteration {iteration} (largest residual {residual:e} N)"
    )]
    LineSearch { iteration: usize, residual: f64 },
}

/// Result of a converged Newton solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonReport {
    pub iterations: usize,
    /// Largest residual at the solution [N].
    pub residual: f64,
}

/// Step halvings tried before the Newton direction is declared useless (2^-40 ≈ 1e-12).
const MAX_HALVINGS: usize = 40;

fn norm2(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Solves R(u) = 0 from the guess in `unknowns` (overwritten with the solution), with a central
/// finite-difference Jacobian (step ε^(1/3)·[`StaticProblem::scale`]), a dense LU (faer) or,
/// where the problem declares its [`StaticProblem::pattern`], coloured differences and a sparse
/// LU, and a backtracking line search from [`StaticProblem::step_limit`]. The Jacobian only steers the iteration; the solution's accuracy is
/// set by the residual alone.
pub fn solve<P: StaticProblem>(
    problem: &mut P,
    unknowns: &mut [f64],
    opts: NewtonOptions,
) -> Result<NewtonReport, NewtonError> {
    let n = problem.dimension();
    assert_eq!(unknowns.len(), n, "unknown vector length");
    let n_len = problem.length_unknowns().min(n);
    let mut r = vec![0.0; n];
    let mut rp = vec![0.0; n];
    let mut delta = vec![0.0; n];
    let mut linear = Linear::new(problem, n).ok_or(NewtonError::Singular { iteration: 0 })?;
    let mut trial = vec![0.0; n];
    let mut update = f64::INFINITY;
    let mut residual = f64::INFINITY;
    for iteration in 0..=opts.max_iterations {
        problem.residual(unknowns, &mut r);
        residual = max_abs(&r);
        if !residual.is_finite() {
            return Err(NewtonError::NonFinite { iteration });
        }
        let residual_tol = opts.residual_tol.max(problem.residual_round_off());
        if residual < residual_tol && update < opts.update_tol {
            return Ok(NewtonReport {
                iterations: iteration,
                residual,
            });
        }
        if iteration == opts.max_iterations {
            break;
        }
        delta.copy_from_slice(&r);
        if !linear.newton_step(problem, unknowns, &mut delta) {
            return Err(NewtonError::Singular { iteration });
        }
        // Backtracking from the problem's step limit: halve the step until the residual's 2-norm
        // decreases (or is already below the tolerance, where round-off makes "decrease"
        // meaningless). Near the solution the full step is taken (unless the limit cuts it), so
        // quadratic convergence and the solution are unchanged.
        let norm = norm2(&r);
        let mut lambda = problem.step_limit(unknowns, &delta).clamp(0.0, 1.0);
        let mut accepted = false;
        for _ in 0..MAX_HALVINGS {
            for i in 0..n {
                trial[i] = unknowns[i] + lambda * delta[i];
            }
            problem.residual(&trial, &mut rp);
            let trial_norm = norm2(&rp);
            if trial_norm.is_finite() && (trial_norm < norm || max_abs(&rp) < residual_tol) {
                accepted = true;
                break;
            }
            lambda *= 0.5;
        }
        if !accepted {
            return Err(NewtonError::LineSearch {
                iteration,
                residual,
            });
        }
        update = 0.0;
        for i in 0..n {
            let step = trial[i] - unknowns[i];
            unknowns[i] = trial[i];
            if i < n_len {
                update = update.max(step.abs());
            }
        }
        if n_len == 0 {
            update = 0.0;
        }
    }
    Err(NewtonError::NoConvergence {
        iterations: opts.max_iterations,
        residual,
        update,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

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
}
