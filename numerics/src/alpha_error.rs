//! Error control of generalised-α: the local error estimate of a step and the step-size rule
//! that keeps it within a tolerance (used by [`crate::GeneralizedAlpha`] when its options carry
//! an [`ErrorControl`]).
//!
//! **The estimate.** Start a step from the exact q, q' at t_n with a_n = q''(t_n + Δh) + O(h²),
//! Δ = α_m − α_f = ½ − γ (Arnold & Brüls 2007, the algorithmic acceleration's lag). Taylor
//! expansion of q_{n+1} = q_n + h q'_n + h²(½ − β) a_n + h² β a_{n+1} against the exact
//! q(t_n + h) leaves the local error of the positions
//!
//! ```text
//! q(t_n + h) − q_{n+1} = C h³ q''' + O(h⁴),   C = γ/2 − β − 1/12,
//! ```
//!
//! estimated by e = C h² (q''_{n+1} − q''_n) from the step's own true accelerations (no extra
//! residual). For Newmark's average acceleration (γ = ½, β = ¼) C = 1/6 − β = −1/12 and e is
//! Zienkiewicz & Xie's estimator (Earthquake Eng. Struct. Dyn. 20 (1991) 871–887); ρ∞ = 0.9 gives
//! C = −0.0840. The first step after a start or restart has a_n = q''_n instead, so its error
//! constant is 1/6 − β(1 − α_f)/(1 − α_m): equal to C at ρ∞ = 0 and 1, 1.4 % off at ρ∞ = 0.9.
//!
//! **The norm: error per step, tolerance transformed.** A step is accepted when
//! `‖e / sc‖_rms ≤ √rtol`, sc = atol + rtol·max(|q_n|, |q_{n+1}|), over the positions (all, or
//! the system's principal ones: [`ErrorPositions`]) and the first-order tail (a controller's
//! states; the audits stay out). Error per step with a
//! second-order method gives a global error ∝ (allowance)^(2/3); the allowance sc·√rtol makes
//! that ∝ tol when rtol and atol are scaled together (Söderlind & Wang, J. Comput. Appl. Math.
//! 185 (2006): tolerance proportionality by transforming the tolerance). Error per *unit* step
//! (allowance ∝ h), the other route to proportionality, was tried and dropped: an acceleration
//! that jumps (a node passing its pulley, a tension reaching its limit) makes C h² Δq'' ∝ h², so
//! an allowance ∝ h forces h ∝ tol/|Δq''| — 1e-8 s on the lumped paper run — and a cable mode of
//! femtometres, once resolved by such steps, is no longer damped by ρ∞ and holds the step
//! there (measured: 4.8 M steps at rtol = 1e-5). With the allowance independent of h a jump
//! costs h ∝ (tol/|Δq''|)^(1/2) and unresolved modes stay under ρ∞'s damping.
//! The velocities are left out: their local error is of the same order h³ and follows the
//! positions' (the same accelerations drive both).
//!
//! **The step.** ε is O(h³), so h_new = h·clamp(0.9 ε^(−1/3), 0.2, 2) (with a PI term, see
//! [`StepHistory`]), at most `max_step` and below a cap after a Newton failure. A
//! proposed growth below 25 % keeps the step, and with it the factorised iteration matrix,
//! whose coefficients scale with h and h² (it is re-evaluated when the step changes by more
//! than a quarter).

/// Tolerances of the error-controlled generalised-α.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ErrorControl {
    /// Relative tolerance (> 0; the allowance per step is its square root times the scale).
    pub rtol: f64,
    /// Absolute tolerance [the components' units].
    pub atol: f64,
    /// Largest step [s].
    pub max_step: f64,
    /// The positions whose local error the norm measures (the tail always counts).
    pub positions: ErrorPositions,
}

/// Which positions enter the error norm.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ErrorPositions {
    /// Every position.
    #[default]
    All,
    /// Only the system's principal positions
    /// ([`crate::SecondOrderSystem::principal_positions`], a robot's effector): the rest rides
    /// on the steps those need, its unresolved modes damped by ρ∞ as on a fixed step.
    Principal,
}

