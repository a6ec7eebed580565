//! The lookahead queue (Klipper's `LookAheadQueue`): moves wait until enough follow them that
//! their speeds can no longer change, then leave with their trapezoids.
//!
//! The backward pass walks from the newest move assuming a stop after it: each move may start
//! no faster than its junction limit and than it can brake to the next move's start
//! (v²_start ≤ v²_next + 2 d a). A second, slower budget (the pseudo-acceleration
//! a (1 − minimum_cruise_ratio)) decides where a move may accelerate and decelerate: its peak
//! cruise² is the mean of the two budgets' ends, so a short move between fast ones does not
//! spike. The forward pass gives moves that cannot accelerate the cruise of the move before.
//! A lazy flush (the queue has reached its time budget) releases only the moves before the last
//! peak, whose speeds no later move can change.

use super::moves::QueuedMove;

/// Klipper's LOOKAHEAD_FLUSH_TIME [s]: the queue's time budget after a flush.
pub(crate) const FLUSH_TIME: f64 = 0.150;
/// Klipper's BUFFER_TIME_HIGH [s]: the budget after the toolhead stopped (start, dwell).
pub(crate) const FLUSH_TIME_AFTER_STOP: f64 = 1.0;

/// The queue and its time budget.
#[derive(Debug, Clone, Default)]
pub(crate) struct Lookahead {
    pub queue: Vec<QueuedMove>,
    pub junction_flush: f64,
    /// Per move of the backward pass: start², cruise² (None: cannot accelerate), next start².
    junctions: Vec<(f64, Option<f64>, f64)>,
}

impl Lookahead {
    pub fn new() -> Self {
        Lookahead {
            junction_flush: FLUSH_TIME_AFTER_STOP,
            ..Default::default()
        }
    }

    /// Queues a move (its junction with the last one computed); true when the time budget is
    /// spent and a lazy flush is due.
    pub fn add(&mut self, mut m: QueuedMove, instant_corner_v: f64) -> bool {
        let Some(prev) = self.queue.last() else {
            self.queue.push(m);
            return false;
        };
        m.calc_junction(prev, instant_corner_v);
        self.junction_flush -= m.min_move_t;
        self.queue.push(m);
        self.junction_flush <= 0.0
    }

    /// Plans the queue (all of it, ending at rest, unless `lazy`) and moves the planned moves,
    /// in order, to `out`.
    pub fn flush(&mut self, lazy: bool, out: &mut Vec<QueuedMove>) {
        self.junction_flush = FLUSH_TIME;
        let mut update_flush_count = lazy;
        let mut flush_count = self.queue.len();
        self.junctions.clear();
        self.junctions.resize(flush_count, (0.0, None, 0.0));
        let (mut next_start_v2, mut next_mcr_start_v2, mut peak_cruise_v2) = (0.0, 0.0, 0.0);
        let mut pending = 0usize;
        for i in (0..flush_count).rev() {
            let m = &self.queue[i];
            let reachable_start_v2 = next_start_v2 + m.delta_v2;
            let start_v2 = m.max_start_v2.min(reachable_start_v2);
            let mut cruise_v2 = None;
            pending += 1;
            let reach_mcr_start_v2 = next_mcr_start_v2 + m.mcr_delta_v2;
            let mcr_start_v2 = m.max_mcr_start_v2.min(reach_mcr_start_v2);
            if mcr_start_v2 < reach_mcr_start_v2 {
                // The move may accelerate: it peaks here if it can also decelerate, or if a
                // full acceleration meets a full deceleration.
                if mcr_start_v2 + m.mcr_delta_v2 > next_mcr_start_v2 || pending > 1 {
                    if update_flush_count && peak_cruise_v2 != 0.0 {
                        flush_count = i + pending;
                        update_flush_count = false;
                    }
                    peak_cruise_v2 = (mcr_start_v2 + reach_mcr_start_v2) * 0.5;
                }
                cruise_v2 = Some(
                    ((start_v2 + reachable_start_v2) * 0.5)
                        .min(m.max_cruise_v2)
                        .min(peak_cruise_v2),
                );
                pending = 0;
            }
            self.junctions[i] = (start_v2, cruise_v2, next_start_v2);
            next_start_v2 = start_v2;
            next_mcr_start_v2 = mcr_start_v2;
        }
        if update_flush_count || flush_count == 0 {
            return;
        }
        let mut prev_cruise_v2 = 0.0f64;
        for (m, &(start_v2, cruise_v2, next_start_v2)) in
            self.queue[..flush_count].iter_mut().zip(&self.junctions)
        {
            let cruise_v2 = cruise_v2.unwrap_or(prev_cruise_v2.min(start_v2));
            m.set_junction(
                start_v2.min(cruise_v2),
                cruise_v2,
                next_start_v2.min(cruise_v2),
            );
            prev_cruise_v2 = cruise_v2;
        }
        out.extend(self.queue.drain(..flush_count));
    }
}
