//! The pulley rule of the spatial lumped model: MODELS.md §4's rule with e_out,i the cable's reel
//! direction r_i.
//!
//! Side rule: node P_j of cable i is stored when (P_j − A_i)·r_i > 0. Two events per cable
//! change r:
//! - the last stored node P_{r−1} reaches the pulley ((P_{r−1} − A)·r_i falls through 0): it
//!   becomes free at A − ε r_i, velocity kept (it lies along r_i); r ← r − 1;
//! - the first free node P_r reaches the pulley ((P_r − A)·r_i rises through 0): it becomes
//!   stored at A + ε r_i, its velocity reduced to the component along r_i (the guide takes the
//!   rest: the recorded energy change), or on a locked or driven reel set to the reel's speed;
//!   r ← r + 1.
//!
//! A third function per cable watches every other node; one passing the pulley out of order
//! stops the run as a modelling error.

use super::LumpedSpatial;
use crate::PULLEY_OFFSET;
use cdpr_core::model::{CableModel, ModelError, ModelEvent};
use nalgebra::Vector3;

/// Functions per cable: last stored node, first free node, ordering watch.
pub(super) const PER_CABLE: usize = 3;

/// All event functions, positive while nothing happens. Each cable's signed distances beyond its
/// pulley come from its three contiguous coordinate slices in one sweep (this runs at every
/// step).
pub(super) fn event_functions(model: &LumpedSpatial, y: &[f64], out: &mut [f64]) {
    let n = model.elements;
    for cable in 0..model.robot().cables() {
        let r = model.stored()[cable];
        let (a, reel) = (model.pulley(cable), model.reel(cable));
        let offset = a.dot(&reel);
        let at = |axis: usize| &y[model.index(cable, 0, axis)..][..n];
        let (x, yy, z) = (at(0), at(1), at(2));
        let beyond = |j: usize| x[j] * reel.x + yy[j] * reel.y + z[j] * reel.z - offset;
        let g = &mut out[PER_CABLE * cable..PER_CABLE * (cable + 1)];
        g[0] = if r > 0 { beyond(r - 1) } else { 1.0 };
        g[1] = if r < n { -beyond(r) } else { 1.0 };
        let stored_watch = (0..r.saturating_sub(1))
            .map(beyond)
            .fold(f64::INFINITY, f64::min);
        let free_watch = ((r + 1).min(n)..n)
            .map(|j| -beyond(j))
            .fold(f64::INFINITY, f64::min);
        g[2] = stored_watch.min(free_watch).min(1.0);
    }
}

/// Writes node `j` of `cable`'s position and velocity into `y`.
fn place(
    model: &LumpedSpatial,
    y: &mut [f64],
    cable: usize,
    j: usize,
    p: Vector3<f64>,
    v: Vector3<f64>,
) {
    let np = model.positions_len();
    for axis in 0..3 {
        let i = model.index(cable, j, axis);
        y[i] = p[axis];
        y[np + i] = v[axis];
    }
}

/// Applies event `index` at `t` (see the module documentation).
pub(super) fn apply_event(
    model: &mut LumpedSpatial,
    index: usize,
    t: f64,
    y: &mut [f64],
) -> Result<ModelEvent, ModelError> {
    let (cable, kind) = (index / PER_CABLE, index % PER_CABLE);
    let mut stored = model.stored().to_vec();
    let r = stored[cable];
    let before = model.energy(y).total();
    let (pulley, reel) = (model.pulley(cable), model.reel(cable));
    let (j, what) = match kind {
        0 => {
            if r == 1 {
                return Err(crate::pulley::paid_out(t, cable));
            }
            let j = r - 1;
            let v = model.node_velocity(y, cable, j);
            place(model, y, cable, j, pulley - reel * PULLEY_OFFSET, v);
            stored[cable] = r - 1;
            (j, "leaves the reel")
        }
        1 => {
            let j = r;
            let v = model.node_velocity(y, cable, j);
            place(
                model,
                y,
                cable,
                j,
                pulley + reel * PULLEY_OFFSET,
                reel * v.dot(&reel),
            );
            stored[cable] = r + 1;
            (j, "is reeled in")
        }
        _ => return Err(crate::pulley::out_of_order(t, cable, r)),
    };
    model.set_stored(&stored);
    if kind == 1
        && let Some((speed, _)) = model.reel_command(y, cable)
    {
        // A locked or driven reel takes the node at its own speed.
        place(
            model,
            y,
            cable,
            j,
            pulley + reel * PULLEY_OFFSET,
            reel * speed,
        );
    }
    Ok(ModelEvent {
        t,
        cable: cable + 1,
        what: format!("node {j} {what}"),
        energy_change: model.energy(y).total() - before,
    })
}
