//! Generalised-α for M(q) q'' = F(t, q, q') in the Arnold–Brüls form (MODELS.md FE.9.3; M. Arnold,
//! O. Brüls, Multibody Syst. Dyn. 18 (2007)): the unknown of each step is the true acceleration
//! q''_{n+1}, the algorithmic acceleration a carries the method's memory:
//!
//! ```text
//! α_m = (2ρ∞ − 1)/(ρ∞ + 1), α_f = ρ∞/(ρ∞ + 1), γ = ½ + α_f − α_m, β = (γ + ½)²/4
//! (1 − α_m) a_{n+1} + α_m a_n = (1 − α_f) q''_{n+1} + α_f q''_n
//! q_{n+1}  = q_n + h q'_n + h² (½ − β) a_n + h² β a_{n+1}
//! q'_{n+1} = q'_n + h (1 − γ) a_n + h γ a_{n+1}
//! R(t_{n+1}, q_{n+1}, q'_{n+1}, q''_{n+1}) = M q'' − F = 0,          a_0 = q''_0.
//! ```
//!
//! Second order for every ρ∞ ∈ [0, 1]; ρ∞ is the spectral radius at h·ω → ∞, so ρ∞ < 1 damps the
//! modes the step does not resolve (the cables' axial modes), ρ∞ = 1 keeps them undamped but
//! period-distorted. The Newton iteration matrix S = ∂R/∂q'' + γ' ∂R/∂q' + β' ∂R/∂q with
//! γ' = γh(1 − α_f)/(1 − α_m), β' = βh²(1 − α_f)/(1 − α_m) is a faer sparse LU ([`IterationMatrix`]):
//! analysed once per run, refactorised only when the modified Newton iteration contracts slowly,
//! when the iterations a stale matrix costs have paid for a refresh, or when the step changed. A
//! step whose Newton iteration fails even with a fresh matrix is retried at half the size; the
//! step grows back after a few successes, and for some steps after a failure Newton starts from
//! the positions moved by their rates rather than from extrapolated accelerations. With an
//! [`ErrorControl`] the step is chosen instead by the local error estimate of
//! [`crate::alpha_error`], below a cap where Newton last failed, and `step` is only the first one
//! and the first after each restart.
//!
//! First-order states that ride along (a controller, energy audits) are the system's business: it
//! updates them from the step's endpoints ([`SecondOrderSystem::end_step`]), e.g. by the trapezoidal
//! rule. Dense output is the cubic Hermite interpolant of the state and its derivative at both ends
//! of the step (one right-hand-side evaluation per step), third order, above the method's own.

mod attempt;

pub use crate::alpha_coefficients::AlphaCoefficients;
use crate::alpha_error::{ErrorControl, ErrorPositions, StepEnds, StepHistory};
use crate::ode::{IntegratorError, SecondOrderSystem, SolverStats, Stepper};
use crate::sparse::IterationMatrix;

/// Settings of [`GeneralizedAlpha`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeneralizedAlphaOptions {
    /// Nominal step h [s].
    pub step: f64,
    /// Spectral radius at infinity ρ∞ ∈ [0, 1].
    pub rho_inf: f64,
    /// Newton converged at max |R| below this (MODELS.md §6: 1e-7 N), or below the model's
    /// round-off where that is larger ([`SecondOrderSystem::residual_round_off`]).
    pub newton_tol: f64,
    /// Newton iterations allowed per matrix.
    pub max_iterations: usize,
    /// A residual shrinking by less than this factor per iteration counts as slow convergence: the
    /// matrix is re-evaluated (modified Newton with a stale matrix contracts linearly). A fresh
    /// matrix contracts by 1e-3 … 1e-2 on the paper's meshes (lumped N = 40, FE N = 10; at
    /// N = 1000 by up to 0.06–0.08, see `FRESH_CONTRACTION`); 0.05 (measured on the paper run, from
    /// 0.005 … 0.5) minimises the total work: ~2 iterations per step for FE with a dozen
    /// factorisations per 5 s, where 0.5 lets the matrix age into ~3 iterations per step. A
    /// model whose matrix is dear and ages in a step may state its own
    /// ([`MatrixCost::slow_contraction`](crate::MatrixCost::slow_contraction)).
    pub slow_contraction: f64,
    /// Smallest step before giving up [s].
    pub min_step: f64,
    /// Error control: `step` is then the first step, and each step's local error estimate
    /// chooses the next ([`crate::alpha_error`]); `None`: the fixed step `step`.
    pub error_control: Option<ErrorControl>,
}

