//! A run's cost as `metrics.json` keys: its solver's counters, the honest measure of what a run
//! took (wall times vary with the machine, these do not).

use cdpr_bench::numerics::SolverStats;
use serde::Serialize;

/// The counters of a spatial run or a print, flattened into its metrics file.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub(crate) struct RunCost {
    /// Accepted steps.
    steps: u64,
    steps_rejected: u64,
    /// Right-hand sides (DOPRI5) or residuals (implicit path, finite-difference matrices'
    /// included).
    rhs_evaluations: u64,
    /// Implicit path only (0 for DOPRI5).
    newton_iterations: u64,
    jacobian_evals: u64,
    factorisations: u64,
    pivotings: u64,
}

impl From<&SolverStats> for RunCost {
    fn from(s: &SolverStats) -> Self {
        Self {
            steps: s.steps_accepted,
            steps_rejected: s.steps_rejected,
            rhs_evaluations: s.rhs_evals,
            newton_iterations: s.newton_iterations,
            jacobian_evals: s.jacobian_evals,
            factorisations: s.factorisations,
            pivotings: s.pivotings,
        }
    }
}
