//! One attempt at a step: the predictor's iterate, the iteration matrix S refreshed (or
//! re-weighed) where due and factorised, and the modified Newton iteration on R(q'') = 0 with its
//! verdict (converged, slow, non-finite).

use super::{GeneralizedAlpha, Newton};
use crate::norms::max_norm;
use crate::ode::{IntegratorError, SecondOrderSystem};

/// Contraction per iteration that still counts as converging with a matrix evaluated for this
/// step (a stale matrix is refreshed at `slow_contraction` already). A fresh matrix that
/// contracts by 0.05–0.5 is still converging, only from further away (a lumped node just past
/// the pulley); rejecting the step there, as the stale-matrix limit did, halved the step over
/// and over at N = 1000 (measured: contractions of 0.06–0.08 on fresh matrices). The iteration
/// limit still bounds the work.
const FRESH_CONTRACTION: f64 = 0.5;

/// The matrix is re-evaluated when the step differs from the one it was built for by more than
/// this ratio (its c_v, c_q scale with h and h²).
const STEP_CHANGE_REFRESH: f64 = 0.25;

impl GeneralizedAlpha {
    /// Evaluates S at the current iterate for step h and factorises it.
    fn refresh<S: SecondOrderSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        t: f64,
        h: f64,
    ) -> Result<(), IntegratorError> {
        let (c_v, c_q) = self.coeff.derivatives(h);
        let cost = sys.iteration_matrix(t, &self.y_try, &self.qdd_try, c_v, c_q, &mut self.values);
        self.stats.rhs_evals += cost.residual_evals;
        self.stats.jacobian_evals += 1;
        self.refresh_price = cost.refresh_price;
        self.slow_contraction = cost.slow_contraction.unwrap_or(self.opts.slow_contraction);
        self.excess_iterations = 0;
        self.factorise(h)
    }

    /// Factorises the values just written as S for step h.
    fn factorise(&mut self, h: f64) -> Result<(), IntegratorError> {
        let matrix = self
            .matrix
            .as_mut()
            .ok_or(IntegratorError::Usage("step before start"))?;
        matrix.factorise(&self.values)?;
        self.stats.factorisations += 1;
        self.stats.pivotings = matrix.pivotings();
        self.matrix_h = h;
        Ok(())
    }

    /// S re-weighted for step h from the parts the system kept at its last evaluation
    /// ([`SecondOrderSystem::reweighted_matrix`]) and factorised; false if it keeps none. The
    /// parts' state is the last refresh's, so the refresh rule's count goes on.
    fn reweigh<S: SecondOrderSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        t: f64,
        h: f64,
    ) -> Result<bool, IntegratorError> {
        let (c_v, c_q) = self.coeff.derivatives(h);
        let Some(cost) =
            sys.reweighted_matrix(t, &self.y_try, &self.qdd_try, c_v, c_q, &mut self.values)
        else {
            return Ok(false);
        };
        self.stats.rhs_evals += cost.residual_evals;
        self.factorise(h)?;
        Ok(true)
    }

    /// Modified Newton on R(q''_{n+1}) = 0 with the current factorisation of S, to max |R| ≤ `tol`.
    /// `fresh`: S was evaluated for this step, so a slow contraction means the step is too long
    /// for Newton, not that S has aged (see [`FRESH_CONTRACTION`]).
    fn newton<S: SecondOrderSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        t: f64,
        h: f64,
        fresh: bool,
        tol: f64,
    ) -> Newton {
        let limit = if fresh {
            FRESH_CONTRACTION
        } else {
            self.slow_contraction
        };
        let mut previous = f64::INFINITY;
        for iterations in 0..=self.opts.max_iterations as u64 {
            self.kinematics(h);
            sys.residual(t, &self.y_try, &self.qdd_try, &mut self.r);
            self.stats.rhs_evals += 1;
            let norm = match max_norm(&self.r) {
                Ok(norm) => norm,
                Err(i) => return Newton::NonFinite(i),
            };
            // Fine stiff meshes cannot go below their round-off (lumped N = 1000 stalls at
            // 1.0–1.3e-7 N against 1e-7 N): `tol` accounts for it.
            if norm <= tol {
                return Newton::Converged(iterations);
            }
            if norm > limit * previous {
                return Newton::Slow;
            }
            previous = norm;
            let Some(matrix) = self.matrix.as_mut() else {
                return Newton::Slow;
            };
            matrix.solve_in_place(&mut self.r);
            for (q, d) in self.qdd_try.iter_mut().zip(&self.r) {
                *q -= d;
            }
            self.stats.newton_iterations += 1;
        }
        Newton::Slow
    }

    /// Size of the step to attempt toward `t_end`: the target, or the remainder if that is within
    /// a hair of it (no sliver steps at the end).
    pub(super) fn step_to(&self, t_end: f64) -> f64 {
        let remaining = t_end - self.t;
        if remaining <= self.h * (1.0 + 1e-6) {
            remaining
        } else {
            self.h
        }
    }

    /// One attempt at the step to `t1` of size `h`: the predictor, the iteration matrix
    /// refreshed where due, and Newton (started over from a fresh matrix if it was slow on a
    /// reused one).
    pub(super) fn attempt<S: SecondOrderSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        t1: f64,
        h: f64,
    ) -> Result<Newton, IntegratorError> {
        sys.begin_step(self.t, &self.y, h);
        self.y_try.copy_from_slice(&self.y);
        self.predict(h);
        let mut fresh = false;
        let step_changed = (self.matrix_h / h - 1.0).abs() > STEP_CHANGE_REFRESH;
        if self.matrix_h == 0.0
            || self.refresh_pays()
            || (step_changed && self.opts.error_control.is_none())
        {
            self.kinematics(h);
            self.refresh(sys, t1, h)?;
            fresh = true;
        } else if self.opts.error_control.is_some() && h != self.matrix_h {
            // Under error control the step changes often: S is re-weighted for it where the
            // system keeps its parts (a factorisation, no model evaluation), else refreshed
            // beyond a quarter's change as on the fixed path.
            self.kinematics(h);
            if !self.reweigh(sys, t1, h)? && step_changed {
                self.refresh(sys, t1, h)?;
                fresh = true;
            }
        }
        // The tolerance of MODELS.md §6, or the forces' round-off where that is larger.
        let tol = self.opts.newton_tol.max(sys.residual_round_off(&self.y));
        let mut outcome = self.newton(sys, t1, h, fresh, tol);
        if outcome == Newton::Slow && !fresh {
            // Re-evaluate the matrix at the current iterate and start over from the predictor.
            self.refresh(sys, t1, h)?;
            self.predict(h);
            outcome = self.newton(sys, t1, h, true, tol);
        }
        self.stats.steps_attempted += 1;
        Ok(outcome)
    }
}