impl Default for GeneralizedAlphaOptions {
    fn default() -> Self {
        Self {
            step: 1e-4,
            rho_inf: 0.9,
            newton_tol: 1e-7,
            max_iterations: 8,
            slow_contraction: 0.05,
            min_step: 1e-12,
            error_control: None,
        }
    }
}

/// Accepted steps at a reduced size after which the step is doubled back toward the nominal one.
const SUCCESSES_BEFORE_GROWTH: u32 = 4;
/// Accepted steps after a Newton failure over which Newton starts from the positions
/// q_n + h q'_n ([`GeneralizedAlpha::predict`]). Measured on the lumped paper run at N = 1000
/// (fixed h = 1e-4 s, its first 0.5 s: 21.9 s before): 8 steps 13.9 s, 30 steps 11.6 s,
/// 200 steps 11.3 s; at N = 40 (the 5 s run) 4 919, 3 234 and 5 279 factorisations (2 855
/// before).
const DISPLACEMENT_PREDICTOR_STEPS: u32 = 30;

/// How one Newton solve ended (converged: after how many iterations).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Newton {
    Converged(u64),
    Slow,
    NonFinite(usize),
}

/// The generalised-α integrator with its buffers (allocated at [`Stepper::start`]).
pub struct GeneralizedAlpha {
    opts: GeneralizedAlphaOptions,
    coeff: AlphaCoefficients,
    n: usize,
    t: f64,
    t_prev: f64,
    /// Target step (nominal, or reduced after failures) [s].
    h: f64,
    successes: u32,
    /// Accepted steps since Newton last failed (saturating; the start counts as long ago).
    since_newton_failure: u32,
    y: Vec<f64>,
    dy: Vec<f64>,
    y_prev: Vec<f64>,
    dy_prev: Vec<f64>,
    /// True acceleration q''_n and algorithmic acceleration a_n.
    qdd: Vec<f64>,
    a: Vec<f64>,
    // Iterate scratch.
    y_try: Vec<f64>,
    qdd_try: Vec<f64>,
    a_try: Vec<f64>,
    r: Vec<f64>,
    /// The candidate's tail rate (error control), and how much of the tail enters the norm.
    rate_try: Vec<f64>,
    error_tail: usize,
    /// The positions in the error norm under [`ErrorPositions::Principal`].
    principal: Vec<usize>,
    /// The system's tail weights in the norm ([`SecondOrderSystem::tail_weights`]; empty: 1).
    tail_weights: Vec<f64>,
    history: StepHistory,
    values: Vec<f64>,
    matrix: Option<IterationMatrix>,
    /// Step the current factorisation was built for (0: none).
    matrix_h: f64,
    /// The last refresh's price ([`MatrixCost::refresh_price`]), and Newton iterations beyond
    /// one per step spent since (the refresh rule of [`Self::refresh_pays`]).
    refresh_price: u64,
    excess_iterations: u64,
    /// The last refresh's limit on a kept matrix's contraction
    /// ([`MatrixCost::slow_contraction`](crate::MatrixCost::slow_contraction), else the options').
    slow_contraction: f64,
    stats: SolverStats,
}

impl GeneralizedAlpha {
    pub fn new(opts: GeneralizedAlphaOptions) -> Self {
        Self {
            coeff: AlphaCoefficients::new(opts.rho_inf),
            opts,
            n: 0,
            t: 0.0,
            t_prev: 0.0,
            h: opts.step,
            successes: 0,
            since_newton_failure: u32::MAX,
            y: Vec::new(),
            dy: Vec::new(),
            y_prev: Vec::new(),
            dy_prev: Vec::new(),
            qdd: Vec::new(),
            a: Vec::new(),
            y_try: Vec::new(),
            qdd_try: Vec::new(),
            a_try: Vec::new(),
            r: Vec::new(),
            rate_try: Vec::new(),
            error_tail: 0,
            principal: Vec::new(),
            tail_weights: Vec::new(),
            history: StepHistory::default(),
            values: Vec::new(),
            matrix: None,
            matrix_h: 0.0,
            refresh_price: 0,
            slow_contraction: opts.slow_contraction,
            excess_iterations: 0,
            stats: SolverStats::default(),
        }
    }

