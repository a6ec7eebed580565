//! Newton's method for the static equilibria every model needs (MODELS.md §2): the service that
//! turns a model's force residual into its initial state.
//!
//! Convergence follows MODELS.md §2: the largest force residual below 1e-7 N and the last update of
//! every length unknown below 1e-12 m. The round-off floor of the residual is stiffness × ulp of a
//! coordinate (1e-9 … 1e-8 N on the paper's meshes), so nothing stricter is asked; on fine meshes,
//! where the floor exceeds 1e-7 N (N = 1000: up to 3.2e-7 N), the problem's declared round-off
//! is the tolerance.

use crate::differences::{CBRT_EPSILON, ColouredDifferences};
use crate::norms::max_abs;
use crate::sparse::IterationMatrix;
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
    /// `cdpr_core::second_order::spring_round_off`).
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

    /// Indices i (row i, unknown i) the sparse LU may also eliminate through its dense border
    /// ([`IterationMatrix::with_coupled`]): where the rows and unknowns that couple the chains
    /// are not each other's partners, an interior without them can be structurally singular
    /// although the whole is not (the spatial FE's δw columns reach only the reel rows).
    fn coupled(&self) -> Vec<usize> {
        Vec::new()
    }
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
                matrix: Box::new(
                    IterationMatrix::with_coupled(n, &pattern, &problem.coupled()).ok()?,
                ),
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