/// Safety factor of the step proposal.
const SAFETY: f64 = 0.9;
/// Bounds of h_new / h.
const MIN_FACTOR: f64 = 0.2;
const MAX_FACTOR: f64 = 2.0;
/// A growth below this factor keeps the step (and the factorised matrix).
const HOLD_BELOW: f64 = 1.25;
/// β of the PI step-size rule (Hairer & Wanner: 0.04 … 0.1 for low orders; 0.08 here).
const PI_BETA: f64 = 0.08;
/// Floor of ε in the step rule (a step with no measurable error grows by `MAX_FACTOR`).
const MIN_ERROR: f64 = 1e-10;

/// One step as the estimate reads it: the positions and the first-order tail in the norm.
pub(crate) struct StepEnds<'a> {
    /// q_n and q_{n+1}.
    pub q0: &'a [f64],
    pub q1: &'a [f64],
    /// q''_n and q''_{n+1}.
    pub qdd0: &'a [f64],
    pub qdd1: &'a [f64],
    /// The tail z_n, z_{n+1} and its rates z'_n, z'_{n+1}.
    pub z0: &'a [f64],
    pub z1: &'a [f64],
    pub rate0: &'a [f64],
    pub rate1: &'a [f64],
    /// The rates z'_{n−1} and the step before, h_{n−1} [s] (None after a start or restart).
    pub before: Option<(&'a [f64], f64)>,
    /// The positions in the norm (None: all).
    pub positions: Option<&'a [usize]>,
    /// Each tail component's factor to the positions' units (None: all 1).
    pub tail_weights: Option<&'a [f64]>,
}

/// Accumulates (e_i / sc_i)², NaN-propagating.
fn add_scaled(sum: &mut f64, e: f64, x0: f64, x1: f64, rtol: f64, atol: f64) {
    let r = e / (atol + rtol * x0.abs().max(x1.abs()));
    // x1·0 is NaN exactly when x1 is (max above would hide it).
    *sum += r * r + x1 * 0.0;
}

impl ErrorControl {
    /// The scaled local error ε of a step of size `h` [s] with error constant
    /// `constant` (C of the module doc): accept at ε ≤ 1. NaN when a component is not finite.
    ///
    /// The tail is advanced by the trapezoidal rule, whose local error is −h³ z'''/12 (Hairer,
    /// Nørsett & Wanner I, §II.7); z''' = (z')'' from the second divided difference of the rates
    /// at the step's ends and the previous step's start. Without a previous step (after a start
    /// or restart) the first difference stands in: h² z''/12, larger for a smooth tail, so the
    /// first step is judged conservatively.
    pub(crate) fn scaled_error(&self, constant: f64, h: f64, ends: &StepEnds) -> f64 {
        let (rtol, atol) = (self.rtol, self.atol);
        let n = ends.q0.len();
        let c = constant * h * h;
        let (q0, q1, a0, a1) = (
            &ends.q0[..n],
            &ends.q1[..n],
            &ends.qdd0[..n],
            &ends.qdd1[..n],
        );
        let mut sum = 0.0;
        let mut position = |i: usize| {
            add_scaled(&mut sum, c * (a1[i] - a0[i]), q0[i], q1[i], rtol, atol);
        };
        let n = match ends.positions {
            Some(positions) => {
                positions.iter().for_each(|&i| position(i));
                positions.len()
            }
            None => {
                (0..n).for_each(position);
                n
            }
        };
        let m = ends.z0.len();
        for i in 0..m {
            let (r0, r1) = (ends.rate0[i], ends.rate1[i]);
            let e = match ends.before {
                Some((rate, h_before)) => {
                    let second = 2.0 * ((r1 - r0) / h - (r0 - rate[i]) / h_before) / (h + h_before);
                    h * h * h * second / 12.0
                }
                None => h * (r1 - r0) / 12.0,
            };
            // A weight of 1 multiplies exactly: the unweighted norm's bits.
            let w = ends.tail_weights.map_or(1.0, |w| w[i]);
            add_scaled(&mut sum, w * e, w * ends.z0[i], w * ends.z1[i], rtol, atol);
        }
        (sum / (n + m).max(1) as f64).sqrt() / rtol.sqrt()
    }
}

/// The step-size controller's memory: the last accepted step's error (the PI term) and whether
/// the last attempt was rejected (no growth right after a rejection, Hairer & Wanner II §IV.8),
/// and the largest step Newton is trusted with ([`Self::newton_failed`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct StepHistory {
    previous_error: f64,
    rejected: bool,
    newton_cap: f64,
}

