//! The parts the implicit integrator's iteration matrix is weighted from,
//! S = c_q ∂R/∂q + c_v ∂R/∂q' + ∂R/∂q'', kept by a model between evaluations so that a new step
//! size (new c_q, c_v) re-weights them instead of evaluating the model again.
//!
//! Each entry is kept as the difference quotient its model took, numerator and width apart, and
//! weighted by [`weighted_entry`] — the very operations an evaluation at those weights performs —
//! so the re-weighted matrix equals, to the bit, the one the model would give at the same state
//! with the new weights. Only the state is old: the matrix is as stale as one kept across steps
//! of equal size.

/// c_q · ∂R/∂q + c_v · ∂R/∂q' + ∂R/∂q'' of one entry from its three difference quotients
/// `numerators[k] / widths[k]` (k: q, q', q''), summed from 0 in that order; a zero weight's
/// quotient is skipped (it may not have been taken).
#[inline(always)]
pub fn weighted_entry(weights: [f64; 3], numerators: [f64; 3], widths: [f64; 3]) -> f64 {
    let mut value = 0.0;
    for k in 0..3 {
        if weights[k] != 0.0 {
            value += weights[k] * numerators[k] / widths[k];
        }
    }
    value
}

/// The three difference quotients of every entry of the iteration pattern, as the last complete
/// evaluation left them (see the module documentation).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MatrixParts {
    numerators: [Vec<f64>; 3],
    widths: [Vec<f64>; 3],
    /// Whether every entry's three quotients were taken (an evaluation with a zero weight skips
    /// one, and a model's structural change, such as a pulley event, voids them).
    complete: bool,
}

impl MatrixParts {
    /// Room for `len` entries, none kept yet.
    pub fn start(&mut self, len: usize) {
        for v in self.numerators.iter_mut().chain(self.widths.iter_mut()) {
            v.resize(len, 0.0);
        }
        self.complete = false;
    }

    /// Entry `at`'s quotients for q, q', q''.
    #[inline(always)]
    pub fn set(&mut self, at: usize, numerators: [f64; 3], widths: [f64; 3]) {
        for k in 0..3 {
            self.numerators[k][at] = numerators[k];
            self.widths[k][at] = widths[k];
        }
    }

    /// Every entry has been set since [`Self::start`].
    pub fn finish(&mut self) {
        self.complete = true;
    }

    /// Forgets the parts (the model's structure or pattern values changed).
    pub fn void(&mut self) {
        self.complete = false;
    }

    /// S at `weights` = [c_q, c_v, 1] into `values` (the pattern's length); false, and `values`
    /// untouched, if no complete evaluation of that length is kept.
    pub fn weigh(&self, weights: [f64; 3], values: &mut [f64]) -> bool {
        if !self.complete || values.len() != self.numerators[0].len() {
            return false;
        }
        let [n_q, n_v, n_a] = &self.numerators;
        let [w_q, w_v, w_a] = &self.widths;
        for (at, value) in values.iter_mut().enumerate() {
            *value = weighted_entry(
                weights,
                [n_q[at], n_v[at], n_a[at]],
                [w_q[at], w_v[at], w_a[at]],
            );
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn re_weighting_equals_weighting_as_taken() {
        let mut parts = MatrixParts::default();
        let mut values = vec![0.0; 2];
        assert!(
            !parts.weigh([1.0, 1.0, 1.0], &mut values),
            "nothing kept yet"
        );
        parts.start(2);
        parts.set(0, [3.0, -1.0, 0.7], [1e-6, 2e-6, 1.0]);
        parts.set(1, [1e-3, 0.0, 2.0], [3e-6, 1e-6, 2.0]);
        assert!(!parts.weigh([1.0, 1.0, 1.0], &mut values), "not finished");
        parts.finish();
        for weights in [[2.5e-9, 5e-5, 1.0], [1.0, 0.0, 0.0], [0.3, 0.1, 1.0]] {
            assert!(parts.weigh(weights, &mut values));
            let direct = weighted_entry(weights, [3.0, -1.0, 0.7], [1e-6, 2e-6, 1.0]);
            assert_eq!(values[0].to_bits(), direct.to_bits());
        }
        // c_q K alone: the q'' quotient skipped, so the entry is the stiffness's.
        assert!(parts.weigh([1.0, 0.0, 0.0], &mut values));
        assert_eq!(values[1], 1e-3 / 3e-6);
        parts.void();
        assert!(!parts.weigh([1.0, 1.0, 1.0], &mut values));
        assert!(
            !parts.weigh([1.0, 1.0, 1.0], &mut [0.0; 3]),
            "another pattern"
        );
    }
}
