//! Frames of the cables' lines during a run, for drawings and animations: on the grid
//! t_k = k·Δt_frame from the dense output, each cable's points from
//! [`CableModel::cable_paths`]. Taken only when an observer asks for them.

use crate::closed_loop::ClosedLoop;
use crate::model::CableModel;
use cdpr_numerics::Stepper;

/// Receives one frame: its time [s] and, per cable, the points of its line from the pulley to
/// the effector, D coordinates each [m].
pub type FrameSink<'a> = dyn FnMut(f64, &[Vec<f64>]) + 'a;

/// Frames every `period` [s] handed to `sink` (a period that is not positive takes none).
pub struct Frames<'a> {
    pub period: f64,
    pub sink: &'a mut FrameSink<'a>,
}

/// The next frame's index and a state buffer, kept through the run.
#[derive(Default)]
pub(super) struct FrameClock {
    next: usize,
    y: Vec<f64>,
}

impl FrameClock {
    /// Hands every frame at or before `t` not yet taken to `frames`' sink.
    pub(super) fn take_through<M: CableModel<D>, const D: usize>(
        &mut self,
        sys: &ClosedLoop<M, D>,
        stepper: &dyn Stepper<ClosedLoop<M, D>>,
        t: f64,
        frames: &mut Option<Frames>,
    ) {
        let Some(frames) = frames.as_mut() else {
            return;
        };
        if frames.period.is_nan() || frames.period <= 0.0 {
            return;
        }
        self.y.resize(stepper.state().len(), 0.0);
        loop {
            let tk = self.next as f64 * frames.period;
            if tk > t {
                break;
            }
            if tk == stepper.time() {
                self.y.copy_from_slice(stepper.state());
            } else {
                stepper.dense_output(tk, &mut self.y);
            }
            let paths: Vec<Vec<f64>> = sys
                .model
                .cable_paths(&self.y[..sys.model_len()])
                .iter()
                .map(|points| points.iter().flat_map(|p| p.iter().copied()).collect())
                .collect();
            (frames.sink)(tk, &paths);
            self.next += 1;
        }
    }
}
