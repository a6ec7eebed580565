//! The second-order form of a cable model, R(q, q', q'', T) = M(q) q'' − F(q, q', T) = 0, which the
//! implicit integrator needs (MODELS.md §6, FE.9.3). Models without an analytic iteration matrix
//! take theirs from `cdpr_numerics::differences::ColouredDifferences`.
//!
//! A model offering this form keeps its state as `[q (n) | q' (n)]`. The residual is in the units of
//! the generalised forces (N for node coordinates), so one Newton tolerance (1e-7 N) serves every
//! model. The tensions enter R linearly; the closed loop adds their dependence on the effector
//! through the controller, so a model never sees the controller.

pub use cdpr_numerics::MatrixCost;
use cdpr_numerics::norms::max_abs;

/// M(q) q'' − F(q, q', T) of a model, with its iteration matrix.
pub trait SecondOrderForm {
    /// Number n of generalised coordinates.
    fn dofs(&self) -> usize;
    /// Index among q of the effector's coordinate along axis k (0: x, the last: z).
    fn effector_coordinate(&self, k: usize) -> usize;
    /// Rows of R in which a commanded tension may appear (the closed loop couples them to the
    /// effector's coordinates the controller measures).
    fn tension_rows(&self) -> Vec<usize>;
    /// The (row, col) entries of ∂R/∂q'', ∂R/∂q' and ∂R/∂q that may be non-zero, for every state
    /// the model can reach (so one symbolic factorisation serves the run).
    fn iteration_pattern(&self) -> Vec<(usize, usize)>;
    /// Coordinates that couple distant parts of [`Self::iteration_pattern`] (e.g. a length
    /// that every node of a span depends on) without being dense enough for the sparse LU to
    /// split them off by itself: candidates for its border (see
    /// `cdpr_numerics::sparse::IterationMatrix::with_coupled`).
    fn coupled_unknowns(&self) -> Vec<usize> {
        Vec::new()
    }
    /// Round-off level of max |R| [N] at `state` (0 if negligible). A force k·(q_b − q_a) from
    /// coordinates of size |q| carries k·ulp(|q|): with k = EA/l0 = 1.8e8 N/m (lumped N = 1000)
    /// that is above MODELS.md's 1e-7 N Newton tolerance, which the integrator then raises to it.
    fn residual_round_off(&self, _state: &[f64]) -> f64 {
        0.0
    }
    /// Per position coordinate q_i (`out`, n long), the largest finite-difference step [m] over
    /// which the forces stay smooth in q_i at `state` = `[q | q']` (∞: nowhere near a kink), e.g. a quarter of
    /// the stretch of the tension-only springs q_i moves. The models' own iteration matrices use
    /// it, and so must any other differentiation of them (the modal analysis).
    fn smooth_reach(&self, _state: &[f64], out: &mut [f64]) {
        out.fill(f64::INFINITY);
    }
    /// Whether R carries reels driven by length, as the model's right-hand side does after
    /// `CableModel::drive_reels` (the closed loop drives them at each residual's time). A form
    /// without them cannot run the `length` controller on the implicit path.
    fn follows_driven_reels(&self) -> bool {
        false
    }

    /// R = M(q) q'' − F(q, q', T) for state `[q | q']` into `r` (n).
    fn residual(&mut self, state: &[f64], qdd: &[f64], tensions: &[f64], r: &mut [f64]);
    /// S = ∂R/∂q'' + c_v ∂R/∂q' + c_q ∂R/∂q at fixed tensions, in the order of
    /// [`Self::iteration_pattern`]. Returns the residual evaluations it made and its refresh
    /// price ([`MatrixCost`]).
    #[allow(clippy::too_many_arguments)]
    fn iteration_matrix(
        &mut self,
        state: &[f64],
        qdd: &[f64],
        tensions: &[f64],
        c_v: f64,
        c_q: f64,
        values: &mut [f64],
    ) -> MatrixCost;

    /// S for new weights (c_v, c_q) from the parts the last [`Self::iteration_matrix`] kept, at
    /// that call's state, without evaluating the model (`cdpr_numerics::MatrixParts`): a step-size
    /// change of the error-controlled path then costs a factorisation, not a matrix. False where
    /// the model keeps no parts.
    fn reweighted_matrix(&self, _c_v: f64, _c_q: f64, _values: &mut [f64]) -> bool {
        false
    }
}

/// Round-off bound of a spring model's residual [N]: a node's force sums two springs, each
/// k·(|q_b − q_a| − l0) from two rounded coordinates, so up to 4 k ulp(max |q|). Measured Newton
/// stalls at N = 1000: 1.0–1.3e-7 N (lumped, bound 2.4e-7 N) and 1.1–1.6e-7 N (FE, bound
/// 3.2e-7 N); at N ≤ 300 the bound stays below 1e-7 N.
pub fn spring_round_off(stiffness: f64, positions: &[f64]) -> f64 {
    4.0 * stiffness * f64::EPSILON * max_abs(positions)
}
