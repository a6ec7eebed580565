//! The model's events between accepted steps (MODELS.md §4), located on the dense output, and
//! the slack-cable check every sample and event passes.

use super::RunError;
use crate::closed_loop::ClosedLoop;
use crate::model::CableModel;
use crate::robot::{CableId, Tensions};
use cdpr_numerics::Stepper;

/// Watches the model's event functions between accepted steps and locates sign changes on the
/// dense output by bisection to [`EVENT_TIME_TOL`] (MODELS.md §4).
pub(super) struct EventMonitor {
    /// g at the start of the current step.
    before: Vec<f64>,
    after: Vec<f64>,
    probe: Vec<f64>,
    y: Vec<f64>,
}

/// Width of the bracket a located event time lies in [s].
pub const EVENT_TIME_TOL: f64 = 1e-12;

impl EventMonitor {
    pub(super) fn new<M: CableModel<D>, const D: usize>(sys: &ClosedLoop<M, D>, y: &[f64]) -> Self {
        let k = sys.model.event_count();
        let mut monitor = Self {
            before: vec![0.0; k],
            after: vec![0.0; k],
            probe: vec![0.0; k],
            y: vec![0.0; if k > 0 { y.len() } else { 0 }],
        };
        monitor.accept(sys, y);
        monitor
    }

    /// Takes `y` as the start of the next step.
    pub(super) fn accept<M: CableModel<D>, const D: usize>(
        &mut self,
        sys: &ClosedLoop<M, D>,
        y: &[f64],
    ) {
        if !self.before.is_empty() {
            sys.model
                .event_functions(&y[..sys.model_len()], &mut self.before);
        }
    }

    /// The earliest event function that fell from > 0 to ≤ 0 over the last accepted step, with
    /// the first time at which it is ≤ 0 (to within [`EVENT_TIME_TOL`]).
    pub(super) fn earliest_crossing<M: CableModel<D>, const D: usize>(
        &mut self,
        sys: &ClosedLoop<M, D>,
        stepper: &dyn Stepper<ClosedLoop<M, D>>,
    ) -> Option<(usize, f64)> {
        if self.before.is_empty() {
            return None;
        }
        let n = sys.model_len();
        sys.model
            .event_functions(&stepper.state()[..n], &mut self.after);
        let mut earliest: Option<(usize, f64)> = None;
        for k in 0..self.before.len() {
            if !(self.before[k] > 0.0 && self.after[k] <= 0.0) {
                continue;
            }
            let (mut a, mut b) = (stepper.previous_time(), stepper.time());
            while b - a > EVENT_TIME_TOL {
                let mid = 0.5 * (a + b);
                if mid <= a || mid >= b {
                    break;
                }
                stepper.dense_output(mid, &mut self.y);
                sys.model.event_functions(&self.y[..n], &mut self.probe);
                if self.probe[k] > 0.0 {
                    a = mid;
                } else {
                    b = mid;
                }
            }
            if earliest.is_none_or(|(_, t)| b < t) {
                earliest = Some((k, b));
            }
        }
        earliest
    }
}

/// A commanded tension ≤ 0 (or NaN) is a slack cable (the first such cable is named): a
/// tension-controlled winch cannot command it. Reels driven by length (`slack_allowed`) leave a
/// cable slack at zero tension, which is physics, not a failure; a negative or NaN tension still
/// is.
#[inline]
pub(super) fn check_slack(
    t: f64,
    tensions: &Tensions,
    slack_allowed: bool,
) -> Result<(), RunError> {
    let slack = |t: f64| t < 0.0 || (t == 0.0 && !slack_allowed) || t.is_nan();
    match tensions.iter().position(|&t| slack(t)) {
        None => Ok(()),
        Some(i) => Err(RunError::SlackCable {
            t,
            cable: CableId(i),
            tension: tensions[i],
        }),
    }
}
