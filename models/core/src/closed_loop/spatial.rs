//! A spatial robot's move (MODELS.md §11): the reference runs eq. 13 along the straight
//! segment `trajectory.start` → `end` (convolved with the shaper's impulses), and the loop starts
//! at rest at the start pose, under the tensions the controller commands there at zero error —
//! for a redundant robot its distribution of the weight.

use super::ClosedLoop;
use super::rest::LoopError;
use crate::controller::{Controller, Reference};
use crate::model::{CableModel, Equilibrium, PoseRule};
use crate::print_path::PrintPath;
use crate::robot::{Effector, Vector, height};
use crate::scenario::Scenario;
use crate::shaper::Impulses;
use crate::trajectory::Segment;
use std::sync::Arc;

/// What a spatial robot (or a printing robot) follows: one `step5` move, or a printed path.
#[derive(Debug, Clone)]
pub enum Path<const D: usize> {
    /// eq. 13 along a segment, convolved with the loop's shaper.
    Move(Segment<D>),
    /// The firmware's plan, each axis shaped by its own shaper.
    Print(Arc<PrintPath<D>>),
}

impl<const D: usize> Path<D> {
    /// Where the path starts [m].
    pub fn start(&self) -> Vector<D> {
        match self {
            Path::Move(s) => s.start,
            Path::Print(p) => p.start(),
        }
    }

    /// Where it ends [m].
    pub fn end(&self) -> Vector<D> {
        match self {
            Path::Move(s) => s.end,
            Path::Print(p) => p.end(),
        }
    }

    /// p_ref, ṗ_ref, p̈_ref at t [s] (ṗ, p̈ zero unless `derivatives`); `shaper` shapes a move.
    #[inline]
    pub fn reference(
        &self,
        shaper: Option<&Impulses>,
        t: f64,
        derivatives: bool,
    ) -> [Vector<D>; 3] {
        match self {
            Path::Move(s) => s.shaped(shaper, t, derivatives),
            Path::Print(p) => p.reference(t, derivatives),
        }
    }

    /// The move, if this is one.
    pub fn as_move(&self) -> Option<&Segment<D>> {
        match self {
            Path::Move(s) => Some(s),
            Path::Print(_) => None,
        }
    }
}

/// The scenario's spatial move, for a robot in space with three or more cables (two cables in
/// space run the plane's move, x1 → x2, with the paper's PID).
pub(super) fn path<const D: usize>(scenario: &Scenario, cables: usize) -> Option<Path<D>> {
    if D != 3 || cables < 3 {
        return None;
    }
    let (start, end) = scenario.trajectory.spatial_move().ok()?;
    let t = &scenario.trajectory;
    Some(Path::Move(Segment {
        start: Vector::from_iterator(start),
        end: Vector::from_iterator(end),
        t1: t.t1,
        t2: t.t2,
    }))
}

impl<M: CableModel<D>, const D: usize> ClosedLoop<M, D> {
    /// p_ref, ṗ_ref, p̈_ref at t [s] along `path`, shaped (ṗ, p̈ zero for controllers without
    /// feedforward).
    #[inline]
    pub(super) fn path_reference(&self, path: &Path<D>, t: f64) -> Reference<D> {
        let [position, velocity, acceleration] =
            path.reference(self.shaper.as_ref(), t, self.feedforward);
        Reference {
            position,
            velocity,
            acceleration,
        }
    }

    /// At rest at the path's start: the controller's tensions there at zero error and zero
    /// states (clamped to the limits), the model's statics under them — refused by the model
    /// when they do not hold the effector — and the controller's states holding them.
    pub(super) fn start_of_path(
        &mut self,
        path: &Path<D>,
    ) -> Result<(Vec<f64>, Equilibrium), LoopError> {
        let start = path.start();
        self.hold = Some(start);
        self.controller.start_at(&start);
        // A controller designed at a point (the LQR) is designed at the end of the move.
        self.controller.hold_height(height(&path.end()))?;
        let reference = self.path_reference(path, 0.0);
        let effector = Effector {
            position: start,
            velocity: Vector::zeros(),
        };
        let states = vec![0.0; self.controller_len()];
        let out = self.controller.output(&reference, &effector, &states);
        let (tensions, _) = self.limits.clamp(&out.tensions);
        let eq = self.model.equilibrium(&PoseRule::new(&start, tensions))?;
        let y = self.assemble_at(&reference, &eq);
        Ok((y, eq))
    }
}