    /// Whether to re-evaluate S before this step although it converges: once the iterations a
    /// stale S has cost beyond one per step reach the last refresh's price
    /// ([`MatrixCost::refresh_price`], by default its cost in residual evaluations). A
    /// rent-or-buy heuristic: an iteration costs a residual and a solve, a refresh its
    /// evaluations and a factorisation (no guarantee where a fresh S itself needs more than one
    /// iteration, or where the factorisation dominates: there the model prices it).
    /// Paper runs: FE N = 10, whose fresh matrix converges in one iteration for hundreds of
    /// steps, 1.05 iterations per step with ~90 refreshes (1.46 with 23 when refreshing only on
    /// slow contraction; 0.216 → 0.184 s); lumped N = 40, whose matrix ages within a step (its
    /// first free nodes sit 0.2–0.5 mm from the pulleys, transverse stiffness T/d, and the
    /// near-horizontal springs' vertical stiffness ≈ k φ² follows the string vibrations), 2.19
    /// iterations per step with a refresh every ~18 steps (its analytic matrix priced at 48,
    /// plus 2 for the closed loop's tension column; 2.11 and every ~11 steps when its
    /// finite-difference matrix was priced at its 18 residual evaluations; 2.66 and every ~27
    /// before the rule). Refreshing every step would not make it one: a fresh lumped matrix
    /// still needs 1.22 iterations per step, and one whose entries are refreshed only
    /// where they moved by more than 1e-6 relative needs 1.96: many small drifts matter, not a
    /// few large ones, so no local update of the matrix would do.
    fn refresh_pays(&self) -> bool {
        self.refresh_price > 0 && self.excess_iterations >= self.refresh_price
    }

    /// Counters so far.
    pub fn stats(&self) -> SolverStats {
        self.stats
    }

    /// Time of the last accepted step [s].
    pub fn time(&self) -> f64 {
        self.t
    }

    /// State at [`Self::time`].
    pub fn state(&self) -> &[f64] {
        &self.y
    }

    /// Non-zeros of the factorised iteration matrix (0 before the start).
    pub fn matrix_nonzeros(&self) -> usize {
        self.matrix.as_ref().map_or(0, IterationMatrix::nonzeros)
    }

    /// The iterate's q, q' from q''_{n+1} = `qdd_try` (and a_{n+1} into `a_try`).
    fn kinematics(&mut self, h: f64) {
        let n = self.n;
        let c = self.coeff;
        let (q0, rest) = self.y.split_at(n);
        let v0 = &rest[..n];
        let (q1, rest) = self.y_try.split_at_mut(n);
        let v1 = &mut rest[..n];
        let inv = 1.0 / (1.0 - c.alpha_m);
        let (w_new, w_old, w_a) = ((1.0 - c.alpha_f) * inv, c.alpha_f * inv, -c.alpha_m * inv);
        let (q_a, q_a1) = (h * h * (0.5 - c.beta), h * h * c.beta);
        let (v_a, v_a1) = (h * (1.0 - c.gamma), h * c.gamma);
        // Every slice cut to n, so the loop carries no bounds checks and vectorises.
        let (qdd_try, qdd, a, a_try) = (
            &self.qdd_try[..n],
            &self.qdd[..n],
            &self.a[..n],
            &mut self.a_try[..n],
        );
        for i in 0..n {
            let a1 = w_new * qdd_try[i] + w_old * qdd[i] + w_a * a[i];
            a_try[i] = a1;
            q1[i] = q0[i] + h * v0[i] + q_a * a[i] + q_a1 * a1;
            v1[i] = v0[i] + v_a * a[i] + v_a1 * a1;
        }
    }

