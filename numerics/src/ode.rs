//! The interfaces between a system and its integrators: an [`OdeSystem`] says what y' is and
//! integrators know nothing else about it; both integrators are driven one accepted step at a
//! time through [`Stepper`], so a runner's sampling and event location do not depend on the
//! method; [`SolverStats`] counts their work and [`MatrixCost`] prices an iteration matrix.

use crate::sparse;

/// What one evaluation of an implicit method's iteration matrix cost, in two parts kept apart:
/// the full residual evaluations it made (counted in [`SolverStats::rhs_evals`], which MODELS.md
/// §6 asks us to report), and the price the refresh rule puts on a refresh: the Newton
/// iterations beyond one per step it lets accumulate before refreshing again. A
/// finite-difference matrix ([`MatrixCost::differences`]) is priced at its residual evaluations
/// (an iteration costs a residual and a solve); a model that knows better (a refresh that buys
/// fewer iterations than it costs, or an analytic matrix whose factorisation dominates) states
/// its own price, with its measurements. A price of 0 (the `Default`) means: refresh only when
/// Newton slows. A model may likewise state how slow a Newton contraction its kept matrix may
/// show before it counts as aged.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct MatrixCost {
    /// Full residual evaluations made.
    pub residual_evals: u64,
    /// The refresh rule's price of this refresh, in Newton iterations beyond one per step
    /// (0: the matrix is refreshed only when Newton slows).
    pub refresh_price: u64,
    /// The contraction per Newton iteration beyond which this matrix, kept across steps, is
    /// re-evaluated (None: the integrator's `slow_contraction`).
    pub slow_contraction: Option<f64>,
}

impl MatrixCost {
    /// A matrix made of `evals` full residual evaluations (finite differences) and little else,
    /// priced at their number.
    pub fn differences(evals: u64) -> Self {
        Self {
            residual_evals: evals,
            refresh_price: evals,
            slow_contraction: None,
        }
    }

    /// A matrix that made no full residual evaluation (analytic, or element-local differences),
    /// priced at `refresh_price`.
    pub fn without_residuals(refresh_price: u64) -> Self {
        Self {
            residual_evals: 0,
            refresh_price,
            slow_contraction: None,
        }
    }

    /// This cost with the model's own limit on a kept matrix's contraction
    /// ([`Self::slow_contraction`]).
    pub fn with_slow_contraction(self, limit: f64) -> Self {
        Self {
            slow_contraction: Some(limit),
            ..self
        }
    }

    /// This cost plus `evals` full residual evaluations made on top (e.g. a column the closed
    /// loop adds), each adding one to the price.
    pub fn plus_residuals(self, evals: u64) -> Self {
        Self {
            residual_evals: self.residual_evals + evals,
            refresh_price: self.refresh_price + evals,
            ..self
        }
    }
}

/// A first-order system y' = f(t, y) of fixed dimension.
pub trait OdeSystem {
    /// Number of state components.
    fn dimension(&self) -> usize;
    /// Writes f(t, y) into `dy` (same length as `y`). Must not allocate in hot loops.
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]);
}

/// Cost counters: the honest measure of an integrator's work.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct SolverStats {
    /// Right-hand-side evaluations (dopri5.f: 2 at the start, 6 per attempted step, 1 per restart).
    pub rhs_evals: u64,
    /// Steps attempted (accepted + rejected).
    pub steps_attempted: u64,
    /// Steps accepted.
    pub steps_accepted: u64,
    /// Steps rejected by the error test, all of them (dopri5.f's NREJCT omits those before the first
    /// accepted step).
    pub steps_rejected: u64,
    /// Restarts after a discontinuity in the state (model events).
    pub restarts: u64,
    /// Newton iterations (implicit methods; each costs one residual evaluation, counted in
    /// `rhs_evals`).
    pub newton_iterations: u64,
    /// Iteration-matrix (Jacobian) evaluations (implicit methods). The full residual evaluations
    /// of a finite-difference matrix are counted in `rhs_evals` too; an analytic or element-local
    /// matrix adds none ([`MatrixCost`]).
    pub jacobian_evals: u64,
    /// Numeric LU factorisations of the iteration matrix (implicit methods).
    pub factorisations: u64,
    /// Of those, the ones that chose their pivots afresh (faer's LU with partial pivoting); the
    /// others reused the last pivot sequence (see `IterationMatrix::pivotings`).
    pub pivotings: u64,
}

/// One-step-at-a-time driving of an integrator on system `S`: what the runner needs for sampling
/// the dense output, locating events and restarting after them.
pub trait Stepper<S: ?Sized> {
    /// Initialises at (t0, y0) for an integration towards `t_end`.
    fn start(
        &mut self,
        sys: &mut S,
        t0: f64,
        y0: &[f64],
        t_end: f64,
    ) -> Result<(), IntegratorError>;
    /// Takes one accepted step, never past `t_end`.
    fn step(&mut self, sys: &mut S, t_end: f64) -> Result<(), IntegratorError>;
    /// Continues from a changed state (t, y), keeping the current step size.
    fn restart(&mut self, sys: &mut S, t: f64, y: &[f64]);
    /// Time of the last accepted step [s].
    fn time(&self) -> f64;
    /// Start of the last accepted step [s].
    fn previous_time(&self) -> f64;
    /// State at [`Self::time`].
    fn state(&self) -> &[f64];
    /// The dense output at t within the last accepted step into `out`.
    fn dense_output(&self, t: f64, out: &mut [f64]);
    /// Counters so far.
    fn stats(&self) -> SolverStats;
    /// Whether the system's last right-hand side was evaluated at the state of the last accepted
    /// step (DOPRI5's first-same-as-last stage), so that what it computed there may be read
    /// back instead of computed again. The time may still differ by an ulp (the last step ends
    /// exactly at t_end): a reader compares it.
    fn last_rhs_at_state(&self) -> bool {
        false
    }
}

