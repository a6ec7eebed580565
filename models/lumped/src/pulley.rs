//! The pulley rule of the lumped model (MODELS.md §4), all in one place.
//!
//! Side rule: node P_j of cable i is stored when (P_j − A_i)·e_out,i > 0. Along each cable the
//! stored nodes are 0 … r−1 and the free nodes r … N−1. Two events per cable change r:
//! - the last stored node P_{r−1} reaches the pulley (g_s = (P_{r−1} − A)·e_out falls through 0):
//!   it becomes free at A − ε e_out, velocity kept; r ← r − 1;
//! - the first free node P_r reaches the pulley (g_f = (P_r − A)·e_out rises through 0): it becomes
//!   stored at A + ε e_out with z = ż = 0, ẋ kept; r ← r + 1.
//!
//! A third function per cable watches every other node: a stored node other than the last one
//! leaving the reel, or a free node other than the first one passing the pulley, breaks the
//! ordering the model relies on and stops the run as a modelling error.

use crate::{Lumped, TOWARD_REEL};
use cdpr_core::model::{CableModel, ModelError, ModelEvent};

/// Offset ε that keeps the side rule unambiguous after an event [m].
pub const PULLEY_OFFSET: f64 = 1e-12;

/// Functions per cable: last stored node, first free node, ordering watch.
const PER_CABLE: usize = 3;
/// Event functions of the model.
pub(crate) const EVENT_COUNT: usize = 2 * PER_CABLE;

/// The side rule's signed distance beyond `cable`'s pulley along e_out of a node at x [m]
/// (> 0: on the reel side), as a function of x (the pulley looked up once).
fn beyond_at(model: &Lumped, cable: usize) -> impl Fn(f64) -> f64 {
    let (pulley, e_out) = (model.pulley(cable).x, TOWARD_REEL[cable]);
    move |x| (x - pulley) * e_out
}

/// Signed distance of node j beyond the pulley along e_out (> 0: on the reel side) [m].
pub(crate) fn beyond(model: &Lumped, y: &[f64], cable: usize, j: usize) -> f64 {
    beyond_at(model, cable)(y[model.x_index(cable, j)])
}

/// All event functions, positive while nothing happens (see [`CableModel::event_functions`]).
pub(crate) fn event_functions(model: &Lumped, y: &[f64], out: &mut [f64]) {
    let n = model.elements;
    for cable in 0..2 {
        let r = model.stored()[cable];
        let g = &mut out[PER_CABLE * cable..PER_CABLE * (cable + 1)];
        // The cable's nodes' x, contiguous.
        let start = model.x_index(cable, 0);
        let x = &y[start..start + n];
        let beyond = beyond_at(model, cable);
        g[0] = if r > 0 { beyond(x[r - 1]) } else { 1.0 };
        g[1] = if r < n { -beyond(x[r]) } else { 1.0 };
        // Stored nodes but the last, free nodes but the first.
        let stored_watch = smallest(&x[..r.saturating_sub(1)], &beyond);
        let free_watch = smallest(&x[(r + 1).min(n)..], |xj| -beyond(xj));
        g[2] = stored_watch.min(free_watch).min(1.0);
    }
}

/// min over `x` of `f` (∞ for none), in four independent lanes: a sequential min is a chain of
/// dependent instructions, and this runs at every step. A min is exact, so the lanes change no
/// bit of the result (but the sign of a zero, which the event location, comparing signs, cannot
/// see).
fn smallest(x: &[f64], f: impl Fn(f64) -> f64) -> f64 {
    let mut lanes = [f64::INFINITY; 4];
    let chunks = x.chunks_exact(4);
    let tail = chunks
        .remainder()
        .iter()
        .fold(f64::INFINITY, |m, &v| m.min(f(v)));
    for chunk in chunks {
        for (m, &v) in lanes.iter_mut().zip(chunk) {
            *m = m.min(f(v));
        }
    }
    lanes.into_iter().fold(tail, f64::min)
}

/// The run's stop when `cable`'s last stored node would leave the reel at `t` [s].
pub(crate) fn paid_out(t: f64, cable: usize) -> ModelError {
    ModelError::State {
        t,
        why: format!(
            "cable {} is paid out to its reel end: lengthen cable.modelled_length",
            cable + 1
        ),
    }
}

/// The run's stop when a node of `cable` other than the boundary ones passes its pulley at `t`
/// [s] (`stored` nodes on the reel).
pub(crate) fn out_of_order(t: f64, cable: usize, stored: usize) -> ModelError {
    ModelError::State {
        t,
        why: format!(
            "cable {}: a node passed the pulley out of order (stored nodes must be 0..{stored}); \
             the lumped model's pulley rule does not hold",
            cable + 1
        ),
    }
}

/// Applies event `index` at `t` (see the module documentation).
pub(crate) fn apply_event(
    model: &mut Lumped,
    index: usize,
    t: f64,
    y: &mut [f64],
) -> Result<ModelEvent, ModelError> {
    let (cable, kind) = (index / PER_CABLE, index % PER_CABLE);
    let mut stored = model.stored();
    let r = stored[cable];
    let np = model.positions_len();
    let before = model.energy(y).total();
    let pulley = model.pulley(cable).x;
    let (j, what) = match kind {
        0 => {
            if r == 1 {
                return Err(paid_out(t, cable));
            }
            let j = r - 1;
            y[model.x_index(cable, j)] = pulley - PULLEY_OFFSET * TOWARD_REEL[cable];
            stored[cable] = r - 1;
            (j, "leaves the reel")
        }
        1 => {
            let j = r;
            let (ix, iz) = (model.x_index(cable, j), model.z_index(cable, j));
            y[ix] = pulley + PULLEY_OFFSET * TOWARD_REEL[cable];
            y[iz] = 0.0;
            y[np + iz] = 0.0;
            stored[cable] = r + 1;
            (j, "is reeled in")
        }
        _ => return Err(out_of_order(t, cable, r)),
    };
    model.set_stored(stored);
    Ok(ModelEvent {
        t,
        cable: cable + 1,
        what: format!("node {j} {what}"),
        energy_change: model.energy(y).total() - before,
    })
}