impl Default for StepHistory {
    fn default() -> Self {
        Self {
            previous_error: 1.0,
            rejected: false,
            newton_cap: f64::INFINITY,
        }
    }
}

/// After Newton fails at h, the steps stay below half of it, a cap that relaxes by this factor
/// per accepted step (back to h after four steps). Without it the error estimate, which knows
/// nothing of Newton, proposed the failed step again right after the halved one: on the lumped
/// paper run with the effector's error controlled, 1 984 failures in 7 125 attempts, each with
/// a fresh matrix; with it 431 in 5 089 (docs/numerics.md).
const NEWTON_CAP_GROWTH: f64 = 1.2;

impl StepHistory {
    /// The step after an accepted step of size `h` with scaled error `error` ≤ 1: Gustafsson's
    /// PI rule h·0.9·ε_n^(−α)·ε_{n−1}^β (α = 1/3 − 0.75 β, β = [`PI_BETA`]), which damps the
    /// accept–reject cycles of the elementary rule.
    pub(crate) fn accepted(&mut self, control: &ErrorControl, h: f64, error: f64) -> f64 {
        let error = error.max(MIN_ERROR);
        let alpha = 1.0 / 3.0 - 0.75 * PI_BETA;
        let mut factor = SAFETY * error.powf(-alpha) * self.previous_error.powf(PI_BETA);
        if self.rejected {
            factor = factor.min(1.0);
        }
        let factor = factor.clamp(MIN_FACTOR, MAX_FACTOR);
        self.previous_error = error;
        self.rejected = false;
        let h_new = if (1.0..HOLD_BELOW).contains(&factor) {
            h
        } else {
            h * factor
        };
        let cap = self.newton_cap;
        self.newton_cap *= NEWTON_CAP_GROWTH;
        h_new.min(control.max_step).min(cap)
    }

    /// After a restart (an event, a jump of the reference) the state that taught the cap is
    /// gone.
    pub(crate) fn restarted(&mut self) {
        self.newton_cap = f64::INFINITY;
    }

    /// The step to retry after Newton failed on a step of size `h`: half of it, with the cap
    /// of [`NEWTON_CAP_GROWTH`] on the steps that follow.
    pub(crate) fn newton_failed(&mut self, h: f64) -> f64 {
        self.rejected = true;
        self.newton_cap = 0.5 * h;
        0.5 * h
    }

    /// The step to retry after a step of size `h` rejected with scaled error `error` > 1 (or
    /// NaN).
    pub(crate) fn rejected(&mut self, h: f64, error: f64) -> f64 {
        self.rejected = true;
        if error.is_finite() {
            h * (SAFETY / error.cbrt()).clamp(MIN_FACTOR, SAFETY)
        } else {
            h * MIN_FACTOR
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CONTROL: ErrorControl = ErrorControl {
        rtol: 1e-6,
        atol: 1e-6,
        max_step: 1.0,
        positions: ErrorPositions::All,
    };

    /// After Newton fails at h the proposals stay below h/2 · 1.2^k however small the error and
    /// reach h again after four accepted steps; a restart lifts the cap at once (the step after
    /// it still keeps the no-growth rule of a rejection, then doubles where the cap would allow
    /// 1.2).
    #[test]
    fn a_newton_failure_caps_the_steps_that_follow() {
        let mut history = StepHistory::default();
        let h = 1e-3;
        let mut step = history.newton_failed(h);
        assert_eq!(step, 0.5 * h);
        let mut caps = Vec::new();
        for k in 0..6 {
            // An error of 1e-6 alone would double the step each time.
            step = history.accepted(&CONTROL, step, 1e-6);
            caps.push(step);
            assert!(step <= 0.5 * h * 1.2f64.powi(k) * (1.0 + 1e-12), "{caps:?}");
        }
        assert!(caps[3] < h && caps[4] > h, "{caps:?}");
        history.newton_failed(h);
        history.restarted();
        let held = history.accepted(&CONTROL, 0.5 * h, 1e-6);
        assert_eq!(held, 0.5 * h);
        assert_eq!(history.accepted(&CONTROL, held, 1e-6), h);
    }
}
