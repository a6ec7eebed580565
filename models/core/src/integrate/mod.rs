//! Time integration, independent of any cable: an [`OdeSystem`] says what y' is; integrators know
//! nothing else about it. [`Dopri5`] is the paper-faithful explicit reference (ode45 class).

mod dopri5;

pub use dopri5::{Dopri5, Dopri5Options};

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
}
