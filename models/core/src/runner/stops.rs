//! Where an error-controlled run stops and restarts: the reference's jumps in velocity or
//! acceleration ([`ClosedLoop::reference_breakpoints`], a print's junctions and phase ends).
//!
//! A step across a jump in the command has a local error that shrinks only as h: the
//! controller's states, advanced by the trapezoidal rule, take half the jump in their rate
//! times h. The error test then cuts the step until it underflows (a print corner's 4 mm/s turn
//! of the reference velocity takes h below 5e-13 s at atol 1e-9). A run that
//! controls its error therefore ends a step just before each jump, where every evaluation sees
//! the reference's old side, and restarts just after it from the same state, where it sees the
//! new side. The state moves by O(v · 2 gap) [m] across the gap of a few picoseconds: far
//! below any tolerance the integrators take.
//!
//! [`ClosedLoop::reference_breakpoints`]: crate::closed_loop::ClosedLoop::reference_breakpoints

/// The half-width of the gap around a jump at `t` [s]: 1 ps, or 16 ulps of t on runs long
/// enough for an ulp to approach it, so that t − gap and t + gap lie on the reference's two
/// sides whatever the rounding of the loop's clock offsets (a few ulps).
pub(super) fn gap(t: f64) -> f64 {
    (16.0 * f64::EPSILON * t.abs()).max(1e-12)
}

/// Jumps closer than this many gaps share one window: a step between two windows shorter than
/// a few gaps would be a sliver no integrator can take (DOPRI5 and the implicit path end a run
/// on steps below round-off of t, or below 1e-12 s).
const MERGE_GAPS: f64 = 8.0;

/// A window around one jump or a cluster of close ones [s]: the run stops at `stop`, before
/// all of them, and restarts at `resume`, after all of them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Window {
    pub stop: f64,
    pub resume: f64,
}

/// The windows still ahead of a run, ascending.
pub(super) struct Stops {
    windows: Vec<Window>,
    next: usize,
}

impl Stops {
    /// Windows around the jumps `times` (ascending) that end before `t_end` [s].
    pub(super) fn new(times: Vec<f64>, t_end: f64) -> Self {
        let mut windows: Vec<Window> = Vec::with_capacity(times.len());
        for b in times {
            match windows.last_mut() {
                Some(w) if b - w.resume < MERGE_GAPS * gap(b) => {
                    w.resume = w.resume.max(b + gap(b))
                }
                _ => windows.push(Window {
                    stop: b - gap(b),
                    resume: b + gap(b),
                }),
            }
        }
        windows.retain(|w| w.resume < t_end);
        Self { windows, next: 0 }
    }

    /// The first window whose stop lies after `t` [s] (the clock only moves forward).
    pub(super) fn after(&mut self, t: f64) -> Option<Window> {
        while let Some(&w) = self.windows.get(self.next) {
            if w.stop > t {
                return Some(w);
            }
            self.next += 1;
        }
        None
    }
}

/// Where a run restarts after an event at `t` [s] located in a step aimed at `window`'s stop:
/// past the window when the event lies within a few gaps of the stop (the step left before it
/// would be a sliver), at the event otherwise.
pub(super) fn restart_after_event(t: f64, window: Option<Window>) -> f64 {
    match window {
        Some(w) if w.stop - t < MERGE_GAPS * gap(w.stop) => w.resume,
        _ => t,
    }
}

#[cfg(test)]
mod tests {
    use super::{MERGE_GAPS, Stops, Window, gap, restart_after_event};

    #[test]
    fn the_gap_straddles_the_jump_on_long_clocks() {
        for b in [0.0, 1e-3, 9.83, 3600.0, 86_400.0] {
            assert!(b - gap(b) < b && b < b + gap(b), "{b}");
            assert!(gap(b) <= 1e-12f64.max(4e-15 * b), "{b}: gap {}", gap(b));
        }
    }

    #[test]
    fn windows_come_in_order_and_none_at_the_end() {
        let mut stops = Stops::new(vec![0.5, 1.0, 2.0, 3.0 - 1e-13], 3.0);
        let w = |b: f64| Window {
            stop: b - gap(b),
            resume: b + gap(b),
        };
        assert_eq!(stops.after(0.0), Some(w(0.5)));
        assert_eq!(
            stops.after(0.0),
            Some(w(0.5)),
            "asking again does not consume"
        );
        assert_eq!(stops.after(0.5 + gap(0.5)), Some(w(1.0)));
        assert_eq!(stops.after(1.5), Some(w(2.0)));
        assert_eq!(
            stops.after(2.0 + gap(2.0)),
            None,
            "a jump within its gap of the end"
        );
    }

    #[test]
    fn close_jumps_share_a_window() {
        let g = gap(1.0);
        let mut stops = Stops::new(vec![1.0, 1.0 + 3.0 * g, 1.0 + 20.0 * g], 2.0);
        let first = stops.after(0.0).unwrap();
        assert_eq!(first.stop, 1.0 - g);
        let after_second = (1.0 + 3.0 * g) + g;
        assert_eq!(first.resume, after_second, "after the second jump's gap");
        let second = stops.after(first.resume).unwrap();
        assert!(
            second.stop - first.resume >= (MERGE_GAPS - 2.0) * g,
            "no sliver between"
        );
    }

    #[test]
    fn an_event_by_the_stop_restarts_past_the_window() {
        let w = Window {
            stop: 1.0 - gap(1.0),
            resume: 1.0 + gap(1.0),
        };
        assert_eq!(restart_after_event(w.stop, Some(w)), w.resume);
        assert_eq!(restart_after_event(w.stop - 1e-13, Some(w)), w.resume);
        assert_eq!(restart_after_event(0.5, Some(w)), 0.5);
        assert_eq!(restart_after_event(0.5, None), 0.5);
    }
}
