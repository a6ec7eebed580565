//! Where an error-controlled run stops and restarts: the reference's jumps in velocity or
//! acceleration ([`ClosedLoop::reference_breakpoints`], a print's junctions and phase ends).
//!
//! A step across a jump in the command has a local error that shrinks only as h: the
//! controller's states, advanced by the trapezoidal rule, take half the jump in their rate
//! times h. The error test then cuts the step until it underflows (the FE cube print at
//! t = 9.83 s: a corner's 4 mm/s turn of the reference velocity, h below 5e-13 s). A run that
//! controls its error therefore ends a step just before each jump, where every evaluation sees
//! the reference's old side, and restarts just after it from the same state, where it sees the
//! new side. The state moves by O(v · 2 gap) [m] across the gap of a few picoseconds: far
//! below any tolerance the integrators take.
//!
//! [`ClosedLoop::reference_breakpoints`]: crate::closed_loop::ClosedLoop::reference_breakpoints

/// The half-width of the gap around a jump at `t` [s]: 1 ps, or 4 ulps of t on runs long
/// enough for an ulp to approach it, so that t − gap and t + gap lie on the reference's two
/// sides whatever the rounding of the loop's clock offsets (a few ulps).
pub(super) fn gap(t: f64) -> f64 {
    (4.0 * f64::EPSILON * t.abs()).max(1e-12)
}

/// The jumps still ahead of a run, ascending.
pub(super) struct Stops {
    times: Vec<f64>,
    next: usize,
}

impl Stops {
    /// Stops at `times` (ascending), before `t_end` [s].
    pub(super) fn new(mut times: Vec<f64>, t_end: f64) -> Self {
        times.retain(|&b| b + gap(b) < t_end);
        Self { times, next: 0 }
    }

    /// The first jump whose gap starts after `t` [s] (the clock only moves forward).
    pub(super) fn after(&mut self, t: f64) -> Option<f64> {
        while let Some(&b) = self.times.get(self.next) {
            if b - gap(b) > t {
                return Some(b);
            }
            self.next += 1;
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::{Stops, gap};

    #[test]
    fn the_gap_straddles_the_jump_on_long_clocks() {
        for b in [0.0, 1e-3, 9.83, 3600.0, 86_400.0] {
            assert!(b - gap(b) < b && b < b + gap(b), "{b}");
            assert!(gap(b) <= 1e-12f64.max(1e-15 * b), "{b}: gap {}", gap(b));
        }
    }

    #[test]
    fn stops_come_in_order_and_none_at_the_end() {
        let mut stops = Stops::new(vec![0.5, 1.0, 2.0, 3.0 - 1e-13], 3.0);
        assert_eq!(stops.after(0.0), Some(0.5));
        assert_eq!(stops.after(0.0), Some(0.5), "asking again does not consume");
        assert_eq!(stops.after(0.5 + gap(0.5)), Some(1.0));
        assert_eq!(stops.after(1.5), Some(2.0));
        assert_eq!(
            stops.after(2.0 + gap(2.0)),
            None,
            "a jump within its gap of the end"
        );
    }
}