    /// Newton's starting iterate for q''_{n+1}: the linear extrapolation of the last two steps'
    /// accelerations (constant after a start or restart, where there is only one). Its error is
    /// O(h^2 q'''') instead of the O(h q''') of a constant predictor.
    ///
    /// Within [`DISPLACEMENT_PREDICTOR_STEPS`] of a Newton failure, the q''_{n+1} whose
    /// positions are q_n + h q'_n instead (a_{n+1} = −(½ − β)/β a_n). Where Newton fails, the
    /// accelerations are not smooth: a tension-only spring crossed its kink, an event restarted
    /// the step, or the unresolved stiff modes ring, whose accelerations alternate in sign from
    /// step to step (the amplification tends to −ρ∞), so that extrapolating them doubles their
    /// error. Moved by h² a, the nodes of a lumped line by its pulley then slacken springs
    /// stretched by less than a micrometre, and Newton fails again; moved by h q' only, the
    /// springs change by their rates. A run whose Newton never fails is not touched.
    fn predict(&mut self, h: f64) {
        let n = self.n;
        if self.since_newton_failure < DISPLACEMENT_PREDICTOR_STEPS {
            let c = self.coeff;
            let a_next = -(0.5 - c.beta) / c.beta;
            let w_a = ((1.0 - c.alpha_m) * a_next + c.alpha_m) / (1.0 - c.alpha_f);
            let w_qdd = -c.alpha_f / (1.0 - c.alpha_f);
            for ((p, &a), &q) in self.qdd_try.iter_mut().zip(&self.a).zip(&self.qdd) {
                *p = w_a * a + w_qdd * q;
            }
            return;
        }
        let h_last = self.t - self.t_prev;
        let qdd_last = &self.dy_prev[n..2 * n];
        // Not across more than 4 × the last step (after a sliver step the slope is noise).
        if h_last > 0.0 && h <= 4.0 * h_last {
            let ratio = h / h_last;
            for ((p, &q), &q_last) in self.qdd_try.iter_mut().zip(&self.qdd).zip(qdd_last) {
                *p = q + ratio * (q - q_last);
            }
        } else {
            self.qdd_try.copy_from_slice(&self.qdd);
        }
    }

    /// The step after Newton failed on one of size `h`: half of it, and under error control
    /// a cap on the steps that follow ([`StepHistory::newton_failed`]).
    fn newton_failed(&mut self, h: f64) -> f64 {
        self.since_newton_failure = 0;
        match self.opts.error_control {
            Some(_) => self.history.newton_failed(h),
            None => 0.5 * h,
        }
    }

    /// A failed attempt (Newton's, or the error test's): the next attempt at `h_new`, or the
    /// error that ends the run when that falls below the minimum (`non_finite`: the component
    /// whose residual was not finite, if that was the failure).
    fn reject(&mut self, h_new: f64, non_finite: Option<usize>) -> Result<(), IntegratorError> {
        self.stats.steps_rejected += 1;
        self.successes = 0;
        self.h = h_new;
        if self.h < self.opts.min_step {
            return Err(match non_finite {
                Some(component) => IntegratorError::NonFinite {
                    t: self.t,
                    component,
                },
                None => IntegratorError::StepSizeUnderflow {
                    t: self.t,
                    h: self.h,
                },
            });
        }
        Ok(())
    }

    /// The converged step to `t1` taken: state, derivative for the dense output, counters and
    /// the step's growth back toward the nominal one.
    fn accept<S: SecondOrderSystem + ?Sized>(&mut self, sys: &mut S, t1: f64, iterations: u64) {
        let n = self.n;
        // y_prev ← y and dy_prev ← dy by swapping the buffers, then y and dy rewritten: the
        // model part from the iterate, the tail carried over (end_step advances it), dy
        // below. Two full-length copies fewer per step (~3 % of the lumped paper run).
        std::mem::swap(&mut self.y_prev, &mut self.y);
        std::mem::swap(&mut self.dy_prev, &mut self.dy);
        self.y[..2 * n].copy_from_slice(&self.y_try[..2 * n]);
        self.y[2 * n..].copy_from_slice(&self.y_prev[2 * n..]);
        self.dy[2 * n..].copy_from_slice(&self.dy_prev[2 * n..]);
        sys.end_step(t1, &mut self.y);
        self.advance(t1, iterations);
        sys.tail_rate(self.t, &self.y, &mut self.dy[2 * n..]);
    }

    /// An error-controlled step to `t1` taken: the candidate, whose tail and its rate
    /// [`Self::candidate_error`] has already formed, becomes the state.
    fn accept_candidate(&mut self, t1: f64, iterations: u64) {
        let n = self.n;
        std::mem::swap(&mut self.y_prev, &mut self.y);
        std::mem::swap(&mut self.dy_prev, &mut self.dy);
        self.y.copy_from_slice(&self.y_try);
        self.advance(t1, iterations);
        self.dy[2 * n..].copy_from_slice(&self.rate_try);
    }

    /// The clock, the accelerations, the derivative's (q', q'') for the dense output (from the
    /// step, whose q'' satisfies R = 0 to the Newton tolerance) and the counters of an accepted
    /// step; the tail's rate is the caller's.
    fn advance(&mut self, t1: f64, iterations: u64) {
        let n = self.n;
        self.t_prev = self.t;
        self.t = t1;
        self.since_newton_failure = self.since_newton_failure.saturating_add(1);
        std::mem::swap(&mut self.qdd, &mut self.qdd_try);
        std::mem::swap(&mut self.a, &mut self.a_try);
        let (dq, rest) = self.dy.split_at_mut(n);
        dq.copy_from_slice(&self.y[n..2 * n]);
        rest[..n].copy_from_slice(&self.qdd);
        self.stats.steps_accepted += 1;
        self.excess_iterations += iterations.saturating_sub(1);
    }