/// Why an integration stopped.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IntegratorError {
    /// dopri5.f's criterion 0.1·|h| ≤ |t|·uround: the step cannot advance time any more.
    #[error(
        "step size underflow at t = {t} s (h = {h:e} s): the problem is too stiff or singular here"
    )]
    StepSizeUnderflow { t: f64, h: f64 },
    /// The right-hand side produced NaN or infinity even at the smallest step tried.
    #[error("non-finite state (NaN or infinity) at t = {t} s, component {component}")]
    NonFinite { t: f64, component: usize },
    /// Asked to step past the end of the interval or with an inconsistent setup.
    #[error("integrator misuse: {0}")]
    Usage(&'static str),
    /// The Newton iteration matrix could not be analysed or factorised.
    #[error("iteration matrix: {0}")]
    Sparse(#[from] sparse::SparseError),
}

/// A second-order system with a first-order tail, as the implicit integrator sees it.
///
/// State layout `[q (n) | q' (n) | tail]`; [`OdeSystem::rhs`] is the same system in first-order
/// form (it gives the consistent initial acceleration and the dense output's derivatives).
pub trait SecondOrderSystem: OdeSystem {
    /// Number n of generalised coordinates q.
    fn dofs(&self) -> usize;
    /// The (row, col) entries of the iteration matrix that may be non-zero, fixed for the run.
    fn iteration_pattern(&self) -> Vec<(usize, usize)>;
    /// Unknowns that couple distant parts of that pattern (a controller feeding one coordinate
    /// back into far rows): the matrix eliminates them last, through a Schur complement, so the
    /// rest keeps its chain structure ([`crate::sparse::IterationMatrix::with_coupled`]).
    fn coupled_unknowns(&self) -> Vec<usize> {
        Vec::new()
    }
    /// A step attempt from (t, y) of size h begins: the system records what its tail update and
    /// its residual need from the step's start.
    fn begin_step(&mut self, t: f64, y: &[f64], h: f64);
    /// R = M(q) q'' − F(t, q, q', …) (n rows) for the iterate whose q, q' are `y[..2n]`.
    fn residual(&mut self, t: f64, y: &[f64], qdd: &[f64], r: &mut [f64]);
    /// S = ∂R/∂q'' + c_v ∂R/∂q' + c_q ∂R/∂q at the iterate, in the order of
    /// [`Self::iteration_pattern`] (duplicates are summed). Returns what it cost.
    #[allow(clippy::too_many_arguments)]
    fn iteration_matrix(
        &mut self,
        t: f64,
        y: &[f64],
        qdd: &[f64],
        c_v: f64,
        c_q: f64,
        values: &mut [f64],
    ) -> MatrixCost;
    /// S for new coefficients (c_v, c_q) at the iterate, from what the last
    /// [`Self::iteration_matrix`] kept where the system keeps it ([`crate::MatrixParts`]): the
    /// parts evaluated at that call's state, as stale as a matrix kept across steps. None: the
    /// system keeps nothing, and S is evaluated afresh.
    #[allow(clippy::too_many_arguments)]
    fn reweighted_matrix(
        &mut self,
        _t: f64,
        _y: &[f64],
        _qdd: &[f64],
        _c_v: f64,
        _c_q: f64,
        _values: &mut [f64],
    ) -> Option<MatrixCost> {
        None
    }
    /// Writes the tail `y[2n..]` at the end t of an accepted step whose q, q' are `y[..2n]`.
    fn end_step(&mut self, t: f64, y: &mut [f64]);
    /// The tail's rate at (t, y) into `out` (the dense output's derivative; q' and q'' come from
    /// the step itself, so no full right-hand side is evaluated per step).
    fn tail_rate(&mut self, t: f64, y: &[f64], out: &mut [f64]);
    /// Round-off level of max |R| at the state `y` (0 if negligible): Newton is not asked for a
    /// residual below it.
    fn residual_round_off(&self, _y: &[f64]) -> f64 {
        0.0
    }
    /// Per tail component in the error norm ([`Self::error_len`]), the factor that converts
    /// it to the positions' units, so that one atol means one thing (a robot's filtered
    /// velocity in m/s enters as the position error its controller treats alike). Empty (the
    /// default): every factor 1.
    fn tail_weights(&self) -> Vec<f64> {
        Vec::new()
    }
    /// The positions a user's quantity of interest lives in (a robot's effector): all that an
    /// error norm on [`crate::ErrorPositions::Principal`] measures. Default: every position.
    fn principal_positions(&self) -> Vec<usize> {
        (0..self.dofs()).collect()
    }
    /// The state's first `error_len` components enter an error-controlled integrator's norm
    /// (q, and the tail up to where audit states begin; the velocities are left to the
    /// method, see `alpha_error`). Default: all.
    fn error_len(&self) -> usize {
        self.dimension()
    }
}