    /// After an accepted fixed step: a step reduced by Newton failures grows back toward the
    /// nominal one after a few successes.
    fn grow_back(&mut self) {
        if self.h < self.opts.step {
            self.successes += 1;
            if self.successes >= SUCCESSES_BEFORE_GROWTH {
                self.h = (2.0 * self.h).min(self.opts.step);
                self.successes = 0;
            }
        }
    }

    /// The scaled local error of the converged iterate of a step of size `h` to
    /// `t1`, after completing the candidate: its tail (the system's rule) and the tail's rate.
    fn candidate_error<S: SecondOrderSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        t1: f64,
        control: &ErrorControl,
        h: f64,
    ) -> f64 {
        let n = self.n;
        sys.end_step(t1, &mut self.y_try);
        sys.tail_rate(t1, &self.y_try, &mut self.rate_try);
        let tail = 2 * n..2 * n + self.error_tail;
        let h_before = self.t - self.t_prev;
        let ends = StepEnds {
            q0: &self.y[..n],
            q1: &self.y_try[..n],
            qdd0: &self.qdd,
            qdd1: &self.qdd_try,
            z0: &self.y[tail.clone()],
            z1: &self.y_try[tail.clone()],
            rate0: &self.dy[tail.clone()],
            rate1: &self.rate_try[..self.error_tail],
            before: (h_before > 0.0).then(|| (&self.dy_prev[tail], h_before)),
            positions: (control.positions == ErrorPositions::Principal)
                .then_some(self.principal.as_slice()),
            tail_weights: (!self.tail_weights.is_empty()).then_some(self.tail_weights.as_slice()),
        };
        control.scaled_error(self.coeff.error_constant(), h, &ends)
    }

    fn initialise<S: SecondOrderSystem + ?Sized>(&mut self, sys: &mut S, t: f64, y: &[f64]) {
        let n = self.n;
        self.t = t;
        self.t_prev = t;
        self.y.copy_from_slice(y);
        sys.rhs(t, &self.y, &mut self.dy);
        self.stats.rhs_evals += 1;
        self.qdd.copy_from_slice(&self.dy[n..2 * n]);
        self.a.copy_from_slice(&self.qdd);
        self.y_prev.copy_from_slice(&self.y);
        self.dy_prev.copy_from_slice(&self.dy);
    }
}

impl<S: SecondOrderSystem + ?Sized> Stepper<S> for GeneralizedAlpha {
    fn start(
        &mut self,
        sys: &mut S,
        t0: f64,
        y0: &[f64],
        t_end: f64,
    ) -> Result<(), IntegratorError> {
        let dim = sys.dimension();
        let n = sys.dofs();
        if y0.len() != dim || 2 * n > dim {
            return Err(IntegratorError::Usage(
                "state length differs from the system's dimension",
            ));
        }
        if t_end <= t0 {
            return Err(IntegratorError::Usage("t_end must be after t0"));
        }
        if !(self.opts.step > 0.0 && (0.0..=1.0).contains(&self.opts.rho_inf)) {
            return Err(IntegratorError::Usage(
                "step must be > 0 and rho_inf in [0, 1]",
            ));
        }
        if let Some(c) = self.opts.error_control
            && !(c.rtol > 0.0 && c.atol >= 0.0 && c.max_step > 0.0)
        {
            return Err(IntegratorError::Usage(
                "error control needs rtol > 0, atol ≥ 0 and max_step > 0",
            ));
        }
        self.n = n;
        for v in [
            &mut self.y,
            &mut self.dy,
            &mut self.y_prev,
            &mut self.dy_prev,
            &mut self.y_try,
        ] {
            *v = vec![0.0; dim];
        }
        for v in [
            &mut self.qdd,
            &mut self.a,
            &mut self.qdd_try,
            &mut self.a_try,
            &mut self.r,
        ] {
            *v = vec![0.0; n];
        }
        self.rate_try = vec![0.0; dim - 2 * n];
        self.error_tail = sys.error_len().clamp(2 * n, dim) - 2 * n;
        self.tail_weights = sys.tail_weights();
        if !(self.tail_weights.is_empty()
            || self.tail_weights.len() == self.error_tail
                && self.tail_weights.iter().all(|w| w.is_finite() && *w > 0.0))
        {
            return Err(IntegratorError::Usage(
                "tail weights must be one finite positive factor per tail component in the norm",
            ));
        }
        if let Some(c) = self.opts.error_control
            && c.positions == ErrorPositions::Principal
        {
            self.principal = sys.principal_positions();
            if self.principal.is_empty() || self.principal.iter().any(|&i| i >= n) {
                return Err(IntegratorError::Usage(
                    "principal positions must be some of the system's coordinates",
                ));
            }
        }
        self.history = StepHistory::default();
        let pattern = sys.iteration_pattern();
        self.values = vec![0.0; pattern.len()];
        (self.refresh_price, self.excess_iterations) = (0, 0);
        self.slow_contraction = self.opts.slow_contraction;
        self.matrix = Some(IterationMatrix::with_coupled(
            n,
            &pattern,
            &sys.coupled_unknowns(),
        )?);
        self.matrix_h = 0.0;
        self.h = match self.opts.error_control {
            Some(control) => self.opts.step.min(control.max_step),
            None => self.opts.step,
        };
        self.stats = SolverStats::default();
        self.since_newton_failure = u32::MAX;
        self.initialise(sys, t0, y0);
        Ok(())
    }

    fn step(&mut self, sys: &mut S, t_end: f64) -> Result<(), IntegratorError> {
        if self.matrix.is_none() {
            return Err(IntegratorError::Usage("step before start"));
        }
        if t_end <= self.t {
            return Err(IntegratorError::Usage(
                "t_end must be after the current time",
            ));
        }
        loop {
            let h = self.step_to(t_end);
            if h < self.opts.min_step {
                return Err(IntegratorError::StepSizeUnderflow { t: self.t, h });
            }
            let last = h == t_end - self.t;
            let t1 = if last { t_end } else { self.t + h };
            match self.attempt(sys, t1, h)? {
                Newton::Converged(iterations) => {
                    let Some(control) = self.opts.error_control else {
                        self.accept(sys, t1, iterations);
                        self.grow_back();
                        return Ok(());
                    };
                    let error = self.candidate_error(sys, t1, &control, h);
                    if error <= 1.0 {
                        self.accept_candidate(t1, iterations);
                        if !last {
                            self.h = self.history.accepted(&control, h, error);
                        }
                        return Ok(());
                    }
                    let h_new = self.history.rejected(h, error);
                    self.reject(h_new, None)?;
                }
                Newton::NonFinite(component) => {
                    let h_new = self.newton_failed(h);
                    self.reject(h_new, Some(component))?
                }
                Newton::Slow => {
                    let h_new = self.newton_failed(h);
                    self.reject(h_new, None)?
                }
            }
        }
    }

    fn restart(&mut self, sys: &mut S, t: f64, y: &[f64]) {
        self.initialise(sys, t, y);
        self.stats.restarts += 1;
        if self.opts.error_control.is_some() {
            // A restart follows a jump (an event, the reference's): the step starts over from
            // the initial one. Kept at its size, it failed some seven times at each of the cube
            // layer's 528 restarts on lumped lines.
            self.h = self.h.min(self.opts.step);
            self.history.restarted();
        }
    }

    fn time(&self) -> f64 {
        GeneralizedAlpha::time(self)
    }

    fn previous_time(&self) -> f64 {
        self.t_prev
    }

    fn state(&self) -> &[f64] {
        GeneralizedAlpha::state(self)
    }

    /// Cubic Hermite interpolation of y from (y, y') at both ends of the last step.
    fn dense_output(&self, t: f64, out: &mut [f64]) {
        let h = self.t - self.t_prev;
        if h <= 0.0 {
            out.copy_from_slice(&self.y[..out.len()]);
            return;
        }
        let s = (t - self.t_prev) / h;
        let s2 = s * s;
        let s3 = s2 * s;
        let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
        let h10 = (s3 - 2.0 * s2 + s) * h;
        let h01 = -2.0 * s3 + 3.0 * s2;
        let h11 = (s3 - s2) * h;
        for (i, o) in out.iter_mut().enumerate() {
            *o = h00 * self.y_prev[i] + h10 * self.dy_prev[i] + h01 * self.y[i] + h11 * self.dy[i];
        }
    }

    fn stats(&self) -> SolverStats {
        GeneralizedAlpha::stats(self)
    }
}
